"""The NMPC (runtime/control/nmpc.py): its prediction model is the C model's, its derivatives are
right, near an operating point it is the LQR of its own model, and its settings are checked."""
import dataclasses

import numpy as np
import pytest

from runtime.casadi_model import parameter_vector
from runtime.control import lqr_design as design
from runtime.control import nmpc
from runtime.control.reference import Target
from runtime.model import Model
from runtime.params import Params

PARAMS = Params.paper_simulation()


def random_point(rng):
    z = np.zeros(design.NZ)
    z[:nmpc.NZ_N] = rng.normal(scale=0.3, size=nmpc.NZ_N)
    return z, rng.normal(scale=0.3, size=2), rng.uniform(0.0, 0.6), rng.uniform(-0.7, 0.7)


def field_gap(model_params, field_params):
    """Largest relative gap between the CasADi field (field_params) and lqr_design.field on the C kernel."""
    f, model = nmpc.reduced_field(), Model(model_params)
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(50):
        z, u, v, kappa = random_point(rng)
        ours = np.array(f(z[:nmpc.NZ_N], u, v, kappa, parameter_vector(field_params))).ravel()
        theirs = design.field(model, z, u, v, kappa)[:nmpc.NZ_N]
        worst = max(worst, np.abs(ours - theirs).max() / np.abs(theirs).max())
    return worst


def test_the_prediction_field_equals_the_c_kernels_reduced_field():
    assert field_gap(PARAMS, PARAMS) < 1e-13


def test_the_field_comparison_fails_for_a_pendulum_mass_off_by_one_in_a_million():
    assert field_gap(PARAMS, PARAMS.with_changes(m_P=PARAMS.m_P * (1 + 1e-6))) > 1e-8


def jacobian_gap(perturb=0.0):
    node = nmpc.node_function(0.1)
    rng = np.random.default_rng(4)
    z, u, v, kappa = random_point(rng)
    z, p = z[:nmpc.NZ_N], parameter_vector(PARAMS)
    _, A, B = node(z, u, v, kappa, p)
    A, B = np.array(A), np.array(B)
    A[0, 0] += perturb
    step = lambda z, u: np.array(node(z, u, v, kappa, p)[0]).ravel()    # noqa: E731
    worst, h = 0.0, 1e-5
    for j in range(nmpc.NZ_N + 2):
        dz, du = np.zeros(nmpc.NZ_N), np.zeros(2)
        (dz if j < nmpc.NZ_N else du)[j % nmpc.NZ_N if j < nmpc.NZ_N else j - nmpc.NZ_N] = h
        column = (step(z + dz, u + du) - step(z - dz, u - du)) / (2 * h)
        exact = A[:, j] if j < nmpc.NZ_N else B[:, j - nmpc.NZ_N]
        worst = max(worst, np.abs(column - exact).max() / max(1.0, np.abs(exact).max()))
    return worst


def test_the_prediction_jacobians_equal_central_differences():
    assert jacobian_gap() < 1e-7


def test_the_jacobian_comparison_fails_for_an_entry_off_by_one_in_a_million():
    assert jacobian_gap(perturb=1e-6) > 5e-7


def test_the_compiled_prediction_equals_casadis_own_evaluation(tmp_path, monkeypatch):
    monkeypatch.setenv("SR_CACHE_DIR", str(tmp_path))
    function = nmpc.node_function(0.1).map(3)
    compiled = nmpc.compiled(function)
    rng = np.random.default_rng(5)
    args = (rng.normal(scale=0.2, size=(nmpc.NZ_N, 3)), rng.normal(scale=0.2, size=(2, 3)), 0.3,
            rng.uniform(-0.5, 0.5, size=(1, 3)), parameter_vector(PARAMS))
    for ours, theirs in zip(compiled(*args), function(*args)):
        assert np.abs(np.array(ours) - np.array(theirs)).max() <= 1e-13 * max(1.0, np.abs(np.array(theirs)).max())
    assert len(list(tmp_path.glob("*.so"))) == 1
    nmpc.compiled(function)                       # the second build is the cached library
    assert len(list(tmp_path.glob("*.so"))) == 1


