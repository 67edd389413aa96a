"""c_printer: shared factors leave sums (fewer products, same value)."""
import sympy as sp


def test_factor_common_takes_a_shared_factor_out_of_a_sum():
    from derive.codegen.c_printer import factor_common
    a, b, x, y, z = sp.symbols("a b x y z", real=True)
    assert factor_common(a * x + a * y + b) == a * (x + y) + b
    nested = a * b * x + a * b * y + a * z + 3 * a**2 * x
    factored = factor_common(nested)
    assert sp.expand(factored - nested) == 0
    assert sp.count_ops(factored, visual=True).coeff(sp.Symbol("MUL")) < \
        sp.count_ops(nested, visual=True).coeff(sp.Symbol("MUL"))
