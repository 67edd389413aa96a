"""The whole closed loop in C (c/include/sr_loop.h, runtime/control/loop_c.py) against the Python loop
it replaces in the sweeps: the same target, torques, readings and plant, sample for sample."""
import dataclasses
import math

import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime.control.closed_loop import simulate_on_sensors
from runtime.control.estimator import SensorEkf
from runtime.control.geometry import heading
from runtime.control.lqr import Lqr
from runtime.control.loop_c import c_path, supports, track
from runtime.control.offsets import LQR_SLOPE_SETTINGS, SLOPE_ESTIMATE_S
from runtime.control.reference import Path
from runtime.control.slope import SlopeEstimator
from runtime.state import IDX_Q
from runtime.sweep.robustness import _task
from tests.runtime.test_sensor_sim_c import RTOL, _sensors, assert_same_run

#: A torque limit that the start off the path reaches in some samples and not in others (the
#: anti-windup skips some integral steps and takes others).
U_MAX = 1.0


def _winding_path(x0, speed):
    """A path from the robot's start whose curvature changes along it (the preview's mean and its
    interpolation matter), 2 m long."""
    s = np.arange(0.0, 2.0, 0.005)
    kappa = 0.8 * np.sin(s / 0.3)
    psi = heading(x0) + np.concatenate([[0.0], np.cumsum(kappa[:-1] * 0.005)])
    points = x0[IDX_Q][:2] + np.concatenate([[[0.0, 0.0]], np.cumsum(0.005 * np.stack([np.cos(psi), np.sin(psi)], 1)[:-1], 0)])
    return Path(points, speed)


def _run(engine, duration=0.3, seed=3, controller=None):
    task = _task("circle", "lqr", "default").with_sensors(_sensors())
    s = task.scenario
    plant = s.params.with_changes(m_P=s.params.paper_params.m_P * 1.1)
    x0 = s.x0.copy()
    x0[IDX_Q.start] += 0.04                          # off the path: a cross-track error to integrate
    x0[-5:] += [0.02, -0.01, 0.03, 0.0, 0.01]
    controller = controller or Lqr(s.params, task.rate, U_MAX, task.controllers[0].gains)
    estimator = SensorEkf(s.params, task.sensors, x0, s.method, hold=s.dt)
    return simulate_on_sensors(plant, controller, _winding_path(s.x0, 0.3), x0, duration, s.dt, estimator,
                               task.sensors, s.method, seed, engine=engine), controller


@pytest.fixture(scope="module")
def runs():
    return _run("python"), _run("c-loop")


def test_the_c_loop_equals_the_python_loop_through_every_path(runs):
    (python, lqr_python), (c, lqr_c) = runs
    assert lqr_c.gains.slope_prior > 0 and np.abs(lqr_c._estimator.slope).max() > 1e-4   # the shipped estimate at work
    assert {kind for _, kind, _ in python.samples} == {"tick", "imu", "encoders", "fixes", "heading"}
    assert 0 < python.saturated_fraction < 1                 # clipped at the start, free later
    assert np.all(lqr_python.integrals != 0)
    assert_same_run(python, c)
    np.testing.assert_allclose(lqr_c.integrals, lqr_python.integrals, rtol=RTOL)
    assert c.saturated_fraction == python.saturated_fraction


def test_a_gain_off_by_a_part_in_a_billion_is_told_apart(runs):
    (python, _), _ = runs
    task = _task("circle", "lqr", "default")
    controller = Lqr(task.scenario.params, task.rate, U_MAX, task.controllers[0].gains)
    nz = controller.schedule.K_path.shape[3]
    for n in range(controller.schedule.K_path.shape[0] * controller.schedule.K_path.shape[1]):
        for torque in range(2):                                # the cross-track gain of either torque
            controller._c.K_path[n][torque * nz + 9] *= 1 + 1e-9
    c, _ = _run("c-loop", controller=controller)
    with pytest.raises(AssertionError):
        assert_same_run(python, c)


