"""`python -m runtime sweep NAME|PATH --out DIR [--samples N] [--scheduler ADDRESS] [--workers N]`.

Runs a sweep file (format: runtime/sweep/spec.py, docs/sweeps.md) on Dask distributed: an
embedded LocalCluster of --workers processes (default: one per core), or the scheduler at
--scheduler ADDRESS (a cluster started with `dask scheduler` / `dask worker`, dask-jobqueue or
dask-kubernetes; the workers need this package installed), or `--scheduler serial` (this
process, no Dask).  Writes OUT/results.parquet (one row per sample: inputs, status, metrics),
OUT/summary.png and OUT/percentiles.md; rerun the same command to resume an interrupted sweep.

Exit status: 0 when every sample ran; 1 when some samples failed (their rows carry the
status); 2 on a bad argument, sweep file or output folder.
"""
import argparse
import sys

from ..errors import SimulationStopped
from ..model import Model
from ..scenarios.atomic import write_text
from ..state import IDX_Q
from .runner import SERIAL, run_sweep
from .spec import load_sweep, shipped_sweeps
from .summary import percentile_table, write_summary_figure


def build_parser():
    """The argument parser of `python -m runtime sweep`."""
    p = argparse.ArgumentParser(prog="python -m runtime sweep", description=__doc__.split("\n\n")[1])
    p.add_argument("sweep", help=f"a shipped sweep ({', '.join(shipped_sweeps())}) or a sweep file")
    p.add_argument("--out", required=True, help="output folder (resumed if it holds this sweep)")
    p.add_argument("--samples", type=int, help="number of samples (default: the file's)")
    p.add_argument("--scheduler", help=f"Dask scheduler address, or '{SERIAL}' (default: an embedded LocalCluster)")
    p.add_argument("--workers", type=int, help="worker processes of the embedded LocalCluster (default: cores)")
    p.add_argument("--samples-per-task", type=int, help="task size (default: the file's, else ~2 s of work)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def nominal_end_point(spec):
    """Where the base scenario, unvaried, ends (x, y) [m]; None if its run stops at a guard."""
    s = spec.scenario
    try:
        traj = Model(s.params).simulate(s.x0, s.dt, s.steps, s.torque_at_step_starts(), method=s.method)
    except SimulationStopped:
        return None
    return tuple(traj[-1, IDX_Q][:2])


def main(argv):
    """`python -m runtime sweep`: run (or resume) a sweep and write its store and summary."""
    args = build_parser().parse_args(argv)
    try:
        spec = load_sweep(args.sweep)
        if args.samples is not None:
            spec = spec.with_samples(args.samples)
        for name in ("workers", "samples_per_task"):
            value = getattr(args, name)
            if value is not None and value < 1:
                raise ValueError(f"--{name.replace('_', '-')}: expected a positive integer, got {value}")
        table = run_sweep(spec, args.out, scheduler=args.scheduler, workers=args.workers,
                          samples_per_task=args.samples_per_task, progress=not args.no_progress)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    first = spec.quantities[0] if spec.quantities else None
    write_summary_figure(table, f"{args.out}/summary.png", spec.name, colour_by=first and first.name,
                         colour_label=first and (f"{first.name} (factor)" if first.relative else first.name),
                         nominal=nominal_end_point(spec))
    summary = percentile_table(table)
    write_text(f"{args.out}/percentiles.md", summary + "\n")
    print(summary)
    failed = sum(1 for s in table.column("status").to_pylist() if s != 0)
    return 1 if failed else 0
