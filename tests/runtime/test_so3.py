"""runtime/so3.py, the one NumPy SO(3) helper module, against SciPy's matrix exponential and the definitions."""
import math

import numpy as np
import pytest
from scipy.linalg import expm

from runtime import so3


def test_hat_is_the_cross_product_and_vee_inverts_it(rng):
    for _ in range(20):
        w, v = rng.normal(size=3), rng.normal(size=3)
        assert np.allclose(so3.hat(w) @ v, np.cross(w, v), rtol=0, atol=1e-15)
        assert np.array_equal(so3.vee(so3.hat(w)), w)


def test_hat_keeps_complex_entries_for_complex_step_differentiation():
    assert so3.hat([1j, 0.0, 0.0]).dtype == complex


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 1e-7, 1e-3, 0.5, 2.0, math.pi - 1e-9])
def test_exp_equals_scipys_matrix_exponential(rng, angle):
    axis = rng.normal(size=3)
    w = angle * axis / np.linalg.norm(axis)
    assert np.abs(so3.exp(w) - expm(so3.hat(w))).max() < 2e-15


def test_exp_of_a_perturbed_vector_is_detected_by_the_comparison(rng):
    w = rng.normal(size=3)
    assert np.abs(so3.exp(w * (1 + 1e-9)) - expm(so3.hat(w))).max() > 2e-15


@pytest.mark.parametrize("angle", [0.0, 1e-10, 1e-5, 0.3, 2.5, math.pi - 1e-4, math.pi - 1e-9, math.pi])
def test_log_inverts_exp_up_to_pi(rng, angle):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    w = so3.log(so3.exp(angle * axis))
    R = so3.exp(angle * axis)
    assert np.abs(so3.exp(w) - R).max() < 1e-12
    assert np.linalg.norm(w) <= math.pi + 1e-12
    if angle < math.pi - 1e-3:
        assert np.abs(w - angle * axis).max() < 1e-12


@pytest.mark.parametrize("rot, axis", [(so3.rot_x, 0), (so3.rot_y, 1), (so3.rot_z, 2)])
def test_rotations_about_an_axis_are_the_exponential_of_its_generator(rot, axis):
    for theta in (-2.0, 0.0, 0.4, 3.0):
        assert np.abs(rot(theta) - expm(theta * so3.hat(np.eye(3)[axis]))).max() < 4e-15


def test_orthonormality_and_rotation_defect_measure_the_distance_from_SO3(rng):
    R = so3.random_rotation(rng)
    gram, det = so3.orthonormality(R)
    assert gram < 1e-15 and abs(det - 1) < 1e-15
    bent = R.copy()
    bent[0, 1] += 1e-6
    assert 5e-7 < so3.rotation_defect(bent) < 3e-6
    assert so3.orthonormality(-R)[1] == pytest.approx(-1.0)
    assert so3.rotation_defect(-R) == pytest.approx(2.0)


def test_nearest_rotation_projects_onto_SO3_and_keeps_rotations(rng):
    R = so3.random_rotation(rng)
    assert np.abs(so3.nearest_rotation(R) - R).max() < 4e-15
    noisy = R + 1e-4 * rng.normal(size=(3, 3))
    assert so3.rotation_defect(so3.nearest_rotation(noisy)) < 4e-15
    assert np.abs(so3.nearest_rotation(noisy) - R).max() < 1e-3


def test_random_rotations_are_proper_rotations(rng):
    for _ in range(50):
        assert so3.rotation_defect(so3.random_rotation(rng)) < 1e-14
