"""Monte Carlo consistency of the EKF (`python -m runtime consistency`, docs/estimation.md,
"Consistency"): N seeded runs of one scenario or task, each simulated (`simulate_log`) and
estimated (`estimate_log`), on the Dask cluster of the sweeps (runtime.sweep.runner.dask_client).

    runs = [run_once("circle", "default", seed) for seed in range(5)]
    report = consistency(runs)            # average NEES against its band, 3-sigma shares, drifts

Errors are compared in physical components (COMPONENTS): the IMU body's attitude error in the
inertial frame (tilt about the floor's x and y axes, heading about its normal), then the joints,
the position, the speeds and the biases.  They are a linear change of the filter's error
coordinates (`transform`), so the NEES over all 18 is the filter's own.  With position fixes or a
heading every component is observable and the NEES runs over all of them; without, over the
observable ones (OBSERVABLE: tilt, joint angles, speeds), while the unobservable heading and
position are checked for a σ that grows as their error does (`drift`).
"""
import dataclasses
import math

import numpy as np
from scipy.stats import chi2

from ..model import Model
from ..sensor_sim import ACCEL_AXES
from .estimate import SETTLE_S, claimed_params, errors, estimate_log, start_heading

#: The compared components, in the order of the filter's error state (ERROR_NAMES) with the
#: shell's attitude error replaced by the IMU body's, in the inertial frame.
COMPONENTS = ("tilt_x", "tilt_y", "heading", "theta_Y", "theta_P", "q_x", "q_y", "w_S_x", "w_S_y", "w_S_z",
              "w_Y", "w_P", "b_g_x", "b_g_y", "b_g_z", "b_a_x", "b_a_y", "b_a_z")
#: What the IMU and the encoders alone make observable.
OBSERVABLE = ("tilt_x", "tilt_y", "theta_Y", "theta_P", "w_S_x", "w_S_y", "w_S_z", "w_Y", "w_P")
#: What drifts without fixes or a heading sensor.
UNOBSERVABLE = ("heading", "q_x", "q_y")
#: The spread of the operator's start heading about the truth's [rad]: the start rule's σ.
START_HEADING_SIGMA = math.radians(10.0)
#: Compared every this many filter rows (20 rows of 5 ms: every 0.1 s).
EVERY = 20
#: `--constrained`: the filter's observability constraint (None: on without fixes and heading).
CONSTRAINED = {"auto": None, "on": True, "off": False}
#: The targets: the share of samples whose average NEES lies in its band, of errors within ±3σ.
NEES_TARGET, WITHIN_TARGET, BAND = 0.90, 0.99, 0.95


def transform(x, body):
    """T (m, 18, 18) with T e the physical components (COMPONENTS) of the filter's errors e at the
    estimates x (m, 35), for an IMU on `body`: the truth's attitude is R_S Exp(ξ) = Exp(R_S ξ) R_S,
    and a joint's error δθ turns the bodies beyond it about the joint's axis in the inertial frame."""
    from ..state import IDX_RS, IDX_RY
    m = len(x)
    T = np.tile(np.eye(18), (m, 1, 1))
    R_S = x[:, IDX_RS].reshape(m, 3, 3)
    T[:, :3, :3] = R_S
    if body in ("yoke", "pendulum"):
        T[:, :3, 3] = R_S[:, :, 0]                                 # R_S e_x: the yoke's hinge
    if body == "pendulum":
        R_Y = x[:, IDX_RY].reshape(m, 3, 3)
        T[:, :3, 4] = np.einsum("nij,nj->ni", R_S, R_Y[:, :, 1])   # R_S R_Y e_y: the pendulum's
    return T


def nees(e, P):
    """The normalised estimation error squared eᵀ P⁻¹ e per sample: e (m, n), P (m, n, n)."""
    L = np.linalg.cholesky(P)
    z = np.linalg.solve(L, e[..., None])[..., 0]
    return np.sum(z * z, axis=-1)


def nees_band(dims, runs, probability=BAND):
    """The `probability` band of the average NEES of `runs` independent runs over `dims` components:
    runs × the average is chi-square with runs·dims degrees of freedom."""
    tail = (1 - probability) / 2
    return (float(chi2.ppf(tail, runs * dims)) / runs, float(chi2.ppf(1 - tail, runs * dims)) / runs)


