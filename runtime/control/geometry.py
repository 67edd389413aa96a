"""What a controller reads off a state: the rolling axis, heading, lean, planar velocity.

Conventions (docs/control.md).  The yoke turns about the shell's x axis, so the shell rolls
about a = R_S e_x, its rolling axis in the inertial frame.  A positive yoke torque rolls the
robot along f = e_z × a / |e_z × a| (from rest with R_S = I: along +y), its *forward* direction;
the heading ψ is the angle of f from the inertial x axis, ψ = atan2(a_x, −a_y).  The *lean* φ
is the angle by which the rolling axis leaves the horizontal, φ = asin(a_z).  Rolling about a
leaning axis turns the robot: the vertical part of the shell's angular velocity is ω_a sin φ,
so the path curvature (positive to the left) is κ = −sin φ / r whatever the speed.
"""
import numpy as np

from ..state import IDX_RS, IDX_WS


def rolling_axis(x):
    """a = R_S e_x (..., 3): the first column of R_S."""
    x = np.asarray(x)
    return x[..., IDX_RS].reshape(x.shape[:-1] + (3, 3))[..., :, 0]


def heading(x):
    """ψ [rad] in (−π, π]: direction of forward rolling, from the inertial x axis."""
    a = rolling_axis(x)
    return np.arctan2(a[..., 0], -a[..., 1])


def lean(x):
    """φ = asin(a_z) [rad]: tilt of the rolling axis out of the horizontal (κ = −sin φ / r)."""
    return np.arcsin(np.clip(rolling_axis(x)[..., 2], -1.0, 1.0))


def lean_for_curvature(kappa, r):
    """The lean φ [rad] that makes the robot roll on a path of curvature κ [1/m] (left positive)."""
    return np.arcsin(np.clip(-np.asarray(kappa) * r, -1.0, 1.0))


def planar_velocity(x, r):
    """q̇ (..., 2) [m/s] of the shell centre: rolling without slipping, q̇ = r (R_S ω_S) × e_z."""
    x = np.asarray(x)
    R_S = x[..., IDX_RS].reshape(x.shape[:-1] + (3, 3))
    w = np.einsum("...ij,...j->...i", R_S, x[..., IDX_WS])
    return r * np.stack([w[..., 1], -w[..., 0]], axis=-1)


def cross_track_rate(x, r, psi):
    """ė_y [m/s]: q̇ along the left normal (−sin ψ, cos ψ) of a path heading ψ (the rate of the
    signed cross-track error, left positive)."""
    v = planar_velocity(x, r)
    return -v[..., 0] * np.sin(psi) + v[..., 1] * np.cos(psi)


def forward_speed(x, r):
    """Speed along the forward direction f [m/s] (negative when rolling backwards)."""
    psi = heading(x)
    v = planar_velocity(x, r)
    return v[..., 0] * np.cos(psi) + v[..., 1] * np.sin(psi)


def wrap_angle(angle):
    """angle wrapped into [−π, π)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi
