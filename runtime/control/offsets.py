"""The offset cases of `make control`: the shipped circle and line against a plant that differs from
the controller's model by one constant mismatch, or stands on an unmodelled slope.

* a mass (m_S, m_b, m_h, m_P, by the paper's names) or a damping (k_S, k_Y, k_P) 20 % off, either way;
* the pendulum's centre of mass c_P moved by 1 cm along one of its frame's axes, either way;
* a slope of a quarter of the plant's climbing limit under u_max (runtime/control/climbing.py):
  the line up, down and across it, and the circle (whose heading turns through every direction);
  with `known_slope`, the slope is in the controller's model as well (its slope feedforward).

Targets (docs/control.md, "Offset-free tracking"): second-half cross-track RMS ≤ 5 mm under every
mismatch and on the line on the slope, ≤ 1 cm on the circle on the slope.
"""
import dataclasses
import math

import numpy as np

from ..so3 import rot_z
from ..state import IDX_RS
from .climbing import climbing_limit
from .lqr import LqrGains

#: The controllers the offset table runs (the PID has no integral on the path); nmpc-c is the NMPC's
#: formulation in C (runtime/control/nmpc.py's NmpcC), which runs the table many times faster;
#: a kind ending in -slope is that controller with its online slope estimate on (runtime/control/slope.py);
#: lqr-plain is the task's LQR with its offset-free settings off (no estimate, no feedforward of it, the
#: cross-track integral at its default), the law the shipped path tasks ran before they carried them.
OFFSET_CONTROLLERS = ("lqr", "lqr-plain", "lqr-slope", "nmpc", "nmpc-slope", "nmpc-c", "nmpc-c-slope")
#: Those the table runs by default: the shipped circle's and line's LQR carries its estimate already
#: (so lqr-slope is the same law there), and the Python NMPC's estimate is the C NMPC's formulation
#: (its tests hold them equal), so only the C one runs it.
DEFAULT_OFFSET_CONTROLLERS = ("lqr", "lqr-plain", "nmpc", "nmpc-c", "nmpc-c-slope")
#: The slope estimate's time constant [s] of the -slope runs.
SLOPE_ESTIMATE_S = 5.0
#: What lqr-slope sets besides the estimate: the estimated pendulum fed forward, and the cross-track
#: integral loosened from 1 to 2 m s (the NMPC's): the estimate's feedforward carries the offsets the
#: integral held, and the looser integral, wound up less by the line's approach, leaves less of it in
#: the second half (docs/control.md, "Offset-free tracking").
LQR_SLOPE_SETTINGS = {"pendulum_feedforward": 1.0, "cross_track_integral_m_s": 2.0}
#: What lqr-plain sets: the offset-free settings back to LqrGains' defaults (off, the integral at 1 m s).
LQR_PLAIN_SETTINGS = {field.name: field.default for field in dataclasses.fields(LqrGains)
                      if field.name in ("slope_estimate_s", "slope_prior", "pendulum_feedforward",
                                        "cross_track_integral_m_s")}


def with_controller(task, kind):
    """The task with only its controller of `kind`; nmpc-c takes the settings of the task's nmpc,
    a kind ending in -slope those of its controller with `slope_estimate_s` = SLOPE_ESTIMATE_S (lqr-slope
    with LQR_SLOPE_SETTINGS too), lqr-plain those of its LQR with LQR_PLAIN_SETTINGS."""
    if kind == "lqr-plain":
        task = task.with_controller("lqr")
        spec = task.controllers[0]
        gains = dataclasses.replace(spec.gains, **LQR_PLAIN_SETTINGS)
        return dataclasses.replace(task, controllers=(dataclasses.replace(spec, gains=gains),))
    if kind.endswith("-slope"):
        task = with_controller(task, kind[:-len("-slope")])
        spec = task.controllers[0]
        more = LQR_SLOPE_SETTINGS if kind == "lqr-slope" else {}
        gains = dataclasses.replace(spec.gains, slope_estimate_s=SLOPE_ESTIMATE_S, **more)
        return dataclasses.replace(task, controllers=(dataclasses.replace(spec, gains=gains),))
    if kind != "nmpc-c" or "nmpc-c" in task.controller_kinds:
        return task.with_controller(kind)
    task = task.with_controller("nmpc")
    return dataclasses.replace(task, controllers=(dataclasses.replace(task.controllers[0], kind="nmpc-c"),))
