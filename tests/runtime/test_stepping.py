"""Lie-Euler stepping (eq. 111) in C: agreement with a direct transcription, and structure preservation."""
import numpy as np
import pytest

from runtime import Model, Params, initial_state
from runtime.verification.sampling import random_inputs, random_state
from runtime.so3 import rot_x, rot_y


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def expm_taylor(A, terms=30):
    """Matrix exponential by its Taylor series (independent of the C Rodrigues formula)."""
    out, term = np.eye(3), np.eye(3)
    for k in range(1, terms):
        term = term @ A / k
        out = out + term
    return out


def lie_euler_python(model, x, u, dt):
    """Eq. (111) as the issue states it: every update uses the old state."""
    R_S, R_Y, R_P = (x[i:i + 9].reshape(3, 3) for i in (0, 9, 18))
    w_S, w_Y, w_P = x[30:33], x[33], x[34]
    gamma = R_S.T @ np.array([0, 0, 1.0])
    y = x.copy()
    y[0:9] = (R_S @ expm_taylor(dt * hat(w_S))).ravel()
    y[9:18] = (R_Y @ expm_taylor(dt * w_Y * hat([1, 0, 0]))).ravel()
    y[18:27] = (R_P @ expm_taylor(dt * w_P * hat([0, 1, 0]))).ravel()
    y[27:30] = x[27:30] + dt * model.params.r * R_S @ hat(w_S) @ gamma
    y[30:35] = x[30:35] + dt * model.accel(x, u)
    return y


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def test_step_matches_a_direct_transcription_of_eq_111(model, rng):
    for _ in range(50):
        x, u = random_state(rng), random_inputs(rng, 1)[0]
        dt = rng.uniform(1e-4, 0.05)
        assert np.allclose(model.step(x, u, dt), lie_euler_python(model, x, u, dt), rtol=1e-13, atol=1e-14)


def test_simulate_equals_repeated_steps(model, rng):
    x0 = random_state(rng, max_speed=2)
    U = random_inputs(rng, 30)
    traj = model.simulate(x0, 0.01, 30, U)
    x = x0
    for n in range(30):
        x = model.step(x, U[n], 0.01)
        assert np.array_equal(traj[n + 1], x)


def test_feedback_simulation_sees_time_and_state(model):
    seen = []

    def control(t, x):
        seen.append(t)
        return np.array([0.1 * np.sin(t), -0.05 * x[33]])

    traj = model.simulate(initial_state(), 0.01, 20, control)
    assert traj.shape == (21, 35)
    assert seen == pytest.approx([0.01 * n for n in range(20)])


def test_small_angle_exponential_is_accurate(model):
    """Tiny rotation steps (the series branch of Rodrigues) still advance R_S exactly."""
    x = initial_state(w_S=(1e-7, -2e-7, 3e-7))
    y = model.step(x, None, 0.5)
    assert np.allclose(y[0:9].reshape(3, 3), expm_taylor(0.5 * hat(x[30:33])), rtol=0, atol=1e-16)


def test_rotations_stay_orthonormal_over_1e5_steps(model):
    x0 = initial_state(theta_Y=0.3, theta_P=0.6, w_S=(2.0, -3.0, 5.0), w_Y=4.0, w_P=-6.0)
    traj = model.simulate(x0, 0.001, 100_000)
    for block in (slice(0, 9), slice(9, 18), slice(18, 27)):
        R = traj[:, block].reshape(-1, 3, 3)
        err = np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max()
        assert err < 1e-12
    # R_Y and R_P keep their one-axis structure exactly.
    assert np.all(traj[:, 9] == 1.0) and np.all(traj[:, 22] == 1.0)


def test_centre_stays_at_height_r(model):
    traj = model.simulate(initial_state(theta_Y=0.5, theta_P=-0.7, w_S=(1, 2, 3)), 0.01, 1000)
    assert np.all(traj[:, 29] == model.params.r)


# -- batches: Model.step on (B, 35) (C: sr_step_batch, vectorised across the states for Lie-Euler) --

def batch(rng, n, params=None, max_speed=10.0):
    x = np.stack([random_state(rng, params, max_speed=max_speed) for _ in range(n)])
    return x, random_inputs(rng, n)


@pytest.mark.parametrize("method, dt", [("lie-euler", 0.01), ("lie-euler", 0.05), ("rkmk4", 0.01), ("cf4", 0.02)])
def test_a_batch_step_equals_single_steps_bit_for_bit(model, rng, method, dt):
    """dt = 0.05 s with speeds to 10 rad/s takes some rows past the lanes' series range."""
    x, u = batch(rng, 150)
    y = model.step(x, u, dt, method)
    assert y.shape == (150, 35)
    assert np.array_equal(y, np.stack([model.step(x[i], u[i], dt, method) for i in range(150)]))
    assert np.array_equal(model.step(x, None, dt, method), np.stack([model.step(s, None, dt, method) for s in x]))


def test_a_batch_step_of_a_general_robot_equals_single_steps(rng):
    from runtime.verification.sampling import random_general_params
    general = Model(random_general_params(rng))
    x, u = batch(rng, 70, general.params)
    assert np.array_equal(general.step(x, u), np.stack([general.step(x[i], u[i]) for i in range(70)]))


def test_a_batch_step_names_the_row_and_entry_that_is_wrong(model, rng):
    x, u = batch(rng, 100)
    x[77, 12] = np.nan
    with pytest.raises(ValueError, match=r"x\[77\]: x\[77\]\[12\] \(R_Y\[1,0\]\) is nan"):
        model.step(x, u)
    x[77, 12] = 0.0
    x[80, 0] += 1e-3
    with pytest.raises(ValueError, match=r"x\[80\]: R_S .* not orthonormal"):
        model.step(x, u)


def test_a_batch_step_checks_the_torques_shape_and_values(model, rng):
    x, u = batch(rng, 5)
    with pytest.raises(ValueError, match="u: shape"):
        model.step(x, u[:4])
    u[3, 1] = np.inf
    with pytest.raises(ValueError, match=r"u\[3, 1\] is inf"):
        model.step(x, u)
