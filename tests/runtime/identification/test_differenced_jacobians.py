"""The all-differences Jacobian source of the fit ("fd-all"): the state Jacobians by central
differences of the batched C step and accelerations are the analytic ones."""
import numpy as np
import pytest

from runtime.identification.coverage import simulated_log
from runtime.identification.sensitivity import accel_state_jacobian, differenced_state_jacobian, step_jacobians
from runtime.model import Model
from runtime.param_derivatives import PARAMETER_NAMES


@pytest.fixture(scope="module")
def motion():
    log, nominal, _ = simulated_log("k_Y,m_P", 0.2, seed=3)
    return Model(nominal), log.truth_states()[:6], log.torque_at(log.truth.t[:6])


def close(got, want, tol=1e-6):
    scale = np.abs(want).max(axis=(0, 1))
    return bool(np.all(np.abs(got - want).max(axis=(0, 1)) <= tol * np.maximum(scale, 1e-12)))


def test_the_differenced_step_jacobian_is_the_analytic_one(motion):
    model, X, U = motion
    assert close(differenced_state_jacobian(model, X, U, 0.01, "rkmk4"), model.step_jacobian(X, U, 0.01, "rkmk4")[0])


def test_the_comparison_fails_for_a_perturbed_column(motion):
    model, X, U = motion
    F = differenced_state_jacobian(model, X, U, 0.01, "rkmk4")
    F[:, :, 10] += 1e-4 * np.abs(F[:, :, 10]).max()
    assert not close(F, model.step_jacobian(X, U, 0.01, "rkmk4")[0])


def test_the_differenced_acceleration_jacobian_is_the_analytic_one(motion):
    model, X, U = motion
    assert close(accel_state_jacobian(model, X, U, "fd-all"), model.accel_jacobian(X, U)[0])


def test_every_source_gives_the_same_step_jacobians(motion):
    model, X, U = motion
    idx = [PARAMETER_NAMES.index(n) for n in ("k_Y", "m_P")]
    F, Jp = step_jacobians(model, X, U, 0.01, "rkmk4", idx, "analytic")
    for source in ("fd", "fd-all"):
        Fs, Jps = step_jacobians(model, X, U, 0.01, "rkmk4", idx, source)
        assert close(Fs, F) and close(Jps, Jp)
