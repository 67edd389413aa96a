"""runtime.casadi_model: the model as CasADi Functions in generated/casadi/ agrees with the C kernels,
and its AD derivatives with the generated Jacobian; the comparison sees a perturbed Function."""
import casadi as ca
import numpy as np
import pytest

from bindings._sr import lib
from runtime import Model, Params, casadi_model
from runtime.verification.sampling import random_inputs, random_states

TOL = 1e-13
METHODS = {"sr_step_lie_euler": "lie-euler", "sr_step_rkmk4": "rkmk4", "sr_step_cf4": "cf4"}


@pytest.fixture(scope="module")
def samples():
    rng = np.random.default_rng(19)
    params = Params()
    return Model(params), casadi_model.parameter_vector(params), random_states(rng, 40, params), random_inputs(rng, 40)


def worst_relative(got, expected):
    return max(np.abs(np.ravel(g) - e).max() / np.abs(e).max() for g, e in zip(got, expected))


def accel_difference(accel, model, p, X, U):
    return worst_relative([accel(x, u, p) for x, u in zip(X, U)], [model.accel(x, u) for x, u in zip(X, U)])


def step_difference(step, method, model, p, X, U, dt=0.01):
    return worst_relative([step(x, u, dt, p) for x, u in zip(X, U)], [model.step(x, u, dt, method) for x, u in zip(X, U)])


def test_casadi_accel_equals_the_c_kernel(samples):
    model, p, X, U = samples
    assert accel_difference(casadi_model.load("sr_accel"), model, p, X, U) <= TOL


@pytest.mark.parametrize("name", sorted(METHODS))
def test_casadi_step_equals_the_c_step(samples, name):
    model, p, X, U = samples
    assert step_difference(casadi_model.load(name), METHODS[name], model, p, X, U) <= TOL


@pytest.mark.parametrize("name", sorted(METHODS))
def test_casadi_step_equals_the_c_step_for_large_rotation_increments(samples, name):
    """dt = 0.2 s at up to 10 rad/s: the closed-form branches of Rodrigues and dexp⁻¹, not the series."""
    model, p, X, U = samples
    assert step_difference(casadi_model.load(name), METHODS[name], model, p, X, U, dt=0.2) <= 1e-12


def test_the_comparison_fails_for_a_function_perturbed_by_1e_6(samples):
    model, p, X, U = samples
    accel = casadi_model.load("sr_accel")
    perturbed = p.copy()
    perturbed[lib.SR_P_m_P] *= 1 + 1e-6
    assert accel_difference(accel, model, perturbed, X, U) > TOL
    step = casadi_model.load("sr_step_rkmk4")
    assert step_difference(lambda x, u, dt, q: step(x, u, dt, q) * (1 + 1e-6), "rkmk4", model, p, X, U) > TOL


def test_ad_jacobian_of_casadi_accel_equals_the_generated_accel_jacobian_in_nu_and_u(samples):
    """The error coordinates' nu block is nu itself: d(nu')/d(nu) and d(nu')/du by CasADi's AD of the
    exported Function against the C accel_jacobian (derived in derive/derivatives.py)."""
    model, p, X, U = samples
    x, u = ca.SX.sym("x", 35), ca.SX.sym("u", 2)
    out = casadi_model.load("sr_accel")(x, u, p)
    jac = ca.Function("accel_partials", [x, u], [ca.jacobian(out, x)[:, 30:35], ca.jacobian(out, u)])
    for xi, ui in zip(X[:10], U[:10]):
        Ja, Jb = model.accel_jacobian(xi, ui)
        J_nu, J_u = (np.array(m) for m in jac(xi, ui))
        assert np.abs(J_nu - Ja[:, 7:12]).max() <= 1e-11 * np.abs(Ja).max()
        assert np.abs(J_u - Jb).max() <= 1e-11 * np.abs(Jb).max()


def test_casadi_function_load_reads_every_generated_file():
    for name in casadi_model.NAMES:
        f = ca.Function.load(str(casadi_model.path(name)))
        assert f.name() == name and f.n_out() == 1


def test_load_refuses_an_unknown_name():
    with pytest.raises(ValueError, match="name: unknown Function .sr_step_euler.; choose one of sr_accel"):
        casadi_model.load("sr_step_euler")


def test_parameter_vector_refuses_a_dict():
    with pytest.raises(ValueError, match="runtime.Params"):
        casadi_model.parameter_vector(Params().as_dict())
