"""The sympy.physics.mechanics (KanesMethod) baseline of runtime/verification/alternatives/kane.py
agrees with the independent CasADi reference (runtime/verification/reference.py).

The symbolic derivation + lambdify run once per process (about 1-2 s here), so
the whole module takes a few seconds; no slow marker is needed.
"""
import dataclasses

import numpy as np
import pytest

from runtime import Params
from runtime.so3 import rot_x, rot_y, rot_z
from runtime.state import initial_state
from runtime.verification.alternatives import kane
from runtime.verification.alternatives.kane import KaneModel
from runtime.verification.reference import ReferenceModel
from runtime.verification.sampling import random_params, random_state

RTOL = 1e-9


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


@pytest.fixture(scope="module")
def models():
    params = Params.paper_simulation().paper_params.as_dict()
    return KaneModel(params), ReferenceModel(params)


def test_agrees_with_reference_at_random_states(models, rng):
    km, ref = models
    p = Params.paper_simulation()
    worst = 0.0
    for _ in range(50):
        x = random_state(rng, p)
        u = rng.uniform(-1.0, 1.0, size=2)
        a = km.accel(x, u)
        assert a.shape == (5,)
        worst = max(worst, _rel(a, ref.accel(x, u)))
    assert worst < RTOL, worst


def test_agrees_with_reference_for_other_parameters(rng):
    for _ in range(3):
        p = random_params(rng)
        km, ref = KaneModel(p), ReferenceModel(p.as_dict())
        for _ in range(5):
            x = random_state(rng, p)
            u = rng.uniform(-1.0, 1.0, size=2)
            assert _rel(km.accel(x, u), ref.accel(x, u)) < RTOL


@pytest.mark.parametrize("distance", [0.0, 1e-12, 1e-8, 1e-4])
@pytest.mark.parametrize("sign", [1, -1])
def test_accurate_at_and_near_the_gimbal_lock(models, distance, sign):
    """cos(theta) -> 0 (the shell's x axis vertical): the angles are ill-determined, accel is not."""
    km, ref = models
    R_S = rot_z(0.7) @ rot_y(sign * (np.pi / 2 - distance)) @ rot_x(-1.1)
    x = initial_state(0.4, -0.9, R_S=R_S, w_S=(1.5, -2.0, 3.0), w_Y=2.0, w_P=-3.0,
                      r=Params.paper_simulation().r)
    u = (0.3, -0.2)
    assert abs(kane.euler_zyx(R_S)[1]) == pytest.approx(np.pi / 2, abs=2 * distance + 1e-12)
    assert _rel(km.accel(x, u), ref.accel(x, u)) < RTOL


def test_euler_conversion_reproduces_the_rotation(rng):
    for R_S in [random_state(rng)[0:9].reshape(3, 3) for _ in range(20)] + [rot_y(np.pi / 2) @ rot_x(0.3)]:
        psi, theta, phi = kane.euler_zyx(R_S)
        np.testing.assert_allclose(rot_z(psi) @ rot_y(theta) @ rot_x(phi), R_S, atol=1e-14)


def test_derivation_is_cached_and_params_checked(models):
    km, _ = models
    other = KaneModel(Params())
    assert other._f_MF is km._f_MF
    assert km.derivation_seconds > 0
    with pytest.raises(ValueError):
        KaneModel({"r": 0.3})


def test_accel_batch_agrees_with_accel_state_by_state(models, rng):
    km, _ = models
    p = Params.paper_simulation()
    lock = initial_state(R_S=rot_z(0.7) @ rot_y(np.pi / 2) @ rot_x(-1.1), w_S=(0.3, -0.2, 0.5), r=p.r)
    X = np.array([random_state(rng, p) for _ in range(5)] + [lock])
    U = rng.uniform(-1.0, 1.0, size=(6, 2))
    A = km.accel_batch(X, U)
    assert A.shape == (6, 5)
    for x, u, a in zip(X, U, A):
        assert _rel(a, km.accel(x, u)) < 1e-13


def test_accel_batch_names_a_wrong_shape(models):
    km, _ = models
    with pytest.raises(ValueError, match="states must have shape"):
        km.accel_batch(np.zeros((3, 34)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="inputs must have shape"):
        km.accel_batch(np.zeros((3, 35)), np.zeros((2, 2)))


def test_math_module_variant_agrees_with_the_numpy_one(models, rng):
    km, _ = models
    p = Params.paper_simulation()
    fast = KaneModel(p, module="math")
    for _ in range(10):
        x, u = random_state(rng, p), rng.uniform(-1.0, 1.0, size=2)
        assert _rel(fast.accel(x, u), km.accel(x, u)) < 1e-13


def test_module_is_checked():
    with pytest.raises(ValueError, match="module"):
        KaneModel(Params.paper_simulation(), module="fortran")


def test_accel_batch_refuses_the_math_module_variant():
    fast = KaneModel(Params.paper_simulation(), module="math")
    with pytest.raises(ValueError, match="module='numpy'"):
        fast.accel_batch(np.zeros((3, 35)), np.zeros((3, 2)))
