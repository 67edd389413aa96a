"""The Jacobian rows of `make verify` (runtime/verification/jacobians.py) pass for the kernel and
fail for a slightly perturbed one."""
import numpy as np
import pytest

from runtime.verification.jacobians import accel_jacobian_checks, step_jacobian_checks


def rows_pass(rows):
    return [rel <= tol for _, _, rel, tol in rows]


def test_accel_jacobian_rows_pass_for_the_kernel():
    assert rows_pass(accel_jacobian_checks(n_states=40, n_difference=5)) == [True, True]


@pytest.mark.parametrize("entry", [(0, 1), (3, 4), (4, 9)])
def test_accel_jacobian_rows_fail_for_a_perturbed_jacobian(entry):
    def perturbed(model, x, u):
        Ja, Jb = model.accel_jacobian(x, u)
        Ja = Ja.copy()
        Ja[entry] *= 1 + 1e-6
        return Ja, Jb
    assert rows_pass(accel_jacobian_checks(n_states=40, n_difference=5, jacobian=perturbed)) == [False, False]


def test_accel_jacobian_rows_fail_for_a_perturbed_input_jacobian():
    def perturbed(model, x, u):
        Ja, Jb = model.accel_jacobian(x, u)
        return Ja, Jb + 1e-6 * np.abs(Jb).max()
    assert rows_pass(accel_jacobian_checks(n_states=40, n_difference=5, jacobian=perturbed)) == [False, False]


def test_step_jacobian_rows_pass_for_every_method():
    assert all(rows_pass(step_jacobian_checks(n_states=4)))


@pytest.mark.parametrize("block", ["F", "G"])
def test_step_jacobian_rows_fail_for_a_perturbed_jacobian(block):
    """An error of 1e-6 of the Jacobian's largest entry (that of F) in one entry of F or of G fails both rows of
    every method."""
    def perturbed(model, x, u, dt, method):
        F, G = model.step_jacobian(x, u, dt, method)
        F, G = F.copy(), G.copy()
        if block == "F":
            F[2, 8] += 1e-6 * np.abs(F).max()
        else:
            G[9, 1] += 1e-6 * np.abs(F).max()
        return F, G
    assert rows_pass(step_jacobian_checks(n_states=4, jacobian=perturbed)) == [False] * 6


def general_robot():
    from runtime.verification.sampling import random_general_params
    return random_general_params(np.random.default_rng(21))


def test_accel_jacobian_rows_pass_for_a_general_robot():
    assert rows_pass(accel_jacobian_checks(n_states=20, n_difference=3, params=general_robot())) == [True, True]


def test_accel_jacobian_rows_fail_for_a_perturbed_jacobian_of_a_general_robot():
    """The general kernel's Jacobian (rotors, slope, full tensors), an entry of the slope's column
    direction δξ off by 1e-6."""
    def perturbed(model, x, u):
        Ja, Jb = model.accel_jacobian(x, u)
        Ja = Ja.copy()
        Ja[1, 0] *= 1 + 1e-6
        return Ja, Jb
    rows = accel_jacobian_checks(n_states=20, n_difference=3, params=general_robot(), jacobian=perturbed)
    assert rows_pass(rows) == [False, False]


def test_step_jacobians_differ_from_the_variational_equations_by_their_methods_local_error():
    from runtime.verification.jacobians import variational_checks
    assert rows_pass(variational_checks(n_states=2)) == [True, True, True]


def test_the_variational_rows_fail_for_another_methods_jacobian():
    """Lie-Euler's Jacobian handed in for RKMK4 and CF4: the difference is O(h^2), not O(h^5)."""
    from runtime.verification.jacobians import variational_checks

    def lie_euler_for_all(model, x, u, dt, method):
        return model.step_jacobian(x, u, dt, "lie-euler")
    assert rows_pass(variational_checks(n_states=1, jacobian=lie_euler_for_all)) == [True, False, False]


def test_the_fourth_order_variational_rows_fail_for_a_jacobian_entry_off_by_1e_3():
    """(Lie-Euler's own O(h^2) difference, 3e-2 at h = 0.01 s, hides such an entry: its Richardson
    rows are the tight ones.)"""
    from runtime.verification.jacobians import variational_checks

    def perturbed(model, x, u, dt, method):
        F, G = model.step_jacobian(x, u, dt, method)
        F = F.copy()
        F[3, 7] += 1e-3 * np.abs(F).max()
        return F, G
    assert rows_pass(variational_checks(n_states=1, jacobian=perturbed)) == [True, False, False]
