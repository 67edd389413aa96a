"""`make control`: every controller of every shipped task (a task file lists its controllers); one table (Markdown and CSV),
a folder per run with summary.json (metrics under `tracking`, the contact force's extremes under `contact`)
and figures.

    python -m runtime control [--out out/control] [--tasks circle,line] [--duration S] [--sensors FILE]
    python -m runtime control --offsets [--known-slope] [--only TEXT] [--out out/control] [--duration S]

`--duration` cuts every task short (a smoke run; the table then says so).  `--sensors` runs every
task on the C EKF of these sensors (a shipped set or a sensors file) instead of its own measurement;
a task's `[sensors]` does so for that task.  `--offsets` runs the offset table instead
(runtime/control/offsets.py): the LQR and the NMPC on the circle and the line against a plant with
one constant mismatch or on an unmodelled slope, out/control/offsets.md and .csv; `--only` keeps the
cases whose "task plant controller" contains TEXT; `--known-slope` runs only the slope cases, the
slope in the controller's model too (its slope feedforward).  A task with the NMPC (kind nmpc) also runs the
C NMPC (kind nmpc-c) on the same settings, in the row after it, unless it lists nmpc-c itself or its
horizon exceeds the C NMPC's capacity.  Below the table, the runs that read an estimate (on sensors,
or a task's `[estimator]`): the estimate's position and heading errors and, for a task on sensors, its
target ("Closed on the estimator": cross-track RMS ≤ 3 cm; the heading step within its nominal
task's settle time + 2 s) and whether it is met.
"""
import argparse
import csv
import dataclasses
import json
import platform
import subprocess
import pathlib
import sys

import numpy as np
from tqdm.auto import tqdm

from ..atomic import atomic_path, write_text
from ..contact import contact_summary
from ..model import Model
from ..sensor_set import load_sensor_set
from ..state import IDX_Q
from .closed_loop import simulate_closed_loop, simulate_on_sensors
from .geometry import heading, wrap_angle
from .metrics import tracking_metrics
from .offsets import DEFAULT_OFFSET_CONTROLLERS, OFFSET_CONTROLLERS, offset_cases, with_controller
from .plots import plot_estimate, plot_run
from .ranges import NMPC_C_RANGES
from .task import load_task, shipped_tasks

COLUMNS = ("cross_track_rms_m", "cross_track_max_m", "heading_settle_s", "speed_settle_s", "overshoot",
           "motor_energy_j", "saturated_fraction", "solve_ms_p50", "solve_ms_p99")
#: The estimator table's columns (the runs whose controller read an estimate).
ESTIMATOR_COLUMNS = ("position_rms_m", "position_max_m", "heading_rms_deg", "heading_max_deg")
#: The targets on the robot's own sensors (docs/control.md, "Closed on the estimator"): the path tasks'
#: second-half cross-track RMS [m]; the heading step within its nominal settle time plus this [s].
SENSORS_CROSS_TRACK_M = 0.03
SENSORS_SETTLE_MARGIN_S = 2.0
#: The suffix of a task on sensors; the same name without it is its nominal task.
SENSORS_SUFFIX = "-sensors"


def cpu_name():
    """The CPU's model name (from lscpu, else what the platform module reports)."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        return next(line.split(":", 1)[1].strip() for line in out.splitlines() if line.startswith("Model name"))
    except (OSError, subprocess.CalledProcessError, StopIteration):
        return platform.processor() or "unknown CPU"


def controller_runs(task):
    """The task with each of its controllers in turn; after the NMPC, the C NMPC on its settings
    (see the module)."""
    runs = []
    for kind in task.controller_kinds:
        runs.append(task.with_controller(kind))
        spec = runs[-1].controllers[0]
        if kind == "nmpc" and "nmpc-c" not in task.controller_kinds and \
                spec.gains.horizon <= NMPC_C_RANGES["horizon"].high:
            runs.append(dataclasses.replace(runs[-1], controllers=(dataclasses.replace(spec, kind="nmpc-c"),)))
    return runs


def run_task(task, progress=False):
    """(ClosedLoopResult, reference, tracking metrics) of one task; memory.MemoryBudgetExceeded
    before anything is built if the run would not fit the memory budget."""
    task.check_memory()
    reference = task.reference()
    if task.sensors is not None:
        result = simulate_on_sensors(task.plant_params, task.controller(), reference, task.scenario.x0,
                                     task.duration, task.scenario.dt, task.make_estimator(), task.sensors,
                                     task.scenario.method, task.noise.seed, progress)
    else:
        result = simulate_closed_loop(task.plant_params, task.controller(), reference, task.scenario.x0,
                                      task.duration, task.scenario.dt, task.scenario.method, task.noise, progress,
                                      task.make_estimator())
    every = max(1, round(1 / (task.rate * task.scenario.dt)))
    return result, reference, tracking_metrics(result, reference, task.reference_spec["kind"],
                                               task.plant_params.r, sample_every=every)


def run_contact(task, result):
    """The contact force's extremes and flags (runtime.contact) along a run of `task`, on its plant."""
    forces = Model(task.plant_params).contact_force(result.trajectory, result.torques)
    return contact_summary(result.time, forces, task.scenario.friction)


