"""`python -m runtime heading-seeds`: the heading step on the robot's own filter over noise seeds.

Each seed runs heading-step-sensors (the C EKF on the simulated sensors, the sensor simulation in C)
with one controller; a run meets the target when the true heading's settle time (the metric's: the
first time after which the error stays within ±3° to the end) is within the same controller's
nominal heading-step settle time + 2 s (benchmark.SENSORS_SETTLE_MARGIN_S).  A miss is classed by
how it misses: `late` (first inside the band after the deadline), `swing` (more than twice the
band out after the deadline), `out at the deadline` (outside then, back later: the approach's
overshoot), `later out` (inside at the deadline, out again later: the wander).  `--set key=value`
changes a gain of both the nominal and the sensors task (docs/control.md, "The heading step over seeds").
Each record gives the estimate's largest heading error after the deadline; `--truth` runs the same
seeds with the controller reading the plant's state instead (the filter, the process noise and the
readings unchanged): a miss that stays is the law's, not the estimate's.
"""
import argparse
import dataclasses
import json
import time

import numpy as np
from scipy import stats

from .benchmark import SENSORS_SETTLE_MARGIN_S, run_task
from .closed_loop import simulate_on_sensors
from .geometry import heading, wrap_angle
from .metrics import HEADING_BAND_RAD, settle_time
from .task import load_task

#: The controllers measured here: the sensors task's kind and its nominal task's.
KINDS = {"lqr": "lqr", "nmpc-c": "nmpc"}
MISSES = ("late", "swing", "out at the deadline", "later out")


def _with_gains(task, kind, changes):
    base = task.controllers[0]
    gains = dataclasses.replace(base.gains, **changes) if changes else base.gains
    return dataclasses.replace(task, controllers=(dataclasses.replace(base, kind=kind, gains=gains),))


def tasks(kind, changes=None):
    """(nominal heading-step task, heading-step-sensors task) with controller `kind`, gains changed by `changes`."""
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    sensors = load_task("heading-step-sensors").with_controller(kind)
    names = {f.name for f in dataclasses.fields(sensors.controllers[0].gains)}
    for key in changes or {}:
        if key not in names:
            raise ValueError(f"set: {key!r} is not a gain of the {kind} (one of {', '.join(sorted(names))})")
    try:
        nominal = _with_gains(load_task("heading-step").with_controller(KINDS[kind]), kind, changes or {})
        return nominal, _with_gains(sensors, kind, changes or {})
    except ValueError as exc:
        raise ValueError(f"set: {exc}") from None


def deadline(nominal):
    """The nominal task's heading settle time + the margin [s] (ValueError when it never settles, or
    so late that no sample of the run is left after the deadline)."""
    settle = run_task(nominal)[2]["heading_settle_s"]
    if settle is None:
        raise ValueError("nominal: the heading step does not settle without the sensors; no deadline")
    limit = settle + SENSORS_SETTLE_MARGIN_S
    if limit >= nominal.duration:
        raise ValueError(f"nominal: the heading step settles at {settle:g} s, so its deadline {limit:g} s "
                         f"leaves nothing of the {nominal.duration:g} s run to score")
    return limit


def classify(t, error, limit, band=HEADING_BAND_RAD):
    """(settle time or None, met, miss class or None) of a heading error `error` [rad] at times `t` [s]
    against the deadline `limit` [s]."""
    out = np.abs(error) > band
    settle = settle_time(t, error, band)
    if settle is not None and settle <= limit:
        return settle, True, None
    after = t > limit
    inside = np.flatnonzero(~out)
    if not inside.size or t[inside[0]] > limit:
        return settle, False, "late"
    if np.abs(error[after]).max() > 2 * band:
        return settle, False, "swing"
    return settle, False, "out at the deadline" if out[np.searchsorted(t, limit, side="right") - 1] else "later out"


