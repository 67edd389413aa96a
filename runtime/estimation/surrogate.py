"""The linear surrogate of a consistency run (`python -m runtime surrogate`, docs/estimation.md,
"Consistency"): a Kalman filter consistent by construction with the EKF's own slow modes.

The NumPy reference of the filter (runtime/verification/ekf_reference.py) is run over one seeded
sense run exactly as `estimate_log` runs the C filter, and records every linear map of its
(augmented) error and every noise it assumes: the predicts' F and Q, the updates' I − K H and
K R Kᵀ (the gates' decisions included: a refused sample maps nothing), the resets, the clones of
late fixes, the held disturbance's block.  Those maps are then driven with exactly those noises
from a start drawn from the filter's P0: each draw is the error of a linear-Gaussian truth whose
model, noises and gains are the filter's, so its covariance is the filter's P at every step, and
`consistency` scores blocks of such draws as it scores the runs.  The share of samples in the
band per block is then the statistic's own spread for this filter's error correlations over time.

    rec = record_run("line", "default", seed=0)
    e = simulate(rec, runs=1000, seed=1)          # (1000, m, 18) physical components
    blocks = block_statistics(rec, e, block=50)   # per block of 50: share in band, ±3σ shares

The same maps driven by the truth's own draws (`driven`), source by source and by the filter's
model of each source (`sources`, `trace`: `python -m runtime surrogate line --trace 50`), say which
of the truth's draws loads a component and whether it differs from what the filter assumes.
"""
import argparse
import json
import sys

import numpy as np

from ..ekf import RECOVER_AFTER, start_from_measurements
from ..model import Model
from ..state import IDX_E_NU, NE
from ..verification.ekf_reference import NB, EkfReference
from .consistency import COMPONENTS, NEES_TARGET, WITHIN_TARGET, consistency, run_log, run_once


class RecordingReference(EkfReference):
    """The reference that keeps its error's linear maps and noises (`ops`): ("map", rows, cols, M)
    for e[rows] ← M e[cols] (the other entries kept), ("resize", index) for e ← e[index] with −1 a
    new zero entry, ("noise", rows, L, context, gain) for e[rows] += L z, z standard normal (an
    update's noise −K v with K its `gain`; `context` what the filter was doing, set by its user),
    and ("sample",) each time P is read."""

    def __init__(self, *args, **kwargs):
        self.ops, self.context = [], None
        super().__init__(*args, **kwargs)

    def linear(self, T):
        """Records e ← T e: a resize (T not square) or the rows T changes, on the columns they read."""
        n_new, n_old = T.shape
        if n_new != n_old:
            unit = np.abs(T).sum(axis=1) > 0
            self.ops.append(("resize", np.where(unit, np.argmax(T, axis=1), -1)))
            return
        rows = np.flatnonzero(np.any(T != np.eye(n_old), axis=1))
        if len(rows):
            cols = np.flatnonzero(np.any(T[rows] != 0, axis=0))
            self.ops.append(("map", rows, cols, T[np.ix_(rows, cols)].copy()))

    def noise(self, rows, C, gain=None):
        """Records a noise of covariance C on `rows` as a factor L (C = L Lᵀ), with its context and gain."""
        w, V = np.linalg.eigh(0.5 * (C + C.T))
        keep = w > 1e-14 * max(w.max(), 1e-300)
        self.ops.append(("noise", np.asarray(rows), V[:, keep] * np.sqrt(w[keep]), self.context, gain))


