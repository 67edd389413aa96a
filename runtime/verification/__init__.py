"""Verification: everything the kernels are checked against.

`reference` (the independent CasADi model; imports nothing from derive/, bindings or the kernels),
`alternatives.kane` (the same robot in sympy.physics.mechanics), `paper_formulas` (the paper's matrix
formulas in NumPy, errata switchable), `sensor_reference` (the sensors as an independent CasADi
model, as independent as `reference`) and `sensor_checks` (the C sensors against it), `errata` (the
evidence table of docs/errata.md), `verify` (`python -m runtime verify`), `convergence` (orders and
drift of the integrators), `soak` (long runs), `sampling` (random states, inputs and parameter sets).
"""
