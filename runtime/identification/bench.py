"""`python -m runtime identify-bench` (`make bench`): what the analytic parameter sensitivities buy a
fit.  The same fit of the same log, once with the analytic Jacobians of the C library and once with
central differences computed in C, batched, for the parameter columns (`Model.step_param_jacobian_fd`,
the state Jacobians analytic in both: the headline ratio); a sensor-log fit also runs a third time
with differences for every Jacobian ("fd-all", its state Jacobians too; a full-state fit has none).
Wall and CPU times, the ratios, the evaluations each took, and how far apart the optima are
(docs/identification.md, "Measured").

The log is `coverage.simulated_log`: the battery-geared robot with the named entries planted within
±30 % of its values, random torques, the default sensor set; a full-state fit by default.  The two
fits run in turns, `--rounds` times after one untimed fit, and each keeps its best time (the same
load for both) and every round's.  Each
run is kept, with its date and CPU, as <date and time>.json in --out (bench/results/identify).
"""
import datetime
import json
import time

import numpy as np

from ..atomic import write_new_file
from ..param_derivatives import PARAMETER_NAMES
from .coverage import simulated_log
from .fit import identify
from .sensitivity import JACOBIANS

#: The fits compared by default: the dampings, the pendulum's mass and hinge inertia and the yoke
#: rotor's inertia; and every entry of the battery-geared robot that its full-state log identifies
#: alone with the other entries held (docs/identification.md, "Base parameters").  Both sources run
#: on the free columns only: the analytic sensitivity has a share every column needs, the
#: differences two batch steps each.
DEFAULT_PARAMS = ("k_S,k_Y,k_P,m_P,J_P_yy,j_mY",
                  "j_S,k_S,k_Y,k_P,m_P,c_P_x,c_P_z,J_P_yy,J_Y_xx,J_Y_yz,c_Y_x,c_Y_z,j_mY,j_mP")


def compare(log, nominal, names, rounds=1, **options):
    """{"analytic": {...}, "fd": {...}, "speedup_wall", "speedup_cpu", "max_difference_sigma",
    "max_difference_relative"}: the fit of `log` by each Jacobian source of `identify` (`JACOBIANS`;
    without "fd-all" for a full-state fit, which has no state Jacobian), after one untimed fit, run in
    turns `rounds` times, each with its best wall and CPU time, each round's CPU time
    ("cpu_s_rounds"; "speedup_cpu_rounds" the ratio round by round), its estimate, sigma and
    evaluations; the optima's largest
    difference in the analytic fit's sigmas and relative to the estimate.  With "fd-all" also
    "speedup_cpu_fd_all" and its optimum's distance "max_difference_sigma_fd_all"."""
    out = {}
    sources = [s for s in JACOBIANS if s != "fd-all" or not options.get("full_state")]
    # One untimed fit first: a process's first fit pays what the later ones reuse (its memory's first
    # touch, the BLAS thread pools, the robot's base parameters: 30-45 ms of CPU in a 30 s full-state
    # fit), which would otherwise fall on the first round's first source.
    identify(log, nominal, names, jacobian=sources[0], **options)
    for _ in range(rounds):
        for source in sources:
            started, cpu = time.perf_counter(), time.process_time()
            fit = identify(log, nominal, names, jacobian=source, **options)
            wall, cpu = time.perf_counter() - started, time.process_time() - cpu
            best = out.setdefault(source, {"wall_s": wall, "cpu_s": cpu, "cpu_s_rounds": []})
            best["wall_s"], best["cpu_s"] = min(best["wall_s"], wall), min(best["cpu_s"], cpu)
            best["cpu_s_rounds"].append(cpu)
            best.update(names=list(fit.names), estimate=fit.estimate.tolist(), sigma=fit.sigma.tolist(),
                        nfev=fit.nfev, rms=fit.residual_check["rms"], message=fit.message)
    a, f = np.array(out["analytic"]["estimate"]), np.array(out["fd"]["estimate"])
    sigma = np.array(out["analytic"]["sigma"])
    with np.errstate(invalid="ignore", divide="ignore"):
        in_sigma = np.abs(a - f) / sigma
    out["speedup_wall"] = out["fd"]["wall_s"] / out["analytic"]["wall_s"]
    out["speedup_cpu"] = out["fd"]["cpu_s"] / out["analytic"]["cpu_s"]
    out["speedup_cpu_rounds"] = [f / a for a, f in zip(out["analytic"]["cpu_s_rounds"], out["fd"]["cpu_s_rounds"])]
    out["max_difference_sigma"] = float(np.nanmax(in_sigma)) if np.isfinite(in_sigma).any() else None
    out["max_difference_relative"] = float(np.max(np.abs(a - f) / np.maximum(np.abs(a), 1e-300)))
    if "fd-all" in out:
        out["speedup_cpu_fd_all"] = out["fd-all"]["cpu_s"] / out["analytic"]["cpu_s"]
        out["max_difference_sigma_fd_all"] = float(np.nanmax(np.abs(a - np.array(out["fd-all"]["estimate"])) / sigma))
    return out


