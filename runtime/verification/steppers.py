"""The steppers of c/ transcribed independently in NumPy: Lie–Euler (eq. 111), RKMK4 and CF4.

The state is acted on by the Lie algebra so(3) × ℝ × ℝ × ℝ³ × ℝ⁵ (13 numbers): exponentials by
scipy.linalg.expm, dexp⁻¹ by its Bernoulli series in ad (no closed form), q̇ and ν̇ straight
from the equations.  The acceleration is a parameter (`accel(x, u) -> (5,)`): the kernel's, to
test the C steppers alone (tests/runtime/test_integrators.py), or the independent reference's,
so that a C step is checked against something that shares no code with it (the bench loop,
runtime/bench/harness.py).  The state layout is the reference's own table.
"""
import math

import numpy as np
from scipy.linalg import expm

from .reference import _NU, _Q, _RP, _RS, _RY, _WP, _WS, _WY

E_X, E_Y = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
BERNOULLI = {0: 1.0, 1: -0.5, 2: 1 / 6, 4: -1 / 30, 6: 1 / 42, 8: -1 / 30, 10: 5 / 66, 12: -691 / 2730, 14: 7 / 6}


def hat(w):
    """The skew-symmetric matrix [[w]] of a 3-vector w."""
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def field(accel, r, x, u):
    """The velocity in the algebra: (ω_S, ω_Y, ω_P, q̇ = r R_S (ω_S × γ), ν̇)."""
    R_S = x[_RS].reshape(3, 3)
    w = x[_WS]
    gamma = R_S.T @ np.array([0, 0, 1.0])
    qdot = r * R_S @ np.cross(w, gamma)
    return np.concatenate([w, [x[_WY], x[_WP]], qdot, accel(x, u)])


def act(x, th):
    """x · exp(θ)."""
    y = x.copy()
    y[_RS] = (x[_RS].reshape(3, 3) @ expm(hat(th[0:3]))).ravel()
    y[_RY] = (x[_RY].reshape(3, 3) @ expm(th[3] * hat(E_X))).ravel()
    y[_RP] = (x[_RP].reshape(3, 3) @ expm(th[4] * hat(E_Y))).ravel()
    y[_Q] = x[_Q] + th[5:8]
    y[_NU] = x[_NU] + th[8:13]
    return y


def dexpinv(th, f):
    """dexp⁻¹_{−θ}(f) = Σ B_k/k! ad_{−θ}^k f on so(3); identity on the abelian part."""
    k_out, term = np.zeros(3), f[0:3].copy()
    for k in range(15):
        k_out += BERNOULLI.get(k, 0.0) / math.factorial(k) * term
        term = np.cross(-th[0:3], term)
    return np.concatenate([k_out, f[3:]])


def lie_euler(accel, r, x, u, h):
    """Eq. (111): x · exp(h F(x))."""
    return act(x, h * field(accel, r, x, u))


def rkmk4(accel, r, x, u, h):
    """One RKMK4 step of size h from x under torque u (the reference implementation)."""
    K = [field(accel, r, x, u)]
    for a in (0.5, 0.5, 1.0):
        th = a * h * K[-1]
        K.append(dexpinv(th, field(accel, r, act(x, th), u)))
    return act(x, h / 6 * (K[0] + 2 * K[1] + 2 * K[2] + K[3]))


def cf4(accel, r, x, u, h):
    """One commutator-free CF4 step of size h from x under torque u (the reference implementation)."""
    F1 = field(accel, r, x, u)
    Y2 = act(x, h / 2 * F1)
    F2 = field(accel, r, Y2, u)
    F3 = field(accel, r, act(x, h / 2 * F2), u)
    F4 = field(accel, r, act(Y2, h * (F3 - F1 / 2)), u)
    y = act(x, h / 12 * (3 * F1 + 2 * F2 + 2 * F3 - F4))
    return act(y, h / 12 * (-F1 + 2 * F2 + 2 * F3 + 3 * F4))


#: By the method names of runtime.model.METHODS.
STEPPERS = {"lie-euler": lie_euler, "rkmk4": rkmk4, "cf4": cf4}
