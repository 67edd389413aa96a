"""A step's state Jacobian and its parameter sensitivity at once (Model.step_jacobians; C:
sr_step_jacobian_param_cols_batch): F is `step_jacobian`'s and Jp those columns of
`step_param_jacobian`, for the general robot and the paper's, both methods."""
import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import Model
from runtime.param_derivatives import NPARAM, PARAMETER_NAMES
from runtime.state import NE
from runtime.verification.param_jacobians import step_param_jacobian_checks
from runtime.verification.sampling import random_general_params, random_inputs, random_state

GENERAL = random_general_params(np.random.default_rng(83))
SHUFFLED = [int(c) for c in np.random.default_rng(5).permutation(NPARAM)]
#: A fit's few free entries, r among them (its column also carries the rolling kinematics).
FEW = [PARAMETER_NAMES.index(n) for n in ("k_S", "m_P", "r", "J_P_yy", "j_mY", "c_P_z")]
#: Every entry that moves only the inertial parameters pi, shuffled: their brackets come from the
#: regressor (each kind of entry of d(pi)/dp once at least).
PI_ONLY = [c for c in SHUFFLED if PARAMETER_NAMES[c] not in ("r", "n_Y", "n_P", "g", "slope")]
ROBOTS = {"general": lambda: Model(GENERAL), "paper": lambda: Model()}


def states(model, n, seed=0):
    rng = np.random.default_rng(seed)
    return np.array([random_state(rng, model.params, max_speed=3.0) for _ in range(n)]), random_inputs(rng, n)


def close(got, want):
    """got equals want to 1e-10 of each column's scale (over the batch and the rows)."""
    axes = tuple(range(want.ndim - 1))
    scale = np.maximum(np.abs(want).max(axis=axes), 1e-300)
    return bool(np.all(np.abs(got - want).max(axis=axes) <= 1e-10 * scale))


@pytest.mark.parametrize("robot", sorted(ROBOTS))
@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
def test_the_state_jacobian_is_that_of_step_jacobian(robot, method):
    model = ROBOTS[robot]()
    X, U = states(model, 5)
    F, _ = model.step_jacobians(X, U, 0.01, method, columns=FEW)
    assert close(F, model.step_jacobian(X, U, 0.01, method)[0])


@pytest.mark.parametrize("robot", sorted(ROBOTS))
@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
@pytest.mark.parametrize("cols", [SHUFFLED, FEW, PI_ONLY], ids=["all-shuffled", "few", "pi-only"])
def test_the_parameter_columns_are_those_of_the_full_sensitivity(robot, method, cols):
    model = ROBOTS[robot]()
    X, U = states(model, 4, seed=1)
    _, Jp = model.step_jacobians(X, U, 0.01, method, columns=cols)
    assert Jp.shape == (4, NE, len(cols))
    assert close(Jp, model.step_param_jacobian(X, U, 0.01, method)[..., cols])


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_columns_of_the_inertial_parameters_alone_are_those_of_the_full_jacobians(robot):
    model = ROBOTS[robot]()
    X, U = states(model, 4, seed=4)
    assert close(model.step_param_jacobian(X, U, 0.01, "rkmk4", columns=PI_ONLY),
                 model.step_param_jacobian(X, U, 0.01, "rkmk4")[..., PI_ONLY])
    assert close(model.param_jacobian(X, U, columns=PI_ONLY), model.param_jacobian(X, U)[..., PI_ONLY])


@pytest.mark.parametrize("which", ["F, a column of xi_S", "F, a column of nu", "Jp, m_P", "Jp, c_P_z"])
def test_the_comparison_fails_for_a_perturbed_column(which):
    model = Model(GENERAL)
    X, U = states(model, 3, seed=2)
    F, Jp = (a.copy() for a in model.step_jacobians(X, U, 0.01, "rkmk4", columns=FEW))
    got, want, c = {"F, a column of xi_S": (F, model.step_jacobian(X, U, 0.01, "rkmk4")[0], 1),
                    "F, a column of nu": (F, model.step_jacobian(X, U, 0.01, "rkmk4")[0], 9),
                    "Jp, m_P": (Jp, model.step_param_jacobian(X, U, 0.01, "rkmk4")[..., FEW], 1),
                    "Jp, c_P_z": (Jp, model.step_param_jacobian(X, U, 0.01, "rkmk4")[..., FEW], 5)}[which]
    got[:, :, c] += 1e-8 * np.abs(got[:, :, c]).max()
    assert not close(got, want)


def parameter_part(model, x, u, h, method):
    return model.step_jacobians(x, u, h, method, columns=np.arange(NPARAM))[1]


def test_the_parameter_part_passes_the_ad_reference_rows():
    rows = step_param_jacobian_checks(n_states=2, n_difference=1, jacobian=parameter_part)
    assert all(rel <= tol for _, _, rel, tol in rows), rows


def test_the_ad_reference_rows_fail_for_a_perturbed_parameter_part():
    def perturbed(model, x, u, h, method):
        J = parameter_part(model, x, u, h, method).copy()
        J[:, PARAMETER_NAMES.index("k_S")] += 1e-6 * np.abs(J).max()
        return J
    rows = step_param_jacobian_checks(n_states=2, n_difference=1, jacobian=perturbed)
    assert [rel <= tol for _, _, rel, tol in rows] == [False] * 4


def test_one_state_gives_one_block():
    model = Model(GENERAL)
    X, U = states(model, 2, seed=3)
    one, batch = model.step_jacobians(X[0], U[0], 0.01, "rkmk4", columns=FEW), model.step_jacobians(
        X, U, 0.01, "rkmk4", columns=FEW)
    np.testing.assert_array_equal(one[0], batch[0][0])
    np.testing.assert_array_equal(one[1], batch[1][0])


def test_a_method_without_a_parameter_sensitivity_is_named():
    with pytest.raises(ValueError, match="method"):
        Model().step_jacobians(random_state(np.random.default_rng(0)), None, 0.01, "cf4", columns=FEW)


def _call(model, x, method=None, cols=(3,), ncols=None, n=None, F=True, Jp=True):
    x = np.ascontiguousarray(np.atleast_2d(x))
    fbuf, jbuf = np.zeros(x.shape[0] * NE * NE), np.zeros(x.shape[0] * NE * max(len(cols), 1))
    failed = ffi.new("long *", -7)
    status = lib.sr_step_jacobian_param_cols_batch(
        model._model, lib.SR_RKMK4 if method is None else method, x.shape[0] if n is None else n,
        ffi.cast("double *", ffi.from_buffer(x)), ffi.NULL, 0.01, len(cols) if ncols is None else ncols,
        ffi.new("int[]", list(cols)) if cols else ffi.NULL,
        ffi.cast("double *", ffi.from_buffer(fbuf)) if F else ffi.NULL,
        ffi.cast("double *", ffi.from_buffer(jbuf)) if Jp else ffi.NULL, failed)
    return status, failed[0]


@pytest.mark.parametrize("wrong, status", [
    (dict(method=lib.SR_CF4), "SR_ERR_ARG"),        # a step without a parameter sensitivity
    (dict(ncols=0), "SR_ERR_ARG"),
    (dict(cols=(NPARAM,)), "SR_ERR_ARG"),
    (dict(n=-1), "SR_ERR_ARG"),
    (dict(cols=()), "SR_ERR_NULL"),
    (dict(F=False), "SR_ERR_NULL"),
    (dict(Jp=False), "SR_ERR_NULL"),
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
