"""The parameter Jacobians on chosen columns (`columns=` of Model.step_param_jacobian and
Model.param_jacobian; C: sr_step_param_jacobian_cols_batch, sr_accel_param_jacobian_cols_batch):
each column computed alone, by its own generated kernel, is that column of the full Jacobian and of
the AD reference."""
import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import Model
from runtime.param_derivatives import NPARAM, PARAMETER_NAMES
from runtime.state import NE
from runtime.verification.param_jacobians import param_jacobian_checks, step_param_jacobian_checks
from runtime.verification.sampling import random_general_params, random_inputs, random_state

GENERAL = random_general_params(np.random.default_rng(83))
#: Every column once, out of order: each per-column kernel against its column of the full one.
SHUFFLED = [int(c) for c in np.random.default_rng(5).permutation(NPARAM)]
#: A fit's few free entries, r among them (its column also carries the rolling kinematics).
FEW = [PARAMETER_NAMES.index(n) for n in ("k_S", "m_P", "r", "J_P_yy", "j_mY", "c_P_z")]


def states(n, seed=0, params=GENERAL):
    rng = np.random.default_rng(seed)
    return np.array([random_state(rng, params, max_speed=3.0) for _ in range(n)]), random_inputs(rng, n)


def columns_match(part, full, cols):
    """The columns cols of `full` (..., m, 32) equal `part` (..., m, len(cols)) to 1e-10 of each column's scale."""
    want = full[..., cols]
    scale = np.abs(want).max(axis=tuple(range(want.ndim - 1)))
    return bool(np.all(np.abs(part - want).max(axis=tuple(range(want.ndim - 1))) <= 1e-10 * np.maximum(scale, 1e-300)))


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
@pytest.mark.parametrize("cols", [SHUFFLED, FEW, [PARAMETER_NAMES.index("slope")]])
def test_the_step_sensitivity_on_chosen_columns_is_those_columns_of_the_full_one(method, cols):
    model = Model(GENERAL)
    X, U = states(5)
    part = model.step_param_jacobian(X, U, 0.01, method, columns=cols)
    assert part.shape == (5, NE, len(cols))
    assert columns_match(part, model.step_param_jacobian(X, U, 0.01, method), cols)


@pytest.mark.parametrize("cols", [SHUFFLED, FEW])
def test_the_accelerations_sensitivity_on_chosen_columns_is_those_columns_of_the_full_one(cols):
    model = Model(GENERAL)
    X, U = states(5, seed=1)
    assert columns_match(model.param_jacobian(X, U, columns=cols), model.param_jacobian(X, U), cols)


@pytest.mark.parametrize("column", ["r", "m_P", "J_P_xy", "slope"])
def test_the_column_check_fails_for_a_perturbed_column(column):
    model = Model(GENERAL)
    X, U = states(3, seed=2)
    part = model.step_param_jacobian(X, U, 0.01, "rkmk4", columns=SHUFFLED).copy()
    c = SHUFFLED.index(PARAMETER_NAMES.index(column))
    part[:, :, c] += 1e-8 * np.abs(part[:, :, c]).max()
    assert not columns_match(part, model.step_param_jacobian(X, U, 0.01, "rkmk4"), SHUFFLED)


def all_columns_step(model, x, u, h, method):
    return model.step_param_jacobian(x, u, h, method, columns=np.arange(NPARAM))


def test_the_per_column_step_sensitivity_passes_the_ad_reference_rows():
    rows = step_param_jacobian_checks(n_states=2, n_difference=1, jacobian=all_columns_step)
    assert all(rel <= tol for _, _, rel, tol in rows), rows


def test_the_per_column_accelerations_sensitivity_passes_the_ad_reference_rows():
    rows = param_jacobian_checks(n_states=10, n_difference=1, jacobian=lambda m, x, u: m.param_jacobian(
        x, u, columns=np.arange(NPARAM)))
    assert all(rel <= tol for _, _, rel, tol in rows), rows


def test_the_ad_reference_rows_fail_for_a_perturbed_per_column_sensitivity():
    def perturbed(model, x, u, h, method):
        J = all_columns_step(model, x, u, h, method).copy()
        J[:, PARAMETER_NAMES.index("m_P")] += 1e-6 * np.abs(J).max()
        return J
    rows = step_param_jacobian_checks(n_states=2, n_difference=1, jacobian=perturbed)
    assert [rel <= tol for _, _, rel, tol in rows] == [False] * 4


def test_one_state_gives_one_block():
    model = Model(GENERAL)
    X, U = states(2, seed=3)
    np.testing.assert_array_equal(model.step_param_jacobian(X[0], U[0], 0.01, "rkmk4", columns=FEW),
                                  model.step_param_jacobian(X, U, 0.01, "rkmk4", columns=FEW)[0])
    np.testing.assert_array_equal(model.param_jacobian(X[0], U[0], columns=FEW),
                                  model.param_jacobian(X, U, columns=FEW)[0])