def load_task(run, duration=None):
    """The scenario or task `run` (a path, or one already loaded), its first `duration` [s] when given."""
    from ..scenario import Scenario
    from .sense import load_run
    task = load_run(run) if isinstance(run, str) else run
    if duration is not None:
        scenario = task if isinstance(task, Scenario) else task.scenario
        short = scenario.with_overrides(steps=max(1, round(duration / scenario.dt)))
        task = short if isinstance(task, Scenario) else dataclasses.replace(task, scenario=short)
    return task


def run_once(run, sensors, seed, duration=None, plant_mismatch=False, every=EVERY, accel_noise="held",
             constrained=None, make_filter=None):
    """One Monte Carlo run: the sensors `sensors` (a SensorSet, a shipped set's name or a file)
    simulated along `run` (a shipped scenario or task name, a file, or the object) with `seed`,
    the filter over the log (accelerometer rule `accel_noise`, observability constraint `constrained`
    (None: `estimate_log`'s rule), `estimate_log`), started from the truth's
    heading off by a seeded N(0, 10°) draw.  Returns {"seed", "t" (m,), "e" (m, 18), "P" (m, 18, 18) (COMPONENTS,
    from SETTLE_S on), "metrics" (`errors`), "counters", "fixes" (whether the set has fixes or a
    heading)}.  With `make_filter` (`estimate_log`'s, None: the C filter) also "T" (m, 18, 18), the
    filter's errors to the components, and "scored", the indices of the scored rows among the rows
    whose covariance was read."""
    from ..sensor_set import SensorSet, load_sensor_set
    from .sense import simulate_log
    task = load_task(run, duration)
    sensors = sensors if sensors is None or isinstance(sensors, SensorSet) else load_sensor_set(sensors)
    log = simulate_log(task, sensors, seed=seed, plant_mismatch=plant_mismatch)
    return run_log(log, seed, every=every, accel_noise=accel_noise, constrained=constrained, make_filter=make_filter)


def run_log(log, seed, every=EVERY, accel_noise="held", constrained=None, make_filter=None):
    """`run_once` over a log already simulated (with its truth) by the run seeded `seed`."""
    # The operator's heading at the start is the truth's off by a draw of the σ the start rule
    # assumes: started at the truth's, the filter would look conservative in heading by design.
    heading = start_heading(log) + np.random.default_rng([seed, 1]).normal(0.0, START_HEADING_SIGMA)
    options = {} if make_filter is None else {"make_filter": make_filter}
    result = estimate_log(log, heading=heading, covariance_every=every, accel_noise=accel_noise,
                          constrained=constrained, **options)
    model = Model(claimed_params(log))
    rows = result.P_rows
    start = min(SETTLE_S, result.t[-1] / 2)
    i = np.clip(np.searchsorted(log.truth.t, result.t[rows]), 0, len(log.truth.t) - 1)
    keep = (np.abs(log.truth.t[i] - result.t[rows]) < 1e-9) & (result.t[rows] >= start)
    rows, i = rows[keep], i[keep]
    x = result.x[rows]
    d = model.local(x, log.truth_states()[i])
    db = log.truth_biases()[i] - result.biases[rows]
    T = transform(x, log.sensors.imu.mount.body)
    e = np.einsum("nij,nj->ni", T, np.column_stack([d, db]))
    P = T @ result.P[keep] @ np.transpose(T, (0, 2, 1))
    out = {"seed": int(seed), "t": result.t[rows], "e": e, "P": P, "metrics": errors(log, result),
           "counters": result.counters,
           "fixes": log.sensors.fixes is not None or log.sensors.heading is not None}
    if make_filter is not None:
        out["T"], out["scored"] = T, np.flatnonzero(keep)
    return out


def drift(e, sigma):
    """Per unobservable component: whether the filter's σ follows its error across the runs: the
    RMS error over the runs and the RMS σ at the first and the last sample, and the ratio
    error / σ at each sample (its median and range)."""
    err = np.sqrt(np.mean(e ** 2, axis=0))
    sig = np.sqrt(np.mean(sigma ** 2, axis=0))
    ratio = err / sig
    return {"error_first": float(err[0]), "error_last": float(err[-1]), "sigma_first": float(sig[0]),
            "sigma_last": float(sig[-1]), "ratio_median": float(np.median(ratio)),
            "ratio_min": float(ratio.min()), "ratio_max": float(ratio.max())}


