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
from runtime.control.reference import Path
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
    task = _task("circle", "lqr", "default")
    s = task.scenario
    sloped = Lqr(s.params.replace(slope=0.01), task.rate, task.u_max)
    assert supports(task.controller(), task.reference())
    assert not supports(sloped, task.reference())
    with pytest.raises(ValueError, match="engine: the C loop runs the LQR on a path"):
        simulate_on_sensors(s.params, sloped, task.reference(), s.x0, 0.1, s.dt,
                            SensorEkf(s.params, task.sensors, s.x0, s.method), task.sensors, s.method, 1,
                            engine="c-loop")


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
