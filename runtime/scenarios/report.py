"""Outputs of a scenario run: trajectory.csv, summary.json, and the whole set of files of a run.

Every file is written atomically (runtime/scenarios/atomic.py).

    files = write_outputs(result, pathlib.Path("out/t-shape"), gif=True)

writes the CSV, the figures (runtime/scenarios/plots.py), the animation
(runtime/scenarios/animation.py) and the summary.  Nothing here simulates:
see runtime/scenarios/scenario.py.
"""
import contextlib
import json
import pathlib
import time

import numpy as np

from ..state import (IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, absolute_inclinations,
                     pendulum_angle, yoke_angle)
from .animation import write_gif
from .atomic import write_text
from .plots import FIGURES, save_figure

#: Columns of trajectory.csv, in order (matrices row-major: R_S_12 is row 1, column 2).
CSV_COLUMNS = (["t", "q_x", "q_y", "q_z"]
               + [f"{m}_{i}{j}" for m in ("R_S", "R_Y", "R_P") for i in (1, 2, 3) for j in (1, 2, 3)]
               + ["w_S_x", "w_S_y", "w_S_z", "w_Y", "w_P", "u_Y", "u_P", "E"])


# -- derived quantities ---------------------------------------------------------------------
def dissipated_power(result):
    """Power taken by the dampers [W] at every sample: k_S|ω_S|² + k_Y ω_Y² + k_P ω_P²."""
    p, x = result.scenario.params, result.trajectory
    return p.k_S * np.sum(x[:, IDX_WS] ** 2, axis=1) + p.k_Y * x[:, IDX_WY] ** 2 + p.k_P * x[:, IDX_WP] ** 2


def motor_power(result):
    """Power the motors put in [W] at every sample: u_Y ω_Y + u_P ω_P."""
    x = result.trajectory
    return result.torques[:, 0] * x[:, IDX_WY] + result.torques[:, 1] * x[:, IDX_WP]


def summary(result, extra_wall_time=None):
    """The numbers of summary.json (SI units, angles in rad)."""
    s, x = result.scenario, result.trajectory
    q = x[:, IDX_Q]
    excursion = np.hypot(q[:, 0] - q[0, 0], q[:, 1] - q[0, 1])
    yoke_abs, pendulum_abs = absolute_inclinations(x[-1:])
    dt = s.dt
    # Rectangle rule with the state at the start of each step, matching the explicit integrator.
    dissipated = float(np.sum(dissipated_power(result)[:-1]) * dt)
    motor_work = float(np.sum(motor_power(result)[:-1]) * dt)
    out = {
        "scenario": s.name,
        "source": s.source,
        "description": s.description,
        "method": s.method,
        "dt_s": s.dt,
        "steps": s.steps,
        "duration_s": s.duration,
        "params": s.params.as_dict(),
        "start_position_m": q[0, :2].tolist(),
        "final_position_m": q[-1, :2].tolist(),
        "final_displacement_m": float(excursion[-1]),
        "largest_excursion_m": float(excursion.max()),
        "largest_excursion_time_s": float(result.time[int(excursion.argmax())]),
        "final_inclinations_rad": {
            "yoke_relative_to_shell": float(yoke_angle(x[-1])),
            "pendulum_relative_to_yoke": float(pendulum_angle(x[-1])),
            "yoke_normal_to_vertical": float(yoke_abs[0]),
            "pendulum_shaft_to_vertical": float(pendulum_abs[0]),
        },
        "energy_J": {
            "initial": float(result.energy[0]),
            "final": float(result.energy[-1]),
            "dissipated": dissipated,
            "motor_work": motor_work,
            # initial + motor work − dissipated − final: zero for the exact flow, O(dt) for Lie–Euler.
            "balance_residual": float(result.energy[0] + motor_work - dissipated - result.energy[-1]),
        },
        "wall_time_s": {"simulation": result.wall_time_s},
    }
    if extra_wall_time:
        out["wall_time_s"].update(extra_wall_time)
    return out


