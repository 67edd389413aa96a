"""newton_euler: the body-by-body form of f equals the Euler-Poincare form."""
import sympy as sp

from derive import dynamics as D
from derive import newton_euler as NE


def test_body_by_body_rhs_equals_the_euler_poincare_rhs():
    assert NE.check_equal_to_rhs() == [0] * 5


def test_body_by_body_check_can_fail():
    """Dropping one intermediate (the yoke's bias torque) leaves a residual that does not reduce to zero."""
    p, f = NE.program()
    p.definitions = [(s, 0 if s.name.startswith("tau_Y") else value) for s, value in p.definitions]
    wrong = p.inline(f)
    assert D.on_manifold(sp.expand(wrong[0] - D.rhs()[0])) != 0


def test_program_inlines_to_one_expression_in_the_state_symbols():
    p, f = NE.program()
    defined = {s for s, _ in p.definitions}
    assert defined and not (p.inline(f).free_symbols & defined)


def test_the_general_robots_body_by_body_rhs_equals_the_euler_poincare_rhs():
    assert NE.check_general_equal_to_rhs() == [0] * 5


def test_the_general_check_can_fail_for_a_missing_rotor():
    """Dropping the pendulum motor's rotor (s_rP) leaves a residual in the pendulum's row."""
    from derive import robot as R
    p, f = NE.general_program()
    p.definitions = [(s, 0 if s.name.startswith("s_rP") else value) for s, value in p.definitions]
    assert D.on_manifold(sp.expand(p.inline(f)[4] - D.rhs(R.GENERAL)[4])) != 0
