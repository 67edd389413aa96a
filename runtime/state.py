"""State layout and constructors; see README, "State, input and parameters".

The layout is not written here: it is read from the compiled module, whose
SR_X_* offsets the generator emitted from derive/state.py (the one place that
decides it).  Every other runtime module indexes states through the names
below, never through raw numbers.
"""
import math

import numpy as np

from bindings._sr import lib

from .so3 import orthonormality, rot_x, rot_y, rot_z  # noqa: F401  (rot_z re-exported: the constructors' rotation forms)

NX, NU, NV = lib.SR_NX, lib.SR_NU, lib.SR_NV

IDX_RS = slice(lib.SR_X_R_S, lib.SR_X_R_S + 9)
"""Index ranges of the blocks of x (matrices row-major).  IDX_WY and IDX_WP are single entries."""
IDX_RY = slice(lib.SR_X_R_Y, lib.SR_X_R_Y + 9)
IDX_RP = slice(lib.SR_X_R_P, lib.SR_X_R_P + 9)
IDX_Q = slice(lib.SR_X_q, lib.SR_X_q + 3)
IDX_WS = slice(lib.SR_X_w_S, lib.SR_X_w_S + 3)
IDX_WY, IDX_WP = lib.SR_X_w_Y, lib.SR_X_w_P
IDX_NU = slice(lib.SR_X_w_S, lib.SR_X_w_S + NV)
"""ν = (ω_S, ω_Y, ω_P), contiguous from ω_S (the generated header promises it)."""
IDX_QZ = lib.SR_X_q + 2
"""q_z (= r on every valid state)."""

ROTATION_BLOCKS = {"R_S": IDX_RS, "R_Y": IDX_RY, "R_P": IDX_RP}
"""The rotation blocks by name, in state order."""
IDX_UY, IDX_UP = lib.SR_U_u_Y, lib.SR_U_u_P
"""Indices of the inputs u = (u_Y, u_P)."""

NE = lib.SR_NE
"""The error state d (12,) of `Model.retract` / `Model.local` and of every Jacobian
(right-trivialised; generated SR_E_* offsets): shell rotation vector, yoke and pendulum
angles, in-plane shift of q, change of ν."""
IDX_E_XI_S = slice(lib.SR_E_xi_S, lib.SR_E_xi_S + 3)
IDX_E_TH_Y, IDX_E_TH_P = lib.SR_E_th_Y, lib.SR_E_th_P
IDX_E_Q = slice(lib.SR_E_q, lib.SR_E_q + 2)
IDX_E_NU = slice(lib.SR_E_nu, lib.SR_E_nu + NV)

STATE_COLUMNS = (("q_x", "q_y", "q_z")
                 + tuple(f"{m}_{i}{j}" for m in ("R_S", "R_Y", "R_P") for i in (1, 2, 3) for j in (1, 2, 3))
                 + ("w_S_x", "w_S_y", "w_S_z", "w_Y", "w_P"))
"""The state's column names in tables (trajectory.csv, logs, estimates), in their order: q, R_S, R_Y,
R_P (row-major: R_S_12 is row 1, column 2), ω_S, ω_Y, ω_P."""
COLUMN_INDEX = np.r_[IDX_Q, IDX_RS, IDX_RY, IDX_RP, IDX_WS, IDX_WY, IDX_WP]
"""x[..., COLUMN_INDEX] is the state in the order of STATE_COLUMNS; x[..., COLUMN_INDEX] = table inverts it."""


def rotations(x):
    """(R_S, R_Y, R_P) of a state (35,) or of states (..., 35): arrays (..., 3, 3), views where possible."""
    x = np.asarray(x)
    if x.ndim == 1:                     # the common case, kept cheap for per-step Python loops
        return x[IDX_RS].reshape(3, 3), x[IDX_RY].reshape(3, 3), x[IDX_RP].reshape(3, 3)
    shape = x.shape[:-1] + (3, 3)
    return x[..., IDX_RS].reshape(shape), x[..., IDX_RY].reshape(shape), x[..., IDX_RP].reshape(shape)


def gamma(x):
    """γ = R_Sᵀ e_z, the vertical in the shell frame: the third row of R_S (..., 3)."""
    return rotations(x)[0][..., 2, :]


def _finite_number(value, name):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}: expected a real number, got {value!r} ({type(value).__name__})")
    if not math.isfinite(value):
        raise ValueError(f"{name}: {float(value)!r}, expected a finite number")
    return float(value)


