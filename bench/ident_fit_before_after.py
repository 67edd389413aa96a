"""CPU time of the identify-bench's full-state fits (runtime/identification/bench.py: the 30 s log of
seed 0, both parameter sets, analytic and "fd" Jacobians) with the Python package as it is and as
it was at a git revision, in turns in separate processes at the same load, `--rounds` times; each
keeps its best time.  The compiled library is the working tree's for both (the revision's Python
runs on it), so this measures changes to the fit's Python only; with --with-c the revision's C
(generated/, c/, bindings/) is built too (setup.py build_ext --inplace, a few minutes) and its
Python runs on its own library: changes to both.

    .venv/bin/python bench/ident_fit_before_after.py --baseline REV [--with-c] [--rounds N] [--out DIR]

The result is kept, with the date, the CPU and the load, as fit-before-after-<date and time>.json in
--out (bench/results/identify).
"""
import argparse
import datetime
import json
import os
import pathlib
import subprocess
import sys
import tarfile
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from runtime.atomic import write_new_file  # noqa: E402
from runtime.bench.timing import cpu_name  # noqa: E402
from runtime.identification.bench import DEFAULT_PARAMS  # noqa: E402

#: One process: the logs, then each Jacobian source's fit of each, twice in turns as the
#: identify-bench runs them (a process's first fit also pays what a process does once), the best CPU
#: seconds as JSON on stdout.
CHILD = """
import json, sys, time
from runtime.identification.coverage import simulated_log
from runtime.identification.fit import identify
logs = {names: simulated_log(names, 30.0, 0) for names in sys.argv[1:]}
out = {}
for _ in range(2):
    for names, (log, nominal, _) in logs.items():
        for source in ("analytic", "fd"):
            started = time.process_time()
            fit = identify(log, nominal, names, jacobian=source, full_state=True)
            cpu = min(time.process_time() - started, out.get(names + "|" + source, [9e9])[0])
            out[names + "|" + source] = [cpu, fit.estimate.tolist(), int(fit.nfev)]
print(json.dumps(out))
"""


def run(pythonpath, names):
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    done = subprocess.run([sys.executable, "-c", CHILD, *names], env=env, cwd=pythonpath, check=True,
                          capture_output=True, text=True)
    return json.loads(done.stdout.splitlines()[-1])


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", required=True, help="the git revision of the 'before' Python package")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--name", help="the result's file name without .json (default: with the date and time)")
    parser.add_argument("--with-c", action="store_true", help="build and use the revision's compiled library too")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "results" / "identify")
    args = parser.parse_args(argv)
    best = {"before": {}, "after": {}}
    estimates = {"before": {}, "after": {}}
    load = [os.getloadavg()]
    with tempfile.TemporaryDirectory() as tmp:
        trees = ["runtime"] + (["bindings", "c", "generated", "setup.py", "pyproject.toml"] if args.with_c else [])
        archive = subprocess.run(["git", "archive", args.baseline, *trees], cwd=ROOT, check=True,
                                 capture_output=True).stdout
        old = pathlib.Path(tmp) / "before"
        old.mkdir()
        with tarfile.open(fileobj=__import__("io").BytesIO(archive)) as tar:
            tar.extractall(old)
        if args.with_c:
            subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"], cwd=old, check=True,
                           capture_output=True)
        for _ in range(args.rounds):
            for version, path in (("before", old), ("after", ROOT)):
                for key, (cpu, estimate, nfev) in run(path, DEFAULT_PARAMS).items():
                    best[version][key] = min(best[version].get(key, cpu), cpu)
                    estimates[version][key] = (estimate, nfev)
    load.append(os.getloadavg())
    rows = []
    for names in DEFAULT_PARAMS:
        row = {"params": names}
        for version in ("before", "after"):
            a, f = best[version][names + "|analytic"], best[version][names + "|fd"]
            row[version] = {"analytic_cpu_s": a, "fd_cpu_s": f, "speedup_cpu": f / a,
                            "nfev": estimates[version][names + "|analytic"][1]}
        ea, eb = (estimates[v][names + "|analytic"][0] for v in ("after", "before"))
        row["max_relative_change_of_estimate"] = max(abs(x - y) / max(abs(y), 1e-300) for x, y in zip(ea, eb))
        rows.append(row)
        print(f"{len(names.split(','))} entries: before {row['before']['analytic_cpu_s']:.3f} s / "
              f"{row['before']['fd_cpu_s']:.3f} s ({row['before']['speedup_cpu']:.2f}x), after "
              f"{row['after']['analytic_cpu_s']:.3f} s / {row['after']['fd_cpu_s']:.3f} s "
              f"({row['after']['speedup_cpu']:.2f}x)")
    date = datetime.datetime.now().isoformat(timespec="seconds")
    record = {"date": date, "cpu": cpu_name(), "baseline": args.baseline, "baseline_c": args.with_c, "rounds": args.rounds,
              "load_start_end": load, "what": __doc__.split("\n\n")[0].replace("\n", " "), "fits": rows}
    print("written:", write_new_file(args.out, args.name or "fit-before-after-" + date.replace(":", "-"), ".json",
                                     json.dumps(record, indent=1) + "\n"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
