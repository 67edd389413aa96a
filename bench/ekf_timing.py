"""Builds and runs bench/bench_ekf.c (one 200 Hz sample of the error-state EKF: an RKMK4 predict, an
IMU and an encoder update; each part alone too; and the same sample on the filter's default path,
the IMU through sr_ekf_update_imu_held with the disturbance held over one IMU period, whole and
without the encoder update) in the portable -O2 build of the bench
(runtime.bench.harness.ekf_sample), and prints its JSON.  With --baseline REV the same program is
also built with the filter's sources (EKF_SOURCES: the filter, the step Jacobians, the
accelerations' Jacobians and the sensors' Jacobians) as they were at the git revision REV, and the two run in turns (the same
samples, the same load): before and after, C against C in one run.  With --callgrind each build's
instructions per sample and per part are counted too (valgrind's callgrind, the setup subtracted):
the numbers a loaded machine does not move.

    .venv/bin/python bench/ekf_timing.py [--baseline REV] [--rounds N] [--callgrind] [--objects DIR] [--out DIR]

Each run is kept, with the date, the CPU and the load average, as <date and time>.json in --out
(bench/results/ekf).
"""
import argparse
import datetime
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from runtime.atomic import write_new_file  # noqa: E402
from runtime.bench.harness import LIBRARY_FLAGS, _compiler, compile_library, with_baseline  # noqa: E402
from runtime.bench.timing import cpu_name  # noqa: E402

#: The bench's EKF build (runtime.bench.harness.ekf_sample): portable, -O2, no contraction.
FLAGS = [f for f in LIBRARY_FLAGS if f != "-O3"] + ["-O2", "-ffp-contract=off"]
#: bench_ekf's PARTS: what each counted run does.
PARTS = {"predict_imu_encoders": 7, "predict": 1, "update_imu": 2, "update_encoders": 4,
         "held_predict_imu_encoders": 13, "held_predict_imu": 9}
#: The sources of c/src that --baseline takes from the other revision: those a sample's own work runs in.
EKF_SOURCES = ("sr_ekf.c", "sr_step_jacobians.c", "sr_jacobians.c", "sr_sensors.c")


def instructions(exe, samples, parts):
    """Instructions of one run of bench_ekf over `samples` samples doing `parts` (callgrind's total)."""
    run = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", str(exe), str(samples),
                          str(parts)], capture_output=True, text=True, check=True)
    found = re.search(r"Collected : (\d+)", run.stderr)
    if not found:
        sys.exit(f"callgrind: no count in {run.stderr[-500:]}")
    return int(found.group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2000)
    parser.add_argument("--baseline", help="a git revision whose filter sources (EKF_SOURCES) to run beside these")
    parser.add_argument("--rounds", type=int, default=5, help="turns of the builds; the best of each")
    parser.add_argument("--callgrind", action="store_true", help="also count instructions per sample (valgrind)")
    parser.add_argument("--objects", type=pathlib.Path, default=None,
                        help="a folder to keep the library's objects in between runs (default: rebuilt each run)")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "results" / "ekf",
                        help="the folder that keeps each run's result file")
    args = parser.parse_args()
    if args.callgrind and not shutil.which("valgrind"):
        sys.exit("--callgrind needs valgrind")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.objects or pathlib.Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        objects = compile_library(folder, FLAGS)
        builds = {"current": objects}
        if args.baseline:
            old = objects
            for source in EKF_SOURCES:
                old = with_baseline(folder, old, source, args.baseline, FLAGS)
            builds = {"baseline": old, "current": objects}
        exes = {}
        for label, objs in builds.items():
            exes[label] = folder / f"bench_ekf_{label}"
            subprocess.run([_compiler(), *FLAGS, str(ROOT / "bench" / "bench_ekf.c"), *map(str, objs), "-lm", "-o",
                            str(exes[label])], check=True)
        out = {}
        for _ in range(args.rounds):     # in turns; the best of each
            for label, exe in exes.items():
                got = json.loads(subprocess.run([str(exe), str(args.samples)], check=True, capture_output=True,
                                                text=True).stdout)
                best = out.setdefault(label, got)
                for k, v in got.items():
                    if k.endswith("_ns"):
                        best[k] = min(best[k], v)
        if args.callgrind:
            n = min(args.samples, 200)
            for label, exe in exes.items():
                setup = instructions(exe, n, 0)
                out[label]["instructions_per_sample"] = {
                    name: round((instructions(exe, n, parts) - setup) / n) for name, parts in PARTS.items()}
    if args.baseline:
        for key, name in (("speedup", "predict_imu_encoders_ns"), ("held_speedup", "held_predict_imu_encoders_ns")):
            out[key] = round(out["baseline"][name] / out["current"][name], 2)
    date = datetime.datetime.now().isoformat(timespec="seconds")
    text = json.dumps({"date": date, "cpu": cpu_name(), "load_average": os.getloadavg(), "baseline": args.baseline,
                       "samples": args.samples, "rounds": args.rounds, "builds": out}, indent=1)
    print(text)
    print(f"written: {write_new_file(args.out, date.replace(':', '-'), '.json', text + chr(10))}")


if __name__ == "__main__":
    main()
