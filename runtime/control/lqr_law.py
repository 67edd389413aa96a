"""The LQR's control law written out in NumPy, independently of c/sr_control.c: what the tests and
the benchmark check `sr_lqr_control` against (runtime/control/lqr_design.py holds the coordinates).

One sample: the operating point's curvature follows the reference's at `kappa_rate`, (z*, u*, K)
interpolated bilinearly in (v_ref, κ) (Schedule.at), u = u* − K (z − z*), clipped to ±u_max; each
integral advances at any error unless its step would push a clipped torque further past its limit,
and ∫e_y only while the error is steady (|ė_y| ≤ `steady_rate`).
"""
import numpy as np

from . import lqr_design as design
from .geometry import cross_track_rate


def numpy_law(schedule, r, x, target, integrals, kappa_before, period, u_max, kappa_rate, steady_rate):
    """(u_raw, u, integrals after, κ of the operating point) of one sample."""
    path = target.cross_track is not None
    kappa = target.curvature if path else 0.0
    if kappa_before is not None:
        step = kappa_rate * period
        kappa = kappa_before + np.clip(kappa - kappa_before, -step, step)
    z_star, u_star, K_path, K_heading = schedule.at(target.speed, kappa)
    z = design.error_coordinates(x, r, target.speed, target.heading, target.cross_track if path else 0.0,
                                 integrals)
    dz = z - z_star
    K = K_path if path else K_heading
    raw = u_star - K @ dz
    u = np.clip(raw, -u_max, u_max)
    e_y = dz[design.Z_EY]
    steps = period * np.array([e_y if path else 0.0, dz[design.Z_OM_X]])
    # A step that changes a clipped torque (by −K[:, 10 + i] s_i) in the direction of its excess is skipped.
    pushes = np.any(-K[:, design.Z_IY:] * steps * (raw - u)[:, None] > 0, axis=0)
    moving = abs(cross_track_rate(x, r, target.heading)) > steady_rate
    advance = ~pushes & np.array([not moving, True])
    return raw, u, np.asarray(integrals, dtype=float) + np.where(advance, steps, 0.0), kappa
