"""The sensor readings of runtime/sensors.py (c/include/sr_sensors.h): their meaning in states whose answer
is known by hand, the Jacobians' shapes and blocks, and bad input named."""
import math

import numpy as np
import pytest

from runtime import Model, Params, initial_state, so3
from runtime import sensors
from runtime.sensors import IDX_ACCEL, IDX_EB_BA, IDX_EB_BG, IDX_GYRO, Mount


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def test_the_default_mount_is_the_yoke_5_cm_below_the_centre_along_its_axes():
    m = sensors.DEFAULT_MOUNT
    assert (m.body, m.lever) == ("yoke", (0.0, 0.0, -0.05))
    assert np.array_equal(m.as_array()[3:], np.eye(3).ravel())


def test_at_rest_the_accelerometer_reads_g_upwards_and_the_gyroscope_nothing(model):
    y = sensors.imu(model, initial_state())
    assert np.allclose(y[IDX_GYRO], 0.0, atol=0)
    assert np.allclose(y[IDX_ACCEL], (0.0, 0.0, model.params.g), rtol=1e-15, atol=1e-15)


def test_on_a_slope_the_floor_frame_reading_at_rest_leans_up_the_slope():
    params = Params.paper_simulation().replace(slope=0.2)
    y = sensors.imu(Model(params), initial_state(), nu_dot=np.zeros(5), mount=Mount("shell", (0, 0, 0)))
    assert np.allclose(y[IDX_ACCEL], params.g * np.array([math.sin(0.2), 0.0, math.cos(0.2)]), rtol=1e-14)


def test_a_tilted_yoke_tilts_the_reading_and_the_biases_add(model):
    x = initial_state(theta_Y=0.3)
    bias = np.array([0.01, 0.02, 0.03, 0.1, 0.2, 0.3])
    y = sensors.imu(model, x, np.zeros(5), mount=Mount("yoke", (0, 0, 0)), bias=bias)
    g = model.params.g
    assert np.allclose(y[IDX_ACCEL], (0.1, g * math.sin(0.3) + 0.2, g * math.cos(0.3) + 0.3), rtol=1e-14)
    assert np.allclose(y[IDX_GYRO], bias[:3], rtol=0, atol=1e-17)


def test_the_gyroscope_reads_the_bodys_rate_in_the_sensor_axes(model):
    x = initial_state(theta_Y=0.4, theta_P=-0.2, w_S=(0.5, -1.0, 2.0), w_Y=1.5, w_P=-0.7)
    R_m = so3.rot_z(0.3)
    y = sensors.imu(model, x, np.zeros(5), mount=Mount("pendulum", (0, 0, 0), R_m))
    R_Y, R_P = so3.rot_x(0.4), so3.rot_y(-0.2)
    w_P = R_P.T @ (R_Y.T @ np.array([0.5, -1.0, 2.0]) + [1.5, 0, 0]) + [0, -0.7, 0]
    assert np.allclose(y[IDX_GYRO], R_m.T @ w_P, rtol=1e-14)


def test_encoders_position_and_heading(model):
    x = initial_state(theta_Y=1.0, theta_P=-3.0, R_S=so3.rot_z(2.5), q=(0.4, -0.6, model.params.r))
    assert np.allclose(sensors.encoders(model, x), (1.0, -3.0), rtol=1e-15)
    assert np.array_equal(sensors.position(model, x), (0.4, -0.6))
    assert sensors.heading(model, x, Mount("shell", (0, 0, 0))) == pytest.approx(2.5, rel=1e-15)