@pytest.mark.parametrize("columns", [[], [NPARAM], [-1], [0.5], [[1, 2]]])
def test_columns_that_are_no_parameter_are_named(columns):
    model = Model(GENERAL)
    X, U = states(1)
    with pytest.raises(ValueError, match="columns"):
        model.step_param_jacobian(X, U, 0.01, "rkmk4", columns=columns)
    with pytest.raises(ValueError, match="columns"):
        model.param_jacobian(X, U, columns=columns)


def _call(model, x, method=None, cols=(3,), ncols=None, n=None, out=True):
    x = np.ascontiguousarray(np.atleast_2d(x))
    buf = np.zeros(x.shape[0] * NE * max(len(cols), 1))
    failed = ffi.new("long *", -7)
    status = lib.sr_step_param_jacobian_cols_batch(
        model._model, lib.SR_RKMK4 if method is None else method, x.shape[0] if n is None else n,
        ffi.cast("double *", ffi.from_buffer(x)), ffi.NULL, 0.01, len(cols) if ncols is None else ncols,
        ffi.new("int[]", list(cols)) if cols else ffi.NULL,
        ffi.cast("double *", ffi.from_buffer(buf)) if out else ffi.NULL, failed)
    return status, failed[0]


@pytest.mark.parametrize("wrong, status", [
    (dict(method=2 ** 20), "SR_ERR_ARG"),           # no such method
    (dict(ncols=0), "SR_ERR_ARG"),
    (dict(ncols=NPARAM + 1), "SR_ERR_ARG"),
    (dict(cols=(NPARAM,)), "SR_ERR_ARG"),
    (dict(cols=(-1,)), "SR_ERR_ARG"),
    (dict(n=-1), "SR_ERR_ARG"),
    (dict(cols=()), "SR_ERR_NULL"),
    (dict(out=False), "SR_ERR_NULL"),
])
def test_the_c_function_refuses_wrong_arguments_with_their_status(wrong, status):
    model = Model(GENERAL)
    X, _ = states(2)
    assert _call(model, X, **wrong) == (getattr(lib, status), -1)


def test_the_c_function_names_the_row_of_a_state_it_cannot_step():
    model = Model(GENERAL)
    X, _ = states(3)
    X[1, 0] = np.nan
    assert _call(model, X) == (lib.SR_ERR_NONFINITE, 1)


def steps_match(a, b):
    """a equals b (B, 35) to 1e-12 of each state's largest entry: rounding, not a different step."""
    return bool(np.all(np.abs(a - b).max(axis=-1) <= 1e-12 * np.abs(b).max(axis=-1)))


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
@pytest.mark.parametrize("params", [GENERAL, None], ids=["general", "paper"])
def test_the_step_from_the_sensitivity_pass_is_the_steppers_to_rounding(method, params):
    model = Model(params)
    X, U = states(6, seed=3, params=params)
    nxt, _ = model.step_and_param_jacobian(X, U, 0.01, method, columns=FEW)
    assert steps_match(nxt, model.step(X, U, 0.01, method))


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
def test_the_sensitivity_pass_that_steps_gives_step_param_jacobians_columns(method):
    model = Model(GENERAL)
    X, U = states(4, seed=4)
    _, Jp = model.step_and_param_jacobian(X, U, 0.01, method, columns=FEW)
    assert np.array_equal(Jp, model.step_param_jacobian(X, U, 0.01, method, columns=FEW))


def test_the_step_check_fails_for_a_perturbed_step():
    model = Model(GENERAL)
    X, U = states(3, seed=5)
    nxt, _ = model.step_and_param_jacobian(X, U, 0.01, "rkmk4", columns=FEW)
    nxt[1, -1] += 1e-10 * np.abs(nxt[1]).max()
    assert not steps_match(nxt, model.step(X, U, 0.01, "rkmk4"))
    assert not steps_match(model.step(X, U, 0.01 * (1 + 1e-9), "rkmk4"), model.step(X, U, 0.01, "rkmk4"))


def test_the_sensitivity_pass_that_steps_refuses_a_null_end_state():
    model = Model(GENERAL)
    X, U = states(2, seed=6)
    Jp, failed = np.empty((2, NE, 1)), ffi.new("long *")
    status = lib.sr_step_and_param_jacobian_cols_batch(
        model._model, lib.SR_RKMK4, 2, ffi.cast("double *", ffi.from_buffer(X)), ffi.cast("double *", ffi.from_buffer(U)),
        0.01, 1, ffi.new("int[]", [0]), ffi.NULL, ffi.cast("double *", ffi.from_buffer(Jp)), failed)
    assert status == lib.SR_ERR_NULL
