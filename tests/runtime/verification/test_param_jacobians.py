"""The parameter-Jacobian rows of `make verify` (runtime/verification/param_jacobians.py) pass for the
kernels and fail for a slightly perturbed sensitivity."""
import numpy as np
import pytest

from runtime.param_derivatives import PARAMETER_NAMES
from runtime.verification.param_jacobians import param_jacobian_checks, step_param_jacobian_checks
from runtime.verification.reference import FLAT_PARAM_NAMES


def rows_pass(rows):
    return [rel <= tol for _, _, rel, tol in rows]


def test_the_reference_lays_out_the_parameters_as_the_c_library():
    assert FLAT_PARAM_NAMES == PARAMETER_NAMES


def test_param_jacobian_rows_pass_for_the_kernel():
    assert rows_pass(param_jacobian_checks(n_states=10, n_difference=1)) == [True, True]


@pytest.mark.parametrize("column", ["r", "J_P_xy", "n_Y", "slope"])
def test_param_jacobian_rows_fail_for_a_perturbed_column(column):
    def perturbed(model, x, u):
        J = model.param_jacobian(x, u).copy()
        k = PARAMETER_NAMES.index(column)
        J[:, k] += 1e-6 * np.abs(J).max()
        return J
    assert rows_pass(param_jacobian_checks(n_states=10, n_difference=1, jacobian=perturbed)) == [False, False]


def test_step_param_jacobian_rows_pass_for_both_methods():
    assert all(rows_pass(step_param_jacobian_checks(n_states=2, n_difference=1)))


@pytest.mark.parametrize("row", [0, 5, 7])
def test_step_param_jacobian_rows_fail_for_a_perturbed_row(row):
    """An error of 1e-6 of the largest entry in one row (ξ_S, q, ν) fails every row of both methods."""
    def perturbed(model, x, u, h, method):
        J = model.step_param_jacobian(x, u, h, method).copy()
        J[row] += 1e-6 * np.abs(J).max()
        return J
    assert rows_pass(step_param_jacobian_checks(n_states=2, n_difference=1, jacobian=perturbed)) == [False] * 4
