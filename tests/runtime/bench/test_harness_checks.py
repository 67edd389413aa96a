"""The C loop's outputs are checked state by state against independent numbers."""
import numpy as np
import pytest

from runtime.bench.checks import WrongNumbers
from runtime.bench.harness import check_harness
from runtime.model import Model
from runtime.params import Params
from runtime.verification.sampling import random_inputs, random_states

STEP_KEYS = {"step_lie_euler": "lie-euler", "step_rkmk4": "rkmk4", "step_cf4": "cf4"}


@pytest.fixture(scope="module")
def loop_outputs():
    """What the C loop prints, made from the same C kernels through the Python API."""
    rng = np.random.default_rng(5)
    model = Model(Params.paper_simulation())
    X, U = random_states(rng, 6, model.params), random_inputs(rng, 6)

    def outputs(fn):
        return {"ns": 1.0, "check": [list(np.ravel(fn(x, u))) for x, u in zip(X, U)]}
    result = {"accel": outputs(model.accel), "accel_unchecked": outputs(model.accel),
              "inertia": outputs(lambda x, u: model.inertia(x))}
    for key, method in STEP_KEYS.items():
        result[key] = outputs(lambda x, u, method=method: model.step(x, u, 0.01, method))
    return model, X, U, result


def fresh(result):
    return {k: {"ns": v["ns"], "check": [list(row) for row in v["check"]]} for k, v in result.items()}


def test_every_state_of_the_c_loop_agrees_with_the_reference_and_the_numpy_tableaux(loop_outputs):
    model, X, U, result = loop_outputs
    result = fresh(result)
    worst = check_harness(result, model, X, U)
    assert result["checked"]["states"] == len(X)
    assert set(worst) >= {"C accel vs reference", "C inertia vs reference", "C rkmk4 step vs NumPy tableau on the reference"}
    assert max(worst.values()) < 1e-11
    assert all("check" not in v for v in result.values() if isinstance(v, dict) and "ns" in v)


@pytest.mark.parametrize("key", ["accel", "accel_unchecked", "inertia", *STEP_KEYS])
def test_a_wrong_number_in_the_last_state_of_any_kernel_is_caught(loop_outputs, key):
    model, X, U, result = loop_outputs
    result = fresh(result)
    result[key]["check"][-1][1] *= 1 + 1e-8
    with pytest.raises(WrongNumbers):
        check_harness(result, model, X, U)


def test_a_loop_that_returns_fewer_states_is_caught(loop_outputs):
    model, X, U, result = loop_outputs
    result = fresh(result)
    result["step_cf4"]["check"].pop()
    with pytest.raises(WrongNumbers, match="5 of its 6 states"):
        check_harness(result, model, X, U)