# -- files ------------------------------------------------------------------------------------
def trajectory_table(result):
    """The rows of trajectory.csv as an array (steps+1, len(CSV_COLUMNS))."""
    x = result.trajectory
    return np.column_stack([result.time, x[:, IDX_Q], x[:, IDX_RS], x[:, IDX_RY], x[:, IDX_RP],
                            x[:, IDX_WS], x[:, IDX_WY], x[:, IDX_WP], result.torques, result.energy])


def write_csv(result, target):
    """trajectory.csv: one header line naming the columns, then one row per sample.

    Numbers are written in Python's shortest round-trip form (repr), so
    reading them back gives the simulated doubles exactly.
    """
    lines = [",".join(CSV_COLUMNS)]
    lines += [",".join(map(repr, row)) for row in trajectory_table(result).tolist()]
    write_text(target, "\n".join(lines) + "\n")


def write_summary(summary_dict, target):
    write_text(target, json.dumps(summary_dict, indent=2) + "\n")


# -- everything for one run --------------------------------------------------------------------
#: Files a stopped run writes instead of the outputs (marked by name: never mistaken for a full run).
PARTIAL_FILES = ("trajectory.partial.csv", "summary.partial.json")

#: Every file name a run may write into its folder: a folder holding any of them "holds outputs".
OUTPUT_FILES = ("trajectory.csv", *FIGURES, "robot.gif", "summary.json", *PARTIAL_FILES)


def existing_outputs(folder):
    """The OUTPUT_FILES already present in `folder` (sorted; empty if the folder does not exist)."""
    folder = pathlib.Path(folder)
    return sorted(name for name in OUTPUT_FILES if (folder / name).exists())


def remove_stale(folder, keep):
    """Delete the OUTPUT_FILES in `folder` that are not in `keep` (paths just written), so that the
    folder holds only what the latest run produced.  Nothing else in the folder is touched."""
    keep = {pathlib.Path(k).name for k in keep}
    for name in OUTPUT_FILES:
        if name not in keep:
            with contextlib.suppress(FileNotFoundError):
                (pathlib.Path(folder) / name).unlink()


def write_outputs(result, folder, gif=True, progress=None):
    """Write trajectory.csv, the FIGURES, robot.gif (if `gif`) and summary.json (last) into `folder`.

    `progress(what, done, total)` reports the GIF's frames.  Returns the paths written.
    Whether an existing folder may be overwritten is the caller's decision (the CLI's --force).
    """
    started = time.perf_counter()
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = [folder / "trajectory.csv"]
    write_csv(result, written[-1])
    for filename, draw in FIGURES.items():
        written.append(folder / filename)
        save_figure(draw(result), written[-1])
    timings = {"csv_and_figures": time.perf_counter() - started}
    if gif:
        gif_started = time.perf_counter()
        written.append(folder / "robot.gif")
        write_gif(result, written[-1],
                  progress=None if progress is None else (lambda done, total: progress("gif", done, total)))
        timings["gif"] = time.perf_counter() - gif_started
    written.append(folder / "summary.json")
    write_summary(summary(result, timings), written[-1])
    return written


def write_partial_outputs(result, folder, stopped):
    """What a run stopped by a guard computed: trajectory.partial.csv (the valid rows, same columns as
    trajectory.csv) and summary.partial.json (the summary of those rows, plus "stopped": step, time
    and reason).  No figures.  `stopped` is the runtime.model.SimulationStopped exception."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    csv_path, summary_path = (folder / name for name in PARTIAL_FILES)
    write_csv(result, csv_path)
    info = summary(result)
    info["steps_computed"] = len(result.trajectory) - 1
    info["stopped"] = {"step": stopped.step, "time_s": stopped.time, "status": stopped.status,
                       "reason": str(stopped)}
    write_summary(info, summary_path)
    return [csv_path, summary_path]
