"""`python -m runtime sweep NAME|PATH --out DIR [--samples N] [--scheduler ADDRESS] [--workers N]`.

Runs a sweep file (format: runtime/sweep/spec.py, docs/sweeps.md) on Dask distributed: an
embedded LocalCluster of --workers processes (default: one per core), or the scheduler at
--scheduler ADDRESS (a cluster started with `dask scheduler` / `dask worker`, dask-jobqueue or
dask-kubernetes; the workers need this package installed), or `--scheduler serial` (this
process, no Dask).  Writes OUT/results.parquet (one row per sample: inputs, status, metrics),
OUT/summary.png and OUT/percentiles.md; rerun the same command to resume an interrupted sweep.

Exit status: 0 when every sample ran; 1 when some samples failed (their rows carry the
status), or when the results are incomplete (chunk files that fail verification, rows refused)
or the environment fails (an unreachable scheduler, a lost cluster, a file that cannot be
written); 2 on a bad argument, sweep file or output folder.  Every error is one line on stderr.
"""
import argparse
import math
import os
import pathlib
import sys

import numpy as np

from ..errors import SimulationStopped
from ..model import Model
from ..atomic import write_text
from ..state import IDX_Q
from .runner import CONNECT_TIMEOUT, SERIAL, run_sweep, scheduler_address
from .robustness import RobustnessSpec, from_identity, in_sweep, with_nominal
from .robustness_summary import summary_text, write_robustness_figure
from .spec import MAX_SAMPLES, load_sweep, shipped_sweeps
from .store import MANIFEST, SweepIncomplete, SweepStore, chunk_schema
from .summary import percentile_table, write_summary_figure