def test_the_jacobians_have_18_columns_and_identity_bias_blocks(model):
    y, H = sensors.imu_jacobian(model, initial_state(theta_P=0.2, w_S=(1, 0, 0)), (0.1, 0.0))
    assert H.shape == (6, 18)
    assert np.array_equal(H[IDX_GYRO, IDX_EB_BG], np.eye(3)) and np.array_equal(H[IDX_ACCEL, IDX_EB_BA], np.eye(3))
    assert not H[IDX_GYRO, IDX_EB_BA].any() and not H[IDX_ACCEL, IDX_EB_BG].any()
    _, H_held, Hn = sensors.imu_partials(model, initial_state(), np.zeros(5))
    assert H_held.shape == (6, 18) and Hn.shape == (6, 5) and not Hn[IDX_GYRO].any()


@pytest.mark.parametrize("mount, field", [
    (dict(body="torso"), "mount.body"),
    (dict(lever=(0.0, 0.0)), "mount.lever"),
    (dict(lever=(0.0, math.nan, 0.0)), "mount.lever"),
    (dict(rotation=np.diag([1.0, 1.0, -1.0])), "mount.rotation"),
    (dict(rotation=np.eye(3) * 1.01), "mount.rotation"),
])
def test_a_bad_mount_is_a_value_error_naming_its_field(mount, field):
    with pytest.raises(ValueError, match=f"^{field}:"):
        Mount(**mount)


@pytest.mark.parametrize("call, field", [
    (lambda m: sensors.imu(m, initial_state(), np.full(5, math.inf)), "nu_dot"),
    (lambda m: sensors.imu(m, initial_state(), np.zeros(4)), "nu_dot"),
    (lambda m: sensors.imu(m, initial_state(), bias=np.ones(5)), "bias"),
    (lambda m: sensors.imu(m, initial_state(), bias=[0, 0, 0, 0, 0, math.nan]), "bias"),
    (lambda m: sensors.imu(m, initial_state(), np.zeros(5), u=(0, 0)), "u"),
    (lambda m: sensors.imu_jacobian(m, initial_state(), (0.0, math.nan)), "u"),
    (lambda m: sensors.imu(m, initial_state(), mount="yoke"), "mount"),
    (lambda m: sensors.encoders(m, np.zeros(35)), "x"),
    (lambda m: sensors.heading(m, initial_state(), Mount("shell", (0, 0, 0), so3.rot_y(-math.pi / 2))), "x"),
])
def test_bad_input_is_a_value_error_naming_the_argument(model, call, field):
    with pytest.raises(ValueError, match=f"^{field}:"):
        call(model)


def test_the_batches_are_the_single_calls_row_by_row(model):
    rng = np.random.default_rng(3)
    X = np.array([initial_state(theta_Y=a, theta_P=b, w_S=w, q=(c, -c, model.params.r))
                  for a, b, w, c in zip(rng.uniform(-3, 3, 4), rng.uniform(-3, 3, 4), rng.normal(size=(4, 3)),
                                        rng.normal(size=4))])
    A = rng.normal(size=(4, 5))
    bias, mount = rng.normal(size=6), Mount("pendulum", (0.01, 0.0, -0.1))
    y, H, Hn = sensors.imu_partials_batch(model, X, A, mount=mount, bias=bias)
    for i in range(4):
        for got, want in zip((y[i], H[i], Hn[i]), sensors.imu_partials(model, X[i], A[i], mount=mount, bias=bias)):
            assert np.array_equal(got, want)
        for batch, single in ((sensors.encoders_jacobian_batch, sensors.encoders_jacobian),
                              (sensors.position_jacobian_batch, sensors.position_jacobian)):
            got, want = batch(model, X)
            assert np.array_equal(got[i], single(model, X[i])[0])
            assert np.array_equal(want[i], single(model, X[i])[1])


def test_a_batch_names_the_bad_state_and_the_shape_of_nu_dot(model):
    X = np.array([initial_state(), np.zeros(35)])
    with pytest.raises(ValueError, match=r"^x\[1\]"):
        sensors.encoders_jacobian_batch(model, X)
    with pytest.raises(ValueError, match="^nu_dot:"):
        sensors.imu_partials_batch(model, X[:1], np.zeros((2, 5)))
