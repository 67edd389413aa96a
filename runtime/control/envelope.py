"""The envelope: what the torque limits allow (docs/control.md).

Computed by simulation with the verified kernels (RKMK4, dt = 0.005 s), Params.paper_simulation():
* steady rolling speed against a constant yoke torque from rest: "steady" = the speed of the
  last 5 s of a 60 s run, whose spread over those 5 s is below 1e-3 of it;
* the yoke flip-over torque: the smallest constant yoke torque (bisection to 1e-3 N m) under
  which the pendulum passes the horizontal (absolute inclination > π/2) within 30 s from rest;
* turns against speed and lean: rolling at v with the PID's speed loop, the lean held at φ by
  the PID's inner lean loop; the steady turn radius is v / mean yaw rate over the last 10 s of a
  40 s run, and the largest |u_P| over those 10 s says whether |u| ≤ u_max holds the turn.

* the friction the benchmark tasks need: every controller of every shipped task (as `make
  control` runs it), the largest friction ratio |F_t|/F_n of the contact force along the run and
  the least normal force (runtime.contact): a floor with a smaller μ would let the robot slide.

    python -m runtime envelope      # prints the numbers, writes docs/figures/control-envelope.png
    python -m runtime envelope --friction-only    # the friction table alone
"""

import argparse
import dataclasses

import numpy as np
from tqdm.auto import tqdm

from ..atomic import output_file
from ..model import Model
from ..params import Params
from ..so3 import rot_z
from ..state import absolute_inclinations, initial_state
from .benchmark import run_contact, run_task
from .closed_loop import simulate_closed_loop
from .geometry import forward_speed, heading, lean
from .pid import Pid
from .reference import SpeedHeading
from .task import load_task, shipped_tasks

DT = 0.005
#: The lean reference of a turn measurement rises at this rate [rad/s] (quasi-steady; a step flings the pendulum).
LEAN_RAMP_RAD_S = 0.05


def steady_speed(params, u_Y, duration=60.0, window=5.0):
    """(speed [m/s], relative spread over the last `window` s) under a constant yoke torque from rest."""
    model = Model(params)
    steps = round(duration / DT)
    traj = model.simulate(initial_state(r=params.r), DT, steps, np.tile([u_Y, 0.0], (steps, 1)), method="rkmk4")
    v = forward_speed(traj[-round(window / DT):], params.r)
    return float(v.mean()), float(np.ptp(v) / abs(v.mean()))


def flips(params, u_Y, duration=30.0):
    """True when the pendulum passes the horizontal under a constant yoke torque u_Y from rest."""
    model = Model(params)
    steps = round(duration / DT)
    try:
        traj = model.simulate(initial_state(r=params.r), DT, steps, np.tile([u_Y, 0.0], (steps, 1)),
                              method="rkmk4", energy_tol=None)
    except ValueError:
        return True
    return bool(np.max(absolute_inclinations(traj)[1]) > np.pi / 2)


def flip_torque(params, lo=0.0, hi=3.0, tol=1e-3):
    """The smallest constant yoke torque [N m] that flips the yoke over (bisection)."""
    if not flips(params, hi):
        raise ValueError(f"the yoke does not flip even at {hi} N m")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if flips(params, mid) else (mid, hi)
    return hi


class _LeanHold(Pid):
    """The PID's speed loop and inner lean loop, the lean reference fixed at `phi`."""

    def __init__(self, params, phi, **kw):
        super().__init__(params, **kw)
        self.phi_hold = phi

    def compute(self, t, x, target):
        u_Y, _ = super().compute(t, x, target)
        g = self.gains
        phi = float(lean(x))
        phi_ref = np.sign(self.phi_hold) * min(abs(self.phi_hold), LEAN_RAMP_RAD_S * t)
        u_P = g.k_phi * (phi_ref - phi) - g.k_phid * (phi - self._prev) / self.period
        self._prev = phi
        return u_Y, u_P

    def reset(self, x0):
        super().reset(x0)
        self._prev = float(lean(x0))


def turn(params, speed, phi, u_max=0.5, window=10.0):
    """(radius [m] (left positive), largest |u_P| [N m], relative spread of the yaw rate) over the last
    `window` s of a run at `speed` whose lean reference ramps to φ and is then held for 2 window."""
    duration = abs(phi) / LEAN_RAMP_RAD_S + 2 * window
    x0 = initial_state(R_S=rot_z(-np.pi / 2), r=params.r, w_S=(-speed / params.r, 0, 0), w_Y=speed / params.r)
    ctl = _LeanHold(params, phi, rate=50.0, u_max=u_max)
    res = simulate_closed_loop(params, ctl, SpeedHeading(speed, 0.0), x0, duration, DT)
    late = res.time >= duration - window
    psi = np.unwrap(heading(res.trajectory[late]))
    rate = (psi[-1] - psi[0]) / window
    per_second = np.diff(psi[::round(1 / DT)])
    v = forward_speed(res.trajectory[late], params.r).mean()
    radius = float(v / rate) if rate != 0 else float("inf")
    return radius, float(np.abs(res.torques[late, 1]).max()), float(np.ptp(per_second) / abs(np.mean(per_second)))


