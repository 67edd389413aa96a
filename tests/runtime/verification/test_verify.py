"""Issue 3: the kernels against the independent CasADi reference, and against the physics."""
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT
from runtime import Model
from runtime.verification import verify


def assert_passed(results):
    for r in results:
        assert r.passed, f"{r.name}: abs {r.abs_error:.3g}, rel {r.rel_error:.3g}, tol {r.tolerance:g}"


def test_kernels_agree_with_the_reference_at_random_states_and_parameters():
    results = verify.cross_check(n_states=200, seed=11, n_param_sets=6)   # 1200 states
    assert_passed(results)


def test_cross_check_fails_for_a_slightly_wrong_kernel(monkeypatch):
    original = Model.accel
    monkeypatch.setattr(Model, "accel", lambda self, x, u=None: original(self, x, u) * (1 + 1e-8))
    results = verify.cross_check(n_states=5, seed=0, n_param_sets=1)
    assert not results[0].passed


def test_energy_is_conserved_without_friction_and_torque():
    assert_passed([verify.energy_conservation(n_runs=2, seed=5, t_end=20.0)])


def test_power_balance_holds_at_random_states():
    assert_passed([verify.power_balance(n_states=40, seed=6)])


def test_power_balance_detects_a_missing_damping_term(monkeypatch):
    original = Model.accel

    def undamped_shell(self, x, u=None):
        a = original(self, x, u)
        return a + 1e-3 * np.r_[x[30:33], 0, 0]
    monkeypatch.setattr(Model, "accel", undamped_shell)
    assert not verify.power_balance(n_states=5, seed=6).passed


def test_contact_point_of_the_simulated_motion_does_not_slip():
    assert_passed([verify.rolling_constraint(seed=7)])


def test_equilibria_are_rest_points_stable_below_and_unstable_above():
    assert_passed(verify.equilibria(seed=8))


def test_planar_motions_stay_planar():
    assert_passed(verify.planar_symmetry(steps=1000))


def test_verify_command_prints_a_table_and_exits_zero():
    out = subprocess.run([sys.executable, "-m", "runtime", "verify", "--states", "10"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "cross-check accel" in out.stdout and "0 failed" in out.stdout


def test_rhs_and_equilibrium_residual_equal_M_times_the_reference_accel(rng):
    """f = M ν̇ with M and ν̇ from the independent reference; at rest and without torque, f is the residual."""
    from runtime import Params
    from runtime.verification.reference import ReferenceModel
    from runtime.verification.sampling import random_inputs, random_state
    params = Params.paper_simulation()
    model, ref = Model(params), ReferenceModel(params.as_dict())
    for _ in range(50):
        x, u = random_state(rng, params), random_inputs(rng, 1)[0]
        expected = ref.inertia(x) @ ref.accel(x, u)
        assert np.allclose(model.rhs(x, u), expected, rtol=1e-11, atol=1e-11 * np.abs(expected).max())
        rest = x.copy()
        rest[30:35] = 0
        expected = ref.inertia(rest) @ ref.accel(rest, np.zeros(2))
        assert np.allclose(model.equilibrium_residual(rest), expected, rtol=1e-11,
                           atol=1e-11 * np.abs(expected).max())