#: Most worker processes of the embedded LocalCluster, per core (more only share the cores).
WORKERS_PER_CORE = 4


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are a ValueError (one line, exit status 2, from `main`)."""

    def error(self, message):
        raise ValueError(message)


def _whole(low, high):
    def whole(text):
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"expected a whole number from {low} to {high}, got {text!r}")
        return value
    return whole


def _seconds(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}")
    return value


def _scheduler(text):
    if text == SERIAL:
        return text
    try:
        return scheduler_address(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def build_parser():
    """The argument parser of `python -m runtime sweep`."""
    p = _Parser(prog="python -m runtime sweep", description=__doc__.split("\n\n")[1])
    cores = os.cpu_count() or 1
    p.add_argument("sweep", help=f"a shipped sweep ({', '.join(shipped_sweeps())}) or a sweep file")
    p.add_argument("--out", required=True, help="output folder (resumed if it holds this sweep)")
    p.add_argument("--samples", type=_whole(1, MAX_SAMPLES), help="number of samples (default: the file's)")
    p.add_argument("--scheduler", type=_scheduler,
                   help=f"Dask scheduler address, or '{SERIAL}' (default: an embedded LocalCluster)")
    p.add_argument("--connect-timeout", type=_seconds, default=CONNECT_TIMEOUT, metavar="SECONDS",
                   help=f"how long to wait for the --scheduler to answer (default: {CONNECT_TIMEOUT:g})")
    p.add_argument("--workers", type=_whole(1, WORKERS_PER_CORE * cores),
                   help="worker processes of the embedded LocalCluster (default: cores)")
    p.add_argument("--samples-per-task", type=_whole(1, MAX_SAMPLES),
                   help="task size (default: the file's, else ~2 s of work)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--rerun", type=_whole(0, MAX_SAMPLES - 1), metavar="SAMPLE",
                   help="a robustness sweep: run this one sample here and print its row (nothing written)")
    p.add_argument("--nominal", default="", metavar="GROUPS",
                   help="with --rerun: comma-separated perturbations left out (masses, dampings, "
                        "centre_of_mass, slope, start)")
    p.add_argument("--finished", action="store_true",
                   help="a robustness sweep: summarise the verified runs in --out so far, running nothing")
    p.add_argument("--combine", nargs="+", metavar="DIR",
                   help="a robustness sweep: summarise into --out the verified runs in these sweeps' folders "
                        "(the same plants, some of its tasks and controllers each), running nothing")
    return p


def nominal_end_point(spec):
    """Where the base scenario, unvaried, ends (x, y) [m]; None if its run stops at a guard."""
    s = spec.scenario
    try:
        traj = Model(s.params).simulate(s.x0, s.dt, s.steps, s.torque_at_step_starts(), method=s.method)
    except SimulationStopped:
        return None
    return tuple(traj[-1, IDX_Q][:2])


def robustness_outputs(spec, table, args):
    """Writes OUT/summary.md and OUT/summary.png of a robustness sweep; returns the summary."""
    command = f"python -m runtime sweep {args.sweep} --out {args.out}" + \
        (f" --samples {args.samples}" if args.samples is not None else "")
    summary = summary_text(table, spec, command)
    write_text(f"{args.out}/summary.md", summary + "\n")
    write_robustness_figure(table, spec, f"{args.out}/summary.png")
    return summary


def _verified_runs(spec, folder, option):
    """The verified rows of the sweep `spec` in `folder` (an Arrow table), finished or not.  A chunk
    file on disk that fails verification is refused by name: summarising without it would report
    its runs as missing, not as altered or foreign."""
    import pyarrow as pa
    store = SweepStore.open(folder, spec, lambda: None)
    tables = []
    for a, b in store.chunks():
        path = store.chunk_path(a, b)
        if path.exists():
            table, why = store.read_chunk(a, b)
            if table is None:
                raise ValueError(f"{option}: {path} is not a verified chunk of {spec.name}: {why}")
            tables.append(table)
    if not tables:
        raise ValueError(f"{option}: {folder} holds no verified runs yet")
    return pa.concat_tables(tables)


def _summarise(spec, table, args):
    """Writes and prints the summary of the runs `table` of `spec` (marked unfinished if some are missing)."""
    summary = robustness_outputs(spec, table, args)
    if table.num_rows < spec.samples:
        summary = f"Unfinished: {table.num_rows} of the sweep's {spec.samples} runs.\n\n" + summary
        write_text(f"{args.out}/summary.md", summary + "\n")
    print(summary)
    return 0


def _finished(spec, args):
    """Summarises the verified chunks of an unfinished robustness sweep (OUT/summary.md, .png)."""
    if not isinstance(spec, RobustnessSpec):
        raise ValueError("--finished: only for a robustness sweep (a sweep file with [control])")
    if not (pathlib.Path(args.out) / MANIFEST).is_file():
        raise ValueError(f"--out: {args.out} holds no sweep")
    return _summarise(spec, _verified_runs(spec, args.out, "--finished"), args)


def _combined(spec, args):
    """Summarises into --out the verified runs of the sweeps in the --combine folders, each a part of
    `spec` (the same plants; some of its tasks and controllers), as runs of `spec`."""
    import json
    import pyarrow as pa
    if not isinstance(spec, RobustnessSpec):
        raise ValueError("--combine: only for a robustness sweep (a sweep file with [control])")
    parts = []
    for folder in args.combine:
        manifest = pathlib.Path(folder) / MANIFEST
        if not manifest.is_file():
            raise ValueError(f"--combine: {folder} holds no sweep")
        record = json.loads(manifest.read_text(encoding="utf-8"))
        part = from_identity(record.get("identity"), record.get("sweep", folder), str(manifest))
        table = _verified_runs(part, folder, "--combine")
        parts.append(in_sweep(table.to_pydict(), part, spec, f"--combine: {folder}"))
    columns = {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}
    samples, first = np.unique(columns["sample"], return_index=True)
    if len(samples) < len(columns["sample"]):
        twice = np.setdiff1d(np.arange(len(columns["sample"])), first)[0]
        raise ValueError(f"--combine: sample {columns['sample'][twice]} of {spec.name} is in more than one folder")
    table = pa.table({name: values[first] for name, values in columns.items()},
                     schema=chunk_schema(spec))
    pathlib.Path(args.out).mkdir(parents=True, exist_ok=True)
    return _summarise(spec, table, args)


def _rerun(spec, sample, nominal=()):
    """Runs one sample of a robustness sweep (the perturbation groups `nominal` left out) and prints
    its inputs and outcome, one per line."""
    if not isinstance(spec, RobustnessSpec):
        raise ValueError("--rerun: only for a robustness sweep (a sweep file with [control])")
    if sample >= spec.samples:
        raise ValueError(f"--rerun: the sweep has samples 0..{spec.samples - 1}, got {sample}")
    with_nominal({}, nominal)                 # names the unknown group before anything runs
    row = spec.run_chunk(sample, sample + 1, nominal)
    task, kind = spec.combos[int(row["task"][0]) * len(spec.controllers) + int(row["controller"][0])]
    print(f"task {task}, controller {kind}")
    for name, values in row.items():
        print(f"{name} = {values[0].item()!r}")
    return 0 if row["status"][0] == 0 else 1


def main(argv):
    """`python -m runtime sweep`: run (or resume) a sweep and write its store and summary."""
    try:
        args = build_parser().parse_args(argv)
        spec = load_sweep(args.sweep)
        if args.samples is not None:
            spec = spec.with_samples(args.samples)
        if args.rerun is not None:
            return _rerun(spec, args.rerun, [g for g in args.nominal.split(",") if g])
        if args.combine:
            return _combined(spec, args)
        if args.finished:
            return _finished(spec, args)
        table = run_sweep(spec, args.out, scheduler=args.scheduler, workers=args.workers,
                          samples_per_task=args.samples_per_task, progress=not args.no_progress,
                          connect_timeout=args.connect_timeout)
        if isinstance(spec, RobustnessSpec):
            summary = robustness_outputs(spec, table, args)
            print(summary)
            return 1 if any(s != 0 for s in table.column("status").to_pylist()) else 0
        first = spec.quantities[0] if spec.quantities else None
        write_summary_figure(table, f"{args.out}/summary.png", spec.name, colour_by=first and first.name,
                             colour_label=first and (f"{first.name} (factor)" if first.relative else first.name),
                             nominal=nominal_end_point(spec))
        summary = percentile_table(table)
        write_text(f"{args.out}/percentiles.md", summary + "\n")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (SweepIncomplete, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted; the finished tasks are kept, rerun the same command to resume", file=sys.stderr)
        return 130
    print(summary)
    failed = sum(1 for s in table.column("status").to_pylist() if s != 0)
    return 1 if failed else 0