def estimate_errors(result):
    """RMS and largest errors of the estimate the controller read against the plant's state at its
    samples: position [m] and heading [deg]."""
    per = round((len(result.time) - 1) / len(result.control_time))
    true, est = result.trajectory[:-1:per], result.estimates
    dq = np.linalg.norm(est[:, IDX_Q][:, :2] - true[:, IDX_Q][:, :2], axis=1)
    dpsi = np.degrees(wrap_angle(heading(est) - heading(true)))
    return {"position_rms_m": float(np.sqrt(np.mean(dq ** 2))), "position_max_m": float(dq.max()),
            "heading_rms_deg": float(np.sqrt(np.mean(dpsi ** 2))), "heading_max_deg": float(np.abs(dpsi).max())}


def _fmt(value):
    return "—" if value is None else f"{value:.4g}"


def sensors_target(row, rows):
    """(target, met) of a run on sensors against "Closed on the estimator": a path task's cross-track RMS
    ≤ 3 cm; a heading task's settle time ≤ its nominal task's (the same controller, the task's name
    without "-sensors", among `rows`) + 2 s.  ("—", None) where no target applies or the nominal
    task was not run."""
    if not row["task"].endswith(SENSORS_SUFFIX):
        return "—", None
    if row["cross_track_rms_m"] is not None:
        return f"RMS ≤ {SENSORS_CROSS_TRACK_M:g} m", row["cross_track_rms_m"] <= SENSORS_CROSS_TRACK_M
    nominal = row["task"][:-len(SENSORS_SUFFIX)]
    settle = [r["heading_settle_s"] for r in rows if r["task"] == nominal and r["controller"] == row["controller"]]
    if not settle or settle[0] is None:
        return "—", None
    limit = settle[0] + SENSORS_SETTLE_MARGIN_S
    return f"settle ≤ {limit:.4g} s", row["heading_settle_s"] is not None and row["heading_settle_s"] <= limit


def estimator_table(rows):
    """The Markdown table of the runs that read an estimate (rows with an `estimate`): the estimate's
    errors against the plant and, on sensors, the target and whether it is met; "" if there are none."""
    runs = [r for r in rows if r.get("estimate") is not None]
    if not runs:
        return ""
    header = ["task", "controller", "estimate position RMS / max [mm]", "estimate heading RMS / max [deg]",
              "target on sensors", "met"]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in runs:
        e = r["estimate"]
        target, met = sensors_target(r, rows)
        lines.append("| " + " | ".join([
            r["task"], r["controller"], f"{1e3 * e['position_rms_m']:.1f} / {1e3 * e['position_max_m']:.1f}",
            f"{e['heading_rms_deg']:.2f} / {e['heading_max_deg']:.2f}", target,
            "—" if met is None else ("yes" if met else "**no**")]) + " |")
    return "On the estimator (the estimate the controller read against the plant's state, at its samples):\n\n" + \
        "\n".join(lines) + "\n"


