"""Model.accel_jacobian and Model.linearize (runtime/derivatives.py, c/src/sr_jacobians.c): the
first-order terms of ν̇ and of the error dynamics in the coordinates of retract/local."""
import numpy as np
import pytest

from runtime import Model, Params
from runtime.state import IDX_E_NU, IDX_E_Q, NE, NU, NV
from runtime.verification.jacobians import richardson_accel_jacobian
from runtime.verification.sampling import random_inputs, random_state, random_states


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def relative_error(ours, theirs):
    return np.abs(ours - theirs).max() / np.abs(theirs).max()


def test_accel_jacobian_is_the_first_order_term_of_accel_along_retract(model, rng):
    for _ in range(5):
        x, u = random_state(rng, model.params), random_inputs(rng, 1)[0]
        Ja, Jb = model.accel_jacobian(x, u)
        fd_a, fd_b = richardson_accel_jacobian(model, x, u)
        assert relative_error(Ja, fd_a) < 1e-8
        assert relative_error(Jb, fd_b) < 1e-8


def test_accel_jacobian_ignores_where_the_shell_is(model, rng):
    Ja, _ = model.accel_jacobian(random_state(rng, model.params))
    assert np.array_equal(Ja[:, IDX_E_Q], np.zeros((NV, 2)))


def test_accel_jacobian_batch_equals_single_calls_bit_for_bit(model, rng):
    x, u = random_states(rng, 4, model.params), random_inputs(rng, 4)
    Ja, Jb = model.accel_jacobian(x, u)
    assert Ja.shape == (4, NV, NE) and Jb.shape == (4, NV, NU)
    for i in range(4):
        a, b = model.accel_jacobian(x[i], u[i])
        assert np.array_equal(Ja[i], a) and np.array_equal(Jb[i], b)


def test_accel_jacobian_refuses_a_bad_state_by_row(model, rng):
    x = random_states(rng, 3, model.params)
    x[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"x\[1"):
        model.accel_jacobian(x)


def error_rate(model, x, u, d, w, h=1e-4, eps=1e-6):
    """d/dt of local(x(t), y(t)) / eps at t = 0, y(0) = x ⊕ eps d under u + eps w: RK4 steps of
    ±h (forward in time from x(−h) is not available, so a forward difference extrapolated from
    h and h/2), an independent estimate of A d + B w."""
    y = model.retract(x, eps * d)

    def rate(step):
        return (model.local(model.step(x, u, step, "rkmk4"), model.step(y, u + eps * w, step, "rkmk4"))
                - eps * d) / step / eps
    return 2 * rate(h / 2) - rate(h)


def test_linearize_matches_the_error_dynamics_of_simulated_neighbours(model, rng):
    x, u = random_state(rng, model.params, max_speed=2.0), random_inputs(rng, 1)[0]
    A, B = model.linearize(x, u)
    d, w = rng.normal(size=NE), rng.normal(size=NU)
    expected = error_rate(model, x, u, d, w)
    assert np.abs(A @ d + B @ w - expected).max() < 1e-3 * np.abs(expected).max()


def test_linearize_check_fails_for_a_wrong_kinematic_block(model, rng):
    """The sign of −ω × δξ matters: flipping it is caught by the same comparison."""
    x, u = random_state(rng, model.params, max_speed=2.0), random_inputs(rng, 1)[0]
    A, B = model.linearize(x, u)
    A[0:3, 0:3] *= -1
    d, w = rng.normal(size=NE), rng.normal(size=NU)
    expected = error_rate(model, x, u, d, w)
    assert np.abs(A @ d + B @ w - expected).max() > 1e-2 * np.abs(expected).max()


def test_linearize_acceleration_rows_are_the_accel_jacobian(model, rng):
    x = random_state(rng, model.params)
    A, B = model.linearize(x)
    Ja, Jb = model.accel_jacobian(x)
    assert np.array_equal(A[IDX_E_NU], Ja) and np.array_equal(B[IDX_E_NU], Jb)


def test_linearize_batch_equals_single_calls(model, rng):
    x = random_states(rng, 3, model.params)
    A, B = model.linearize(x)
    for i in range(3):
        a, b = model.linearize(x[i])
        assert np.allclose(A[i], a, rtol=0, atol=1e-15) and np.array_equal(B[i], b)
