"""Symbolic derivation of the spherical-robot model of S. Fiori (2024).

Pipeline: parameters (Section 2.3) -> state in matrix form (2.6-2.7) ->
Lagrangians ℓ and ℓ_c (eqs. 36, 41) -> M and f (Sections 3-4) -> C
(codegen).  Run ``python -m derive`` (``make generate``) to rewrite generated/.
"""
