"""`python -m runtime run SCENARIO [--out DIR] [--method M] [--dt DT] [--steps N] [--no-gif] [--force]`.

SCENARIO is a shipped name (see `--help`), a path to a TOML scenario file
(format: docs/scenarios.md), or `all` for the paper's three simulations.
Each scenario writes into OUT/<name>/ (see runtime/scenarios/report.py for the files).

A folder that already holds outputs of a run (any of report.OUTPUT_FILES) is
not overwritten unless --force is given; with --force, the output files of
the earlier run that this run does not rewrite are deleted, so the folder
never mixes two runs.  Other files in the folder are never touched.

If a guard stops the simulation (docs/robustness.md), the rows computed
before the failing step go to trajectory.partial.csv and summary.partial.json
(with the step, time and reason), and no figures are drawn.

Exit status: 0 on success; 2 on a bad argument or scenario file, or an output
folder that holds outputs (without --force); 3 when a simulation was stopped
by a guard (partial outputs written).
"""
import argparse
import pathlib
import sys
import time

from . import report
from ..errors import KernelError, SimulationStopped
from .scenario import PAPER_SCENARIOS, load_scenario, run_scenario, scenario_path, shipped_scenarios


class Progress:
    """A one-line progress indicator on stderr, shown only once a task has taken more than `delay` s.

    On a terminal the line is redrawn in place; otherwise a line is printed at
    every quarter, so logs stay readable.
    """

    def __init__(self, label, stream=None, delay=1.0):
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.delay = delay
        self.started = time.perf_counter()
        self.shown = False
        self.last_quarter = -1
        self.interactive = hasattr(self.stream, "isatty") and self.stream.isatty()

    def __call__(self, what, done, total):
        elapsed = time.perf_counter() - self.started
        if elapsed < self.delay and not self.shown:
            return
        fraction = done / total if total else 1.0
        if self.interactive:
            bar = "#" * int(30 * fraction)
            self.stream.write(f"\r{self.label}: {what:<9} [{bar:<30}] {100 * fraction:5.1f}%  {elapsed:5.1f} s")
            if done >= total:
                self.stream.write("\n")
        else:
            quarter = int(4 * fraction)
            if quarter == self.last_quarter:
                return
            self.last_quarter = quarter
            self.stream.write(f"{self.label}: {what} {100 * fraction:.0f}% ({elapsed:.1f} s)\n")
        self.stream.flush()
        self.shown = True

    def restart(self):
        self.started, self.shown, self.last_quarter = time.perf_counter(), False, -1


def build_parser():
    shipped = ", ".join(shipped_scenarios())
    parser = argparse.ArgumentParser(
        prog="python -m runtime run",
        description="Simulate a scenario and write trajectory.csv, figures, robot.gif and summary.json "
                    "into OUT/<name>/.")
    parser.add_argument("scenario", metavar="SCENARIO",
                        help=f"a shipped scenario ({shipped}), a path to a .toml file, or 'all' (the three of the paper)")
    parser.add_argument("--out", default="out", type=pathlib.Path, help="output folder (default: out)")
    parser.add_argument("--method", help="integrator, overriding the file's (see runtime.model.METHODS)")
    parser.add_argument("--dt", type=float, help="time step [s], overriding the file's; the duration is kept "
                                                 "unless --steps is given")
    parser.add_argument("--steps", type=int, help="number of steps, overriding the file's")
    parser.add_argument("--no-gif", dest="gif", action="store_false", help="skip the animation (the slow part)")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors")
    parser.add_argument("--force", "--overwrite", dest="force", action="store_true",
                        help="overwrite an output folder that already holds the outputs of a run")
    return parser


class Stopped(Exception):
    """A run stopped by a simulation guard; the partial outputs are written (exit status 3)."""


def run_one(name_or_path, args):
    """Load, override, simulate and write one scenario; returns its summary dict."""
    scenario = load_scenario(name_or_path).with_overrides(dt=args.dt, steps=args.steps, method=args.method)
    folder = args.out / scenario.name
    check_output_folder(folder, args.force)
    progress = Progress(scenario.name, delay=float("inf") if args.quiet else 1.0)
    try:
        result = run_scenario(scenario, progress=lambda done, total: progress("simulate", done, total))
    except SimulationStopped as exc:  # a guard fired: keep what was computed, clearly marked
        written = report.write_partial_outputs(exc.result, folder, exc)
        report.remove_stale(folder, written)
        raise Stopped(f"{scenario.source}: {exc}; wrote the {len(exc.trajectory)} valid rows to "
                      f"{written[0]} and {written[1].name}") from None
    except KernelError as exc:        # the state left the model's domain: say which scenario
        raise ValueError(f"{scenario.source}: simulation failed: {exc}") from None
    progress.restart()
    written = report.write_outputs(result, folder, gif=args.gif, progress=progress)
    report.remove_stale(folder, written)
    summary = report.summary(result)
    if not args.quiet:
        x, y = summary["final_position_m"]
        print(f"{scenario.name}: {scenario.steps} steps of {scenario.dt:g} s ({scenario.method}) in "
              f"{result.wall_time_s:.3f} s; final position ({x:+.4f}, {y:+.4f}) m, largest excursion "
              f"{summary['largest_excursion_m']:.4f} m; wrote {len(written)} files to {folder}/")
    return summary


def check_output_folder(folder, force):
    """Refuse (ValueError) a folder that already holds outputs of a run, unless `force`."""
    existing = report.existing_outputs(folder)
    if existing and not force:
        raise ValueError(f"{folder}: already holds the outputs of a run ({', '.join(existing)}); "
                         f"pass --force to overwrite them, or choose another --out")


def main(argv):
    args = build_parser().parse_args(argv)
    names = list(PAPER_SCENARIOS) if args.scenario == "all" else [args.scenario]
    try:
        # Every folder is checked before the first run, so `all` does not stop half-way.
        for name in names:
            check_output_folder(args.out / scenario_path(name).stem, args.force)
        for name in names:
            run_one(name, args)
    except Stopped as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 3
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:            # unwritable --out, disk full, ...
        print(f"error: {exc.filename or args.out}: cannot write the outputs ({exc.strerror or exc})",
              file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
