"""A scenario in both simulators: the kernels and the exported MJCF in MuJoCo, with the same torques.

`python -m runtime compare-mujoco SCENARIO [--out DIR] [--timesteps 2e-3,1e-3,...]` runs the
scenario with the kernels (RKMK4 at a tenth of the scenario's dt: the exact model as far as
MuJoCo is concerned) and in MuJoCo for each setting of a sweep: the exported contact settings at
several time steps (the contact's time constant two steps, so the contact hardens as the step
shrinks), then variants at 1 ms (MuJoCo's first-order implicitfast integrator, no no-slip
iterations, pyramidal cones, impratio 1, MuJoCo's default soft contact).  At every sample of the scenario (its dt) it records the distance between the shell
centres, the angle between the shells' rotations, the joint angle differences, the energy
difference (each energy from its start) and the speed with which MuJoCo's shell slides on the floor
at the contact.  Writes DIR/summary.json (worst of each per setting, the targets and whether they
hold), DIR/comparison.csv (every sample of every setting) and DIR/comparison.png,
DIR/convergence.png (docs/interop.md, "MuJoCo").

Target (the exported settings at 1 ms): the t-shape within 1e-3 of its path length, the other
runs within 1 mm, at every sample.
"""
import argparse
import csv
import dataclasses
import io
import json
import math
import pathlib
import sys

import numpy as np

from runtime.atomic import write_text
from runtime.model import Model
from runtime.scenario import load_scenario
from runtime.so3 import log
from runtime.state import IDX_Q, IDX_RS, IDX_WS, IDX_WY, IDX_WP, pendulum_angle, rotations, yoke_angle

from . import mjcf

DEFAULT_TIMESTEPS = (2e-3, 1e-3, 5e-4, 2.5e-4)
"""MuJoCo time steps [s] of the sweep with the exported contact settings."""
TARGET_RELATIVE = 1e-3
"""The t-shape's target: the largest distance between the centres over the path's length."""
TARGET_ABSOLUTE = 1e-3
"""The other runs' target: the largest distance between the centres [m]."""
RELATIVE_TARGET_SCENARIOS = ("t-shape",)
"""The scenarios held to TARGET_RELATIVE of their path (a long path); the others to TARGET_ABSOLUTE."""


def settings_sweep(timesteps=DEFAULT_TIMESTEPS):
    """(label, ContactSettings) of the sweep: the exported settings at each time step (their contact
    time constant two steps), then variants of the exported settings at 1 ms."""
    runs = [(f"exported, dt {dt * 1e3:g} ms", mjcf.EXPORTED.replace(timestep=dt, solref=(2 * dt, 1.0)))
            for dt in timesteps]
    base = mjcf.EXPORTED
    runs += [("implicitfast integrator, 1 ms", base.replace(integrator="implicitfast")),
             ("no no-slip iterations, 1 ms", base.replace(noslip_iterations=0)),
             ("pyramidal cones, 1 ms", base.replace(cone="pyramidal")),
             ("impratio 1, 1 ms", base.replace(impratio=1.0)),
             ("MuJoCo's default contact, 1 ms", base.replace(solref=(0.02, 1.0), solimp=(0.9, 0.95, 0.001, 0.5, 2.0),
                                                            friction=1.0, impratio=1.0, noslip_iterations=0))]
    return runs


@dataclasses.dataclass
class Trace:
    """One simulator's run sampled at the scenario's dt: time (n,), centre q (n, 3), shell rotation
    R_S (n, 3, 3), joint angles (n, 2), energy from its start (n,), slip speed at the contact (n,)
    (zero for the kernels, NaN where MuJoCo's shell has left the floor)."""
    time: np.ndarray
    q: np.ndarray
    R_S: np.ndarray
    angles: np.ndarray
    energy: np.ndarray
    slip: np.ndarray


REFERENCE_SUBSTEPS = 10
"""The kernels' steps per sample: RKMK4 at a tenth of the scenario's dt changes by 3e-11 rad on
tilted-pendulum when the step is halved again; at the scenario's dt itself it is 3.6e-7 rad off,
which MuJoCo's finest settings resolve."""


