"""The LQR's control law written out in NumPy, independently of c/sr_control.c: what the tests and
the benchmark check `sr_lqr_control` against (runtime/control/lqr_design.py holds the coordinates).

One sample: the operating point's curvature follows the reference's at `kappa_rate`, (z*, u*, K)
interpolated bilinearly in (v_ref, κ) (Schedule.at), u = u* − K (z − z*), clipped to ±u_max; each
integral advances at any error unless its step would push a clipped torque further past its limit,
and ∫e_y only while the error is steady (|ė_y| ≤ `steady_rate`).  On a path, with tight gains
(`tight_band` > 0), the gain's robot and path columns move toward K_tight by the weight
w = min(max(0, 1 − |e_y − e_y*| / tight_band), w_before + period / tight_rise) clamped to
[−tight_wait, 1], where after a clipped sample the second term is w_before − period / tight_fall
(w_before when tight_fall is 0); below 0 the gain is K_path's, so after a long clip the tight gains
return tight_wait · tight_rise later; the integrators' columns stay K_path's.  On a heading reference
with `heading_band` > 0 the same weight, with the heading error z[2] − z*[2] against heading_band and
`heading_rise`, moves the gain toward K_heading_tight (its integrators' columns K_heading's).  A share `world_share` of
∫e_y is held as a world vector W along the path's left normal n(ψ) = (−sin ψ, cos ψ): z[10] reads
I + n·W, and a step s of ∫e_y adds (1 − share) s to I and share·s·n to W (pass the integrals as
(I, ∫speed, W_x, W_y) to carry W).  Recovery at a large error (`recovery` = (cross_track, heading,
slow, rise), zeros: off): the law acts on e_y − e_y* clipped to ±cross_track and z[2] − z*[2] to
±heading (a bound of 0: not clipped); beyond either it is recovering: the tight weight's bound is 0,
no integral advances, and the recovery weight r moves by ±period / rise toward 1 (recovering) or 0
(when slow > 0); the sample's speed reference is v_ref (1 − slow · r_before).
"""
import dataclasses

import numpy as np

from . import lqr_design as design
from .geometry import cross_track_rate


def numpy_law(*args, **kwargs):
    """(u_raw, u, integrals after, κ of the operating point, the tight gains' weight) of one sample
    (`recovering_law` without its recovery weight)."""
    return recovering_law(*args, **kwargs)[:5]


def recovering_law(schedule, r, x, target, integrals, kappa_before, period, u_max, kappa_rate, steady_rate,
                   tight_before=0.0, clipped_before=False, tight_band=0.0, tight_rise=1.0, world_share=0.0,
                   tight_fall=0.0, tight_wait=0.0, heading_band=0.0, heading_rise=1.0, recovery=(0.0, 0.0, 0.0, 1.0),
                   recovery_before=0.0):
    """(u_raw, u, integrals after, κ of the operating point, the tight gains' weight, the recovery
    weight) of one sample; `integrals` (2,) or (4,) with the world part W, returned in the same form."""
    bound_y, bound_heading, slow, recovery_rise = recovery
    target = dataclasses.replace(target, speed=target.speed * (1 - slow * recovery_before))
    path = target.cross_track is not None
    held = np.zeros(4)
    held[:len(integrals)] = integrals
    normal = np.array([-np.sin(target.heading), np.cos(target.heading)])
    z_integrals = np.array([held[0] + (normal @ held[2:] if path else 0.0), held[1]])
    kappa = target.curvature if path else 0.0
    if kappa_before is not None:
        step = kappa_rate * period
        kappa = kappa_before + np.clip(kappa - kappa_before, -step, step)
    z_star, u_star, K_path, K_heading = schedule.at(target.speed, kappa)
    z = design.error_coordinates(x, r, target.speed, target.heading, target.cross_track if path else 0.0,
                                 z_integrals)
    dz = z - z_star
    recovering = False
    for i, bound in ((design.Z_EY, bound_y if path else 0.0), (2, bound_heading)):
        if bound > 0 and abs(dz[i]) > bound:
            dz[i], recovering = np.copysign(bound, dz[i]), True
    K = K_path if path else K_heading
    weight = 0.0
    band, rise_s, error = (tight_band, tight_rise, dz[design.Z_EY]) if path else (heading_band, heading_rise, dz[2])
    if band > 0:
        fall = period / tight_fall if tight_fall > 0 else 0.0
        rise = tight_before - fall if clipped_before else tight_before + period / rise_s
        weight = float(np.clip(min(rise, 0.0 if recovering else max(0.0, 1.0 - abs(error) / band)), -tight_wait, 1.0))
        robot_and_path = slice(0, design.Z_IY)
        K = K.copy()
        tight = schedule.tight_at(target.speed, kappa) if path else schedule.heading_tight_at(target.speed, kappa)
        K[:, robot_and_path] += max(weight, 0.0) * (tight[:, robot_and_path] - K[:, robot_and_path])
    raw = u_star - K @ dz
    u = np.clip(raw, -u_max, u_max)
    e_y = dz[design.Z_EY]
    steps = period * np.array([e_y if path else 0.0, dz[design.Z_OM_X]])
    # A step that changes a clipped torque (by −K[:, 10 + i] s_i) in the direction of its excess is skipped.
    pushes = np.any(-K[:, design.Z_IY:] * steps * (raw - u)[:, None] > 0, axis=0)
    moving = abs(cross_track_rate(x, r, target.heading)) > steady_rate
    advance = ~pushes & np.array([not moving, True]) & (not recovering)
    steps = np.where(advance, steps, 0.0)
    after = held + np.concatenate([[(1 - world_share) * steps[0], steps[1]], world_share * steps[0] * normal])
    weight_r = recovery_before
    if slow > 0:
        weight_r = float(np.clip(recovery_before + (period if recovering else -period) / recovery_rise, 0.0, 1.0))
    return raw, u, after[:len(integrals)], kappa, weight, weight_r
