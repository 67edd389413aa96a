"""Model.step_param_jacobian_fd (C: sr_step_param_jacobian_fd_batch): a step's sensitivity to
chosen parameters by finite differences in C, batched; the reference that the analytic sensitivity
is timed against and the Jacobian of a fit without it."""
import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import Model, Params
from runtime.param_derivatives import NPARAM, PARAMETER_NAMES
from runtime.state import NE
from runtime.verification.sampling import random_general_params, random_inputs, random_state

GENERAL = random_general_params(np.random.default_rng(38))


def states(model, n, seed=0):
    rng = np.random.default_rng(seed)
    return np.array([random_state(rng, model.params, max_speed=3.0) for _ in range(n)]), random_inputs(rng, n)


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
def test_the_differences_are_the_analytic_sensitivity_in_the_columns_asked_for(method):
    model = Model(GENERAL)
    X, U = states(model, 4)
    cols = [PARAMETER_NAMES.index(n) for n in ("k_P", "r", "m_P", "J_Y_xx", "j_mY")]   # r: the states' q_z moves
    fd = model.step_param_jacobian_fd(X, U, 0.01, method, columns=cols)
    exact = model.step_param_jacobian(X, U, 0.01, method)[:, :, cols]
    assert fd.shape == (4, NE, len(cols))
    scale = np.abs(exact).max(axis=(0, 1))
    assert np.all(np.abs(fd - exact).max(axis=(0, 1)) <= 1e-6 * scale), np.abs(fd - exact).max(axis=(0, 1)) / scale


def test_a_parameter_at_a_bound_takes_the_one_sided_difference():
    """The paper's rotors have zero inertia: a side below zero is no robot."""
    paper = Params.paper_simulation().replace(j_mY=0.0)
    model = Model(paper)
    X, U = states(model, 2, seed=1)
    col = [PARAMETER_NAMES.index("j_mY")]
    fd = model.step_param_jacobian_fd(X, U, 0.01, "rkmk4", columns=col)
    exact = model.step_param_jacobian(X, U, 0.01, "rkmk4")[:, :, col]
    assert np.abs(fd - exact).max() <= 1e-6 * np.abs(exact).max()


def test_one_state_gives_one_block():
    model = Model(GENERAL)
    X, U = states(model, 2, seed=2)
    np.testing.assert_array_equal(model.step_param_jacobian_fd(X[0], U[0], 0.01, "rkmk4", columns=[3]),
                                  model.step_param_jacobian_fd(X, U, 0.01, "rkmk4", columns=[3])[0])


@pytest.mark.parametrize("columns", [[], [NPARAM], [-1], [0.5]])
def test_columns_that_are_no_parameter_are_named(columns):
    model = Model(GENERAL)
    X, U = states(model, 1)
    with pytest.raises(ValueError, match="columns"):
        model.step_param_jacobian_fd(X, U, 0.01, "rkmk4", columns=columns)


def test_a_parameter_with_no_robot_on_either_side_is_named():
    """The paper's yoke lies on its tensor's triangle inequality: a product of inertia cannot move."""
    model = Model(Params.paper_simulation())
    X, U = states(model, 1)
    with pytest.raises(ValueError, match="no valid robot on either side"):
        model.step_param_jacobian_fd(X, U, 0.01, "rkmk4", columns=[PARAMETER_NAMES.index("J_Y_xz")])


def _call(model, x, method=None, cols=(3,), ncols=None, work=True, n=None):
    x = np.ascontiguousarray(np.atleast_2d(x))
    out = np.zeros(x.shape[0] * NE * max(len(cols), 1))
    buf = np.zeros(x.shape[0] * lib.SR_NX * 5)
    failed = ffi.new("long *", -7)
    status = lib.sr_step_param_jacobian_fd_batch(
        model._model, lib.SR_RKMK4 if method is None else method, x.shape[0] if n is None else n,
        ffi.cast("double *", ffi.from_buffer(x)), ffi.NULL, 0.01, len(cols) if ncols is None else ncols,
        ffi.new("int[]", list(cols)) if cols else ffi.NULL, ffi.cast("double *", ffi.from_buffer(out)),
        ffi.cast("double *", ffi.from_buffer(buf)) if work else ffi.NULL, failed)
    return status, failed[0]


@pytest.mark.parametrize("wrong, status", [
    (dict(method=2 ** 20), "SR_ERR_ARG"),           # no such method
    (dict(ncols=0), "SR_ERR_ARG"),
    (dict(cols=(NPARAM,)), "SR_ERR_ARG"),
    (dict(n=-1), "SR_ERR_ARG"),
    (dict(cols=()), "SR_ERR_NULL"),
    (dict(work=False), "SR_ERR_NULL"),
])
def test_the_c_function_refuses_wrong_arguments_with_their_status(wrong, status):
    model = Model(GENERAL)
    X, _ = states(model, 2)
    assert _call(model, X, **wrong) == (getattr(lib, status), -1)


def test_the_c_function_names_the_row_of_a_state_it_cannot_step():
    model = Model(GENERAL)
    X, _ = states(model, 3)
    X[1, 0] = np.nan
    assert _call(model, X) == (lib.SR_ERR_NONFINITE, 1)
