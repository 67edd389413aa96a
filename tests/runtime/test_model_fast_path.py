"""The one-state fast path of Model.accel and Model.step (bindings/fastcall.c).

It must give the full path's numbers bit for bit, apply the full C state check, leave every
input it does not take (other dtypes, shapes, layouts, lists) to the full path, and let the
full path raise the same messages as before.
"""
import numpy as np
import pytest

from bindings._fastcall import Kernels
from runtime import KernelError, Model, Params, initial_state
from runtime.model import METHODS
from runtime.so3 import rot_x, rot_z
from runtime.verification.sampling import random_inputs, random_states


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


@pytest.fixture(scope="module")
def states(model):
    rng = np.random.default_rng(17)
    return random_states(rng, 20, model.params), random_inputs(rng, 20)


@pytest.fixture
def x():
    return initial_state(theta_Y=0.3, theta_P=-0.4, R_S=rot_z(0.2) @ rot_x(0.1), w_S=(0.2, -0.1, 0.0), w_Y=0.5)


def test_fast_accel_equals_the_full_path_bit_for_bit(model, states):
    X, U = states
    for x, u in zip(X, U):
        fast = model._fast.accel(x, u)
        assert fast is not None
        assert np.array_equal(fast, model._accel(x, u))
        assert np.array_equal(model._fast.accel(x, None), model._accel(x, None))


@pytest.mark.parametrize("method", sorted(METHODS))
def test_fast_step_equals_the_full_path_bit_for_bit(model, states, method):
    X, U = states
    for x, u in zip(X[:5], U[:5]):
        fast = model._fast.step(x, u, 0.01, METHODS[method])
        assert fast is not None
        assert np.array_equal(fast, model._step(x, u, 0.01, method))


def test_fast_path_returns_a_fresh_array_each_call(model, x):
    a, b = model.accel(x), model.accel(x)
    assert a is not b
    a[:] = 0.0
    assert np.array_equal(b, model.accel(x))


@pytest.mark.parametrize("variant", [
    lambda x: x.astype(np.float32),                          # another dtype
    lambda x: x.astype(">f8"),                               # float64, byte-swapped
    lambda x: np.repeat(x, 2)[::2],                          # not contiguous
    lambda x: x[None, :],                                    # a batch of one
    lambda x: x.tolist(),                                    # a list
    lambda x: np.frombuffer(b"\0" + x.tobytes(), offset=1),  # misaligned
])
def test_inputs_the_fast_path_does_not_take_go_to_the_full_path(model, x, variant):
    assert model._fast.accel(variant(x), None) is None
    assert model._fast.step(variant(x), None, 0.01, METHODS["rkmk4"]) is None
    expected = model.accel(x)
    assert np.allclose(np.reshape(model.accel(variant(x)), expected.shape), expected, rtol=1e-6, atol=1e-6)


def test_inputs_of_the_wrong_kind_are_refused_by_the_fast_path(model, x):
    assert model._fast.accel(x, np.zeros(3)) is None            # u of the wrong length
    assert model._fast.accel(x, [0.0, 0.0]) is None             # u as a list
    assert model._fast.step(x, None, 1, METHODS["cf4"]) is None  # dt as an int
    assert model._fast.step(x, None, 0.01, 1.0) is None         # a method code that is no int
    with pytest.raises(TypeError):
        model._fast.accel(x)


def test_the_fast_path_applies_the_full_c_state_check(model, x):
    x[11] = 1e-3   # R_Y[0,2]: the kernel does not read it and sr_accel alone does not check it
    assert model._fast.accel(x, None) is None
    assert model._fast.step(x, None, 0.01, METHODS["lie-euler"]) is None
    with pytest.raises(KernelError, match=r"R_Y \(x\[9:18\]\) must be a rotation about x: R_Y\[0,2\]"):
        model.accel(x)
    with pytest.raises(KernelError, match=r"R_Y \(x\[9:18\]\) must be a rotation about x: R_Y\[0,2\]"):
        model.step(x)


def test_a_state_c_refuses_gets_the_full_paths_message(model, x):
    x[0:9] = (1 + 2e-6) * x[0:9]     # R_S off by 2e-6: |gamma| = 1 fails to 1e-6 only in full
    with pytest.raises(KernelError, match=r"R_S \(x\[0:9\]\) is not orthonormal"):
        model.accel(x)


def test_a_non_finite_torque_is_named_after_the_fast_path_refuses_it(model, x):
    with pytest.raises(ValueError, match=r"^u: u\[1\] is nan, expected a finite number$"):
        model.accel(x, np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match=r"^u: u\[1\] is nan, expected a finite number$"):
        model.step(x, np.array([0.0, np.nan]))


@pytest.mark.parametrize("dt, message", [(0.0, "dt: expected a positive finite number"),
                                         (np.inf, "dt: expected a positive finite number"),
                                         (np.nan, "dt: expected a positive finite number")])
def test_a_bad_step_size_is_named_after_the_fast_path_refuses_it(model, x, dt, message):
    assert model._fast.step(x, None, dt, METHODS["rkmk4"]) is None
    with pytest.raises(ValueError, match=message):
        model.step(x, dt=dt)


def test_an_unknown_method_is_named(model, x):
    with pytest.raises(ValueError, match=r"method: unknown integrator 'rk45'"):
        model.step(x, method="rk45")
    with pytest.raises(ValueError, match=r"method: unknown integrator \['rkmk4'\]"):
        model.step(x, method=["rkmk4"])


def test_kernels_refuses_null_addresses():
    with pytest.raises(ValueError, match="null address"):
        Kernels(0, 0, 0, None)
