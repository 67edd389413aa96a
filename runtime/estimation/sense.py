"""Simulated sensor logs: the sensors of a `SensorSet` read along a run of a scenario (its torque
program) or a control task (its first controller, reading the true state), with the set's process
noise driving the truth (docs/estimation.md, "Simulated logs").

    log = simulate_log(load_scenario("t-shape"), SensorSet.default(), seed=1)
    write_log(log, "out/t-shape-log")

The truth is the verified model on the C steppers (the scenario's integrator and dt) under the
applied torques and the set's white torque disturbance, read by runtime/sensor_sim.py (the same
simulation the closed loop on the estimator runs): per-run biases, white noise, the IMU's
saturation, the encoders' quantisation, the fixes' latency; the biases as they walk are the truth's
last columns (log.json's "truth_bias": their draw at t = 0).  Seeded: one seed gives the same log.
"""
import dataclasses
import math
import time

import numpy as np

from .. import memory
from ..model import Model
from ..scenario import Scenario
from ..sensor_set import SensorSet
from ..sensor_sim import SensorSimulation
from ..state import COLUMN_INDEX, IDX_Q
from .logs import COLUMNS, Log, samples

#: `plant_mismatch`: the truth's masses and inertias times this, its dampings times DAMPING_FACTOR.
MASS_FACTOR, DAMPING_FACTOR = 1.1, 0.8


def mismatched(params):
    """`params` with masses +10 % (inertias with them: the same bodies, heavier) and dampings −20 %."""
    damping = {k: getattr(params, k) * DAMPING_FACTOR for k in ("k_S", "k_Y", "k_P")}
    if params.paper_params is not None:
        paper = params.paper_params
        return params.with_changes(**{k: getattr(paper, k) * MASS_FACTOR for k in ("m_S", "m_b", "m_h", "m_P")},
                                   **damping)
    heavier = {k: getattr(params, k) * MASS_FACTOR for k in ("m_S", "m_Y", "m_P", "j_S")}
    heavier.update({k: tuple(map(tuple, np.asarray(getattr(params, k)) * MASS_FACTOR)) for k in ("J_Y", "J_P")})
    return params.replace(**heavier, **damping)


def memory_estimate(steps, duration, sensors):
    """{what: bytes} of a simulated log's arrays."""
    parts = {"truth": memory.trajectory_bytes(steps) + (steps + 1) * 6 * 8, "torques": (steps + 1) * 3 * 8}
    for kind in ("imu", "encoders", "fixes", "heading"):
        spec = getattr(sensors, kind)
        if spec is not None:
            parts[kind] = (math.floor(duration * spec.rate) + 1) * len(COLUMNS[kind]) * 8
    return parts


class _OpenLoop:
    """The torques of a scenario's program, row k on step k."""

    def __init__(self, scenario):
        self.u = scenario.torque_at_step_starts()

    def __call__(self, k, x):
        return self.u[k]


class _ClosedLoop:
    """A task's first controller sampled every `per` steps on the true state, its torques held."""

    def __init__(self, task):
        from ..control.geometry import heading as robot_heading
        self.heading = robot_heading
        self.controller, self.reference = task.controller(), task.reference()
        self.per = round(self.controller.period / task.scenario.dt)
        self.dt, self.u, self.started = task.scenario.dt, None, False

    def __call__(self, k, x):
        if k % self.per:
            return self.u
        if not self.started:
            self.controller.reset(x)
            if hasattr(self.reference, "reset"):
                self.reference.reset()
            self.started = True
        t = k * self.dt
        target = self.reference.target(t, x[IDX_Q], float(self.heading(x)))
        if getattr(self.reference, "is_path", False) and hasattr(self.controller, "preview_distances"):
            target = dataclasses.replace(target, curvature_ahead=self.reference.curvature_ahead(
                self.controller.preview_distances(target)))
        self.u = np.asarray(self.controller.update(t, x, target), dtype=float)
        return self.u


