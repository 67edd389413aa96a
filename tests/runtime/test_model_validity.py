"""A Model whose C model (sr_model) is not what sr_model_init left is refused by every method, with a
KernelError naming the model (SR_ERR_MODEL), never a result.  (C: c/tests/test_model_validity.c.)"""
import math

import numpy as np
import pytest
from bindings._sr import ffi, lib

from runtime import Model, Params, initial_state
from runtime.errors import KernelError

X = initial_state(theta_Y=0.3, theta_P=-0.2, w_S=(0.2, 0.0, 0.1))
XB = np.stack([X, X])
U = np.array([0.1, -0.05])

CALLS = {
    "accel": lambda m: m.accel(X, U),
    "accel batch": lambda m: m.accel(XB),
    "inertia": lambda m: m.inertia(X),
    "rhs": lambda m: m.rhs(X, U),
    "energy": lambda m: m.energy(X),
    "equilibrium_residual": lambda m: m.equilibrium_residual(X),
    "step": lambda m: m.step(X, U, 0.01),
    "step rkmk4 batch": lambda m: m.step(XB, None, 0.01, "rkmk4"),
    "simulate": lambda m: m.simulate(X, 0.01, 3),
    "simulate_adaptive": lambda m: m.simulate_adaptive(X, 0.03, 0.01),
    "retract": lambda m: m.retract(X, np.zeros(12)),
    "local": lambda m: m.local(X, X),
    "accel_jacobian": lambda m: m.accel_jacobian(X, U),
    "accel_jacobian batch": lambda m: m.accel_jacobian(XB),
    "step_jacobian": lambda m: m.step_jacobian(X, U, 0.01, "rkmk4"),
}


def poisoned(field, index, value):
    m = Model(Params())
    getattr(m._model, field)[index] = value
    return m


@pytest.mark.parametrize("name", CALLS)
def test_a_valid_model_gives_results(name):
    """The baseline: the same calls on an untouched model succeed."""
    CALLS[name](Model(Params()))


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("field, index, value", [("p", 0, math.nan), ("p", 15, 1.5), ("c", 3, math.inf)],
                         ids=["r NaN", "m_P changed", "a constant inf"])
def test_a_changed_model_is_refused_naming_the_model(name, field, index, value):
    with pytest.raises(KernelError, match=r"^model: is not a valid sr_model") as info:
        CALLS[name](poisoned(field, index, value))
    assert info.value.field == "model" and info.value.status == lib.SR_ERR_MODEL


def test_a_zeroed_model_is_refused_naming_the_model():
    m = Model(Params())
    ffi.memmove(m._model, bytes(ffi.sizeof("sr_model")), ffi.sizeof("sr_model"))
    with pytest.raises(KernelError, match=r"^model: ") as info:
        m.step(X, U, 0.01)
    assert info.value.status == lib.SR_ERR_MODEL


def test_the_status_has_a_name():
    assert "model" in ffi.string(lib.sr_status_string(lib.SR_ERR_MODEL)).decode()