def compute(params=None, u_max=0.5):
    """Every number of the envelope (a dict), for `params` (default Params.paper_simulation())."""
    params = Params.paper_simulation() if params is None else params
    torques = np.linspace(0.05, u_max, 10)
    speeds = [steady_speed(params, u) for u in torques]
    leans = np.radians([5, 10, 15, 20, 30])
    turn_speeds = (0.15, 0.3, 0.5)
    turns = {v: [turn(params, v, phi, u_max) for phi in tqdm(leans, desc=f"turns at {v} m/s", leave=False)]
             for v in turn_speeds}
    return {"torques": torques, "speeds": speeds, "flip_torque": flip_torque(params),
            "leans": leans, "turns": turns, "u_max": u_max}


def task_friction(names=None, duration=None):
    """[(task, controller, largest |F_t|/F_n, its time [s], least F_n [N])] of every controller of the
    shipped tasks (or of `names`), each run as `make control` runs it (cut to `duration` s if given)."""
    rows = []
    for name in shipped_tasks() if names is None else names:
        task = load_task(name)
        for kind in tqdm(task.controller_kinds, desc=f"friction of {name}", leave=False):
            run = task.with_controller(kind)
            if duration is not None:
                steps = max(1, round(min(duration, run.duration) / run.scenario.dt))
                run = dataclasses.replace(run, scenario=dataclasses.replace(run.scenario, steps=steps))
            contact = run_contact(run, run_task(run)[0])
            rows.append((task.name, kind, contact["largest_friction_ratio"], contact["largest_friction_ratio_time_s"],
                         contact["least_normal_force_N"]))
    return rows


def friction_table(rows):
    """The rows of `task_friction` as a Markdown table (a ratio of None: the robot left the floor)."""
    lines = ["| task | controller | largest \\|F_t\\|/F_n | at t [s] | least F_n [N] |", "|---|---|---|---|---|"]
    lines += [f"| {task} | {kind} | " + ("lifts off | — " if ratio is None else f"{ratio:.4f} | {t:.2f}") + f" | {fn:.1f} |"
              for task, kind, ratio, t, fn in rows]
    return "\n".join(lines)


def tightest_turn(rows, leans, u_max):
    """(radius, lean) of the smallest steady radius whose pendulum torque stayed below u_max, or None."""
    held = [(abs(R), phi) for (R, up, _), phi in zip(rows, leans) if up < u_max]
    return min(held) if held else None


def main(argv=()):
    """Prints the envelope's numbers and rewrites its figure (docs/control.md)."""
    parser = argparse.ArgumentParser(prog="python -m runtime envelope")
    parser.add_argument("figure", nargs="?", type=output_file, default="docs/figures/control-envelope.png", help="where to write the figure")
    parser.add_argument("--friction-only", action="store_true", help="print only the friction the benchmark tasks need")
    args = parser.parse_args(list(argv))
    print("friction the benchmark tasks need (largest |F_t|/F_n along each run):")
    print(friction_table(task_friction()))
    if args.friction_only:
        return 0
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    env = compute()
    gain = np.polyfit(env["torques"], [v for v, _ in env["speeds"]], 1)[0]
    print("steady speed per yoke torque: " + ", ".join(f"{u:.2f} N m -> {v:.4f} m/s (spread {s:.1e})"
                                                     for u, (v, s) in zip(env["torques"], env["speeds"])))
    print(f"slope {gain:.4f} m/s per N m; at u_max = {env['u_max']} N m: {env['speeds'][-1][0]:.4f} m/s")
    print(f"yoke flip-over torque (constant torque from rest): {env['flip_torque']:.3f} N m")
    for v, rows in env["turns"].items():
        print(f"v = {v} m/s: " + ", ".join(f"lean {np.degrees(phi):.0f}° -> R = {R:.2f} m (max |u_P| {up:.3f} N m, "
                                           f"yaw-rate spread {sp:.2f})" for phi, (R, up, sp) in zip(env["leans"], rows)))
        best = tightest_turn(rows, env["leans"], env["u_max"])
        print(f"  tightest turn within |u_P| < {env['u_max']} N m: "
              + ("none" if best is None else f"R = {best[0]:.2f} m at lean {np.degrees(best[1]):.0f}°"))
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    a.plot(env["torques"], [v for v, _ in env["speeds"]], "o-")
    a.set_xlabel("constant yoke torque u_Y [N m]"), a.set_ylabel("steady rolling speed [m/s]")
    a.set_title(f"steady speed (flip-over from rest at {env['flip_torque']:.2f} N m)")
    for v, rows in env["turns"].items():
        held = [up < env["u_max"] for _, up, _ in rows]
        radii = [abs(R) for R, _, _ in rows]
        line, = b.plot(np.degrees(env["leans"]), radii, "-", label=f"{v} m/s")
        b.plot(np.degrees(env["leans"])[held], np.array(radii)[held], "o", color=line.get_color())
        b.plot(np.degrees(env["leans"])[~np.array(held)], np.array(radii)[~np.array(held)], "x", color=line.get_color())
    b.set_xlabel("lean of the rolling axis φ [deg]"), b.set_ylabel("steady turn radius [m]"), b.legend()
    b.set_yscale("log"), b.set_title(f"turns (o: held with |u_P| < {env['u_max']} N m, x: saturated)")
    fig.tight_layout()
    out = args.figure
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")
    return 0
