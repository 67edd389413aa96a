"""The LQR's control law written out in NumPy, independently of c/sr_control.c: what the tests and
the benchmark check `sr_lqr_control` against (runtime/control/lqr_design.py holds the coordinates).

One sample: the operating point's curvature follows the reference's at `kappa_rate`, (z*, u*, K)
interpolated bilinearly in (v_ref, κ) (Schedule.at), u = u* − K (z − z*), clipped to ±u_max; when
neither torque was clipped the integrals advance (∫e_y only while |e_y| ≤ zone).
"""
import numpy as np

from . import lqr_design as design


def numpy_law(schedule, r, x, target, integrals, kappa_before, period, u_max, kappa_rate, zone):
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
    raw = u_star - (K_path if path else K_heading) @ dz
    u = np.clip(raw, -u_max, u_max)
    if np.all(u == raw):
        in_zone = path and abs(dz[design.Z_EY]) <= zone
        integrals = np.asarray(integrals) + period * np.array([dz[design.Z_EY] if in_zone else 0.0,
                                                               dz[design.Z_OM_X]])
    return raw, u, integrals, kappa