def simulate_log(run, sensors=None, seed=0, plant_mismatch=False, progress=None, disturbance_in_accel=True):
    """The `Log` (with truth) of the sensors along `run`: a runtime.scenario.Scenario, or a
    runtime.control.task.Task (its first controller reads the true state).  `sensors`: the set (None:
    the run's `[sensors]`, else the default); `seed` (an int >= 0) seeds every draw; `plant_mismatch`:
    the truth's robot is `mismatched` while the log claims the nominal one.  `progress(done, total)`
    is called every 1000 steps.  `disturbance_in_accel=False`: the accelerometer reads the acceleration
    of the applied torques alone (the disturbance still moves the truth)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected a whole number >= 0, got {seed!r}")
    scenario = run if isinstance(run, Scenario) else run.scenario
    sensors = sensors if sensors is not None else scenario.sensors or SensorSet.default()
    if not isinstance(sensors, SensorSet):
        raise ValueError(f"sensors: expected a runtime.sensor_set.SensorSet, got {type(sensors).__name__}")
    nominal = scenario.params
    truth_params = run.plant_params if not isinstance(run, Scenario) else nominal
    truth_params = mismatched(truth_params) if plant_mismatch else truth_params
    dt, steps, duration, method = scenario.dt, scenario.steps, scenario.duration, scenario.method
    memory.check(scenario.source, memory_estimate(steps, duration, sensors))
    torque = _OpenLoop(scenario) if isinstance(run, Scenario) else _ClosedLoop(run)
    started = time.perf_counter()
    sim = SensorSimulation(Model(truth_params), sensors, dt, steps, method, seed, disturbance_in_accel)
    truth = np.empty((steps + 1, len(COLUMN_INDEX) + 6))
    applied = np.empty((steps + 1, 2))
    x = scenario.x0.copy()
    for k in range(steps + 1):
        truth[k, :-6] = x[COLUMN_INDEX]
        truth[k, -6:] = sim.bias                                # what step k's IMU samples read
        u = torque(k, x) if k < steps else applied[k - 1]    # the last row starts no step: held
        applied[k] = u
        x, _ = sim.advance(k, x, u, last=k == steps)
        if progress is not None and k % 1000 == 0:
            progress(k, steps)
    times, readings, bias, fix_latency = sim.times, sim.readings, sim.bias_at(0), sim.latency
    fixes = None
    if "fixes" in times:
        fixes = samples("fixes", times["fixes"] + fix_latency, np.column_stack([times["fixes"], readings["fixes"]]))
    meta = {"source": scenario.source, "run": scenario.name,
            "kind": "scenario" if isinstance(run, Scenario) else "task", "seed": int(seed), "dt": dt,
            "steps": steps, "method": method, "params": nominal.as_json(),
            "plant_mismatch": bool(plant_mismatch), "truth_params": truth_params.as_json(),
            "truth_bias": {"gyro": bias[:3].tolist(), "accel": bias[3:].tolist()},
            "wall_time_s": time.perf_counter() - started}
    return Log(torques=samples("torques", np.arange(steps + 1) * dt, applied),
               imu=samples("imu", times["imu"], readings["imu"]),
               encoders=samples("encoders", times["encoders"], readings["encoders"]),
               fixes=fixes,
               heading=samples("heading", times["heading"], readings["heading"]) if "heading" in times else None,
               truth=samples("truth", np.arange(steps + 1) * dt, truth),
               sensors=sensors, meta=meta)


# -- python -m runtime sense ---------------------------------------------------------------------
def load_run(name_or_path):
    """A shipped scenario or task name, or a path to either kind of file (a task has a [reference])."""
    import tomllib

    from ..control.task import load_task, shipped_tasks
    from ..scenario import load_scenario, scenario_path, shipped_scenarios
    if "/" not in str(name_or_path) and not str(name_or_path).endswith(".toml"):
        if name_or_path in shipped_scenarios():
            return load_scenario(name_or_path)
        if name_or_path in shipped_tasks():
            return load_task(name_or_path)
        raise ValueError(f"{name_or_path}: no such scenario or task (shipped scenarios: "
                         f"{', '.join(shipped_scenarios())}; tasks: {', '.join(shipped_tasks())})")
    path = scenario_path(name_or_path)
    if not path.is_file():
        raise ValueError(f"{path}: no such scenario or task file")
    try:
        is_task = "reference" in tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    return load_task(path) if is_task else load_scenario(path)


def summary(log, files):
    """The numbers of summary.json: the run, the sensor set, the draws and the sample counts."""
    return {**{k: v for k, v in log.meta.items() if k not in ("params", "truth_params")},
            "samples": {kind: len(table) for kind, table in log.tables().items() if kind != "truth"},
            "imu_saturated": int(np.sum(np.any(np.abs(log.imu.data) >= np.repeat(
                [log.sensors.imu.gyro_range, log.sensors.imu.accel_range], 3), axis=1))),
            "sensors": log.sensors.as_table(),
            "files": [f.name for f in files]}


def build_parser():
    """The argument parser of `python -m runtime sense`."""
    import argparse
    import pathlib

    from ..cli_types import duration, whole_number

    seed = whole_number(0)

    parser = argparse.ArgumentParser(
        prog="python -m runtime sense",
        description="Simulate the sensors along a scenario or a control task and write the log (CSV and "
                    "Parquet), its truth, log.json and summary.json into OUT (docs/estimation.md).")
    parser.add_argument("run", metavar="SCENARIO|TASK", help="a shipped scenario or task, or a .toml file")
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the log's folder (created if missing)")
    parser.add_argument("--sensors", metavar="FILE",
                        help="a sensors file or shipped set (default: the file's [sensors], else 'default')")
    parser.add_argument("--seed", type=seed, default=0, help="seed of every random draw (default 0)")
    parser.add_argument("--duration", type=duration, help="simulate only this long [s] (a whole number of steps)")
    parser.add_argument("--plant-mismatch", action="store_true",
                        help="the truth's robot 10 %% heavier with 20 %% less damping; the log claims the nominal one")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return parser


def main(argv):
    """`python -m runtime sense`: simulate and write a log; exit status 2 on a bad argument or file."""
    import json
    import os
    import sys

    from ..atomic import write_text
    from ..errors import KernelError
    from ..sensor_set import load_sensor_set
    from .logs import write_log
    args = build_parser().parse_args(argv)
    try:
        out = args.out
        if out.exists() and not out.is_dir():
            raise ValueError(f"{out}: is a file, expected a folder")
        probe = out if out.is_dir() else next((p for p in out.parents if p.exists()), out)
        if not os.access(probe, os.W_OK | os.X_OK):
            raise ValueError(f"{out}: the folder {probe} is not writable")
        run = load_run(args.run)
        sensors = load_sensor_set(args.sensors) if args.sensors else None
        if args.duration is not None:
            scenario = (run if isinstance(run, Scenario) else run.scenario).with_overrides(
                steps=max(1, round(args.duration / (run if isinstance(run, Scenario) else run.scenario).dt)))
            run = scenario if isinstance(run, Scenario) else dataclasses.replace(run, scenario=scenario)
        try:
            log = simulate_log(run, sensors, seed=args.seed, plant_mismatch=args.plant_mismatch)
        except KernelError as exc:
            raise ValueError(f"{args.run}: simulation failed: {exc}") from None
        files = write_log(log, out)
        write_text(out / "summary.json", json.dumps(summary(log, files), indent=2) + "\n")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"error: {exc.filename or args.out}: cannot write the log ({exc.strerror or exc})", file=sys.stderr)
        return 2
    if not args.quiet:
        counts = ", ".join(f"{len(t)} {kind}" for kind, t in log.tables().items() if kind != "truth")
        print(f"{log.meta['run']}: {log.meta['steps']} steps of {log.meta['dt']:g} s, seed {args.seed}"
              f"{', plant mismatch' if args.plant_mismatch else ''}; {counts} samples; wrote {out}/")
    return 0
