"""`python -m runtime soak`: a long run for drift, not a unit test (docs/robustness.md).

Runs --steps steps in total (default 10⁷) split over --states random initial states
(default 10), with the fourth-order method (default rkmk4) on the frictionless robot, so the
energy is a conserved quantity, and reports per state and overall:

* the largest orthonormality defect max |RᵀR − I| (entries, and |det R − 1|) of R_S, R_Y, R_P,
* the largest |q_z − r|,
* the largest energy drift |E − E₀| relative to the energy scale (kinetic energy at the start
  + m_P g l, the scale of the simulation's energy guard),
* the speed in ns per step.

The guards of `Model.simulate` stay on (a failing guard is reported as a failure).  The
quantities are sampled every --chunk steps (the last state of each C call).
Exit status 0, or 1 if a guard stopped a run.
"""
import argparse
import json
import math
import time

import numpy as np

from ..errors import SimulationStopped
from ..model import METHODS, Model
from ..params import Params
from ..so3 import rotation_defect
from ..state import IDX_NU, IDX_QZ, rotations
from .sampling import random_state


def defects(x, r):
    """(max orthonormality defect of the three rotations, |q_z − r|) of one state."""
    return max(rotation_defect(R) for R in rotations(x)), abs(x[IDX_QZ] - r)


def energy_scale(model, x):
    """The energy scale of state x: its kinetic energy plus the range of the potential energy."""
    rest = x.copy()
    rest[IDX_NU] = 0
    p = model.params
    return model.energy(x) - model.energy(rest) + p.potential_range()


def soak_one(model, x0, steps, dt, method, chunk):
    """Simulates `steps` steps from x0 in chunks and returns the worst rotation defect, q_z error and
    energy drift, and the time per step."""
    e0, scale = model.energy(x0), energy_scale(model, x0)
    worst_rot, worst_qz, worst_e, x, done = 0.0, 0.0, 0.0, x0, 0
    started = time.perf_counter()
    while done < steps:
        n = min(chunk, steps - done)
        x = model.simulate(x, dt, n, method=method)[-1]
        done += n
        rot, qz = defects(x, model.params.r)
        worst_rot, worst_qz = max(worst_rot, rot), max(worst_qz, qz)
        worst_e = max(worst_e, abs(model.energy(x) - e0) / scale)
    seconds = time.perf_counter() - started
    return {"steps": steps, "rotation_defect": worst_rot, "qz_error_m": worst_qz,
            "energy_drift_rel": worst_e, "final_energy_drift_rel": abs(model.energy(x) - e0) / scale,
            "energy_scale_J": scale, "ns_per_step": seconds / steps * 1e9}


def main(argv):
    """`python -m runtime soak`: long runs from random states, reporting the drift of the invariants."""
    parser = argparse.ArgumentParser(prog="python -m runtime soak", description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=10_000_000, help="total steps (default 1e7)")
    parser.add_argument("--states", type=int, default=10, help="random initial states (default 10)")
    parser.add_argument("--dt", type=float, default=0.001, help="time step [s] (default 0.001)")
    parser.add_argument("--method", default="rkmk4", choices=sorted(METHODS), help="integrator (default rkmk4)")
    parser.add_argument("--max-speed", type=float, default=5.0, help="initial speeds up to this [rad/s]")
    parser.add_argument("--chunk", type=int, default=100_000, help="steps per C call (sampling interval)")
    parser.add_argument("--seed", type=int, default=8)
    parser.add_argument("--json", help="also write the results to this JSON file")
    args = parser.parse_args(argv)
    for option, value, ok, rule in (
            ("--steps", args.steps, args.steps >= 1, "a positive integer"),
            ("--states", args.states, args.states >= 1, "a positive integer"),
            ("--chunk", args.chunk, args.chunk >= 1, "a positive integer"),
            ("--seed", args.seed, args.seed >= 0, "a non-negative integer"),
            ("--dt", args.dt, math.isfinite(args.dt) and args.dt > 0, "a positive finite number of seconds"),
            ("--max-speed", args.max_speed, math.isfinite(args.max_speed) and args.max_speed >= 0,
             "a non-negative finite speed in rad/s")):
        if not ok:
            parser.error(f"{option}: expected {rule}, got {value!r}")

    model = Model(Params.paper_simulation(k_S=0, k_Y=0, k_P=0))
    rng = np.random.default_rng(args.seed)
    per_state = args.steps // args.states
    print(f"soak: {per_state * args.states:,} steps of {args.method}, dt = {args.dt:g} s, {args.states} random "
          f"states (speeds up to {args.max_speed:g} rad/s), frictionless; sampled every {args.chunk:,} steps")
    runs, failed = [], 0
    for k in range(args.states):
        x0 = random_state(rng, model.params, max_speed=args.max_speed)
        try:
            run = soak_one(model, x0, per_state, args.dt, args.method, args.chunk)
        except SimulationStopped as exc:
            failed += 1
            run = {"steps": per_state, "stopped": str(exc)}
            print(f"  state {k}: STOPPED: {exc}")
        else:
            print(f"  state {k}: max |RᵀR − I| {run['rotation_defect']:.2e}   max |q_z − r| {run['qz_error_m']:.1e} m"
                  f"   max |ΔE|/scale {run['energy_drift_rel']:.2e}   {run['ns_per_step']:.0f} ns/step")
        runs.append(run)
    ok = [r for r in runs if "stopped" not in r]
    total = {"steps": per_state * args.states, "method": args.method, "dt": args.dt, "seed": args.seed,
             "stopped_runs": failed, "runs": runs}
    if ok:
        total.update({key: max(r[key] for r in ok) for key in ("rotation_defect", "qz_error_m", "energy_drift_rel")})
        total["ns_per_step"] = float(np.mean([r["ns_per_step"] for r in ok]))
        print(f"soak: worst over {len(ok)} states: max |RᵀR − I| {total['rotation_defect']:.2e}, "
              f"max |q_z − r| {total['qz_error_m']:.1e} m, max |ΔE|/scale {total['energy_drift_rel']:.2e}; "
              f"{total['ns_per_step']:.0f} ns/step (guards on)")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(total, f, indent=2)
    return 1 if failed else 0
