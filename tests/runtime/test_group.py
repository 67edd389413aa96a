"""x ⊕ d and y ⊖ x (runtime/group.py, c/src/sr_group.c): inverse of each other for every angle, with
the meaning of each block as runtime/group.py defines it, and bad input named."""
import math

import numpy as np
import pytest

from runtime import Model
from runtime import so3
from runtime.errors import KernelError
from runtime.state import (IDX_E_NU, IDX_E_Q, IDX_E_TH_P, IDX_E_TH_Y, IDX_E_XI_S, IDX_NU, IDX_Q, NE,
                           rotations)
from runtime.verification.sampling import random_state, random_states


@pytest.fixture(scope="module")
def model():
    return Model()


def random_error(rng, n=None, angle=math.pi * 0.999):
    """Errors whose angles stay below π (where local inverts retract), any direction."""
    shape = (NE,) if n is None else (n, NE)
    d = rng.uniform(-1.0, 1.0, shape)
    axis = rng.normal(size=shape[:-1] + (3,))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    d[..., IDX_E_XI_S] = axis * rng.uniform(0, angle, shape[:-1] + (1,))
    d[..., IDX_E_TH_Y] = rng.uniform(-angle, angle, shape[:-1])
    d[..., IDX_E_TH_P] = rng.uniform(-angle, angle, shape[:-1])
    return d


def test_local_inverts_retract_for_angles_up_to_pi(model, rng):
    x = random_states(rng, 200, model.params)
    d = random_error(rng, 200)
    assert np.allclose(model.local(x, model.retract(x, d)), d, rtol=0, atol=1e-9)


def test_retract_inverts_local_between_any_two_states(model, rng):
    x, y = random_states(rng, 200, model.params), random_states(rng, 200, model.params)
    assert np.allclose(model.retract(x, model.local(x, y)), y, rtol=0, atol=1e-12)


@pytest.mark.parametrize("gap", [0.0, 1e-12, 1e-9, 1e-6, 1e-3])
def test_local_is_accurate_near_pi(model, rng, gap):
    """Rotations by π − gap: the recovered vector has the angle and axis to rounding, where
    θ/sin θ times the skew part would lose all accuracy."""
    x = random_state(rng, model.params)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    d = np.zeros(NE)
    d[IDX_E_XI_S] = (math.pi - gap) * axis
    got = model.local(x, model.retract(x, d))[IDX_E_XI_S]
    if gap == 0.0:                      # at π itself ±axis are the same rotation
        got = got if got @ axis > 0 else -got
    assert np.allclose(got, d[IDX_E_XI_S], rtol=0, atol=1e-12)


def test_local_near_pi_agrees_with_the_numpy_log(model, rng):
    x = random_state(rng, model.params)
    d = np.zeros(NE)
    d[IDX_E_XI_S] = (math.pi - 1e-7) * np.array([0.6, -0.8, 0.0])
    y = model.retract(x, d)
    R, R2 = rotations(x)[0], rotations(y)[0]
    assert np.allclose(model.local(x, y)[IDX_E_XI_S], so3.log(R.T @ R2), atol=1e-12)


def test_retract_moves_each_block_as_the_issue_defines(model, rng):
    x = random_state(rng, model.params)
    d = random_error(rng)
    y = model.retract(x, d)
    (RS, RY, RP), (RS2, RY2, RP2) = rotations(x), rotations(y)
    assert np.allclose(RS2, RS @ so3.exp(d[IDX_E_XI_S]), atol=1e-14)
    assert np.allclose(RY2, RY @ so3.rot_x(d[IDX_E_TH_Y]), atol=1e-14)
    assert np.allclose(RP2, RP @ so3.rot_y(d[IDX_E_TH_P]), atol=1e-14)
    assert np.array_equal(y[IDX_Q], x[IDX_Q] + np.append(d[IDX_E_Q], 0.0))
    assert np.array_equal(y[IDX_NU], x[IDX_NU] + d[IDX_E_NU])


def test_joint_angles_wrap_into_minus_pi_to_pi(model, rng):
    x = random_state(rng, model.params)
    d = np.zeros(NE)
    d[IDX_E_TH_Y], d[IDX_E_TH_P] = 1.5 * math.pi, -1.5 * math.pi
    back = model.local(x, model.retract(x, d))
    assert back[IDX_E_TH_Y] == pytest.approx(-0.5 * math.pi, abs=1e-12)
    assert back[IDX_E_TH_P] == pytest.approx(0.5 * math.pi, abs=1e-12)


def test_single_and_batch_forms_agree_bit_for_bit(model, rng):
    x, d = random_states(rng, 5, model.params), random_error(rng, 5)
    y = model.retract(x, d)
    assert np.array_equal(y, np.array([model.retract(a, b) for a, b in zip(x, d)]))
    assert np.array_equal(model.local(x, y), np.array([model.local(a, b) for a, b in zip(x, y)]))


def test_local_of_a_state_with_itself_is_zero(model, rng):
    x = random_state(rng, model.params)
    assert np.array_equal(model.local(x, x), np.zeros(NE))


def test_retract_refuses_a_nonfinite_error_naming_the_entry(model, rng):
    d = np.zeros(NE)
    d[4] = np.nan
    with pytest.raises(ValueError, match=r"d\[4\]"):
        model.retract(random_state(rng, model.params), d)


def test_retract_refuses_an_error_of_the_wrong_shape(model, rng):
    with pytest.raises(ValueError, match="d: "):
        model.retract(random_state(rng, model.params), np.zeros(11))


def test_local_refuses_an_invalid_second_state_by_name(model, rng):
    x = random_state(rng, model.params)
    y = x.copy()
    y[0] += 0.1
    with pytest.raises(KernelError, match="^y"):
        model.local(x, y)


def test_local_refuses_states_of_different_shapes(model, rng):
    x = random_states(rng, 2, model.params)
    with pytest.raises(ValueError, match="y: shape"):
        model.local(x, x[0])


def test_batch_failure_names_the_row(model, rng):
    x = random_states(rng, 3, model.params)
    d = np.zeros((3, NE))
    d[2, 0] = np.inf
    with pytest.raises(ValueError, match=r"d\[2, 0\]"):
        model.retract(x, d)
