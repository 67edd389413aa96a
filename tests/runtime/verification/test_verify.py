"""The kernels against the independent CasADi reference, and against the physics.

Every row of `make verify` has a test that it FAILS for a slightly perturbed kernel: a
parameter off by 1e-6 relative in the kernel only (the reference keeps the true one), or the
kernel's output wrapped with a small error of the kind the row is there to catch.
"""
import dataclasses
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


@pytest.fixture
def kernel_with(monkeypatch):
    """kernel_with(m_P=1e-6): verify builds its models with those parameters scaled by (1 + 1e-6)."""
    def perturb(**relative):
        def perturbed_model(params):
            return Model(dataclasses.replace(params, **{k: getattr(params, k) * (1 + v) for k, v in relative.items()}))
        monkeypatch.setattr(verify, "Model", perturbed_model)
    return perturb


@pytest.fixture
def accel_with(monkeypatch):
    """accel_with(f): Model.accel returns f(x, true accel) instead."""
    def perturb(error):
        original = Model.accel
        monkeypatch.setattr(Model, "accel", lambda self, x, u=None: error(np.asarray(x), original(self, x, u)))
    return perturb


def test_kernels_agree_with_the_reference_at_random_states_and_parameters():
    results = verify.cross_check(n_states=200, seed=11, n_param_sets=6)   # 1200 states
    assert_passed(results)


def test_cross_check_fails_for_a_slightly_wrong_kernel(monkeypatch):
    original = Model.accel
    monkeypatch.setattr(Model, "accel", lambda self, x, u=None: original(self, x, u) * (1 + 1e-8))
    results = verify.cross_check(n_states=5, seed=0, n_param_sets=1)
    assert not results[0].passed


@pytest.mark.parametrize("row", [0, 1, 2], ids=["accel", "inertia", "energy"])
def test_each_cross_check_row_fails_for_a_kernel_with_a_mass_off_by_1e_6(kernel_with, row):
    kernel_with(m_P=1e-6)
    assert not verify.cross_check(n_states=5, seed=0, n_param_sets=1)[row].passed


def test_general_robots_agree_with_both_independent_models():
    assert_passed(verify.general_cross_check(n_states=40, seed=12, n_robots=3))


@pytest.mark.parametrize("name, rows", [("m_Y", [0, 1, 2, 3]), ("slope", [0, 1, 3]), ("n_Y", [0, 1, 2, 3]),
                                        ("j_mP", [0, 1, 2, 3])])
def test_general_rows_fail_for_a_kernel_with_a_parameter_off_by_1e_6(kernel_with, name, rows):
    """The slope enters ν̇ and the energy, not M; a rotor and the yoke's mass everything."""
    kernel_with(**{name: 1e-6})
    results = verify.general_cross_check(n_states=5, seed=12, n_robots=1)
    assert [i for i, r in enumerate(results) if not r.passed] == rows


def test_general_robots_conserve_energy_on_their_slopes():
    assert_passed([verify.energy_conservation(n_runs=2, seed=7, t_end=3.0, general=True)])


def test_general_energy_row_fails_for_an_accel_off_by_1e_6_relative(accel_with):
    accel_with(lambda x, a: a * (1 + 1e-6))
    assert not verify.energy_conservation(n_runs=1, seed=7, t_end=3.0, general=True).passed


def test_energy_is_conserved_without_friction_and_torque():
    assert_passed([verify.energy_conservation(n_runs=2, seed=5, t_end=20.0)])


def test_energy_conservation_fails_for_an_accel_off_by_1e_6_relative(accel_with):
    accel_with(lambda x, a: a * (1 + 1e-6))
    assert not verify.energy_conservation(n_runs=1, seed=5, t_end=5.0).passed


def test_power_balance_holds_at_random_states():
    assert_passed([verify.power_balance(n_states=40, seed=6)])


def test_power_balance_detects_a_missing_damping_term(monkeypatch):
    original = Model.accel

    def undamped_shell(self, x, u=None):
        a = original(self, x, u)
        return a + 1e-3 * np.r_[x[30:33], 0, 0]
    monkeypatch.setattr(Model, "accel", undamped_shell)
    assert not verify.power_balance(n_states=5, seed=6).passed


def test_power_balance_fails_for_a_kernel_with_shell_damping_off_by_1e_6(kernel_with):
    kernel_with(k_S=1e-6)
    assert not verify.power_balance(n_states=5, seed=6).passed


def test_c_stepped_motions_obey_the_contact_force_and_angular_momentum_balances():
    assert_passed(verify.rolling_contact(seed=7))


@pytest.mark.parametrize("row", [0, 1], ids=["contact force", "angular momentum"])
@pytest.mark.parametrize("name", ["m_P", "k_S"])
def test_rolling_rows_fail_for_a_kernel_with_a_parameter_off_by_1e_6(kernel_with, name, row):
    kernel_with(**{name: 1e-6})
    assert not verify.rolling_contact(n_runs=1, seed=7)[row].passed


def test_the_contact_force_kernel_equals_the_reference_multiplier():
    assert_passed([verify.contact_force(n_states=10, seed=3)])


def test_the_contact_force_row_fails_for_a_force_off_by_1e_9(monkeypatch):
    original = Model.contact_force
    monkeypatch.setattr(Model, "contact_force", lambda self, x, u=None: original(self, x, u) * (1 + 1e-9))
    assert not verify.contact_force(n_states=3, seed=3, n_robots=0).passed


@pytest.mark.parametrize("name", ["m_Y", "slope"])
def test_the_contact_force_row_fails_for_a_kernel_with_a_parameter_off_by_1e_6(kernel_with, name):
    """m_Y enters only through the general robot's yoke first moment, the slope only through gravity."""
    kernel_with(**{name: 1e-6})
    assert not verify.contact_force(n_states=3, seed=3, n_robots=1).passed


def test_equilibria_are_rest_points_stable_below_and_unstable_above():
    assert_passed(verify.equilibria(seed=8))


def test_equilibrium_row_fails_for_a_spurious_accel_of_1e_10_at_rest(accel_with):
    accel_with(lambda x, a: a + 1e-10)
    assert not verify.equilibria(seed=8)[0].passed


def test_pendulum_down_row_fails_for_an_accel_of_the_wrong_sign(accel_with):
    accel_with(lambda x, a: -a)
    assert not verify.equilibria(seed=8)[1].passed


def test_pendulum_up_row_fails_for_a_kernel_with_gravity_too_weak(kernel_with):
    kernel_with(g=-1 + 1e-4)
    assert not verify.equilibria(seed=8)[2].passed


def test_planar_motions_stay_planar():
    assert_passed(verify.planar_symmetry(steps=1000))


@pytest.mark.parametrize("row", [0, 1], ids=["x-z plane", "y-z plane"])
def test_symmetry_rows_fail_for_a_motion_that_leaks_1e_9_out_of_its_plane(monkeypatch, row):
    original = Model.simulate

    def leaking(self, x0, dt, steps, **kwargs):
        X = original(self, x0, dt, steps, **kwargs)
        X[:, 30:33] += 1e-9 * X[:, [31, 30, 30]]      # ω_S couples x<->y by 1e-9
        return X
    monkeypatch.setattr(Model, "simulate", leaking)
    assert not verify.planar_symmetry(steps=200)[row].passed


def test_sensor_rows_pass_for_both_robots_and_say_what_they_catch():
    rows = verify.sensor_rows(10)
    assert len(rows) == 2 * len(verify.SENSOR_CATCHES)
    assert all(r.passed and r.catches for r in rows), verify.format_table(rows)


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