def consistency(runs, components=None):
    """The consistency of `runs` (`run_once`'s results, one time grid): the average NEES over the
    `components` (None: every COMPONENT when the runs have fixes, else OBSERVABLE) per sample against
    its BAND, the share of samples in it (and the same over the robot's state alone, without the
    biases: "state"), the share of errors within ±3σ per component, and,
    without fixes, the `drift` of the UNOBSERVABLE ones.  Returns {"t", "anees" (arrays), "band",
    "inside", "within_3_sigma", "drift", "components", "passes"}."""
    if not runs:
        raise ValueError("runs: expected at least one run")
    n = min(len(r["t"]) for r in runs)
    if n == 0:
        raise ValueError("runs: no sample after the settling time")
    fixes = all(r["fixes"] for r in runs)
    components = tuple(components) if components is not None else (COMPONENTS if fixes else OBSERVABLE)
    unknown = [c for c in components if c not in COMPONENTS]
    if unknown:
        raise ValueError(f"components: unknown {', '.join(unknown)} (known: {', '.join(COMPONENTS)})")
    idx = [COMPONENTS.index(c) for c in components]
    e = np.stack([r["e"][:n] for r in runs])                       # (runs, n, 18)
    P = np.stack([r["P"][:n] for r in runs])
    sigma = np.sqrt(np.diagonal(P, axis1=-2, axis2=-1))
    sub = P[..., idx, :][..., :, idx]
    anees = nees(e[..., idx], sub).mean(axis=0)
    low, high = nees_band(len(idx), len(runs))
    inside = float(np.mean((anees >= low) & (anees <= high)))
    within = {c: float(np.mean(np.abs(e[..., k]) <= 3 * sigma[..., k])) for k, c in enumerate(COMPONENTS)}
    state = [k for k in idx if k < 12]                             # the robot's state, without the biases
    state_anees = nees(e[..., state], P[..., state, :][..., :, state]).mean(axis=0)
    state_low, state_high = nees_band(len(state), len(runs))
    report = {"t": runs[0]["t"][:n], "anees": anees, "band": (low, high), "dims": len(idx),
              "runs": len(runs), "components": list(components), "inside": inside,
              "state": {"dims": len(state), "band": [state_low, state_high], "mean": float(state_anees.mean()),
                        "inside": float(np.mean((state_anees >= state_low) & (state_anees <= state_high)))},
              "within_3_sigma": within, "fixes": fixes, "drift": None}
    passes = inside >= NEES_TARGET and all(within[c] >= WITHIN_TARGET for c in components)
    if not fixes:
        report["drift"] = {c: drift(e[..., COMPONENTS.index(c)], sigma[..., COMPONENTS.index(c)])
                           for c in UNOBSERVABLE}
    report["passes"] = bool(passes)
    report["_e"], report["_sigma"] = e, sigma
    return report


#: The accuracy metrics of `errors` the targets name, and the targets with / without fixes.
METRICS = ("position_rms_m", "heading_rms_deg", "tilt_rms_deg", "forward_speed_rms_m_s")
TARGETS = {True: {"position_rms_m": 0.01, "heading_rms_deg": 1.0, "tilt_rms_deg": 0.3,
                  "forward_speed_rms_m_s": 0.01},
           False: {"tilt_rms_deg": 0.5, "forward_speed_rms_m_s": 0.02}}


def accuracy(runs):
    """The accuracy metrics over the runs: per metric the mean and the worst run's RMS, and whether
    the worst meets its target (with or without fixes)."""
    fixes = all(r["fixes"] for r in runs)
    out = {}
    for name in METRICS:
        values = np.array([r["metrics"][name] for r in runs])
        target = TARGETS[fixes].get(name)
        out[name] = {"mean": float(values.mean()), "worst": float(values.max()), "target": target,
                     "meets": None if target is None else bool(values.max() <= target)}
    return out