def kernels_trace(scenario):
    """The scenario by the kernels, RKMK4 at a tenth of its dt, sampled at its dt."""
    model = Model(scenario.params)
    fine = scenario.with_overrides(dt=scenario.dt / REFERENCE_SUBSTEPS)
    trajectory = model.simulate(fine.x0, fine.dt, fine.steps, fine.torque_at_step_starts(),
                                method="rkmk4")[::REFERENCE_SUBSTEPS]
    energy = np.array([model.energy(x) for x in trajectory])
    angles = np.stack([yoke_angle(trajectory), pendulum_angle(trajectory)], axis=1)
    return Trace(time=np.arange(len(trajectory)) * scenario.dt, q=trajectory[:, IDX_Q],
                 R_S=rotations(trajectory)[0], angles=angles, energy=energy - energy[0],
                 slip=np.zeros(len(trajectory)))


def load_model(params, contact=mjcf.EXPORTED):
    """The MuJoCo MjModel of the exported MJCF (`mjcf.to_mjcf`)."""
    import mujoco
    return mujoco.MjModel.from_xml_string(mjcf.to_mjcf(params, contact=contact))


def mujoco_state(model, data, params, x):
    """Set MuJoCo's qpos and qvel to the kernels' state x (the rolling velocity of the centre from ω_S)."""
    import mujoco
    R_S = x[IDX_RS].reshape(3, 3)
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, R_S.ravel())
    w_world = R_S @ x[IDX_WS]
    qpos, qvel = np.zeros(model.nq), np.zeros(model.nv)
    qpos[0:3] = x[IDX_Q] - (0.0, 0.0, params.r)     # the slides move the shell from its place at (0, 0, r)
    qpos[3:7] = quat
    qpos[7], qpos[8] = yoke_angle(x), pendulum_angle(x)
    qvel[0:3] = params.r * np.cross(w_world, (0.0, 0.0, 1.0))
    qvel[3:6] = x[IDX_WS]
    qvel[6], qvel[7] = x[IDX_WY], x[IDX_WP]
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(model, data)


def _slip_speed(model, data, shell):
    """The tangential speed of the shell's material point at the contact, relative to the floor [m/s]
    (NaN without contact)."""
    if data.ncon == 0:
        return math.nan
    contact = data.contact[0]
    w = data.xmat[shell].reshape(3, 3) @ data.qvel[3:6]
    v = data.qvel[0:3] + np.cross(w, contact.pos - data.xpos[shell])
    normal = contact.frame[:3]
    return float(np.linalg.norm(v - normal * (normal @ v)))


def mujoco_trace(scenario, contact):
    """The scenario in MuJoCo under `contact`: torques held over each of the scenario's steps, sampled
    at its dt."""
    import mujoco
    params = scenario.params
    model = load_model(params, contact)
    data = mujoco.MjData(model)
    mujoco_state(model, data, params, scenario.x0)
    shell = model.body("shell").id
    substeps = round(scenario.dt / contact.timestep)
    if abs(substeps * contact.timestep - scenario.dt) > 1e-9 * scenario.dt:
        raise ValueError(f"compare-mujoco: MuJoCo's time step {contact.timestep:g} s does not divide the "
                         f"scenario's dt {scenario.dt:g} s")
    gears = np.array([params.n_Y, params.n_P])
    u = scenario.torque_at_step_starts()
    n = scenario.steps + 1
    q, R_S, angles, energy, slip = np.empty((n, 3)), np.empty((n, 3, 3)), np.empty((n, 2)), np.empty(n), np.empty(n)

    def record(k):
        mujoco.mj_forward(model, data)
        q[k], R_S[k] = data.xpos[shell], data.xmat[shell].reshape(3, 3)
        angles[k] = data.qpos[7], data.qpos[8]
        energy[k] = data.energy[0] + data.energy[1]
        slip[k] = _slip_speed(model, data, shell)

    record(0)
    for k in range(scenario.steps):
        data.ctrl[:] = u[k] / gears
        mujoco.mj_step(model, data, nstep=substeps)
        record(k + 1)
    return Trace(time=np.arange(n) * scenario.dt, q=q, R_S=R_S, angles=angles, energy=energy - energy[0],
                 slip=slip)


