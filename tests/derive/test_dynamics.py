"""dynamics: structure of M and f, and the equilibrium set of eq. (108)."""
import sympy as sp

from derive import dynamics as D
from derive import lagrangian as L
from derive import state as S


def test_inertia_is_symmetric():
    M = D.inertia()
    assert (M - M.T).applyfunc(sp.expand) == sp.zeros(5, 5)


def test_kinetic_energy_is_half_nu_M_nu():
    k_c = L.constrained_kinetic_energy()
    quad = (S.nu.T * D.inertia() * S.nu)[0] / 2
    assert D.on_manifold(k_c - quad) == 0


def test_reduction_on_the_manifold_keeps_values_on_valid_states():
    k_c = L.constrained_kinetic_energy()
    reduced = D.on_manifold(k_c)
    point = {S.RY_c: sp.Rational(3, 5), S.RY_s: sp.Rational(4, 5), S.RP_c: sp.Rational(5, 13),
             S.RP_s: sp.Rational(-12, 13), S.gamma[0]: sp.Rational(2, 3), S.gamma[1]: sp.Rational(-1, 3),
             S.gamma[2]: sp.Rational(2, 3)}
    assert sp.expand((k_c - reduced).subs(point)) == 0
    assert reduced != sp.expand(k_c)


def test_inertia_does_not_depend_on_speeds_or_inputs():
    free = set().union(*(m.free_symbols for m in D.inertia()))
    assert free.isdisjoint(set(S.nu) | set(S.u))


def test_rhs_is_affine_in_the_motor_torques_with_unit_coefficients():
    f = D.rhs()
    J = f.jacobian(S.u)
    assert J == sp.Matrix([[0, 0], [0, 0], [0, 0], [1, 0], [0, 1]])


def test_equilibrium_residual_vanishes_exactly_on_eq_108():
    assert D.check_equilibrium_set() == [0] * 7


def test_equilibrium_check_can_fail():
    """The identity check is not vacuous: a perturbed residual does not pass it."""
    res = D.equilibrium_residual()
    a = D.pendulum_axis()
    wrong = sp.expand(res[0] - 2 * D.cross(a, S.gamma)[0])
    assert wrong != 0


def test_yoke_and_pendulum_rates_do_not_couple():
    """M_34 = 0 is what lets the accel kernel eliminate the joint accelerations first."""
    assert D.inertia()[3, 4] == 0
