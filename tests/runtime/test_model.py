"""runtime.Model: shapes, batches, and the structure every kernel output must have."""
import numpy as np
import pytest

from runtime import Model, Params, initial_state
from runtime.errors import KernelError
from runtime.verification.sampling import random_inputs, random_params, random_state, random_states
from runtime.so3 import rot_x, rot_y, rot_z


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def test_accel_of_one_state_has_shape_5(model, rng):
    assert model.accel(random_state(rng), np.array([0.1, -0.2])).shape == (5,)


def test_batch_accel_equals_row_by_row_accel(model, rng):
    X, U = random_states(rng, 50), random_inputs(rng, 50)
    batch = model.accel(X, U)
    assert batch.shape == (50, 5)
    rows = np.array([model.accel(x, u) for x, u in zip(X, U)])
    assert np.array_equal(batch, rows)


def test_batch_accel_over_several_blocks_equals_row_by_row_accel(model, rng):
    # C runs a batch 64 rows at a time through the vectorised kernel (sr_checked_accel_batch).
    X, U = random_states(rng, 150), random_inputs(rng, 150)
    assert np.array_equal(model.accel(X, U), np.array([model.accel(x, u) for x, u in zip(X, U)]))
    assert np.array_equal(model.accel(X), np.array([model.accel(x) for x in X]))


def test_batch_accel_checks_every_state_in_full(model, rng):
    X = random_states(rng, 150)
    X[130, 0] += 1e-3           # R_S no longer a rotation; |gamma| = 1 still (the kernel's cheap check)
    with pytest.raises(KernelError, match=r"^x\[130\]: .*R_S"):
        model.accel(X)


def test_accel_without_input_equals_zero_torque(model, rng):
    x = random_state(rng)
    assert np.array_equal(model.accel(x), model.accel(x, np.zeros(2)))


def test_inertia_has_shape_5x5_and_energy_is_a_float(model, rng):
    x = random_state(rng)
    assert model.inertia(x).shape == (5, 5)
    assert isinstance(model.energy(x), float)


@pytest.mark.parametrize("seed", range(5))
def test_inertia_is_symmetric_positive_definite(seed):
    rng = np.random.default_rng(seed)
    params = random_params(rng)
    model = Model(params)
    for x in random_states(rng, 200, params):
        M = model.inertia(x)
        assert np.array_equal(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0


def test_kinetic_energy_is_half_nu_M_nu(model, rng):
    for _ in range(20):
        x = random_state(rng)
        at_rest = x.copy()
        at_rest[30:35] = 0
        nu = x[30:35]
        kinetic = model.energy(x) - model.energy(at_rest)
        assert kinetic == pytest.approx(0.5 * nu @ model.inertia(x) @ nu, rel=1e-12)


def test_accel_solves_M_accel_equals_rhs(model, rng):
    for _ in range(50):
        x, u = random_state(rng), random_inputs(rng, 1)[0]
        a, M, f = model.accel(x, u), model.inertia(x), model.rhs(x, u)
        assert np.allclose(M @ a, f, rtol=1e-12, atol=1e-12 * np.abs(f).max())


def test_dynamics_depend_on_R_S_only_through_gamma(model, rng):
    """A rotation of the inertial frame about the vertical, R_S -> R_z(α) R_S, changes nothing."""
    for _ in range(50):
        x, u = random_state(rng), random_inputs(rng, 1)[0]
        y = x.copy()
        y[0:9] = (rot_z(rng.uniform(-np.pi, np.pi)) @ x[0:9].reshape(3, 3)).ravel()
        assert np.allclose(model.accel(y, u), model.accel(x, u), rtol=1e-13, atol=1e-12)
        assert np.allclose(model.inertia(y), model.inertia(x), rtol=1e-13, atol=1e-14)
        assert model.energy(y) == pytest.approx(model.energy(x), rel=1e-13)


def test_equilibrium_residual_vanishes_at_both_configurations_of_eq_108(model, rng):
    scale = model.params.potential_range()
    for _ in range(50):
        theta_Y, theta_P = rng.uniform(-np.pi, np.pi, size=2)
        R_YP = rot_x(theta_Y) @ rot_y(theta_P)
        for up in (False, True):
            # R_S R_Y R_P e_z = ±e_z: choose R_S = R_z(α) (R_Y R_P)ᵀ, flipped for the upright pendulum.
            flip = rot_x(np.pi) if up else np.eye(3)
            R_S = rot_z(rng.uniform(-np.pi, np.pi)) @ flip @ R_YP.T
            x = initial_state(theta_Y, theta_P, R_S=R_S)
            assert np.abs(model.equilibrium_residual(x)).max() < 1e-14 * scale
            assert np.abs(model.accel(x)).max() < 1e-12


def test_equilibrium_residual_is_nonzero_away_from_equilibrium(model):
    x = initial_state(theta_P=0.3)
    assert np.abs(model.equilibrium_residual(x)).max() > 0.1
