"""kernels: only proven forms of f are emitted."""
import pytest
import sympy as sp


def test_code_generation_refuses_an_unproven_form():
    from derive.codegen.kernels import proven
    with pytest.raises(ValueError, match="differs from the derivation"):
        proven("test", [0, sp.Symbol("x")])
