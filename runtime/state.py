"""State layout (35 float64) and constructors; see README, "State, input and parameters"."""
import numpy as np

NX, NU, NV = 35, 2, 5
#: Index ranges of the blocks of x.
IDX_RS, IDX_RY, IDX_RP = slice(0, 9), slice(9, 18), slice(18, 27)
IDX_Q, IDX_WS, IDX_WY, IDX_WP, IDX_NU = slice(27, 30), slice(30, 33), 33, 34, slice(30, 35)


def rot_x(theta):
    """Rotation about x by theta: the form of R_Y (Section 2.4, Observation)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(theta):
    """Rotation about y by theta: the form of R_P, Exp(theta Σ_P)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def initial_state(theta_Y=0.0, theta_P=0.0, R_S=None, q=None, w_S=(0.0, 0.0, 0.0), w_Y=0.0, w_P=0.0, *, r=0.3):
    """A state vector: R_Y = rot_x(theta_Y), R_P = rot_y(theta_P), R_S (default I), q (default (0, 0, r))."""
    x = np.zeros(NX)
    x[IDX_RS] = (np.eye(3) if R_S is None else np.asarray(R_S, dtype=np.float64).reshape(3, 3)).ravel()
    x[IDX_RY] = rot_x(theta_Y).ravel()
    x[IDX_RP] = rot_y(theta_P).ravel()
    x[IDX_Q] = (0.0, 0.0, r) if q is None else np.asarray(q, dtype=np.float64).reshape(3)
    x[IDX_WS] = np.asarray(w_S, dtype=np.float64).reshape(3)
    x[IDX_WY], x[IDX_WP] = w_Y, w_P
    return x


def yoke_angle(x):
    """θ_Y read back from R_Y (for plots and summaries; the model never uses angles)."""
    x = np.asarray(x)
    return np.arctan2(x[..., 16], x[..., 13])


def pendulum_angle(x):
    """θ_P read back from R_P."""
    x = np.asarray(x)
    return np.arctan2(x[..., 20], x[..., 18])