def test_the_targets_equal_the_python_references():
    x0 = _task("circle", "lqr", "default").scenario.x0
    path = _winding_path(x0, 0.3)
    keep = []
    c = c_path(path, keep)
    target = ffi.new("sr_lqr_target *")
    distances = np.linspace(-0.2, 0.8, 41)
    ahead = np.empty(41)
    rng = np.random.default_rng(0)
    for s in np.linspace(0.0, 1.9, 40):
        position = np.interp(s, path.s, path.points[:, 0]), np.interp(s, path.s, path.points[:, 1])
        position = np.array(position) + rng.normal(0.0, 0.05, 2)
        want = path.target(0.0, position, 0.0)
        assert lib.sr_path_target(c, ffi.cast("double *", ffi.from_buffer(position)), target) == lib.SR_OK
        assert c.hint == path._hint
        assert (target.heading, target.curvature) == (want.heading, want.curvature)
        assert math.isclose(target.cross_track, want.cross_track, rel_tol=1e-12, abs_tol=1e-15)
        assert lib.sr_path_curvature_ahead(c, ffi.cast("double *", ffi.from_buffer(distances)), 41,
                                           ffi.cast("double *", ffi.from_buffer(ahead))) == lib.SR_OK
        np.testing.assert_allclose(ahead, path.curvature_ahead(distances), rtol=1e-12, atol=1e-15)


def test_a_path_that_is_not_one_is_refused_with_a_status():
    x0 = _task("circle", "lqr", "default").scenario.x0
    path = _winding_path(x0, 0.3)
    c = c_path(path, keep := [])
    assert lib.sr_path_check(c) == lib.SR_OK
    c.hint = c.n
    assert lib.sr_path_check(c) == lib.SR_ERR_ARG
    c.hint, c.n = 0, 1
    assert lib.sr_path_check(c) == lib.SR_ERR_ARG
    c.n = len(path.s)
    keep[1][5] = keep[1][4]                                   # arc lengths that do not increase
    assert lib.sr_path_check(c) == lib.SR_ERR_ARG
    keep[1][5] = math.nan
    assert lib.sr_path_check(c) == lib.SR_ERR_NONFINITE
    assert lib.sr_path_check(ffi.NULL) == lib.SR_ERR_NULL


def test_a_controller_with_python_of_its_own_is_not_run_in_c():
    # the slope estimate in NumPy (runtime/control/slope.py's SlopeEstimator) has no C struct to update
    task = _task("circle", "lqr", "default")
    s = task.scenario
    estimating = _slope_controller()
    assert supports(task.controller(), task.reference()) and supports(estimating, task.reference())
    estimating._estimator = SlopeEstimator(s.params, estimating.period, SLOPE_ESTIMATE_S)
    assert not supports(estimating, task.reference())
    with pytest.raises(ValueError, match="engine: the C loop runs the LQR .its slope estimate the C one. on a path"):
        simulate_on_sensors(s.params, estimating, task.reference(), s.x0, 0.1, s.dt,
                            SensorEkf(s.params, task.sensors, s.x0, s.method), task.sensors, s.method, 1,
                            engine="c-loop")


#: How far the C loop with the slope estimate may stray from the Python loop over its 0.3 s (relative,
#: against |value| + 1e-3): not bit for bit, as the filter's first samples already differ by 1e-17
#: between the loops and the estimate's first solves, on normal equations of condition up to 1e10,
#: magnify that (this start, off the winding path at the torque limit, magnifies any difference five
#: times per 10 samples even without the estimate).  Measured: 3e-8 (the C estimate in both loops),
#: 1.2e-7 (the Python loop on the NumPy estimate).
SLOPE_LOOP_RTOL = 1e-6


def _slope_controller():
    """lqr-slope's LQR (the offset table's settings) on the loop test's task, its estimate the C one and
    unweighted (`slope_prior` 0: the shipped circle's weighted estimate runs in `runs` above), so its
    first solves are the ill-conditioned ones this comparison is about."""
    task = _task("circle", "lqr", "default")
    gains = dataclasses.replace(task.controllers[0].gains, slope_estimate_s=SLOPE_ESTIMATE_S, slope_prior=0.0,
                                **LQR_SLOPE_SETTINGS)
    return Lqr(task.scenario.params, task.rate, U_MAX, gains)


