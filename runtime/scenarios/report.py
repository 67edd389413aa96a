"""Outputs of a scenario run: trajectory.csv, summary.json, and the whole set of files of a run.

Every file is written atomically (runtime/atomic.py).

    files = write_outputs(result, pathlib.Path("out/t-shape"), gif=True)

writes the CSV, the figures (runtime/scenarios/plots.py), the animation
(runtime/scenarios/animation.py), the interactive replay (runtime/scenarios/replay.py)
and the summary.  Nothing here simulates:
see runtime/scenario.py.
"""
import contextlib
import json
import pathlib
import time

import numpy as np

from ..state import (COLUMN_INDEX, IDX_Q, IDX_WP, IDX_WS, IDX_WY, STATE_COLUMNS, absolute_inclinations,
                     pendulum_angle, yoke_angle)
from .animation import frame_samples, write_gif
from ..atomic import write_text
from ..contact import contact_summary
from .plots import FIGURES, save_figure
from .replay import write_replay

#: Columns of trajectory.csv, in order (matrices row-major: R_S_12 is row 1, column 2).
CSV_COLUMNS = ["t", *STATE_COLUMNS, "u_Y", "u_P", "E"]


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
        "params": s.params.as_json(),
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
    if result.contact_force is not None and len(result.contact_force):
        out["contact"] = contact_summary(result.time, result.contact_force, s.friction)
    if extra_wall_time:
        out["wall_time_s"].update(extra_wall_time)
    return out


# -- files ------------------------------------------------------------------------------------
def trajectory_table(result):
    """The rows of trajectory.csv as an array (steps+1, len(CSV_COLUMNS))."""
    x = result.trajectory
    return np.column_stack([result.time, x[:, COLUMN_INDEX], result.torques, result.energy])


def write_csv(result, target):
    """trajectory.csv: one header line naming the columns, then one row per sample.

    Numbers are written in Python's shortest round-trip form (repr), so
    reading them back gives the simulated doubles exactly.
    """
    lines = [",".join(CSV_COLUMNS)]
    lines += [",".join(map(repr, row)) for row in trajectory_table(result).tolist()]
    write_text(target, "\n".join(lines) + "\n")


def write_summary(summary_dict, target):
    """Writes the summary dict as indented JSON to `target`, atomically."""
    write_text(target, json.dumps(summary_dict, indent=2) + "\n")


# -- everything for one run --------------------------------------------------------------------
#: Files a stopped run writes instead of the outputs (marked by name: never mistaken for a full run).
PARTIAL_FILES = ("trajectory.partial.csv", "summary.partial.json")


def _write_figure(draw):
    return lambda result, target, progress=None: save_figure(draw(result), target)


#: How each output file of a complete run is written: writer(result, target, progress=None), where
#: `progress(done, total)` may be called as the work goes (the GIF's frames).  summary.json is not
#: here: it is written last, from the others' timings.
WRITERS = {
    "trajectory.csv": lambda result, target, progress=None: write_csv(result, target),
    **{name: _write_figure(draw) for name, draw in FIGURES.items()},
    "robot.gif": write_gif,
    "replay.html": write_replay,
}

#: Every file name a run may write into its folder: a folder holding any of them "holds outputs".
OUTPUT_FILES = (*WRITERS, "summary.json", *PARTIAL_FILES)

#: Which wall-time entry of summary.json each file's writing time is added to.
TIMING_KEYS = {"robot.gif": "gif", "replay.html": "replay"}


def planned_files(gif=True, replay=True):
    """The names of the files a complete run writes before summary.json, in writing order."""
    return [name for name in WRITERS
            if (gif or name != "robot.gif") and (replay or name != "replay.html")]


def progress_units(result, name):
    """How many progress units writing `name` counts for: its frames for the GIF, 1 for any other file."""
    return len(frame_samples(len(result.trajectory))) if name == "robot.gif" else 1


def write_file(result, folder, name, progress=None):
    """Write the output file `name` (one of WRITERS) of `result` into `folder`; returns its wall time [s]."""
    started = time.perf_counter()
    WRITERS[name](result, pathlib.Path(folder) / name, progress=progress)
    return time.perf_counter() - started


def timings_by_key(seconds_by_file):
    """The "wall_time_s" entries of summary.json from each file's writing time."""
    out = {}
    for name, seconds in seconds_by_file.items():
        key = TIMING_KEYS.get(name, "csv_and_figures")
        out[key] = out.get(key, 0.0) + seconds
    return out


def finish_run(result, folder, seconds_by_file):
    """Write summary.json (last, so a folder with a summary is complete) and delete the stale outputs
    of an earlier run; returns the paths the run wrote."""
    folder = pathlib.Path(folder)
    written = [folder / name for name in seconds_by_file] + [folder / "summary.json"]
    write_summary(summary(result, timings_by_key(seconds_by_file)), written[-1])
    remove_stale(folder, written)
    return written


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


def write_outputs(result, folder, gif=True, replay=True, progress=None):
    """Write the files of a complete run into `folder` in this process, one after the other:
    trajectory.csv, the FIGURES, robot.gif (if `gif`), replay.html (if `replay`), summary.json (last).

    `progress(what, done, total)` reports each file's work.  Returns the paths written.  Output files
    of an earlier run that this one does not write are not deleted here (see `finish_run`).
    Whether an existing folder may be overwritten is the caller's decision (the CLI's --force).
    runtime/scenarios/parallel.py writes the same files of several runs in parallel processes.
    """
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    seconds = {}
    for name in planned_files(gif, replay):
        report = None if progress is None else (lambda done, total, name=name: progress(name, done, total))
        seconds[name] = write_file(result, folder, name, report)
    written = [folder / name for name in seconds] + [folder / "summary.json"]
    write_summary(summary(result, timings_by_key(seconds)), written[-1])
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