#: Relative change of a mass or a damping.
MISMATCH = 0.20
#: How far the pendulum's centre of mass moves [m].
CENTRE_SHIFT_M = 0.01
#: The slope as a fraction of the plant's climbing limit.
SLOPE_FRACTION = 0.25
MASSES = ("m_S", "m_b", "m_h", "m_P")
DAMPINGS = ("k_S", "k_Y", "k_P")
#: The line's directions on the slope (the plane's x axis runs up it): heading [rad].
LINE_ON_SLOPE = {"up": 0.0, "down": math.pi, "across": math.pi / 2}
#: Case names and their targets [m] on the second-half cross-track RMS.
MISMATCH_TARGET_M = 0.005
SLOPE_LINE_TARGET_M = 0.005
SLOPE_CIRCLE_TARGET_M = 0.01


@dataclasses.dataclass(frozen=True)
class OffsetCase:
    """One run of the offset table: the task (its plant changed), what changed, its target [m]."""
    name: str
    change: str
    target_m: float
    task: object


def _turned(task, psi):
    """The task started heading ψ instead (its initial attitude turned about the vertical, its line's
    direction with it)."""
    x0 = task.scenario.x0.copy()
    x0[IDX_RS] = (rot_z(psi) @ x0[IDX_RS].reshape(3, 3)).ravel()
    spec = dict(task.reference_spec)
    if spec["kind"] == "line":
        spec["heading"] = spec.get("heading", 0.0) + psi
    return dataclasses.replace(task, scenario=dataclasses.replace(task.scenario, x0=x0), reference_spec=spec)


def slope_angle(params, u_max):
    """A quarter of the climbing limit of `params` under the yoke torque u_max [rad]."""
    return SLOPE_FRACTION * climbing_limit(params, u_max)


def offset_cases(circle, line, known_slope=False):
    """The OffsetCase list for the two shipped tasks (runtime.control.task.Task, one controller each);
    `known_slope`: the slope cases only, the slope in the controller's model too."""
    cases = []
    for base in (circle, line):
        plant = base.plant_params
        shifted = []
        for axis, label in enumerate("xyz"):
            for sign in (+1, -1):
                c_P = np.array(plant.c_P, dtype=float)
                c_P[axis] += sign * CENTRE_SHIFT_M
                shifted.append((f"c_P {label}{sign * 100 * CENTRE_SHIFT_M:+.0f} cm", {"c_P": tuple(c_P)}))
        scaled = [(f"{name} {sign * 100 * MISMATCH:+.0f} %", {name: getattr(plant.paper_params, name) * (1 + sign * MISMATCH)})
                  for name in MASSES + DAMPINGS for sign in (+1, -1)]
        for change, overrides in ([] if known_slope else scaled + shifted):
            cases.append(OffsetCase(base.name, change, MISMATCH_TARGET_M,
                                    dataclasses.replace(base, plant_params=plant.with_changes(**overrides))))
        slope = slope_angle(plant, base.u_max)
        on_slope = dataclasses.replace(base, plant_params=plant.replace(slope=slope))
        if known_slope:
            on_slope = dataclasses.replace(on_slope, scenario=dataclasses.replace(
                base.scenario, params=base.scenario.params.replace(slope=slope)))
        known = ", known" if known_slope else ""
        if base.reference_spec["kind"] == "line":
            for where, psi in LINE_ON_SLOPE.items():
                cases.append(OffsetCase(base.name, f"slope {math.degrees(slope):.3f} deg{known}, {where}",
                                        SLOPE_LINE_TARGET_M, _turned(on_slope, psi)))
        else:
            cases.append(OffsetCase(base.name, f"slope {math.degrees(slope):.3f} deg{known}", SLOPE_CIRCLE_TARGET_M, on_slope))
    return cases