class ReferenceFilter:
    """`Ekf`'s methods over a RecordingReference started where an `Ekf` starts (its x, biases, P,
    noise, mount, gates, method, constraint and recovery policy)."""

    def __init__(self, ekf):
        self.ekf, n = ekf, ekf.noise
        self.ref = RecordingReference(ekf.model, ekf.x, ekf.biases, ekf.P, method=ekf.method,
                                      recover_after=ekf.recover_after, constrained=ekf.constrained)
        self.psd = (n.torque_psd,) * 3
        self.t, self.count = 0.0, {}
        self.imu_sigma = np.array([n.gyro] * 3 + list(n.accel))

    def _at(self, kind, sigma):
        """Sets the reference's context: (kind, the sample's index among its kind's, time, the
        standard deviations of its readings the filter assumes)."""
        i = self.count.get(kind, 0)
        self.count[kind] = i + 1
        self.ref.context = (kind, i, self.t, np.asarray(sigma, dtype=float))

    def predict(self, u, dt):
        """`Ekf.predict`."""
        n = self.ekf.noise
        white = dt - (min(dt, self.ref.held_remaining) if self.ref.held is not None else 0.0)
        self.ref.context = ("predict", self.t, self.t + dt, white)
        self.ref.predict(u, dt, self.psd, n.gyro_bias_rw, n.accel_bias_rw)
        self.t += dt

    def update_imu(self, y, u):
        """`Ekf.update_imu`: the held update when the noise holds the disturbance, else per axis."""
        n, gate = self.ekf.noise, self.ekf.gate["imu"]
        self._at("imu", self.imu_sigma)
        if n.torque_hold > 0:
            return self.ref.update_imu_held(y, u, self.ekf.mount, self.imu_sigma, self.psd, n.torque_hold, gate)
        return self.ref.update_imu(y, u, self.ekf.mount, n.gyro, n.accel, gate)

    def update_encoders(self, y):
        """`Ekf.update_encoders`."""
        self._at("encoders", [self.ekf.noise.encoder] * 2)
        return self.ref.update_encoders(y, self.ekf.noise.encoder, self.ekf.gate["encoders"])

    def update_position(self, y):
        """`Ekf.update_position`."""
        self._at("position", [self.ekf.noise.position] * 2)
        return self.ref.update_position(y, self.ekf.noise.position, self.ekf.gate["position"])

    def mark_position(self, slot):
        """`Ekf.mark_position`."""
        self.ref.mark_position(slot)

    def update_position_delayed(self, slot, y):
        """`Ekf.update_position_delayed`."""
        self._at("position", [self.ekf.noise.position] * 2)
        return self.ref.update_position_delayed(slot, y, self.ekf.noise.position, self.ekf.gate["position"])

    def update_heading(self, y):
        """`Ekf.update_heading`."""
        self._at("heading", [self.ekf.noise.heading])
        return self.ref.update_heading(y, self.ekf.heading_mount, self.ekf.noise.heading, self.ekf.gate["heading"])

    @property
    def x(self):
        """The state (35,)."""
        return self.ref.x.copy()

    @property
    def biases(self):
        """The biases (6,)."""
        return self.ref.b.copy()

    @property
    def P(self):
        """The covariance (18, 18); reading it marks a sample in the recorded maps."""
        self.ref.ops.append(("sample",))
        return self.ref.P

    @property
    def sigma(self):
        """The error state's standard deviations (18,)."""
        return np.sqrt(np.diag(self.ref.P))

    @property
    def counters(self):
        """`Ekf.counters`: per kind accepted, gated, recovered and the last NIS."""
        r = self.ref
        return {k: {"accepted": r.accepted[k], "gated": r.gated[k], "recovered": r.recovered[k], "nis": r.nis[k]}
                for k in r.accepted}


def _reference_start(model, **kwargs):
    return ReferenceFilter(start_from_measurements(model, recover_after=RECOVER_AFTER, **kwargs))


def record_run(run, sensors, seed, duration=None, accel_noise="held", log=None):
    """One consistency run (`run_once`'s) with the NumPy reference as the filter: its result
    ({"t", "e", "P", ...}, the components from SETTLE_S on) and the recorded "ops", "P0" (18, 18),
    "T" (m, 18, 18: the filter's errors to the physical components at the scored samples),
    "scored" (the indices of the scored samples among the "sample" ops), the start "x0", "b0".
    `log`: the run's log already simulated (`run_log`; `run`, `sensors` and `duration` unused)."""
    recorded = {}

    def make_filter(model, **kwargs):
        f = _reference_start(model, **kwargs)
        recorded["filter"] = f
        return f

    if log is None:
        result = run_once(run, sensors, seed, duration=duration, accel_noise=accel_noise, make_filter=make_filter)
    else:
        result = run_log(log, seed, accel_noise=accel_noise, make_filter=make_filter)
    f = recorded["filter"]
    result["ops"], result["P0"], result["x0"], result["b0"] = f.ref.ops, f.ekf.P, f.ekf.x, f.ekf.biases
    return result