def main(argv=()):
    """`python -m runtime control`: run every controller on the benchmark tasks and write the tables and
    run folders."""
    parser = argparse.ArgumentParser(prog="python -m runtime control")
    parser.add_argument("--out", default="out/control", help="folder of the table and of one folder per run "
                        "(created as needed)")
    parser.add_argument("--tasks", default=",".join(shipped_tasks()),
                        help="comma-separated tasks: each a shipped name, or a path to a task file")
    parser.add_argument("--duration", type=float, default=None, help="cut every task to this many seconds")
    parser.add_argument("--offsets", action="store_true", help="the offset table instead: the LQR and the NMPC on "
                        "the circle and the line against one constant mismatch or a slope at a time")
    parser.add_argument("--only", default="", help="with --offsets: the cases whose 'task plant controller' "
                        "contains this text")
    parser.add_argument("--known-slope", action="store_true", help="with --offsets: only the slope cases, the "
                        "slope known to the controller's model")
    parser.add_argument("--controllers", default=",".join(DEFAULT_OFFSET_CONTROLLERS),
                        help=f"with --offsets: comma-separated controller kinds of {', '.join(OFFSET_CONTROLLERS)}")
    parser.add_argument("--sensors", metavar="FILE", default=None,
                        help="run every task on the C EKF of these sensors (a shipped set or a sensors file)")
    args = parser.parse_args(list(argv))
    if args.duration is not None and not args.duration > 0:
        parser.error(f"--duration: must be > 0 s, got {args.duration:g}")
    out = pathlib.Path(args.out)
    if args.offsets:
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            parser.error(f"--out: cannot create the folder {out} ({exc.strerror})")
        kinds = tuple(args.controllers.split(","))
        unknown = sorted(set(kinds) - set(OFFSET_CONTROLLERS))
        if unknown:
            parser.error(f"--controllers: {unknown[0]!r} is not one of {', '.join(OFFSET_CONTROLLERS)}")
        return offset_table(out, args.duration, args.only, kinds, args.known_slope)
    try:
        tasks = [load_task(name) for name in args.tasks.split(",")]
        if args.sensors is not None:
            sensors = load_sensor_set(args.sensors)
            tasks = [task.with_sensors(sensors) for task in tasks]
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    # A run's folder is named after its task's name (a task file's stem), never its path: every run
    # lands under --out, whichever folder the task file is in.
    names = [task.name for task in tasks]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        parser.error(f"--tasks: two tasks named {', '.join(map(repr, twice))} would write the same run folders")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        parser.error(f"--out: cannot create the folder {out} ({exc.strerror})")
    rows = []
    runs = [(task.name, run) for task in tasks for run in controller_runs(task)]
    if args.duration is not None:
        runs = [(name, dataclasses.replace(task, scenario=dataclasses.replace(
            task.scenario, steps=max(1, round(min(args.duration, task.duration) / task.scenario.dt)))))
            for name, task in runs]
    try:                                # every run is sized before the first starts
        for _, task in runs:
            task.check_memory()
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for name, task in tqdm(runs, unit="run"):
        result, reference, metrics = run_task(task)
        folder = out / f"{name}-{task.controller_kind}"
        folder.mkdir(exist_ok=True)
        summary = {"task": name, "controller": task.controller_kind, "rate_hz": task.rate, "u_max": task.u_max,
                   "duration_s": task.duration, "cpu": cpu_name(), "tracking": metrics,
                   "contact": run_contact(task, result)}
        estimate = None if result.estimates is None else estimate_errors(result)
        if estimate is not None:
            summary["estimate"] = estimate
        write_text(folder / "summary.json", json.dumps(summary, indent=2) + "\n")
        plot_run(result, reference, task, folder / "tracking.png")
        if task.sensors is not None:
            plot_estimate(result, reference, task, folder / "estimate.png")
        rows.append({"task": name, "controller": task.controller_kind, **metrics, "estimate": estimate})
    header = ["task", "controller", *COLUMNS]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join([r["task"], r["controller"]] + [_fmt(r[c]) for c in COLUMNS]) + " |" for r in rows]
    cut = "" if args.duration is None else f" Every task cut to at most {args.duration:g} s (smoke run)."
    estimates = estimator_table(rows)
    table = "\n".join(lines) + "\n\n" + (estimates + "\n" if estimates else "") + f"CPU: {cpu_name()}.{cut}\n"
    write_text(out / "table.md", table)
    with atomic_path(out / "table.csv") as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=header, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    print(table)
    return 0


def _cut(task, duration):
    if duration is None:
        return task
    return dataclasses.replace(task, scenario=dataclasses.replace(
        task.scenario, steps=max(1, round(min(duration, task.duration) / task.scenario.dt))))


def offset_table(out, duration=None, only="", kinds=DEFAULT_OFFSET_CONTROLLERS, known_slope=False):
    """The offset cases (runtime/control/offsets.py) of the circle and the line for each controller of
    `kinds`, those whose "task plant controller" contains `only` (with `known_slope`, the slope cases
    known to the controller): out/offsets.md, .csv."""
    circle, line = load_task("circle"), load_task("line")
    runs = [(kind, case) for kind in kinds
            for case in offset_cases(_cut(with_controller(circle, kind), duration),
                                     _cut(with_controller(line, kind), duration), known_slope)
            if only in f"{case.name} {case.change} {kind}"]
    if not runs:
        print(f"error: --only: no offset case contains {only!r}", file=sys.stderr)
        return 2
    rows = []
    for kind, case in tqdm(runs, unit="run"):
        _, _, metrics = run_task(case.task)
        rms = metrics["cross_track_rms_m"]
        rows.append({"task": case.name, "plant": case.change, "controller": kind, "cross_track_rms_m": rms,
                     "cross_track_max_m": metrics["cross_track_max_m"], "target_m": case.target_m,
                     "met": rms <= case.target_m})
    header = list(rows[0])
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join([r["task"], r["plant"], r["controller"], _fmt(r["cross_track_rms_m"]),
                                 _fmt(r["cross_track_max_m"]), _fmt(r["target_m"]), "yes" if r["met"] else "**no**"]) + " |"
              for r in rows]
    met = sum(r["met"] for r in rows)
    cut = "" if duration is None else f" Every task cut to at most {duration:g} s (smoke run)."
    table = "\n".join(lines) + f"\n\n{met} of {len(rows)} runs meet their target. CPU: {cpu_name()}.{cut}\n"
    write_text(out / "offsets.md", table)
    with atomic_path(out / "offsets.csv") as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=header)
        writer.writeheader()
        writer.writerows(rows)
    print(table)
    return 0