def figure(report, path, title):
    """consistency.png: the average NEES with its band, and the errors of every run with the ±3σ
    envelope (the RMS σ over the runs) of the tilt, the heading, a position and the forward-axis
    shell rate."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shown = ("tilt_x", "heading", "q_x", "w_S_x")
    fig, axes = plt.subplots(1 + len(shown), 1, figsize=(8, 2.0 * (1 + len(shown))), sharex=True)
    t = report["t"]
    low, high = report["band"]
    axes[0].plot(t, report["anees"], lw=0.8, label=f"average NEES ({report['runs']} runs, {report['dims']} components)")
    axes[0].axhspan(low, high, color="tab:green", alpha=0.2, label=f"{BAND:.0%} band")
    axes[0].set_yscale("log")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[0].set_title(title, fontsize=10)
    e, sigma = report["_e"], report["_sigma"]
    for ax, name in zip(axes[1:], shown):
        k = COMPONENTS.index(name)
        ax.plot(t, e[..., k].T, lw=0.4, color="tab:blue", alpha=0.4)
        s = 3 * np.sqrt(np.mean(sigma[..., k] ** 2, axis=0))
        ax.plot(t, s, "k--", lw=1, label="±3σ (RMS over the runs)")
        ax.plot(t, -s, "k--", lw=1)
        ax.set_ylabel(name + (" (rad)" if name in ("tilt_x", "heading") else " (m)" if name == "q_x" else " (rad/s)"))
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def summary(report, accuracy_table, meta):
    """summary.json's content: the run's description, the NEES result, the 3σ shares, the drifts,
    the accuracy."""
    return {**meta, "runs": report["runs"], "components": report["components"], "dims": report["dims"],
            "scored_from_s": float(report["t"][0]), "samples_per_run": int(len(report["t"])),
            "nees_band": list(report["band"]), "nees_mean": float(np.mean(report["anees"])),
            "nees_inside_band": report["inside"], "nees_target": NEES_TARGET, "nees_state": report["state"],
            "within_3_sigma": report["within_3_sigma"], "within_target": WITHIN_TARGET,
            "drift": report["drift"], "consistent": report["passes"], "accuracy": accuracy_table}


def run_many(run, sensors, seeds, duration=None, plant_mismatch=False, scheduler=None, workers=None,
             progress=True, accel_noise="held", constrained=None):
    """`run_once` for every seed: on an embedded LocalCluster of `workers` processes (scheduler
    None), a Dask scheduler's address, or in this process ("serial"); with a tqdm bar.  The
    results in the seeds' order."""
    from tqdm.auto import tqdm

    from ..sweep.runner import SERIAL, dask_client
    out = {}
    with tqdm(total=len(seeds), unit="run", desc="consistency", disable=not progress or None) as bar:
        if scheduler == SERIAL:
            for seed in seeds:
                out[seed] = run_once(run, sensors, seed, duration, plant_mismatch, accel_noise=accel_noise,
                                     constrained=constrained)
                bar.update(1)
        else:
            from distributed import as_completed
            with dask_client(scheduler, workers) as client:
                futures = {client.submit(run_once, run, sensors, seed, duration, plant_mismatch, EVERY, accel_noise,
                                         constrained, pure=False): seed
                           for seed in seeds}
                for future in as_completed(futures):
                    out[futures[future]] = future.result()
                    future.release()
                    bar.update(1)
    return [out[s] for s in seeds]


def sample_table(runs):
    """The samples of every run as columns: seed, t, nees over every component, e_<c>, sigma_<c>."""
    import pyarrow as pa
    cols = {"seed": np.concatenate([np.full(len(r["t"]), r["seed"]) for r in runs]),
            "t": np.concatenate([r["t"] for r in runs]),
            "nees": np.concatenate([nees(r["e"], r["P"]) for r in runs])}
    e = np.concatenate([r["e"] for r in runs])
    s = np.concatenate([np.sqrt(np.diagonal(r["P"], axis1=-2, axis2=-1)) for r in runs])
    cols.update({f"e_{c}": e[:, k] for k, c in enumerate(COMPONENTS)})
    cols.update({f"sigma_{c}": s[:, k] for k, c in enumerate(COMPONENTS)})
    return pa.table(cols)