def simulate(rec, runs, seed):
    """`runs` draws of the linear-Gaussian truth of the recorded filter: the error starts from
    N(0, P0), moves by the recorded maps and receives the recorded noises; its current block at the
    scored samples in the physical components (runs, m, 18)."""
    rng = np.random.default_rng(seed)
    e = rng.standard_normal((runs, NB)) @ np.linalg.cholesky(rec["P0"]).T
    samples = []
    for op in rec["ops"]:
        kind = op[0]
        if kind == "map":
            _, rows, cols, M = op
            e[:, rows] = e[:, cols] @ M.T
        elif kind == "noise":
            rows, L = op[1], op[2]
            e[:, rows] += rng.standard_normal((runs, L.shape[1])) @ L.T
        elif kind == "resize":
            index = op[1]
            e = np.where(index >= 0, e[:, np.maximum(index, 0)], 0.0)
        else:
            samples.append(e[:, :NB].copy())
    d = np.stack(samples, axis=1)[:, rec["scored"]]
    return np.einsum("mij,rmj->rmi", rec["T"], d)


def simulated_log(run, sensors, seed, duration=None):
    """The log (with its truth) of `record_run`'s run."""
    from .consistency import load_task
    from .sense import simulate_log
    from ..sensor_set import SensorSet, load_sensor_set
    sensors = sensors if sensors is None or isinstance(sensors, SensorSet) else load_sensor_set(sensors)
    return simulate_log(load_task(run, duration), sensors, seed=seed)


def truth_draws(run, sensors, seed, duration=None, log=None):
    """What the truth of `record_run`'s run drew, as the filter's linear model takes it: per sample
    the measurement noise (reading less the noiseless reading of the truth, so the encoders'
    quantisation too) by kind ("imu", "encoders", "position", "heading"), the torque disturbance's acceleration M⁻¹ w per step ("a"), the
    biases per step ("b"), the step ("dt"), the truth's start ("x0"; "model" the truth's robot).
    `log`: the run's log (`simulated_log`) when already simulated."""
    import math
    from ..sensor_sim import random_streams
    from .. import sensors as readings
    from .estimate import claimed_params
    log = simulated_log(run, sensors, seed, duration) if log is None else log
    model = Model(claimed_params(log))
    xs, bs, dt, spec = log.truth_states(), log.truth_biases(), float(log.meta["dt"]), log.sensors
    stream = random_streams(seed)["process"]
    q_std = spec.process.generalized() / math.sqrt(dt)
    a = np.array([np.linalg.solve(model.inertia(xs[k]), stream.normal(0.0, 1.0, 5) * q_std)
                  for k in range(len(xs) - 1)])

    def step(t):
        return int(round(t / dt))

    imu = [log.imu.data[i] - readings.imu(model, xs[step(t)], model.accel(xs[step(t)], log.torque_at(t))
                                          + (a[step(t)] if step(t) < len(a) else 0.0),
                                          mount=spec.imu.mount, bias=bs[step(t)])
           for i, t in enumerate(log.imu.t)]
    out = {"imu": np.array(imu), "a": a, "b": bs, "dt": dt, "x0": xs[0], "model": model,
           "encoders": np.array([log.encoders.data[i] - readings.encoders(model, xs[step(t)])
                                 for i, t in enumerate(log.encoders.t)])}
    if log.fixes is not None and len(log.fixes):
        out["position"] = np.array([log.fixes.select("x", "y")[i] - readings.position(model, xs[step(t)])
                                    for i, t in enumerate(log.fixes["t_measured"])])
    if log.heading is not None and len(log.heading):
        out["heading"] = np.array([[math.remainder(log.heading.data[i][0] - readings.heading(
            model, xs[step(t)], spec.imu.mount), 2 * math.pi)] for i, t in enumerate(log.heading.t)])
    return out


#: The truth's draws, source by source (`sources`): the start error, the gyroscope's noise, each
#: accelerometer axis's noise, the encoders' quantisation, the fixes' and the heading's noise, the
#: torque disturbance (M⁻¹ w: held over a step, and over the part of a step no held a covers), the
#: biases' walk.
SOURCES = ("start", "gyro", "accel_x", "accel_y", "accel_z", "encoders", "position", "heading", "torque", "bias")
#: Each update kind's reading columns by source.
_READINGS = {"imu": (("gyro", [0, 1, 2]), ("accel_x", [3]), ("accel_y", [4]), ("accel_z", [5])),
             "encoders": (("encoders", [0, 1]),), "position": (("position", [0, 1]),), "heading": (("heading", [0]),)}


