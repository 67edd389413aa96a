"""`python -m runtime run SCENARIO [--out DIR] [--method M] [--dt DT] [--steps N] [--no-gif] [--no-replay] [--force]`.

SCENARIO is a shipped name (see `--help`), a path to a TOML scenario file
(format: docs/scenarios.md), or `all` for the paper's three simulations.
Each scenario writes into OUT/<name>/ (see runtime/scenarios/report.py for the files).
The simulations run one after the other; then the files of all runs are
written in parallel processes (runtime/scenarios/parallel.py), with one
progress bar per run on a terminal.

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

from . import report
from ..contact import contact_flags
from ..errors import KernelError, SimulationStopped
from .parallel import RunBar, write_runs
from ..scenario import PAPER_SCENARIOS, check_memory, load_scenario, run_scenario, scenario_path, shipped_scenarios


def build_parser():
    """The argument parser of `python -m runtime run`."""
    shipped = ", ".join(shipped_scenarios())
    parser = argparse.ArgumentParser(
        prog="python -m runtime run",
        description="Simulate a scenario and write trajectory.csv, figures, robot.gif, replay.html and "
                    "summary.json into OUT/<name>/.")
    parser.add_argument("scenario", metavar="SCENARIO",
                        help=f"a shipped scenario ({shipped}), a path to a .toml file, or 'all' (the three of the paper)")
    parser.add_argument("--out", default="out", type=pathlib.Path, help="output folder (default: out)")
    parser.add_argument("--method", help="integrator, overriding the file's (see runtime.model.METHODS)")
    parser.add_argument("--dt", type=float, help="time step [s], overriding the file's; the duration is kept "
                                                 "unless --steps is given")
    parser.add_argument("--steps", type=int, help="number of steps, overriding the file's")
    parser.add_argument("--no-gif", dest="gif", action="store_false", help="skip the animation (robot.gif)")
    parser.add_argument("--no-replay", dest="replay", action="store_false",
                        help="skip the interactive replay (replay.html)")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors (no progress bars)")
    parser.add_argument("--force", "--overwrite", dest="force", action="store_true",
                        help="overwrite an output folder that already holds the outputs of a run")
    return parser


class Stopped(Exception):
    """A run stopped by a simulation guard; the partial outputs are written (exit status 3)."""


def simulate(scenario, args):
    """Simulate one loaded scenario (a passing progress bar for long runs); a guard's stop writes the
    partial outputs and raises Stopped, a kernel error raises ValueError naming the scenario."""
    folder = args.out / scenario.name
    with RunBar(total=scenario.steps, desc=f"{scenario.name} (simulating)", unit="step", leave=False,
              disable=True if args.quiet else None, delay=1.0) as bar:
        try:
            return run_scenario(scenario, progress=lambda done, total: bar.update(done - bar.n))
        except SimulationStopped as exc:  # a guard fired: keep what was computed, clearly marked
            written = report.write_partial_outputs(exc.result, folder, exc)
            report.remove_stale(folder, written)
            raise Stopped(f"{scenario.source}: {exc}; wrote the {len(exc.trajectory)} valid rows to "
                          f"{written[0]} and {written[1].name}") from None
        except KernelError as exc:        # the state left the model's domain: say which scenario
            raise ValueError(f"{scenario.source}: simulation failed: {exc}") from None


def run_many(names, args):
    """Simulate the scenarios in turn, then write the files of every run that finished (in parallel);
    returns their summaries.  If a run fails, the runs before it are still written, then the error
    is raised (the runs after it are not simulated)."""
    scenarios = [load_scenario(name).with_overrides(dt=args.dt, steps=args.steps, method=args.method)
                 for name in names]
    for scenario in scenarios:          # before the first run: `all` does not stop half-way
        check_memory(scenario)
    results, failure = [], None
    for scenario in scenarios:
        check_output_folder(args.out / scenario.name, args.force)
        try:
            results.append(simulate(scenario, args))
        except (Stopped, ValueError) as exc:
            failure = exc
            break
    written = write_runs([(result, args.out / result.scenario.name) for result in results],
                         gif=args.gif, replay=args.replay, quiet=args.quiet)
    summaries = []
    for result, files in zip(results, written):
        summary = report.summary(result)
        summaries.append(summary)
        if not args.quiet:
            scenario = result.scenario
            x, y = summary["final_position_m"]
            print(f"{scenario.name}: {scenario.steps} steps of {scenario.dt:g} s ({scenario.method}) in "
                  f"{result.wall_time_s:.3f} s; final position ({x:+.4f}, {y:+.4f}) m, largest excursion "
                  f"{summary['largest_excursion_m']:.4f} m; wrote {len(files)} files to {files[0].parent}/")
            for flag in contact_flags(result.time, result.contact_force, scenario.friction):
                print(f"warning: {scenario.name}: {flag.message(scenario.friction)}", file=sys.stderr)
    if failure is not None:
        raise failure
    return summaries


def check_output_folder(folder, force):
    """Refuse (ValueError) a folder that already holds outputs of a run, unless `force`."""
    existing = report.existing_outputs(folder)
    if existing and not force:
        raise ValueError(f"{folder}: already holds the outputs of a run ({', '.join(existing)}); "
                         f"pass --force to overwrite them, or choose another --out")


def main(argv):
    """`python -m runtime run`: simulate the scenarios named in argv and write their output folders."""
    args = build_parser().parse_args(argv)
    names = list(PAPER_SCENARIOS) if args.scenario == "all" else [args.scenario]
    try:
        # Every folder is checked before the first run, so `all` does not stop half-way.
        for name in names:
            check_output_folder(args.out / scenario_path(name).stem, args.force)
        run_many(names, args)
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