def first_torque_against_lqr(R_scale=1.0):
    """(NMPC's first torque − u*, the LQR's −K δz) at a state δz = 1e-4 off straight rolling at 0.3 m/s."""
    from scipy.linalg import solve_discrete_are
    controller = nmpc.Nmpc(PARAMS)
    s = controller.schedule
    i, j = int(np.argmin(np.abs(s.speeds - 0.3))), int(np.argmin(np.abs(s.curvatures)))
    v, z_star, u_star = s.speeds[i], s.z_star[i, j], s.u_star[i, j]
    _, A, B = nmpc.node_function(controller.node_period)(z_star[:nmpc.NZ_N], u_star, v, 0.0, parameter_vector(PARAMS))
    A, B = np.array(A), np.array(B)
    R = R_scale * controller._r * np.eye(2)
    P = solve_discrete_are(A, B, np.diag(controller._q_path), R)
    K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
    dz = 1e-4 * np.random.default_rng(6).normal(size=nmpc.NZ_N)
    dz[design.Z_IY] = 0.0                         # the controller's own integral starts at 0
    z = z_star.copy()
    z[:nmpc.NZ_N] += dz
    x = design.lift(z, v, PARAMS.r)
    controller.reset(x)
    u = controller.compute(0.0, x, Target(speed=v, heading=0.0, curvature=0.0, cross_track=z[design.Z_EY]))
    return u - u_star, -K @ dz


def test_near_straight_rolling_the_first_torque_is_the_lqr_of_the_prediction_model():
    ours, lqr = first_torque_against_lqr()
    assert np.abs(ours - lqr).max() < 1e-3 * np.abs(lqr).max()


def test_the_lqr_comparison_fails_for_a_torque_weight_doubled():
    ours, lqr = first_torque_against_lqr(R_scale=2.0)
    assert np.abs(ours - lqr).max() > 1e-2 * np.abs(lqr).max()


def test_the_horizon_is_previewed_node_by_node():
    controller = nmpc.Nmpc(PARAMS)
    d = controller.preview_distances(Target(speed=0.3, heading=0.0))
    assert len(d) == controller.n + 1 and d[1] == pytest.approx(0.3 * controller.node_period)


@pytest.mark.parametrize("name, value", [("horizon", 0.0), ("horizon", 2.5), ("node_periods", 0.0),
                                         ("iterations", 0.0)])
def test_bad_settings_are_named(name, value):
    with pytest.raises(ValueError, match=name):
        nmpc.NmpcGains(**{name: value})


def test_a_diverged_prediction_falls_back_to_the_reference_torques(monkeypatch):
    controller = nmpc.Nmpc(PARAMS)
    x = design.lift(np.zeros(design.NZ), 0.3, PARAMS.r)
    controller.reset(x)

    def overflowing(*args):
        raise nmpc._Diverged
    monkeypatch.setattr(controller, "_iteration", overflowing)
    u = controller.compute(0.0, x, Target(speed=0.3, heading=0.0, curvature=0.0, cross_track=0.0))
    _, u_star = controller._references(0.3, np.zeros(controller.n + 1))
    assert np.array_equal(u, u_star[0]) and controller.restarts == 1


def circle_offset_against_a_heavier_plant(integral_m_s):
    """Mean cross-track error over the last 10 s of the circle, plant 10 % heavier, no noise, the
    integral alone (no offset estimate)."""
    from runtime.control.benchmark import run_task
    from runtime.control.closed_loop import Noise
    from runtime.control.task import load_task
    from runtime.state import IDX_Q
    task = load_task("circle-mismatch").with_controller("nmpc")
    spec = task.controllers[0]
    spec = dataclasses.replace(spec, gains=dataclasses.replace(spec.gains, cross_track_integral_m_s=integral_m_s,
                                                                      disturbance_gain=0.0))
    result, reference, _ = run_task(dataclasses.replace(task, controllers=(spec,), noise=Noise()))
    late = result.time >= result.time[-1] - 10.0
    return float(np.mean(reference.cross_track(result.trajectory[late][::20, IDX_Q][:, :2])))


def test_the_cross_track_integral_removes_the_offset_of_a_mismatched_plant():
    assert abs(circle_offset_against_a_heavier_plant(nmpc.NmpcGains().cross_track_integral_m_s)) < 0.002


def test_the_offset_check_fails_without_the_integral():
    assert abs(circle_offset_against_a_heavier_plant(1e6)) > 0.01