def _finite_array(value, name, shape):
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:          # ragged nested lists
        raise ValueError(f"{name}: expected an array of real numbers ({exc})") from None
    if raw.dtype.kind not in "iuf":
        raise ValueError(f"{name}: expected real numbers (integer or float dtype), got dtype {raw.dtype}")
    if raw.shape != shape and not (raw.size == math.prod(shape) and raw.ndim == 1 and len(shape) == 2):
        raise ValueError(f"{name}: expected shape {shape}, got {raw.shape}")
    arr = raw.astype(np.float64).reshape(shape)
    if not np.isfinite(arr).all():
        raise ValueError(f"{name}: entry {tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])} is "
                         f"{float(arr[~np.isfinite(arr)][0])!r}, expected finite numbers")
    return arr


def initial_state(theta_Y=0.0, theta_P=0.0, R_S=None, q=None, w_S=(0.0, 0.0, 0.0), w_Y=0.0, w_P=0.0, *, r=0.3):
    """A state vector: R_Y = rot_x(theta_Y), R_P = rot_y(theta_P), R_S (default I), q (default (0, 0, r)).

    Every argument is checked, and a bad one raises ValueError naming it: angles, speeds and r
    finite real numbers (r > 0), R_S a rotation (orthonormal with det +1 to ROTATION_TOL, the
    rule of the C state check), q with q_z = r (the shell rests on the plane), shapes (3, 3) and (3,).
    """
    r = _finite_number(r, "r")
    if not r > 0:
        raise ValueError(f"r: {r!r}, expected a positive radius")
    theta_Y, theta_P = _finite_number(theta_Y, "theta_Y"), _finite_number(theta_P, "theta_P")
    w_Y, w_P = _finite_number(w_Y, "w_Y"), _finite_number(w_P, "w_P")
    R = np.eye(3) if R_S is None else _finite_array(R_S, "R_S", (3, 3))
    defect, det = orthonormality(R)
    if defect > lib.SR_ROTATION_TOL or abs(det - 1) > lib.SR_ROTATION_TOL:
        raise ValueError(f"R_S: not a rotation: max |RᵀR − I| = {defect:.3g}, det = {det:.6g} (needs orthonormal "
                         f"with det +1 to {lib.SR_ROTATION_TOL:g})")
    position = np.array([0.0, 0.0, r]) if q is None else _finite_array(q, "q", (3,))
    if abs(position[2] - r) > lib.SR_ROTATION_TOL * r:
        raise ValueError(f"q: q_z = {float(position[2])!r} must equal r = {r:g} (the shell rests on the plane)")
    x = np.zeros(NX)
    x[IDX_RS] = R.ravel()
    x[IDX_RY] = rot_x(theta_Y).ravel()
    x[IDX_RP] = rot_y(theta_P).ravel()
    x[IDX_Q] = position
    x[IDX_WS] = _finite_array(w_S, "w_S", (3,))
    x[IDX_WY], x[IDX_WP] = w_Y, w_P
    return x


def yoke_angle(x):
    """θ_Y read back from R_Y (for plots and summaries; the model never uses angles)."""
    R_Y = rotations(x)[1]
    return np.arctan2(R_Y[..., 2, 1], R_Y[..., 1, 1])


def pendulum_angle(x):
    """θ_P read back from R_P."""
    R_P = rotations(x)[2]
    return np.arctan2(R_P[..., 0, 2], R_P[..., 0, 0])


def _angle_to_vertical(axis):
    """Angle [rad] between unit vectors `axis` (..., 3) and e_z, accurate near 0 and π."""
    return np.arctan2(np.hypot(axis[..., 0], axis[..., 1]), axis[..., 2])


def absolute_inclinations(x):
    """(yoke, pendulum) [rad] against the vertical, as in Fig. 5, of a state or states (..., 35).

    Yoke: the angle between the normal of the yoke plane, R_S R_Y e_z, and e_z.
    Pendulum: the angle between the shaft, R_S R_Y R_P (−e_z), and −e_z.
    Both are unsigned, in [0, π].
    """
    R_S, R_Y, R_P = rotations(x)
    yoke = R_S @ R_Y
    return _angle_to_vertical(yoke[..., :, 2]), _angle_to_vertical((yoke @ R_P)[..., :, 2])
