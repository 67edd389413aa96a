"""Random states, inputs and parameter sets for the cross-checks (tests and `python -m runtime verify`)."""
import numpy as np

from ..params import Params
from ..so3 import random_rotation
from ..state import NU, initial_state


def random_state(rng, params=None, max_speed=10.0):
    """Random R_S, θ_Y, θ_P, position on the plane and speeds with |ω| components up to max_speed rad/s."""
    r = (params or Params()).r
    w = rng.uniform(-max_speed, max_speed, size=5)
    q = (rng.uniform(-1, 1), rng.uniform(-1, 1), r)
    return initial_state(theta_Y=rng.uniform(-np.pi, np.pi), theta_P=rng.uniform(-np.pi, np.pi),
                         R_S=random_rotation(rng), q=q, w_S=w[:3], w_Y=w[3], w_P=w[4], r=r)


def random_states(rng, n, params=None, max_speed=10.0):
    """n random valid states (n, 35), speeds up to `max_speed`."""
    return np.array([random_state(rng, params, max_speed) for _ in range(n)])


def random_inputs(rng, n, max_torque=1.0):
    """n random torque pairs (n, 2), uniform in +-max_torque [N m]."""
    return rng.uniform(-max_torque, max_torque, size=(n, NU))


def random_params(rng):
    """A parameter set that respects the geometry (yoke and pendulum inside the shell)."""
    r = rng.uniform(0.1, 0.6)
    half_diag = rng.uniform(0.3, 0.95) * r
    angle = rng.uniform(0.15, np.pi / 2 - 0.15)
    return Params.paper(r=r, m_S=rng.uniform(0.5, 5), k_S=rng.uniform(0, 0.3),
                  b=2 * half_diag * np.sin(angle), h=2 * half_diag * np.cos(angle),
                  m_b=rng.uniform(0.2, 5), m_h=rng.uniform(0.2, 5), k_Y=rng.uniform(0, 0.1),
                  l=rng.uniform(0.2, 1.0) * r, m_P=rng.uniform(0.2, 5), k_P=rng.uniform(0, 0.1),
                  g=rng.uniform(1.0, 10.0))


def random_inertia(rng, mass, size):
    """A random physical inertia tensor about the centre of mass: random principal moments of a
    body of extent ~size (those of a solid box, so the triangle inequality holds), rotated."""
    a, b, c = rng.uniform(0.1, 1.0, size=3) * size
    moments = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    R = random_rotation(rng)
    J = R @ np.diag(moments) @ R.T
    return (J + J.T) / 2


def random_centre(rng, radius):
    """A random point strictly inside the ball of this radius."""
    v = rng.normal(size=3)
    return v / np.linalg.norm(v) * rng.uniform(0.0, 0.9) * radius


def random_general_params(rng):
    """A general robot with every feature: off-centre masses, full tensors, geared rotors, a slope."""
    r = rng.uniform(0.1, 0.6)
    m_S, m_Y, m_P = rng.uniform(0.5, 5, size=3)
    return Params(r=r, m_S=m_S, j_S=rng.uniform(0.3, 0.7) * m_S * r**2, k_S=rng.uniform(0, 0.3),
                  m_Y=m_Y, c_Y=random_centre(rng, 0.5 * r), J_Y=random_inertia(rng, m_Y, r), k_Y=rng.uniform(0, 0.1),
                  m_P=m_P, c_P=random_centre(rng, r), J_P=random_inertia(rng, m_P, 0.5 * r), k_P=rng.uniform(0, 0.1),
                  j_mY=rng.uniform(0, 1e-3), n_Y=rng.choice([-1, 1]) * rng.uniform(1, 50),
                  j_mP=rng.uniform(0, 1e-3), n_P=rng.choice([-1, 1]) * rng.uniform(1, 50),
                  g=rng.uniform(1.0, 10.0), slope=rng.uniform(-0.4, 0.4))