def _wrapped(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


def differences(ours, theirs):
    """Per sample: position (distance between the centres, m), attitude (angle of R_oursᵀ R_theirs,
    rad), yoke and pendulum angle differences (rad), energy difference (J) and MuJoCo's slip (m/s)."""
    attitude = np.array([np.linalg.norm(log(a.T @ b)) for a, b in zip(ours.R_S, theirs.R_S)])
    return {"position": np.linalg.norm(theirs.q - ours.q, axis=1),
            "attitude": attitude,
            "yoke": np.abs(_wrapped(theirs.angles[:, 0] - ours.angles[:, 0])),
            "pendulum": np.abs(_wrapped(theirs.angles[:, 1] - ours.angles[:, 1])),
            "energy": np.abs(theirs.energy - ours.energy),
            "slip": theirs.slip}


def path_length(trace):
    """The length of the path of the shell's centre [m] (the sum of the sample-to-sample chords)."""
    return float(np.sum(np.linalg.norm(np.diff(trace.q[:, :2], axis=0), axis=1)))


def position_tolerance(name, ours):
    """The target for the largest distance between the centres [m]: 1e-3 of the path for the t-shape,
    1 mm for the others."""
    return TARGET_RELATIVE * path_length(ours) if name in RELATIVE_TARGET_SCENARIOS else TARGET_ABSOLUTE


def _worst(values):
    finite = values[np.isfinite(values)]
    return float(finite.max()) if finite.size else math.nan


def compare(scenario, runs, progress=None):
    """{"ours": Trace, "runs": [(label, ContactSettings, Trace, differences)]} for the sweep `runs`
    ((label, ContactSettings) pairs); `progress` wraps the iteration over the runs (e.g. tqdm)."""
    ours = kernels_trace(scenario)
    results = []
    for label, contact in (progress(runs) if progress else runs):
        theirs = mujoco_trace(scenario, contact)
        results.append((label, contact, theirs, differences(ours, theirs)))
    return {"ours": ours, "runs": results}


def summary(scenario, comparison):
    """The JSON summary: per setting the worst of each difference, the target and whether it holds."""
    ours = comparison["ours"]
    tolerance = position_tolerance(scenario.name, ours)
    rows = []
    for label, contact, theirs, diff in comparison["runs"]:
        worst = {key: _worst(value) for key, value in diff.items()}
        rows.append({"setting": label, "contact": contact.as_json(),
                     "worst": worst, "final_position": float(diff["position"][-1]),
                     "samples_without_contact": int(np.sum(~np.isfinite(theirs.slip))),
                     "position_target_met": bool(np.all(diff["position"] <= tolerance))})
    return {"scenario": scenario.name, "duration_s": scenario.duration, "samples": len(ours.time),
            "path_length_m": path_length(ours), "position_target_m": tolerance,
            "target": ("1e-3 of the path length" if scenario.name in RELATIVE_TARGET_SCENARIOS else "1 mm")
            + " at every sample, exported settings at 1 ms",
            "kernels": f"RKMK4 at the scenario's dt / {REFERENCE_SUBSTEPS}", "settings": rows}


def csv_text(comparison):
    """Every sample of every setting: setting, t, position, attitude, yoke, pendulum, energy, slip."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    keys = ("position", "attitude", "yoke", "pendulum", "energy", "slip")
    writer.writerow(("setting", "t") + tuple(f"{k}_difference" if k != "slip" else "slip_speed" for k in keys))
    time = comparison["ours"].time
    for label, _, _, diff in comparison["runs"]:
        for k, t in enumerate(time):
            writer.writerow((label, f"{t:.6g}") + tuple(f"{diff[key][k]:.6e}" for key in keys))
    return out.getvalue()


def _envelope(time, values, bins=400):
    """(time, values) thinned to at most `bins` points, each the largest value of its stretch of samples
    (the figures show the worst, not an aliased sample of an oscillation)."""
    size = max(1, math.ceil(len(values) / bins))
    count = len(values) // size * size
    if size == 1 or count == 0:
        return time, values
    peaks = np.fmax.reduce(values[:count].reshape(-1, size), axis=1)
    return time[:count].reshape(-1, size)[:, 0], peaks


PLOT_FLOOR = 1e-12
"""The figures' lower limit: a difference below it (rounding, the start) is drawn at it."""


def plot(scenario, comparison, tolerance, path):
    """Position, attitude, energy differences and slip speed over time, one line per setting."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    time = comparison["ours"].time
    panels = (("position", "distance between centres [m]"), ("attitude", "angle between shells [rad]"),
              ("energy", "|energy difference| [J]"), ("slip", "MuJoCo slip speed [m/s]"))
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    for ax, (key, title) in zip(axes.ravel(), panels):
        for label, _, _, diff in comparison["runs"]:
            ax.semilogy(*_envelope(time, np.maximum(diff[key], PLOT_FLOOR)), lw=0.8, label=label)
        if key == "position":
            ax.axhline(tolerance, color="k", ls="--", lw=0.8, label="target")
        ax.set_title(title, fontsize=9)
        ax.set_ylim(bottom=PLOT_FLOOR)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=6.5, loc="lower right")
    fig.suptitle(f"{scenario.name}: MuJoCo (exported MJCF) against the kernels", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def plot_convergence(scenario, comparison, tolerance, path):
    """The worst distance between the centres against MuJoCo's time step (exported settings)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    points = [(c.timestep, _worst(d["position"]), _worst(d["slip"]))
              for label, c, _, d in comparison["runs"] if label.startswith("exported")]
    if not points:
        return
    dt, position, slip = map(np.array, zip(*points))
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.loglog(dt * 1e3, position, "o-", label="worst distance between centres [m]")
    ax.loglog(dt * 1e3, slip, "s-", label="worst slip speed [m/s]")
    ax.axhline(tolerance, color="k", ls="--", lw=0.8, label="target")
    ax.set_xticks(dt * 1e3, [f"{v:g}" for v in dt * 1e3])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("MuJoCo time step [ms] (contact time constant: 2 steps)")
    ax.set_title(f"{scenario.name}: exported settings", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv):
    """`python -m runtime compare-mujoco SCENARIO`: the scenario in both, summary, CSV and figures."""
    parser = argparse.ArgumentParser(prog="python -m runtime compare-mujoco",
                                     description="Run a scenario with the kernels and in MuJoCo (the exported "
                                                 "MJCF) and report their differences.")
    parser.add_argument("scenario", help="a shipped scenario (t-shape, tilted-pendulum, tilted-yoke, ...) or a file")
    parser.add_argument("--out", default=None, help="output folder (default out/mujoco/SCENARIO)")
    parser.add_argument("--timesteps", type=_timesteps, default=DEFAULT_TIMESTEPS,
                        help="MuJoCo time steps [s] of the exported settings, comma-separated "
                             "(default " + ",".join(f"{t:g}" for t in DEFAULT_TIMESTEPS) + ")")
    args = parser.parse_args(argv)
    try:
        scenario = load_scenario(args.scenario)
    except (ValueError, OSError) as exc:
        print(f"compare-mujoco: {exc}", file=sys.stderr)
        return 2
    for dt in args.timesteps:
        if abs(round(scenario.dt / dt) * dt - scenario.dt) > 1e-9 * scenario.dt:
            print(f"compare-mujoco: --timesteps: {dt:g} s does not divide the scenario's dt {scenario.dt:g} s",
                  file=sys.stderr)
            return 2
    out = pathlib.Path(args.out or f"out/mujoco/{scenario.name}")
    from tqdm import tqdm
    try:
        comparison = compare(scenario, settings_sweep(args.timesteps),
                             progress=lambda runs: tqdm(runs, desc=f"MuJoCo settings ({scenario.name})", unit="run"))
        result = summary(scenario, comparison)
        out.mkdir(parents=True, exist_ok=True)
        write_text(out / "summary.json", json.dumps(result, indent=2) + "\n")
        write_text(out / "comparison.csv", csv_text(comparison))
        plot(scenario, comparison, result["position_target_m"], out / "comparison.png")
        plot_convergence(scenario, comparison, result["position_target_m"], out / "convergence.png")
    except (ValueError, OSError) as exc:
        print(f"compare-mujoco: {exc}", file=sys.stderr)
        return 1
    print(f"{scenario.name}: path {result['path_length_m']:.4f} m, target {result['position_target_m']:.3g} m")
    for row in result["settings"]:
        worst = row["worst"]
        print(f"  {row['setting']:<34} position {worst['position']:.3e} m  attitude {worst['attitude']:.3e} rad  "
              f"energy {worst['energy']:.3e} J  slip {worst['slip']:.3e} m/s  "
              f"{'meets' if row['position_target_met'] else 'misses'} the target")
    print(f"written: {out}/summary.json, comparison.csv, comparison.png, convergence.png")
    return 0


def _timesteps(text):
    values = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected comma-separated time steps in s, got {text!r}") from None
        if not (math.isfinite(value) and 0 < value <= 0.01):
            raise argparse.ArgumentTypeError(f"a time step must lie in (0, 0.01] s, got {part!r}")
        values.append(value)
    return tuple(values)