def sources(rec, draws, model_draws=0, seed=0):
    """The recorded linear system driven one source at a time (SOURCES): by the truth's own draw of
    it (`truth_draws`) and by `model_draws` draws of the filter's model of it (the start from
    N(0, P0), an update's noise −K v with v ~ N(0, λ diag(σ²)) of the σ the filter assumed, λ a
    recovery's, the held disturbance's prior, the predicts' Q: its torque block and its biases'
    block).  Returns (S, 1 + model_draws, m, 18), the own draw first, in the physical components at
    the scored samples: the linear system is linear, so the sum over the sources of the own draws
    is `driven`, and a source whose truth is the filter's model has its own draw's error² / σ²
    spread as its model draws'."""
    rng = np.random.default_rng(seed)
    dt, model, k = draws["dt"], draws["model"], 1 + model_draws
    at = {name: i for i, name in enumerate(SOURCES)}
    e = np.zeros((len(SOURCES), k, NB))
    e[at["start"], 0] = np.concatenate([model.local(rec["x0"], draws["x0"]), draws["b"][0] - rec["b0"]])
    e[at["start"], 1:] = rng.standard_normal((model_draws, NB)) @ np.linalg.cholesky(rec["P0"]).T
    nu, bias = np.r_[IDX_E_NU], np.r_[NE:NB]
    samples = []
    for op in rec["ops"]:
        if op[0] == "map":
            _, rows, cols, M = op
            e[:, :, rows] = e[:, :, cols] @ M.T
        elif op[0] == "resize":
            e = np.where(op[1] >= 0, e[:, :, np.maximum(op[1], 0)], 0.0)
        elif op[0] == "noise":
            _, rows, L, context, gain = op
            if context[0] == "predict":          # rows 0 … NB − 1: Q is block-diagonal, torque and biases
                k0, k1 = int(round(context[1] / dt)), int(round(context[2] / dt))
                z = rng.standard_normal((model_draws, L.shape[1])) @ L.T
                e[at["bias"]][0, bias] += draws["b"][k1] - draws["b"][k0]
                e[at["bias"]][1:, bias] += z[:, bias]
                if k0 < len(draws["a"]):         # the part of the step no held disturbance covers
                    e[at["torque"]][0, nu] += draws["a"][k0] * context[3]
                e[at["torque"]][1:, nu] += z[:, nu]
            elif gain is None:                   # the held disturbance's prior
                i = int(round(context[2] / dt))
                e[at["torque"]][0, rows] += draws["a"][i] if i < len(draws["a"]) else 0.0
                e[at["torque"]][1:, rows] += rng.standard_normal((model_draws, L.shape[1])) @ L.T
            else:
                kind, sigma = context[0], context[3]
                lam = np.sum(L * L) / np.sum((gain * sigma) ** 2)    # a recovery's λ R, else 1
                v = rng.standard_normal((model_draws, len(sigma))) * sigma * np.sqrt(lam)
                for name, cols in _READINGS[kind]:
                    e[at[name]][0, rows] -= gain[:, cols] @ draws[kind][context[1]][cols]
                    e[at[name]][1:, rows] -= v[:, cols] @ gain[:, cols].T
        else:
            samples.append(e[:, :, :NB].copy())
    d = np.stack(samples, axis=2)[:, :, rec["scored"]]
    return np.einsum("mij,skmj->skmi", rec["T"], d)


def redrawn_imu(log, draws, seed):
    """`log` with its IMU's noise (`truth_draws`'s "imu") replaced by an independent draw of the
    same σ, seeded `seed`: the same truth, torques and other sensors."""
    import dataclasses
    spec = log.sensors.imu
    noise = np.random.default_rng(seed).standard_normal(draws["imu"].shape) * np.repeat(
        [spec.gyro_noise, spec.accel_noise], 3)
    return dataclasses.replace(log, imu=dataclasses.replace(log.imu, data=log.imu.data - draws["imu"] + noise))


def driven(rec, draws):
    """The recorded linear system driven by the truth's own draws (`truth_draws`) from the run's
    start error: e ← T e at every map; at every noise the draw it stands for (an update's −K v, the
    held disturbance's a, the biases' steps, M⁻¹ w over the part of a step no held a covers); the current error at the
    scored samples in the physical components (m, 18), to compare with the run's own ("e")."""
    return sources(rec, draws)[:, 0].sum(axis=0)


