"""The LQR's design model (runtime/control/lqr_design.py) against independent computations: the
Floquet exponents of the full model's periodic motion, the stability module's steady rolling, and a
simulation of the full model from a turn's operating point."""
import numpy as np
import pytest

from runtime.control import lqr_design as design
from runtime import stability
from runtime.model import Model
from runtime.params import Params
from runtime.state import IDX_Q

MODEL = Model(Params.paper_simulation())


def reduced_exponents(field=design.field, v=0.5):
    z, u = design.operating_point(MODEL, v)
    A, _ = design.linearization(MODEL, z, u, v)
    ev = np.linalg.eigvals(A[:design.NZ_ROBOT, :design.NZ_ROBOT])
    return np.sort(ev[np.abs(ev) > 1e-7].real)


def floquet_real_parts(v=0.5):
    return np.sort(stability.nontrivial(stability.floquet_exponents(MODEL, v), 1e-6).real)


def test_reduced_eigenvalues_at_straight_rolling_are_the_floquet_exponents_of_the_full_model():
    # Two routes to the same stability: the reduced chart's linearisation at its equilibrium, and
    # the monodromy of the full model's RKMK4 step Jacobians over one period (stability.py).
    a, b = reduced_exponents(), floquet_real_parts()
    assert a.shape == b.shape == (8,)
    assert np.abs(a - b).max() < 1e-6


def test_the_floquet_comparison_fails_for_a_field_with_a_slightly_wrong_transport_term(monkeypatch):
    true_field = design.field

    def perturbed(model, z, u, v, kappa, z_star_om_x=0.0):
        out = true_field(model, z, u, v, kappa, z_star_om_x)
        x = design.lift(z, v, model.params.r)
        w_S, w_Y = x[design.IDX_WS], x[design.IDX_WY]
        out[design.Z_OM] -= 1e-4 * np.cross([w_Y, 0.0, 0.0], w_S)   # the term −ω_Y e_x × Ω, 1e-4 too large
        return out

    monkeypatch.setattr(design, "field", perturbed)
    a = reduced_exponents()
    monkeypatch.undo()
    assert np.abs(a - floquet_real_parts()).max() > 1e-6


def test_the_straight_operating_point_is_the_stability_modules_steady_rolling():
    v = 0.4
    z, u = design.operating_point(MODEL, v)
    x, u_ref = stability.steady_rolling(MODEL, -v)     # its speed is signed along +x of the shell
    p = MODEL.params
    assert np.isclose(z[0], np.arcsin(x[stability.SIN_ALPHA]), rtol=0, atol=1e-10)   # the yoke's tilt
    assert np.allclose(z[1:], 0.0, atol=1e-10)
    assert np.allclose(u, [v * (p.k_S + p.k_Y) / p.r, 0.0], rtol=0, atol=1e-10)
    assert np.isclose(u[0], u_ref[0], rtol=1e-10)


def circle_radius(points):
    """Least-squares circle through points (n, 2) (Kåsa's algebraic fit): its radius and the RMS residual."""
    A = np.column_stack([2 * points, np.ones(len(points))])
    b = (points ** 2).sum(axis=1)
    (cx, cy, c), *_ = np.linalg.lstsq(A, b, rcond=None)
    radius = np.sqrt(c + cx ** 2 + cy ** 2)
    return radius, np.sqrt(np.mean((np.hypot(points[:, 0] - cx, points[:, 1] - cy) - radius) ** 2))


def simulated_turn_radius(u_change=(0.0, 0.0), v=0.3, kappa=0.5, seconds=8.0, dt=0.005):
    z, u = design.operating_point(MODEL, v, kappa)
    x0 = design.lift(z, v, MODEL.params.r)
    steps = round(seconds / dt)
    traj = MODEL.simulate(x0, dt, steps, np.tile(u + np.asarray(u_change), (steps, 1)), method="rkmk4")
    return circle_radius(traj[:, IDX_Q][:, :2])


def test_a_turns_operating_point_rolls_the_full_model_on_a_circle_of_radius_one_over_kappa():
    radius, residual = simulated_turn_radius()
    assert abs(radius - 2.0) < 1e-3 and residual < 1e-4


def test_the_turn_check_fails_for_a_pendulum_torque_one_percent_off():
    _, u = design.operating_point(MODEL, 0.3, 0.5)
    radius, _ = simulated_turn_radius(u_change=(0.0, 0.01 * u[1]))
    assert abs(radius - 2.0) > 1e-3


@pytest.mark.parametrize("kappa", [-0.5, 0.0, 0.25])
def test_lqr_gains_make_the_sampled_linear_loop_stable(kappa):
    z, u = design.operating_point(MODEL, 0.3, kappa)
    A, B = design.linearization(MODEL, z, u, 0.3, kappa)
    Ad, Bd = design.discretize(A, B, 0.02)
    K = design.gains(A, B, 0.02)
    assert np.abs(np.linalg.eigvals(Ad)).max() > 1.0            # open loop: the wobble grows
    assert np.abs(np.linalg.eigvals(Ad - Bd @ K)).max() < 1.0


def test_an_infeasible_turn_is_named():
    with pytest.raises(ValueError, match="operating_point: no steady rolling found at v = 0.7"):
        design.operating_point(MODEL, 0.7, 0.5)
