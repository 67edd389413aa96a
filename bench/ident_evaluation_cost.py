"""CPU time of one evaluation (`_Problem.assemble`: the segments, their rows, the whitening, the
compression and the sparse Jacobian) of the sensor fit of identify-bench's 4 s log (seed 0, six
entries), for each Jacobian source of the fit, in turns in one process, `--rounds` times; the
least and the median of each, and their ratios to the analytic one.  The work outside the
evaluations (the start guess, the first guess, the start fit, the report) is left out.

    .venv/bin/python bench/ident_evaluation_cost.py [--rounds 20] [--label NAME] [--out DIR]

Run on another tree's Python with PYTHONPATH pointing there (its compiled library too), so that
before and after run one after the other at the same load.  The result is kept, with the date,
the CPU and the load, as evaluation-cost-<label>-<date and time>.json in --out
(bench/results/identify).
"""
import argparse
import datetime
import json
import os
import pathlib
import time

import numpy as np

from runtime.atomic import write_new_file
from runtime.bench.timing import cpu_name
from runtime.identification import fit
from runtime.identification.bench import DEFAULT_PARAMS
from runtime.identification.coverage import simulated_log
from runtime.identification.sensitivity import JACOBIANS


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--label", default="run")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parent / "results" / "identify")
    args = parser.parse_args()
    names = DEFAULT_PARAMS[0]
    log, nominal, _ = simulated_log(names, 4.0, 0)
    x, b, sigma = fit._start_guess(log, nominal, with_sigma=True)
    problems = {}
    for source in JACOBIANS:
        problems[source] = fit._Problem(log, nominal, fit.free_parameters(names), 0.5, "rkmk4", x, b, source, sigma)
        problems[source].assemble(problems[source].z0())
    times = {source: [] for source in problems}
    with fit._blas_threads().limit(limits=1, user_api="blas"):
        for _ in range(args.rounds):
            for source, prob in problems.items():
                prob._cache = (None, None)
                started = time.process_time()
                prob.assemble(prob.z0())
                times[source].append(time.process_time() - started)
    result = {s: {"least_ms": 1e3 * min(t), "median_ms": 1e3 * float(np.median(t))} for s, t in times.items()}
    for s in result:
        result[s]["ratio_least"] = result[s]["least_ms"] / result["analytic"]["least_ms"]
        result[s]["ratio_median"] = result[s]["median_ms"] / result["analytic"]["median_ms"]
        print(f"{s:>8}: {result[s]['least_ms']:.2f} ms (median {result[s]['median_ms']:.2f}), "
              f"{result[s]['ratio_least']:.2f}x the analytic one (median {result[s]['ratio_median']:.2f}x)")
    date = datetime.datetime.now().isoformat(timespec="seconds")
    record = {"date": date, "cpu": cpu_name(), "load_average": os.getloadavg(), "label": args.label,
              "log": {"duration_s": 4.0, "seed": 0, "params": names}, "rounds": args.rounds, "evaluation": result}
    path = write_new_file(args.out, f"evaluation-cost-{args.label}-{date.replace(':', '-')}", ".json",
                          json.dumps(record, indent=1) + "\n")
    print(f"written: {path}")


if __name__ == "__main__":
    main()