# -- python -m runtime consistency -------------------------------------------------------------------
def build_parser():
    """The argument parser of `python -m runtime consistency`."""
    import argparse
    import pathlib

    from ..cli_types import duration, whole_number as whole

    parser = argparse.ArgumentParser(
        prog="python -m runtime consistency",
        description="Monte Carlo consistency of the EKF: RUNS seeded sense + estimate runs of a scenario or "
                    "task on Dask; writes samples.parquet, runs.csv, nees.csv, consistency.png and "
                    "summary.json into OUT (docs/estimation.md).")
    parser.add_argument("run", metavar="SCENARIO|TASK", help="a shipped scenario or task, or a .toml file")
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the output folder (created if missing)")
    parser.add_argument("--runs", type=whole(2), default=50, help="number of seeded runs (default 50)")
    parser.add_argument("--first-seed", type=whole(0), default=0, help="seeds first-seed, first-seed + 1, ...")
    parser.add_argument("--sensors", metavar="FILE", default="default",
                        help="a sensors file or shipped set (default: 'default')")
    parser.add_argument("--duration", type=duration, help="simulate only this long [s]")
    parser.add_argument("--plant-mismatch", action="store_true",
                        help="the truth's robot 10 %% heavier with 20 %% less damping")
    parser.add_argument("--accel-noise", choices=ACCEL_AXES, default="held",
                        help="the filter's accelerometer noise rule (runtime.sensor_sim.ekf_noise; 'held', the "
                             "default: the torque disturbance the accelerometer reads modelled; 'largest', "
                             "'each': its share of the reading in the accelerometer's sigma)")
    parser.add_argument("--constrained", choices=CONSTRAINED, default="auto",
                        help="the filter's observability constraint (OC-EKF: heading and position kept "
                             "unobservable by the IMU and the encoders; docs/estimation.md); default 'auto': on "
                             "when the sensor set has neither fixes nor a heading")
    parser.add_argument("--scheduler", help="a Dask scheduler's address, or 'serial' (default: an embedded "
                                            "LocalCluster)")
    parser.add_argument("--workers", type=whole(1), help="worker processes of the embedded cluster (default: cores)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, print nothing but errors")
    return parser


def main(argv):
    """`python -m runtime consistency`: exit status 0 when consistent, 1 when not, 2 on a bad argument."""
    import csv
    import io
    import json
    import sys

    import pyarrow.parquet as pq

    from ..atomic import atomic_path, write_text
    from ..errors import KernelError
    from ..sensor_set import load_sensor_set
    from ..sweep.runner import SERIAL, scheduler_address
    from .sense import load_run
    args = build_parser().parse_args(argv)
    try:
        if args.out.exists() and not args.out.is_dir():
            raise ValueError(f"{args.out}: is a file, expected a folder")
        if args.scheduler is not None and args.scheduler != SERIAL:
            try:
                scheduler_address(args.scheduler)
            except ValueError as exc:
                raise ValueError(f"--scheduler: {exc}") from None
        load_run(args.run)
        sensors = load_sensor_set(args.sensors)
        seeds = list(range(args.first_seed, args.first_seed + args.runs))
        try:
            runs = run_many(args.run, sensors, seeds, args.duration, args.plant_mismatch, args.scheduler,
                            args.workers, progress=not args.quiet, accel_noise=args.accel_noise,
                            constrained=CONSTRAINED[args.constrained])
        except KernelError as exc:
            raise ValueError(f"{args.run}: a run failed: {exc}") from None
        report = consistency(runs)
        table = accuracy(runs)
        args.out.mkdir(parents=True, exist_ok=True)
        with atomic_path(args.out / "samples.parquet") as path:
            pq.write_table(sample_table(runs), path)
        text = io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        kinds = ("imu", "encoders", "position")
        writer.writerow(["seed", *METRICS, *(f"gated_{k}" for k in kinds), *(f"recovered_{k}" for k in kinds)])
        for r in runs:
            c = r["counters"]
            writer.writerow([r["seed"], *(repr(r["metrics"][m]) for m in METRICS), *(c[k]["gated"] for k in kinds),
                             *(c[k]["recovered"] for k in kinds)])
        write_text(args.out / "runs.csv", text.getvalue())
        low, high = report["band"]
        write_text(args.out / "nees.csv", "t,anees,low,high\n" + "".join(
            f"{t!r},{a!r},{low!r},{high!r}\n" for t, a in zip(report["t"].tolist(), report["anees"].tolist())))
        title = (f"{args.run}, {args.sensors}{', plant mismatch' if args.plant_mismatch else ''}: "
                 f"{report['inside']:.0%} of samples in the band")
        with atomic_path(args.out / "consistency.png") as path:
            figure(report, path, title)
        meta = {"run": args.run, "sensors": args.sensors, "accel_noise": args.accel_noise,
                "constrained": args.constrained, "seeds": [seeds[0], seeds[-1]],
                "duration_s": args.duration, "plant_mismatch": args.plant_mismatch}
        result = summary(report, table, meta)
        write_text(args.out / "summary.json", json.dumps(result, indent=2) + "\n")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (ConnectionError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if not args.quiet:
        print(json.dumps({k: result[k] for k in ("runs", "dims", "nees_band", "nees_mean", "nees_inside_band",
                                                 "nees_state", "within_3_sigma", "drift", "consistent", "accuracy")}, indent=2))
    return 0 if result["consistent"] else 1