def block_statistics(rec, e, block=50):
    """`consistency` over consecutive blocks of `block` draws, each draw a run with the recorded P:
    per block the share of samples in the band and the share within ±3σ per component."""
    out = []
    for k in range(len(e) // block):
        runs = [{"t": rec["t"], "e": draws, "P": rec["P"], "fixes": rec["fixes"]}
                for draws in e[k * block:(k + 1) * block]]
        report = consistency(runs)
        out.append({"inside": report["inside"], "within_3_sigma": report["within_3_sigma"],
                    "mean_anees": float(np.mean(report["anees"]))})
    return out


def summarise(blocks):
    """The distribution of the blocks' statistics: the share in band (mean, quantiles, lowest, the
    share of blocks below NEES_TARGET) and the share of blocks with a component below WITHIN_TARGET
    within ±3σ (any, and per component)."""
    inside = np.array([b["inside"] for b in blocks])
    worst = np.array([min(b["within_3_sigma"].values()) for b in blocks])
    return {"blocks": len(blocks), "inside_mean": float(inside.mean()),
            "inside_quantiles": {q: float(np.quantile(inside, q)) for q in (0.01, 0.05, 0.1, 0.25, 0.5)},
            "inside_min": float(inside.min()),
            "share_below_target": float(np.mean(inside < NEES_TARGET)),
            "worst_within_mean": float(worst.mean()),
            "share_within_below_target": float(np.mean(worst < WITHIN_TARGET)),
            "within_below_target_per_component": {
                c: float(np.mean([b["within_3_sigma"][c] < WITHIN_TARGET for b in blocks])) for c in COMPONENTS}}


def build_parser():
    """The command's arguments."""
    from ..cli_types import duration, whole_number as whole
    p = argparse.ArgumentParser(prog="python -m runtime surrogate", description=__doc__.split("\n\n")[0])
    p.add_argument("run", metavar="SCENARIO|TASK", help="a shipped scenario or task, or a .toml file")
    p.add_argument("--sensors", metavar="FILE", default="default", help="a sensor set (default: the default set)")
    p.add_argument("--seed", type=whole(0), default=0, help="the sense run whose filter is recorded (default 0)")
    p.add_argument("--duration", type=duration, help="simulate only this long [s]")
    p.add_argument("--draws", type=whole(2), default=1000, help="draws of the linear system (default 1000)")
    p.add_argument("--block", type=whole(2), default=50, help="draws scored together, as runs (default 50)")
    p.add_argument("--out", metavar="FILE", help="a JSON file for the summary and every block")
    p.add_argument("--driven", type=whole(1), metavar="N", help="instead: seeds seed … seed + N − 1, each "
                   "run's error²/σ² and its linear model's driven by its own draws (`driven`)")
    p.add_argument("--trace", type=whole(1), metavar="N", help="instead: seeds seed … seed + N − 1, each run's "
                   "linear model driven source by source, by the truth's draw and by the filter's model of it (`trace`)")
    p.add_argument("--model-draws", type=whole(2), default=20, help="with --trace: draws of each source's model "
                   "per seed (default 20)")
    p.add_argument("--redraw", action="store_true", help="with --trace: also each run's draws through the maps "
                   "recorded with its IMU's noise redrawn")
    return p


def main(argv):
    """`python -m runtime surrogate`: records the run, draws, scores the blocks, prints the summary;
    exit status 2 on a bad argument."""
    from .sense import load_run
    from ..sensor_set import load_sensor_set
    args = build_parser().parse_args(argv)
    if args.draws < args.block:
        print(f"--draws: expected at least --block ({args.block}), got {args.draws}", file=sys.stderr)
        return 2
    try:
        load_run(args.run)
        load_sensor_set(args.sensors)
    except ValueError as exc:
        print(exc, file=sys.stderr)
        return 2
    if args.driven:
        return _main_driven(args)
    if args.trace:
        return _main_trace(args)
    rec = record_run(args.run, args.sensors, args.seed, duration=args.duration)
    e = simulate(rec, args.draws, seed=[args.seed, 2])
    blocks = block_statistics(rec, e, args.block)
    out = {"run": args.run, "seed": args.seed, "draws": args.draws, "block": args.block,
           "recovered": {k: v["recovered"] for k, v in rec["counters"].items()},
           "summary": summarise(blocks), "blocks": blocks}
    text = json.dumps(out, indent=1)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)
    print(json.dumps(out["summary"], indent=1))
    return 0


