"""derive/sensors.py: the derivation's forms mean what the docs say (closed forms checked
symbolically; the numbers are checked against the independent reference in tests/runtime/verification)."""
import sympy as sp

from derive import sensors as SE
from derive import state as S
from derive.dynamics import on_manifold


def test_the_centres_acceleration_in_the_shell_frame_is_r_nu_dot_cross_gamma():
    expected = SE.radius * SE.nu_dot[0:3, 0].cross(S.gamma)
    assert (SE.centre_acceleration() - expected).applyfunc(sp.expand) == sp.zeros(3, 1)


def test_the_yokes_rate_is_the_shells_turned_back_plus_its_joints():
    expected = S.R_Y.T * S.w_S + sp.Matrix([S.w_Y, 0, 0])
    assert (SE.angular_velocity("yoke") - expected).applyfunc(on_manifold) == sp.zeros(3, 1)


def test_at_rest_the_specific_force_is_gravity_reversed_in_the_body_frame():
    rest = {s: 0 for s in list(S.nu) + list(SE.nu_dot)}
    for body in SE.BODIES:
        reading = SE.specific_force(body).xreplace(rest)
        expected = SE.to_body(body, SE.g_x * S.chi + SE.g_z * S.gamma)
        assert (reading - expected).applyfunc(sp.expand) == sp.zeros(3, 1)


def test_only_the_accelerometer_reads_nu_dot_and_the_biases_enter_as_identities():
    H, Hn = SE.imu_jacobians("shell")
    assert Hn[0:3, :] == sp.zeros(3, 5)
    assert H[:, S.NE:] == sp.eye(6)


def test_the_encoder_and_position_jacobians_pick_their_coordinates():
    E, P = SE.encoders_jacobian(), SE.position_jacobian()
    assert E == sp.Matrix(2, SE.NEB, lambda i, j: int(j == 3 + i))
    assert P == sp.Matrix(2, SE.NEB, lambda i, j: int(j == 5 + i))