def run_seed(task, seed, limit, truth=False):
    """One seed's record: settle time, met, miss class, largest error after the deadline [deg], the
    estimate's largest heading error after it [deg], clipped share; `truth`: the controller reads the
    plant's state instead of the estimate."""
    task = dataclasses.replace(task, noise=dataclasses.replace(task.noise, seed=seed))
    reference = task.reference()
    result = simulate_on_sensors(task.plant_params, task.controller(), reference, task.scenario.x0, task.duration,
                                 task.scenario.dt, task.make_estimator(), task.sensors, task.scenario.method, seed,
                                 engine="c", record_samples=False, read_truth=truth)
    every = max(1, round(1 / (task.rate * task.scenario.dt)))
    t = result.time[::every]
    true = heading(result.trajectory[::every])
    error = wrap_angle(reference.heading - true)
    settle, met, miss = classify(t, error, limit)
    # The estimate at sample k is the filter's at t[k], the rows of the trajectory one per sample.
    estimate = wrap_angle(heading(result.estimates) - true[:len(result.estimates)])
    return {"seed": seed, "settle_s": settle, "met": met, "miss": miss,
            "worst_after_deg": float(np.degrees(np.abs(error[t > limit]).max())),
            "estimate_after_deg": float(np.degrees(np.abs(estimate[t[:len(estimate)] > limit]).max())),
            "saturated": float(result.saturated_fraction)}


def summary(records, limit):
    """The summary line: runs within the deadline, the 95 % Clopper–Pearson interval, the misses by class
    (and, when the records give it, the estimate's largest heading error after the deadline in the misses)."""
    n, k = len(records), sum(r["met"] for r in records)
    ci = stats.binomtest(k, n).proportion_ci(0.95, method="exact")
    misses = ", ".join(f"{name} {sum(r['miss'] == name for r in records)}" for name in MISSES)
    clipped = float(np.median([r["saturated"] for r in records]))
    missed = [r["estimate_after_deg"] for r in records if not r["met"] and "estimate_after_deg" in r]
    estimate = f"; the estimate's heading error after the deadline in the misses ≤ {max(missed):.2f}°" if missed else ""
    return (f"{k}/{n} within {limit:.3f} s ({100 * k / n:.1f} %, 95 % CI {100 * ci.low:.1f}-{100 * ci.high:.1f} %); "
            f"misses: {misses}{estimate}; clipped p50 {100 * clipped:.1f} %")


def _seeds(text):
    try:
        first, _, last = text.partition("-")
        first, last = int(first), int(last or first)
    except ValueError:
        raise ValueError(f"seeds: expected FIRST-LAST (integers), got {text!r}") from None
    if first < 0 or last < first:
        raise ValueError(f"seeds: expected 0 <= FIRST <= LAST, got {text!r}")
    return range(first, last + 1)


def _changes(pairs):
    changes = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        try:
            changes[key] = float(value) if sep else None
        except ValueError:
            changes[key] = None
        if changes[key] is None:
            raise ValueError(f"set: expected KEY=NUMBER, got {pair!r}")
    return changes


def main(argv=()):
    """`python -m runtime heading-seeds`: the heading step closed on the C EKF over a range of noise
    seeds, each run scored against the nominal settle time + 2 s; prints the count, its Clopper–Pearson
    interval and the misses by class."""
    parser = argparse.ArgumentParser(prog="python -m runtime heading-seeds", description=__doc__.split("\n\n")[0])
    parser.add_argument("--kind", default="lqr", choices=sorted(KINDS), help="the controller")
    parser.add_argument("--seeds", default="0-99", help="noise seeds FIRST-LAST (default 0-99)")
    parser.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE", help="gains changed in both tasks")
    parser.add_argument("--details", action="store_true", help="one JSON line per seed")
    parser.add_argument("--truth", action="store_true",
                        help="the controller reads the plant's state, not the estimate (the rest unchanged)")
    args = parser.parse_args(list(argv))
    try:
        seeds, changes = _seeds(args.seeds), _changes(args.set)
        nominal, task = tasks(args.kind, changes)
        limit = deadline(nominal)
    except ValueError as exc:
        parser.error(str(exc))
    started = time.process_time()
    records = []
    for seed in seeds:
        records.append(run_seed(task, seed, limit, args.truth))
        if args.details:
            print(json.dumps(records[-1]), flush=True)
    reads = ", on the true state" if args.truth else ""
    print(f"{args.kind} {changes or 'as the task files'}{reads}, seeds {seeds.start}-{seeds.stop - 1}: "
          f"{summary(records, limit)}; "
          f"CPU {time.process_time() - started:.1f} s")
    return 0
