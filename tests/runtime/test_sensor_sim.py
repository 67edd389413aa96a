"""What a filter assumes of a sensor set (runtime.sensor_sim.ekf_noise): the accelerometer's
standard deviation axis by axis, and the biases' random walks the set declares."""
import dataclasses
import math

import numpy as np
import pytest

from runtime import Params
from runtime.sensor_set import SensorSet
from runtime.sensor_sim import ekf_noise


@pytest.fixture(scope="module")
def params():
    return Params.paper_simulation()


def test_each_accelerometer_axis_may_carry_its_own_share_of_the_process_noise(params):
    # At rest the torque disturbances accelerate the IMU on the yoke horizontally, unequally on its
    # x and y axes, and not at all along the vertical: its z axis keeps the white noise alone.
    sensors = SensorSet.default()
    white = sensors.imu.accel_noise
    sx, sy, sz = ekf_noise(sensors, params, accel_axes="each").accel
    assert sz == pytest.approx(white, rel=1e-9)
    assert sx > 1.2 * white and sy > 2 * sx


def test_largest_gives_every_accelerometer_axis_the_largest_share(params):
    sensors = SensorSet.default()
    largest = max(ekf_noise(sensors, params, accel_axes="each").accel)
    assert ekf_noise(sensors, params, accel_axes="largest").accel == (largest,) * 3
    assert ekf_noise(sensors, params, accel_axes="largest").torque_hold == 0


def test_by_default_the_filter_models_the_held_disturbance_with_the_white_noise_alone(params):
    sensors = SensorSet.default()
    noise = ekf_noise(sensors, params)
    assert noise.torque_hold == 1 / sensors.imu.rate
    assert noise.accel == (sensors.imu.accel_noise,) * 3


def test_an_unknown_accel_axes_rule_is_a_value_error_naming_it(params):
    with pytest.raises(ValueError, match="^accel_axes:"):
        ekf_noise(SensorSet.default(), params, accel_axes="mean")


def test_without_process_noise_every_axis_is_the_white_noise(params):
    quiet = dataclasses.replace(SensorSet.default(), process=dataclasses.replace(SensorSet.default().process,
                                                                                 shell=0.0, yoke=0.0, pendulum=0.0))
    assert ekf_noise(quiet, params, accel_axes="each").accel == pytest.approx((quiet.imu.accel_noise,) * 3, rel=1e-12)


def test_the_biases_random_walks_are_the_sensor_sets(params):
    default = SensorSet.default()
    noise = ekf_noise(default, params)
    assert (noise.gyro_bias_rw, noise.accel_bias_rw) == (default.imu.gyro_bias_rw, default.imu.accel_bias_rw)
    assert noise.gyro_bias_rw > 0 and noise.accel_bias_rw > 0
    other = dataclasses.replace(default, imu=dataclasses.replace(default.imu, gyro_bias_rw=3e-4, accel_bias_rw=0.0))
    assert (ekf_noise(other, params).gyro_bias_rw, ekf_noise(other, params).accel_bias_rw) == (3e-4, 0.0)


def test_a_bias_random_walk_keeps_the_bias_sigma_from_shrinking_without_bound(params):
    # At rest, level, the joints read: the gyroscope's x bias is seen, and with no random walk its
    # σ keeps falling; with one it settles at a floor.
    from runtime import Model, initial_state
    from runtime.ekf import IDX_EB_BG, Ekf
    model = Model(params)
    x0 = initial_state(r=params.r)
    y = np.array([0.0, 0.0, 0.0, 0.0, 0.0, params.g])
    final = {}
    for rw in (0.0, 1e-3):
        noise = dataclasses.replace(ekf_noise(SensorSet.default(), params), gyro_bias_rw=rw)
        ekf = Ekf(model, x0, sigma=np.full(18, 0.01), noise=noise, gate=1)
        sigmas = []
        for _ in range(4):
            for _ in range(200):
                ekf.predict(None, 0.005)
                ekf.update_imu(y)
                ekf.update_encoders((0.0, 0.0))
            sigmas.append(ekf.sigma[IDX_EB_BG][0])
        final[rw] = sigmas
    assert final[0.0][-1] < 0.8 * final[0.0][-2]                                  # still shrinking
    assert final[1e-3][-1] == pytest.approx(final[1e-3][-2], rel=0.02)            # settled
    assert final[1e-3][-1] > 3 * final[0.0][-1] and math.isfinite(final[1e-3][-1])


# -- the truth's biases walk ----------------------------------------------------------------------
def walked(params, gyro_rw, accel_rw, steps, seed=5, streams=None, monkeypatch=None, **imu):
    """A SensorSimulation at rest for `steps` steps of 5 ms with the given bias random walks (and
    other `imu` fields) and no process noise: (the simulation, the biases of every step (steps + 1, 6))."""
    from runtime import Model, initial_state
    from runtime import sensor_sim
    from runtime.sensor_set import ProcessNoise
    if streams is not None:
        monkeypatch.setattr(sensor_sim, "STREAMS", streams)
    default = SensorSet.default()
    sensors = dataclasses.replace(default, process=ProcessNoise(0.0, 0.0, 0.0),
                                  imu=dataclasses.replace(default.imu, gyro_bias_rw=gyro_rw, accel_bias_rw=accel_rw, **imu))
    sim = sensor_sim.SensorSimulation(Model(params), sensors, 0.005, steps, "rkmk4", seed)
    x, u = initial_state(r=params.r), np.zeros(2)
    for k in range(steps + 1):
        x, _ = sim.advance(k, x, u, last=k == steps)
    return sim, np.array([sim.bias_at(k) for k in range(steps + 1)])


def test_the_truths_biases_walk_with_the_declared_variance_per_step(params):
    # 2000 steps, 3 axes: 6000 increments per sensor, whose sample variance is within 15 % of
    # rw² dt at 8 standard deviations of its spread; a walk off by a factor 2 in variance fails.
    steps, dt = 2000, 0.005
    _, b = walked(params, 1e-5, 1e-4, steps)
    d = np.diff(b, axis=0)
    assert abs(np.mean(d[:, :3] ** 2) / (1e-5 ** 2 * dt) - 1) < 0.15
    assert abs(np.mean(d[:, 3:] ** 2) / (1e-4 ** 2 * dt) - 1) < 0.15


def test_the_imu_reads_the_bias_of_its_step(params):
    sim, b = walked(params, 1e-3, 1e-2, 200, gyro_noise=0.0, accel_noise=0.0)
    assert np.ptp(b, axis=0).min() > 1e-4                  # the bias moved
    at_rest = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 9.81])
    assert np.abs(sim.readings["imu"] - b - at_rest).max() < 1e-9


def test_without_a_walk_every_reading_is_the_old_streams_bit_for_bit(params, monkeypatch):
    from runtime import sensor_sim
    old = tuple(s for s in sensor_sim.STREAMS if s != "bias_walk")
    new, b = walked(params, 0.0, 0.0, 100)
    assert np.array_equal(b, np.tile(b[0], (101, 1)))
    before, _ = walked(params, 0.0, 0.0, 100, streams=old, monkeypatch=monkeypatch)
    monkeypatch.undo()
    for kind in new.readings:
        assert np.array_equal(new.readings[kind], before.readings[kind]), kind
    # The walk's own stream leaves every other draw alone: only the IMU moves, by the walk.
    walking, wb = walked(params, 1e-3, 1e-2, 100)
    assert np.array_equal(walking.readings["encoders"], new.readings["encoders"])
    assert np.abs(walking.readings["imu"] - new.readings["imu"] - (wb - b)).max() < 1e-12
