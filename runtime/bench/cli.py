"""`python -m runtime bench` (`make bench`): see runtime/bench/__init__.py for what is measured."""
import argparse
import json
import datetime
import os
import pathlib
import sys
import tempfile

import numpy as np

from ..model import Model
from ..params import Params
from ..verification.sampling import random_inputs, random_states
from .baselines import python_timings
from .checks import WrongNumbers
from .kane_compiled import kane_inputs as kane_coordinates, write_kane_c
from .harness import (ROOT, build_harness, casadi_reference_c, check_harness, ekf_sample, memory_floor,
                      run_harness, step_anatomy)
from .report import format_markdown, format_report, write_results
from .timing import cpu_name, pin_to_one_core

RESULTS = ROOT / "bench" / "results"
#: Parts of the C benchmarks that --skip can leave out (each has its own test).
SKIPPABLE = ("step-anatomy", "ekf")


def main(argv=None):
    """`python -m runtime bench`: the benchmarks on one pinned core (or, with --markdown, a stored
    result rendered as Markdown); returns the exit status."""
    parser = argparse.ArgumentParser(prog="python -m runtime bench", description="Benchmarks against the alternatives.")
    parser.add_argument("--states", type=int, default=1024, help="states in the C loop (<= 4096)")
    parser.add_argument("--repeats", type=int, default=200, help="sweeps over the states per timing")
    parser.add_argument("--batch", type=int, default=1_000_000, help="states in the Python batch accel")
    parser.add_argument("--native", action="store_true", help="also build the C loop with -march=native")
    parser.add_argument("--no-kane", action="store_true", help="skip the sympy.physics.mechanics baseline")
    parser.add_argument("--loop-steps", type=int, default=10_000,
                        help="steps of the alternatives' t-shape run in a Python Lie-Euler loop (<= 10,000)")
    parser.add_argument("--skip", action="append", default=[], choices=SKIPPABLE,
                        help="leave out a part of the C benchmarks (repeatable; the result says which)")
    parser.add_argument("--out", type=pathlib.Path, default=RESULTS)
    parser.add_argument("--markdown", type=pathlib.Path, metavar="RESULT.json",
                        help="print a stored run's tables as Markdown (for the README) and exit")
    args = parser.parse_args(argv)
    if args.markdown:
        try:
            result = json.loads(args.markdown.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:      # a missing file, not UTF-8, not JSON
            parser.error(f"--markdown: cannot read {args.markdown}: {exc}")
        print(format_markdown(result))
        return 0
    if not 1 <= args.states <= 4096:
        parser.error("--states: must be between 1 and 4096")
    if not 1 <= args.loop_steps <= 10_000:
        parser.error("--loop-steps: must be between 1 and 10,000")

    def progress(msg):
        print(f"bench: {msg}", file=sys.stderr, flush=True)

    try:
        original_affinity = os.sched_getaffinity(0)
    except (AttributeError, OSError):
        original_affinity = None
    core = pin_to_one_core()
    try:
        return run(args, core, progress)
    finally:
        if original_affinity:
            os.sched_setaffinity(0, original_affinity)


def run(args, core, progress):
    """Runs every benchmark of `args` (pinned to `core`, reporting through `progress`), prints the
    report and writes the result file; returns 0, or 1 when a path gives wrong numbers."""
    rng = np.random.default_rng(0)
    params = Params.paper_simulation()
    model = Model(params)
    X, U = random_states(rng, args.states, params), random_inputs(rng, args.states)
    result = {"date": datetime.datetime.now().isoformat(timespec="seconds"), "cpu": cpu_name(),
              "pinned_core": core, "states": args.states, "params": "Params.paper_simulation()",
              "skipped": sorted(set(args.skip))}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            build = pathlib.Path(tmp)
            progress("generating the CasADi reference C and building the C loop")
            casadi_reference_c(params, build)
            kane, kane_inputs = None, None
            if not args.no_kane:
                progress("the Kane model as C: CasADi (ca.solve), SymPy's C printer and PyDy's C (generic LU)")
                kane, kane_inputs = write_kane_c(build), kane_coordinates(X)
            exe = build_harness(build, native=False, with_casadi=True, kane=kane)
            result["c_loop"] = run_harness(exe, params, X, U, args.repeats, kane_inputs)
            check_harness(result["c_loop"], model, X, U)
            if "step-anatomy" not in args.skip:
                progress("the anatomy of a fourth-order step (its accelerations and everything else)")
                result["step_anatomy"] = step_anatomy(build, exe.parent / "input.bin", max(1, args.repeats // 4))
            if "ekf" not in args.skip:
                progress("one 200 Hz sample of the EKF: predict, an IMU and an encoder update")
                result["ekf_sample"] = ekf_sample(build)
            if args.native:
                exe = build_harness(build, native=True, with_casadi=False)
                result["c_loop_native"] = run_harness(exe, params, X, U, args.repeats)
                check_harness(result["c_loop_native"], model, X, U)
                progress(f"the memory floor of a batch of {args.batch:.0e} states")
                result["memory_floor_ns_per_state"] = memory_floor(build, args.batch)
        result["python"] = python_timings(model, X, U, args.batch, progress, with_kane=not args.no_kane,
                                          loop_steps=args.loop_steps)
    except WrongNumbers as exc:
        print(f"bench: WRONG NUMBERS: {exc}", file=sys.stderr)
        return 1
    print(format_report(result))
    written = write_results(result, args.out)
    print(f"\nwritten: {written}")
    return 0