def compare_driven(run, sensors, seeds, duration=None):
    """Per seed the mean error² / σ² per component of the run and of its linear model driven by
    its own draws: {"seeds", "components", "run" (n, 18), "linear" (n, 18)}."""
    real, linear = [], []
    for seed in seeds:
        rec = record_run(run, sensors, seed, duration=duration)
        lin = driven(rec, truth_draws(run, sensors, seed, duration=duration))
        var = np.diagonal(rec["P"], axis1=1, axis2=2)
        real.append(np.mean(rec["e"] ** 2 / var, axis=0))
        linear.append(np.mean(lin ** 2 / var, axis=0))
    return {"seeds": list(seeds), "components": list(COMPONENTS), "run": np.array(real), "linear": np.array(linear)}


def _main_driven(args):
    out = compare_driven(args.run, args.sensors, range(args.seed, args.seed + args.driven), args.duration)
    table = {"seeds": out["seeds"], "components": out["components"],
             "run": out["run"].tolist(), "linear": out["linear"].tolist(),
             "mean": {c: [float(out["run"][:, k].mean()), float(out["linear"][:, k].mean())]
                      for k, c in enumerate(COMPONENTS)}}
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(json.dumps(table, indent=1))
    print(json.dumps(table["mean"], indent=1))
    return 0


def trace(run, sensors, seeds, model_draws=20, duration=None, redraw=False):
    """Per seed and component the mean error² / σ² of the run ("run"), of its linear model driven by
    its own draws ("linear") and by `model_draws` whole draws of the filter's model ("model", their
    mean; "rank", the share of them below "linear"), and per source (SOURCES, `sources`) of the
    linear model driven by that source alone: its own draw ("own"), its model's draws ("of_model",
    their mean) and the own draw's place among them ("source_rank").  A source whose truth is the
    filter's model has "own" spread as "of_model" over the seeds, and a "source_rank" of ½ on
    average: a source that loads a component beyond its model shows as both above.  `redraw`:
    also "redrawn", the run's own draws through the maps the filter records on the same truth with
    its IMU's noise redrawn (`redrawn_imu`): near "linear" when the maps do not depend on the
    draws they propagate; "redrawn_sigma", that filter's σ over the run's, averaged over time.  Arrays (n, 18) and (n, S, 18) under those keys, with "seeds",
    "components", "sources"."""
    keys = ("run", "linear", "model", "rank", "own", "of_model", "source_rank") + (
        ("redrawn", "redrawn_sigma") if redraw else ())
    out = {k: [] for k in keys}
    for seed in seeds:
        log = simulated_log(run, sensors, seed, duration)
        rec = record_run(run, sensors, seed, log=log)
        draws = truth_draws(run, sensors, seed, log=log)
        e = sources(rec, draws, model_draws, seed=[seed, 3])
        var = np.diagonal(rec["P"], axis1=1, axis2=2)
        per = np.mean(e ** 2 / var, axis=2)                        # (S, 1 + draws, 18)
        whole = np.mean(e.sum(axis=0) ** 2 / var, axis=1)          # (1 + draws, 18)
        values = (np.mean(rec["e"] ** 2 / var, axis=0), whole[0], whole[1:].mean(axis=0),
                  np.mean(whole[1:] < whole[0], axis=0), per[:, 0], per[:, 1:].mean(axis=1),
                  np.mean(per[:, 1:] < per[:, :1], axis=1))
        if redraw:
            other = record_run(run, sensors, seed, log=redrawn_imu(log, draws, [seed, 4]))
            other_var = np.diagonal(other["P"], axis1=1, axis2=2)
            values += (np.mean(driven(other, draws) ** 2 / other_var, axis=0), np.mean(np.sqrt(other_var / var), axis=0))
        for k, v in zip(keys, values):
            out[k].append(v)
    return {"seeds": list(seeds), "components": list(COMPONENTS), "sources": list(SOURCES),
            **{k: np.array(v) for k, v in out.items()}}


def _main_trace(args):
    out = trace(args.run, args.sensors, range(args.seed, args.seed + args.trace), args.model_draws, args.duration,
                args.redraw)
    mean = {k: dict(zip(COMPONENTS, np.round(out[k].mean(axis=0), 4).tolist()))
            for k in ("run", "linear", "model", "rank") + (("redrawn", "redrawn_sigma") if args.redraw else ())}
    mean["sources"] = {name: {k: dict(zip(COMPONENTS, np.round(out[k][:, i].mean(axis=0), 4).tolist()))
                              for k in ("own", "of_model", "source_rank")} for i, name in enumerate(SOURCES)}
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(json.dumps({**{k: v.tolist() if isinstance(v, np.ndarray) else v for k, v in out.items()},
                                 "mean": mean}, indent=1))
    print(json.dumps(mean, indent=1))
    return 0
