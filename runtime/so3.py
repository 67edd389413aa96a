"""SO(3) in NumPy: hat and vee, the exponential and logarithm, rotations about an axis, rotation checks.

The one copy of these helpers for the Python side (state construction,
validation, verification, benchmarks, the independent reference).  It imports
NumPy and math only, never `bindings` or `derive`, so the independent
reference may use it and stay independent of the kernels and of the
derivation (tests/runtime/test_imports.py checks this).

Conventions: ⟦w⟧ = hat(w) is the skew matrix with hat(w) v = w × v;
rotations act on column vectors.
"""
import math

import numpy as np


def hat(w):
    """⟦w⟧, the skew-symmetric matrix with hat(w) @ v == cross(w, v) (complex entries allowed)."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def vee(W):
    """The inverse of hat on skew matrices: (W[2,1], W[0,2], W[1,0])."""
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def exp(w):
    """Exp(⟦w⟧) by Rodrigues' formula, I + a⟦w⟧ + b⟦w⟧², with the Taylor series of a and b below 1e-8 rad."""
    # Python floats: this runs once per step in the benchmark's Python loops, where NumPy scalars cost 2x.
    wx, wy, wz = w.tolist() if isinstance(w, np.ndarray) else w
    theta2 = wx * wx + wy * wy + wz * wz
    if theta2 < 1e-16:
        a, b = 1.0 - theta2 / 6, 0.5 - theta2 / 24
    else:
        theta = math.sqrt(theta2)
        a, b = math.sin(theta) / theta, (1 - math.cos(theta)) / theta2
    K = np.array([[0.0, -wz, wy], [wz, 0.0, -wx], [-wy, wx, 0.0]])
    return np.eye(3) + a * K + b * (K @ K)


def log(R):
    """w with Exp(⟦w⟧) = R and |w| ≤ π, for a rotation matrix R (accurate near 0 and near π)."""
    R = np.asarray(R, dtype=float)
    skew = 0.5 * vee(R - R.T)                       # sin(θ) n
    cos_theta = max(-1.0, min(1.0, 0.5 * (np.trace(R) - 1.0)))
    sin_theta = float(np.linalg.norm(skew))
    theta = math.atan2(sin_theta, cos_theta)
    if theta < 1e-8:
        return skew * (1.0 + theta * theta / 6)     # θ/sin θ to second order
    if math.pi - theta > 1e-6:
        return skew * (theta / sin_theta)
    # Near π, sin θ carries no accuracy: the axis from the symmetric part,
    # (R + Rᵀ)/2 + I = (1 + cos θ) I + (1 − cos θ) n nᵀ = 2 n nᵀ + O((π − θ)²).
    S = 0.25 * (R + R.T) + 0.5 * np.eye(3)
    column = int(np.argmax(np.diag(S)))
    n = S[:, column] / math.sqrt(S[column, column])
    if n @ skew < 0:
        n = -n
    return theta * n / np.linalg.norm(n)


def rot_x(theta):
    """Rotation about x by theta, Exp(θ⟦e_x⟧): the form of R_Y (Section 2.4, Observation)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(theta):
    """Rotation about y by theta, Exp(θ⟦e_y⟧): the form of R_P."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(theta):
    """Rotation about z by theta, Exp(θ⟦e_z⟧)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def orthonormality(R):
    """(max |(RᵀR − I)_ij|, det R) of a 3×3 matrix, computed as the C check sr_check_state does
    (determinant by cofactors along the first row)."""
    gram = R.T @ R - np.eye(3)
    det = (R[0, 0] * (R[1, 1] * R[2, 2] - R[1, 2] * R[2, 1]) - R[0, 1] * (R[1, 0] * R[2, 2] - R[1, 2] * R[2, 0])
           + R[0, 2] * (R[1, 0] * R[2, 1] - R[1, 1] * R[2, 0]))
    return float(np.abs(gram).max()), float(det)


def rotation_defect(R):
    """How far R is from SO(3): max(max |RᵀR − I|, |det R − 1|)."""
    gram, det = orthonormality(R)
    return max(gram, abs(det - 1.0))


def nearest_rotation(R):
    """The rotation nearest to R in the Frobenius norm (polar factor, det +1)."""
    U, _, Vt = np.linalg.svd(R)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    return U @ D @ Vt


def random_rotation(rng):
    """A rotation matrix drawn uniformly from SO(3) (QR of a Gaussian matrix, signs fixed)."""
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q
