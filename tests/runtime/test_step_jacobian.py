"""Model.step_jacobian (runtime/step_jacobian.py): shapes, batches, the definition it satisfies, bad input.
(Its agreement with differences of the C step and with linearize: tests/runtime/verification/test_jacobians.py.)"""
import numpy as np
import pytest

from runtime import Model, Params
from runtime.verification.sampling import random_inputs, random_states

METHODS = ["lie-euler", "rkmk4", "cf4"]


@pytest.fixture(scope="module")
def model():
    return Model(Params())


@pytest.fixture(scope="module")
def samples(model):
    rng = np.random.default_rng(12)
    return random_states(rng, 5, model.params), random_inputs(rng, 5)


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobian_predicts_the_step_of_a_small_perturbation_to_second_order(model, samples, method):
    X, U = samples
    rng = np.random.default_rng(1)
    x, u = X[0], U[0]
    F, G = model.step_jacobian(x, u, 0.01, method)
    direction, torque = rng.normal(size=12), rng.normal(size=2)
    y0 = model.step(x, u, 0.01, method)
    errors = []
    for eps in (1e-3, 5e-4):
        moved = model.local(y0, model.step(model.retract(x, eps * direction), u + eps * torque, 0.01, method))
        errors.append(np.abs(moved - eps * (F @ direction + G @ torque)).max())
    assert errors[1] < errors[0] / 3          # the remainder is O(eps^2): halving eps quarters it


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobian_batch_equals_single_calls(model, samples, method):
    X, U = samples
    F, G = model.step_jacobian(X, U, 0.01, method)
    assert F.shape == (5, 12, 12) and G.shape == (5, 12, 2)
    for i in range(5):
        Fi, Gi = model.step_jacobian(X[i], U[i], 0.01, method)
        assert np.array_equal(F[i], Fi) and np.array_equal(G[i], Gi)


def test_step_jacobian_refuses_an_unknown_method(model, samples):
    with pytest.raises(ValueError, match="method: unknown integrator"):
        model.step_jacobian(samples[0][0], None, 0.01, "euler")


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), "0.01"])
def test_step_jacobian_refuses_a_bad_dt(model, samples, dt):
    with pytest.raises(ValueError, match="dt"):
        model.step_jacobian(samples[0][0], None, dt, "rkmk4")


def test_step_jacobian_refuses_a_state_that_is_no_state(model, samples):
    x = samples[0][0].copy()
    x[0] = 2.0
    with pytest.raises(ValueError, match="R_S"):
        model.step_jacobian(x, None, 0.01, "rkmk4")


def general_model():
    from runtime.verification.sampling import random_general_params
    return Model(random_general_params(np.random.default_rng(31)))


@pytest.mark.parametrize("dt", [0.01, 0.5])
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("robot", ["paper", "general"])
def test_c_step_jacobian_equals_casadi_ad_of_the_exported_step(model, samples, dt, method, robot):
    """Two derivations: the C kernels by hand (right Jacobian of SO(3), rolling kinematics, accel_jacobian,
    for RKMK4 and CF4 stage by stage with dexp^-1 differentiated) and CasADi's AD of the SX step;
    dt = 0.5 s takes the closed forms rather than the series.  The general robot's too."""
    m = model if robot == "paper" else general_model()
    X, U = samples
    for x, u in zip(X, U):
        x = x.copy()
        x[29] = m.params.r
        F, G = m.step_jacobian(x, u, dt, method)
        F_ad, G_ad = m.casadi_step_jacobian(x, u, dt, method)
        scale = np.abs(F_ad).max()
        # A 0.5 s step of a fast random state can blow the Jacobian up to ~1e7 (rounding grows with it).
        tol = 1e-12 if dt == 0.01 else 1e-10
        assert np.abs(F - F_ad).max() <= tol * scale and np.abs(G - G_ad).max() <= tol * scale


@pytest.mark.parametrize("method", ["rkmk4", "cf4"])
def test_the_comparison_with_casadi_ad_sees_a_step_jacobian_off_by_1e_9(model, samples, method):
    x, u = samples[0][0], samples[1][0]
    F, G = model.step_jacobian(x, u, 0.05, method)
    F_ad, _ = model.casadi_step_jacobian(x, u, 0.05, method)
    F[3, 7] += 1e-9 * np.abs(F_ad).max()
    assert np.abs(F - F_ad).max() > 1e-12 * np.abs(F_ad).max()


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobian_batch_names_the_row_that_fails(model, samples, method):
    X, U = samples
    X = X.copy()
    X[1, 33] = np.nan
    with pytest.raises(ValueError, match=r"x\[1\]"):
        model.step_jacobian(X, U, 0.01, method)
