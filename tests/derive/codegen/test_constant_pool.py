"""constant_pool: parameter-only subexpressions leave the kernels and come back equal."""
import sympy as sp


def test_constant_pool_moves_parameter_only_subexpressions_out_of_the_kernels():
    from derive import parameters as P
    from derive.codegen.constant_pool import ConstantPool
    from derive.state import gamma
    pool = ConstantPool(P.CONSTANTS)
    expr = P.l * P.m_P * P.r / 2 * gamma[0] - P.l * P.m_P * P.r / 2 * gamma[1] + P.j_P + P.j_S
    hoisted = pool.hoist(expr)
    assert hoisted.free_symbols <= {gamma[0], gamma[1], *pool.symbols()}
    assert len(pool.symbols()) == 2          # l m_P r / 2 (once, for both signs) and j_P + j_S
    back = hoisted.xreplace(dict(zip(pool.symbols(), pool.expressions())))
    assert sp.expand(back - expr) == 0
