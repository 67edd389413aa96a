"""Builds and runs bench/param_jacobian_timing.c on 256 random states of the paper's robot and of a
general robot (geared, off-centre battery, slope), and prints its JSON per robot: the step
Jacobian, the analytic step-parameter Jacobian and the batched finite-difference one, ns per state.
With --baseline REV the same program is also built with c/src/sr_param_jacobians.c as it was at
the git revision REV, and the two run in turns (the same states, the same load): before and after.

    .venv/bin/python bench/param_jacobian_timing.py [--repeats N] [--baseline REV] [--objects DIR] [--out DIR]

Each run is kept, with the date and the CPU, as <date and time>.json in --out (bench/results/param-jacobian).
"""
import argparse
import datetime
import json
import pathlib
import struct
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from runtime.atomic import write_new_file  # noqa: E402
from runtime.bench.harness import LIBRARY_FLAGS, _compiler, compile_library, general_robot, with_baseline  # noqa: E402
from runtime.param_derivatives import random_states  # noqa: E402
from runtime.params import Params  # noqa: E402
from runtime.bench.timing import cpu_name  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--states", type=int, default=256)
    parser.add_argument("--baseline", help="a git revision whose sr_param_jacobians.c to time beside this one")
    parser.add_argument("--rounds", type=int, default=3, help="turns of the two builds (with --baseline)")
    parser.add_argument("--objects", type=pathlib.Path, default=None,
                        help="a folder to keep the library's objects in between runs (default: rebuilt each run)")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "results" / "param-jacobian",
                        help="the folder that keeps each run's result file")
    args = parser.parse_args()
    paper = Params.paper_simulation()
    rng = np.random.default_rng(0)
    X = random_states(rng, args.states, paper.r, max_speed=3.0)
    U = rng.uniform(-0.5, 0.5, size=(args.states, 2))
    with tempfile.TemporaryDirectory() as tmp:
        exe = pathlib.Path(tmp) / "param_jacobian_timing"
        folder = args.objects or pathlib.Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        objects = compile_library(folder, LIBRARY_FLAGS)
        builds = {"current": objects}
        if args.baseline:
            builds = {"baseline": with_baseline(folder, objects, "sr_param_jacobians.c", args.baseline, LIBRARY_FLAGS),
                      "current": objects}
        exes = {}
        for label, objs in builds.items():
            exes[label] = folder / f"param_jacobian_timing_{label}"
            subprocess.run([_compiler(), *LIBRARY_FLAGS, str(ROOT / "bench" / "param_jacobian_timing.c"),
                            *map(str, objs), "-lm", "-o", str(exes[label])], check=True)
        out = {}
        for name, params in (("paper", paper), ("general", general_robot(paper))):
            data = folder / f"{name}.bin"
            with open(data, "wb") as f:
                f.write(struct.pack("i", len(X)))
                f.write(np.ascontiguousarray(params.as_array()).tobytes())
                f.write(np.ascontiguousarray(X).tobytes())
                f.write(np.ascontiguousarray(U).tobytes())
            for _ in range(args.rounds if args.baseline else 1):     # in turns; the best of each
                for label, exe in exes.items():
                    run = subprocess.run([str(exe), str(data), str(args.repeats)], capture_output=True, text=True)
                    if run.returncode:
                        sys.exit(f"{name}: {run.stderr}")
                    got = json.loads(run.stdout)
                    del got["sink"]
                    key = f"{name} ({label})" if args.baseline else name
                    best = out.setdefault(key, got)
                    for k, v in got.items():
                        if k.startswith(("step_", "fd_batched")) and isinstance(v, float):
                            best[k] = min(best[k], v)
        for key, row in out.items():
            for m in ("rkmk4", "lie_euler"):
                row[f"ratio_to_step_jacobian_{m}"] = round(row[f"step_param_jacobian_{m}"] / row[f"step_jacobian_{m}"], 2)
                row[f"fd_over_analytic_{m}"] = round(row[f"fd_batched_{m}"] / row[f"step_param_jacobian_{m}"], 1)
    date = datetime.datetime.now().isoformat(timespec="seconds")
    text = json.dumps({"date": date, "cpu": cpu_name(), "baseline": args.baseline, "robots": out}, indent=1)
    print(text)
    print(f"written: {write_new_file(args.out, date.replace(':', '-'), '.json', text + chr(10))}")


if __name__ == "__main__":
    main()
