"""The `tracking` metrics of a closed-loop run, each a pure function of arrays.

Definitions (docs/control.md, "Metrics"):
* cross_track_rms_m, cross_track_max_m: RMS and largest |e_y| of the samples at t ≥ T/2
  (path tasks; e_y the signed distance to the nearest point of the path);
* heading_settle_s / speed_settle_s: the first time after which the error stays within the band
  for the rest of the run (±3° of the heading; ±5 % of the reference speed); None if the last
  sample is outside the band;
* overshoot: how far the response goes past its target, as a fraction of the step (speed and
  heading tasks), or of the initial offset (the line task: the largest excursion to the far side);
* motor_energy_j: ∫ (|u_Y ω_Y| + |u_P ω_P|) dt, the mechanical work both motors deliver or absorb
  (ω_Y, ω_P are their shaft speeds relative to their housings);
* saturated_fraction: the fraction of controller samples with a torque clipped to ±u_max;
* solve_ms_p50, solve_ms_p99: percentiles of the controller's computation time per sample.
"""
import math

import numpy as np

from ..state import IDX_Q, IDX_WP, IDX_WY
from .geometry import forward_speed, heading, wrap_angle

HEADING_BAND_RAD = math.radians(3.0)
SPEED_BAND = 0.05


def settle_time(t, error, band):
    """First time after which |error| ≤ band until the end; None if the last sample is outside."""
    outside = np.nonzero(np.abs(np.asarray(error)) > band)[0]
    if len(outside) == 0:
        return float(t[0])
    if outside[-1] == len(t) - 1:
        return None
    return float(t[outside[-1] + 1])


def step_overshoot(values, start, target):
    """max(0, largest excursion of `values` past `target`) / |target − start|."""
    step = target - start
    if step == 0:
        raise ValueError("step_overshoot: target equals start")
    past = (np.asarray(values) - target) * np.sign(step)
    return float(max(0.0, past.max()) / abs(step))


def second_half_stats(t, error):
    """(RMS, max) of |error| over the samples with t ≥ t_end / 2."""
    t, error = np.asarray(t), np.asarray(error)
    late = error[t >= t[-1] / 2]
    return float(np.sqrt(np.mean(late ** 2))), float(np.max(np.abs(late)))


def motor_energy(t, torques, yoke_rate, pendulum_rate):
    """∫ |u_Y ω_Y| + |u_P ω_P| dt [J], rectangle rule: row n holds over [t_n, t_n+1)."""
    dt = np.diff(np.asarray(t))
    power = np.abs(torques[:-1, 0] * yoke_rate[:-1]) + np.abs(torques[:-1, 1] * pendulum_rate[:-1])
    return float(np.sum(power * dt))


def tracking_metrics(result, reference, kind, r, sample_every=1):
    """The metrics of a `ClosedLoopResult` on `reference` (task kind `kind`; r the shell radius)."""
    t = result.time[::sample_every]
    x = result.trajectory[::sample_every]
    v = forward_speed(x, r)
    target = reference.speed
    out = {"cross_track_rms_m": None, "cross_track_max_m": None, "heading_settle_s": None,
           "speed_settle_s": settle_time(t, v - target, SPEED_BAND * abs(target)) if target else None,
           "overshoot": None}
    psi = heading(x)
    if reference.is_path:
        e = reference.cross_track(x[:, IDX_Q][:, :2])
        out["cross_track_rms_m"], out["cross_track_max_m"] = second_half_stats(t, e)
        if kind == "line":
            # e starts at −offset (the path is on the left); the far side is e > 0.
            out["overshoot"] = float(max(0.0, e.max()) / abs(e[0])) if e[0] != 0 else None
    else:
        e_psi = wrap_angle(reference.heading - psi)
        out["heading_settle_s"] = settle_time(t, e_psi, HEADING_BAND_RAD)
        if kind == "heading":
            psi0 = float(psi[0])
            unwrapped = psi0 + np.unwrap(psi - psi0)
            goal = psi0 + float(wrap_angle(reference.heading - psi0))
            out["overshoot"] = step_overshoot(unwrapped, psi0, goal)
        elif kind == "speed":
            out["overshoot"] = step_overshoot(v, float(v[0]), target)
    out["motor_energy_j"] = motor_energy(result.time, result.torques, result.trajectory[:, IDX_WY],
                                         result.trajectory[:, IDX_WP])
    out["saturated_fraction"] = float(result.saturated_fraction)
    solve_ms = 1e3 * np.asarray(result.solve_s)
    out["solve_ms_p50"] = float(np.percentile(solve_ms, 50))
    out["solve_ms_p99"] = float(np.percentile(solve_ms, 99))
    return out
