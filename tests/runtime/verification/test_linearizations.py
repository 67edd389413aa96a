"""The linearisation rows of `make verify` (runtime/verification/linearizations.py) pass, and each fails
for a slightly perturbed kernel."""
import numpy as np
import pytest

from runtime import stability
from runtime.model import Model
from runtime.state import IDX_E_NU, IDX_E_TH_P
from runtime.verification import linearizations as L


def passed(rows):
    return [rel <= tol for _, _, rel, tol in rows]


def test_equilibrium_eigenvalue_rows_pass():
    assert passed(L.equilibrium_checks()) == [True, True]


def test_equilibrium_eigenvalue_rows_fail_for_a_perturbed_linearization():
    def perturbed(model, x, u):
        A, B = model.linearize(x, u)
        A = A.copy()
        A[IDX_E_NU.start + 4, IDX_E_TH_P] *= 1 + 1e-6        # the pendulum's restoring stiffness
        return A, B
    assert passed(L.equilibrium_checks(linearize=perturbed)) == [False, False]


def test_steady_rolling_row_passes():
    assert passed(L.steady_rolling_checks()) == [True]


def test_steady_rolling_row_fails_for_a_perturbed_accel(monkeypatch):
    accel = Model.accel

    def perturbed(self, x, u=None):
        return accel(self, x, u) + np.array([0.0, 0.0, 0.0, 1e-6, 0.0])
    monkeypatch.setattr(Model, "accel", perturbed)
    assert passed(L.steady_rolling_checks(speeds=(1.0,))) == [False]


def test_rolling_stability_row_passes():
    assert passed(L.rolling_stability_checks()) == [True]


def test_rolling_stability_row_fails_for_the_snapshot_eigenvalues_of_linearize():
    """The naive analysis (eigenvalues of linearize at one instant of the periodic motion) is refused."""
    def snapshot(model, speed):
        x, u = stability.steady_rolling(model, speed)
        ev = stability.eigenvalues(model, x, u)
        return ev[np.argsort(-ev.real)]
    assert passed(L.rolling_stability_checks(floquet=snapshot)) == [False]


def test_rolling_stability_row_fails_for_step_jacobians_of_a_step_2_percent_too_long(monkeypatch):
    step_jacobian = Model.step_jacobian

    def perturbed(self, x, u=None, dt=0.01, method="lie-euler"):
        return step_jacobian(self, x, u, 1.02 * dt, method)
    monkeypatch.setattr(Model, "step_jacobian", perturbed)
    assert passed(L.rolling_stability_checks()) == [False]