def main(argv):
    """`python -m runtime identify-bench [--params NAMES ...] [--duration S] [--seed N] [--rounds N]
    [--sensors] [--out DIR]`: one comparison (`compare`) per parameter set, all kept in one file."""
    import argparse
    import pathlib
    import sys

    from ..bench.timing import cpu_name
    from ..cli_types import duration, whole_number

    parser = argparse.ArgumentParser(prog="python -m runtime identify-bench", description=__doc__.split("\n\n")[0])
    parser.add_argument("--params", action="append", help="comma-separated entries to fit; repeatable, one fit "
                        f"each (default: {' and '.join(DEFAULT_PARAMS)})")
    parser.add_argument("--duration", type=duration, default=30.0, help="the log's length [s] (30)")
    parser.add_argument("--seed", type=whole_number(0), default=0, help="the log's seed (0)")
    parser.add_argument("--rounds", type=whole_number(1), default=2, help="turns of the two fits; best of each (2)")
    parser.add_argument("--sensors", action="store_true", help="fit the sensor log instead of its truth")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[2] / "bench"
                        / "results" / "identify", help="the folder that keeps each run's result file")
    args = parser.parse_args(argv)
    comparisons = []
    for names in args.params or DEFAULT_PARAMS:
        try:
            log, nominal, truth = simulated_log(names, args.duration, args.seed)
            result = compare(log, nominal, names, args.rounds, full_state=not args.sensors)
        except ValueError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        fitted = result["analytic"]["names"]
        comparisons.append({"params": names, "truth": {n: float(truth.as_array()[PARAMETER_NAMES.index(n)])
                                                       for n in fitted}, **result})
        print(f"{len(fitted)} entries ({names}):")
        for source in (s for s in JACOBIANS if s in result):
            r = result[source]
            print(f"  {source:>8}: {r['wall_s']:.2f} s wall, {r['cpu_s']:.2f} s CPU, {r['nfev']} evaluations")
        print(f"  analytic faster by {result['speedup_wall']:.1f}x (wall), {result['speedup_cpu']:.1f}x (CPU; round by "
              f"round {', '.join(f'{r:.2f}' for r in result['speedup_cpu_rounds'])}x); optima "
              f"{result['max_difference_sigma']:.2g} sigma apart at most ({result['max_difference_relative']:.2g} "
              "relative)")
        if "fd-all" in result:
            print(f"  against differences for every Jacobian (fd-all): {result['speedup_cpu_fd_all']:.1f}x (CPU)")
    date = datetime.datetime.now().isoformat(timespec="seconds")
    record = {"date": date, "cpu": cpu_name(), "log": {"robot": "battery-geared", "duration_s": args.duration,
                                                       "seed": args.seed, "mode": "sensors" if args.sensors
                                                       else "full-state"},
              "rounds": args.rounds, "fits": comparisons}
    text = json.dumps(record, indent=1)
    print(f"written: {write_new_file(args.out, date.replace(':', '-'), '.json', text + chr(10))}")
    return 0