def _relative(a, b):
    return max(float((np.abs(getattr(a, n) - getattr(b, n)) / (np.abs(getattr(a, n)) + 1e-3)).max())
               for n in ("trajectory", "estimates", "torques"))


@pytest.fixture(scope="module")
def slope_runs():
    numpy_estimate = _slope_controller()
    numpy_estimate._estimator = SlopeEstimator(numpy_estimate.params.replace(slope=0.0), numpy_estimate.period,
                                               SLOPE_ESTIMATE_S)
    return _run("python", controller=_slope_controller()), _run("c-loop", controller=_slope_controller()), \
        _run("python", controller=numpy_estimate)


def test_the_c_loop_with_the_slope_estimate_equals_the_python_loop(slope_runs):
    (python, lqr_python), (c, lqr_c), (numpy_run, lqr_numpy) = slope_runs
    # the estimate is at work: a slope, a heavier pendulum (the plant's m_P is 10 % up) and a torque offset
    assert np.abs(lqr_c._estimator.slope).max() > 1e-3 and lqr_c._estimator.pendulum[0] > 0.1
    assert np.abs(lqr_c._estimator.torque_offset).max() > 0.1
    assert _relative(python, c) <= SLOPE_LOOP_RTOL
    assert _relative(numpy_run, c) <= SLOPE_LOOP_RTOL
    for name in ("slope", "torque_offset", "pendulum"):     # each against its largest entry
        a, b = getattr(lqr_c._estimator, name), getattr(lqr_numpy._estimator, name)
        assert np.abs(a - b).max() <= SLOPE_LOOP_RTOL * np.abs(b).max()


@pytest.mark.parametrize("plant", ["share", "column", "table"])
def test_the_slope_loops_comparison_fails_for_a_planted_error(slope_runs, plant):
    (python, _), _, _ = slope_runs
    controller = _slope_controller()
    if plant == "share":                        # the pendulum's feedforward at 99.99 %
        controller._c.pendulum_share = 0.9999
    elif plant == "column":                     # the estimate's c_P,z column off by a part in 10^4
        controller._estimator._c.factor[3] *= 1 + 1e-4
    else:                                       # the slope's table: dz*/d(up) of every point off by 10^-4
        for n in range(len(controller._c.slope.dz_up)):
            controller._c.slope.dz_up[n][3] *= 1 + 1e-4
    c, _ = _run("c-loop", controller=controller)
    assert _relative(python, c) > 10 * SLOPE_LOOP_RTOL


def test_a_track_of_positions_equals_the_paths_own_matching():
    from runtime.sweep.robustness import progress
    x0 = _task("circle", "lqr", "default").scenario.x0
    path = _winding_path(x0, 0.3)
    rng = np.random.default_rng(1)
    s = np.linspace(0.1, 1.9, 300)
    positions = np.stack([np.interp(s, path.s, path.points[:, 0]), np.interp(s, path.s, path.points[:, 1]),
                          np.zeros_like(s)], 1) + rng.normal(0.0, 0.02, (300, 3))
    cross_track, travelled = track(path, positions)
    np.testing.assert_allclose(cross_track, path.cross_track(positions), rtol=1e-12, atol=1e-15)
    assert travelled == progress(path, positions) > 1.5


def test_the_c_nmpcs_loop_with_the_targets_read_in_c_equals_the_python_loop():
    task = _task("figure8", "nmpc-c", "default").with_sensors(_sensors())
    s = task.scenario
    x0 = s.x0.copy()
    x0[IDX_Q.start] += 0.04

    def run(engine):
        return simulate_on_sensors(s.params, task.controller(), task.reference(), x0, 0.3, s.dt,
                                   SensorEkf(s.params, task.sensors, x0, s.method, hold=s.dt), task.sensors, s.method, 5,
                                   engine=engine)
    assert_same_run(run("python"), run("c"))
