"""Instructions per state of a fit's step Jacobians, by callgrind: builds
bench/ident_jacobian_instructions.c with the library (the flags of the timed benches) and counts,
on 64 consecutive states of the battery-geared robot under random torques (RKMK4, h = 0.01 s), one
call of each kernel: F alone, the analytic parameter columns alone, both at once, the columns by
batched central differences, and F by batched central differences.  With --baseline REV the
"before" row: the same program on c/src/sr_param_jacobians.c as it was at REV.

    .venv/bin/python bench/ident_jacobian_instructions.py [--baseline REV] [--out DIR]

The result is kept, with the date and the CPU, as instructions-<date and time>.json in --out
(bench/results/identify).
"""
import argparse
import datetime
import json
import pathlib
import re
import struct
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from runtime.atomic import write_new_file  # noqa: E402
from runtime.bench.harness import LIBRARY_FLAGS, _compiler, compile_library, with_baseline  # noqa: E402
from runtime.bench.timing import cpu_name  # noqa: E402
from runtime.identification.bench import DEFAULT_PARAMS  # noqa: E402
from runtime.identification.coverage import random_torques  # noqa: E402
from runtime.model import Model  # noqa: E402
from runtime.param_derivatives import PARAMETER_NAMES  # noqa: E402
from runtime.scenario import load_scenario  # noqa: E402

N = 64


def states():
    """(params, X, U): N consecutive states of the battery-geared robot's scenario under random torques."""
    scenario = load_scenario("battery-geared")
    rng = np.random.default_rng(0)
    program = random_torques(2.0, rng)
    U = np.array([program_at(program, k * 0.01) for k in range(N)])
    X = Model(scenario.params).simulate(scenario.x0, 0.01, N, u=U, method="rkmk4", energy_tol=None)[:-1]
    return scenario.params, X, U


def program_at(program, t):
    for w in program:
        if w.t_from <= t < w.t_to:
            return np.array([w.u_Y, w.u_P], dtype=float)
    return np.zeros(2)


def instructions(exe, data, mode, cols):
    """Instructions callgrind counts inside run() for one call, per state."""
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "cg.out"
        subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=run", f"--callgrind-out-file={out}",
                        str(exe), str(data), mode, *map(str, cols)], check=True, capture_output=True)
        total = re.search(r"^(?:summary|totals): (\d+)", out.read_text(), re.M)
        return int(total.group(1)) / N


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", help="a git revision whose sr_param_jacobians.c to count beside this one")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "results" / "identify")
    args = parser.parse_args()
    params, X, U = states()
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        data = folder / "states.bin"
        with open(data, "wb") as f:
            f.write(struct.pack("i", N))
            f.write(np.ascontiguousarray(params.as_array()).tobytes())
            f.write(np.ascontiguousarray(X).tobytes())
            f.write(np.ascontiguousarray(U).tobytes())
        objects = compile_library(folder, LIBRARY_FLAGS)
        builds = {"current": (objects, [])}
        if args.baseline:
            builds["baseline"] = (with_baseline(folder, objects, "sr_param_jacobians.c", args.baseline, LIBRARY_FLAGS),
                                  ["-DSR_NO_BOTH"])
        record = {"date": datetime.datetime.now().isoformat(timespec="seconds"), "cpu": cpu_name(),
                  "robot": "battery-geared", "method": "rkmk4", "states": N, "per_state": {}}
        for label, (objs, extra) in builds.items():
            exe = folder / f"ident_jacobian_instructions_{label}"
            subprocess.run([_compiler(), *LIBRARY_FLAGS, *extra, str(ROOT / "bench" / "ident_jacobian_instructions.c"),
                            *map(str, objs), "-lm", "-o", str(exe)], check=True)
            for names in DEFAULT_PARAMS:
                cols = [PARAMETER_NAMES.index(n) for n in names.split(",")]
                row = {mode: instructions(exe, data, mode, cols)
                       for mode in ("F", "cols", "both", "fd", "fdF") if not (extra and mode == "both")}
                row["analytic_arm"] = row["both"] if "both" in row else row["F"] + row["cols"]
                row["fd_arm"] = row["F"] + row["fd"]
                row["fd_all_arm"] = row["fdF"] + row["fd"]
                record["per_state"][f"{len(cols)} columns ({label})"] = row
                print(f"{label}, {len(cols)} columns: " + ", ".join(f"{k} {v:,.0f}" for k, v in row.items()))
    text = json.dumps(record, indent=1)
    print(f"written: {write_new_file(args.out, 'instructions-' + record['date'].replace(':', '-'), '.json', text + chr(10))}")


if __name__ == "__main__":
    main()
