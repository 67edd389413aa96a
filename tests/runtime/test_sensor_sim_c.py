"""The closed loop on sensors in C (runtime/sensor_sim_c.py, c/src/sr_sim.c) against the Python
simulation it replaces in the sweeps: the same readings, in the same order, to the filter."""
import dataclasses

import numpy as np
import pytest

from runtime.control.closed_loop import simulate_on_sensors
from runtime.control.estimator import SensorEkf
from runtime.sensor_set import FixSpec, HeadingSpec, SensorSet
from runtime.sweep.robustness import _task

#: Relative agreement of the two engines: they differ only in how M⁻¹ w is solved (LAPACK against
#: the library's Cholesky), a few ulp that the closed loop carries along over a short run.
RTOL = 1e-10


def _sensors():
    """The default set made to reach every path of the C loop: an IMU between the plant's steps, a
    slower encoder, fixes that arrive late, and a heading sensor."""
    d = SensorSet.default()
    return dataclasses.replace(d, imu=dataclasses.replace(d.imu, rate=400.0),
                               encoders=dataclasses.replace(d.encoders, rate=100.0),
                               fixes=FixSpec(rate=20.0, noise=0.01, latency=0.0125),
                               heading=HeadingSpec(rate=50.0, noise=0.05))


def _run(engine, duration=0.3, seed=3, held=True):
    """`held` False: the filter's IMU updates leave the held disturbance out (sr_ekf_update_imu_axes,
    the same sigma), on this engine only."""
    task = _task("circle", "lqr", "default").with_sensors(_sensors())
    s = task.scenario
    plant = s.params.with_changes(m_P=s.params.paper_params.m_P * 1.1)
    x0 = s.x0.copy()
    x0[-5:] += [0.02, -0.01, 0.03, 0.0, 0.01]        # moving at the start: the rates enter the readings
    estimator = SensorEkf(s.params, task.sensors, x0, s.method, hold=s.dt)   # two IMU samples a hold
    if not held:
        estimator.filter.noise = dataclasses.replace(estimator.filter.noise, torque_hold=0.0)
    return simulate_on_sensors(plant, task.controller(), task.reference(), x0, duration, s.dt, estimator,
                               task.sensors, s.method, seed, engine=engine)


def assert_same_run(a, b):
    """The two results read the same samples in the same order, and the plant, the estimates and
    the torques agree to RTOL."""
    assert [(t, kind) for t, kind, _ in a.samples] == [(t, kind) for t, kind, _ in b.samples]
    for (_, kind, ya), (_, _, yb) in zip(a.samples, b.samples):
        if kind != "tick":
            np.testing.assert_allclose(yb, ya, rtol=RTOL, atol=RTOL * 1e-3, err_msg=kind)
    for name in ("trajectory", "estimates", "torques"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=RTOL, atol=RTOL * 1e-3, err_msg=name)


@pytest.fixture(scope="module")
def runs():
    return _run("python"), _run("c")


def test_the_c_loop_reads_every_sensor_as_the_python_simulation_does(runs):
    python, c = runs
    kinds = {kind for _, kind, _ in python.samples}
    assert kinds == {"tick", "imu", "encoders", "fixes", "heading"}
    assert_same_run(python, c)


def test_the_loops_filter_reads_the_imu_through_the_held_disturbance(runs):
    python, _ = runs
    task = _task("circle", "lqr", "default").with_sensors(_sensors())
    estimator = SensorEkf(task.scenario.params, task.sensors, task.scenario.x0, task.scenario.method,
                          hold=task.scenario.dt)
    assert estimator.filter.noise.torque_hold == task.scenario.dt
    assert estimator.filter.noise.accel == (task.sensors.imu.accel_noise,) * 3    # the white noise alone


@pytest.mark.parametrize("engine", ["python", "c"])
def test_either_engine_leaving_the_held_disturbance_out_is_told_apart(runs, engine):
    python, c = runs
    held = c if engine == "python" else python
    other = _run(engine, held=False)
    with pytest.raises(AssertionError):
        assert_same_run(held, other)
    # The first controller period's readings are the same: the filter's update alone moves the estimate.
    assert not np.allclose(other.estimates[1], held.estimates[1], rtol=RTOL, atol=RTOL * 1e-3)


def test_one_reading_off_by_a_part_in_a_billion_is_told_apart(runs):
    python, c = runs
    i = next(i for i, (_, kind, _) in enumerate(c.samples) if kind == "encoders")
    t, kind, y = c.samples[i]
    samples = list(c.samples)
    samples[i] = (t, kind, y + 1e-9 * (1 + np.abs(y)))
    with pytest.raises(AssertionError, match="encoders"):
        assert_same_run(python, dataclasses.replace(c, samples=samples))


def test_another_seed_gives_other_readings(runs):
    python, _ = runs
    with pytest.raises(AssertionError):
        assert_same_run(python, _run("c", seed=4))


def test_the_sample_list_may_be_left_out():
    task = _task("line", "lqr", "default")
    s = task.scenario
    result = simulate_on_sensors(s.params, task.controller(), task.reference(), s.x0, 0.1, s.dt,
                                 SensorEkf(s.params, task.sensors, s.x0, s.method), task.sensors, s.method, 1,
                                 engine="c", record_samples=False)
    assert result.samples is None and np.all(np.isfinite(result.trajectory))


def test_an_unknown_engine_is_a_value_error_naming_it():
    task = _task("line", "lqr", "default")
    s = task.scenario
    with pytest.raises(ValueError, match="engine: expected one of python, c, c-loop, got 'fortran'"):
        simulate_on_sensors(s.params, task.controller(), task.reference(), s.x0, 0.1, s.dt,
                            SensorEkf(s.params, task.sensors, s.x0, s.method), task.sensors, s.method, 1,
                            engine="fortran")
