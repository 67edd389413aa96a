"""The error-state EKF over a sensor log (`python -m runtime estimate`, docs/estimation.md, "Estimates").

    log = read_log("out/circle-log")
    result = estimate_log(log)                  # the filter started by the start rule, run over every sample
    result.x, result.sigma, errors(log, result)

The filter (runtime.ekf, C in c/src/sr_ekf.c) assumes what the log's sensor set declares
(`ekf_noise`); between two samples it predicts under the torques the log says were applied (a
torque row holds until the next), with the truth's stepping method when the log says which
(`prediction_method`, else RKMK4); samples of one time are applied IMU first, then encoders,
fixes and heading.  A fix that arrives after the instant it measures (`t_measured` < `t`) is marked
at that instant and applied on arrival as a delayed fix (runtime.ekf, `mark_position`).  The
accelerometer's noise is `ekf_noise`'s rule `accel_noise`: by default ("held") the process noise
is a torque held over each torque row's period (the simulation's step), which the accelerometer
reads and the predicts of that period step with (the samples' noise and the process noise
correlated, c/include/sr_ekf.h, "Held disturbance"); "largest" and "each" put what the process
noise adds to the reading into its σ instead.
"""
import dataclasses
import math

import numpy as np

from ..ekf import DELAYED_SLOTS, METHODS, start_from_measurements
from ..model import Model
from ..sensors import heading as heading_of
from ..sensor_sim import ACCEL_AXES, ekf_noise
from ..params import Params
from ..state import (COLUMN_INDEX, IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WS, NX, STATE_COLUMNS,
                     pendulum_angle, yoke_angle)

#: The error state's names (the 12 error coordinates of Model.retract, then the IMU's biases), the
#: columns `sigma_<name>` of estimate.csv.
ERROR_NAMES = ("xi_S_x", "xi_S_y", "xi_S_z", "theta_Y", "theta_P", "q_x", "q_y", "w_S_x", "w_S_y", "w_S_z",
               "w_Y", "w_P", "b_g_x", "b_g_y", "b_g_z", "b_a_x", "b_a_y", "b_a_z")
#: Errors are scored after this long [s] (the filter's start-up), or after half the log if shorter.
SETTLE_S = 10.0
#: IMU samples averaged by the start rule's tilt (the robot at rest at the start).
START_SAMPLES = 20
#: The speeds' standard deviation [rad/s] at the start of a robot that already moves.
MOVING_RATE_SIGMA = 2.0


@dataclasses.dataclass(frozen=True, eq=False)
class Estimate:
    """The filter's output at every torque row and sample time `t` (n,): the state `x` (n, 35) and
    the error state's standard deviations `sigma` (n, 18) (ERROR_NAMES), the biases (n, 6), and the
    filter's counters per sensor kind ({"accepted", "gated", "recovered", "nis"}); with `covariance_every` = k,
    the whole covariance `P` (m, 18, 18) at the rows `P_rows` (every k-th), else None."""
    t: np.ndarray
    x: np.ndarray
    sigma: np.ndarray
    biases: np.ndarray
    counters: dict
    P: np.ndarray = None
    P_rows: np.ndarray = None


def claimed_params(log):
    """The robot a log claims (log.json), else the paper's simulation robot."""
    return log.params() or Params.paper_simulation()


def start_heading(log):
    """The operator's knowledge of the IMU's heading at the start [rad] when a log does not say
    (log.json's "start_heading"): the truth's, when the log has truth, else 0."""
    if "start_heading" in log.meta:
        return float(log.meta["start_heading"])
    if log.truth is None:
        return 0.0
    model = Model(claimed_params(log))
    return heading_of(model, log.truth_states()[0], log.sensors.imu.mount)


def moving_at_start(log):
    """Whether the gyroscope's first START_SAMPLES samples say the body turns (any axis beyond five
    noise and three bias standard deviations): the start rule's "at rest" does not hold."""
    imu = log.sensors.imu
    gyro = log.imu.select("gyro_x", "gyro_y", "gyro_z")[:START_SAMPLES].mean(axis=0)
    return bool(np.any(np.abs(gyro) > 5 * imu.gyro_noise / math.sqrt(START_SAMPLES) + 3 * imu.gyro_bias))


def torque_period(log):
    """The period of the log's torque rows [s] (their median spacing; None for a single row): the
    step over which a simulated truth holds its torque disturbance."""
    t = log.torques.t
    return float(np.median(np.diff(t))) if len(t) > 1 else None


def prediction_method(log):
    """The stepping method the filter predicts with: the truth's, when the log says which (log.json's
    "method", written by `sense`), else RKMK4 (a robot's own log); the filter then predicts between
    the log's rows, at the truth's step when the log has one row per step."""
    method = log.meta.get("method", "rkmk4")
    if method not in METHODS:
        raise ValueError(f"log.json method: expected one of {sorted(METHODS)}, got {method!r}")
    return method


def estimate_log(log, params=None, noise=None, gate=0.999, heading=None, progress=None, covariance_every=None,
                 accel_noise="held", constrained=None, make_filter=start_from_measurements):
    """Run the filter over `log` (runtime.estimation.logs.Log) for the robot `params` (None: the one
    the log claims, else the paper's simulation robot), started by the start rule (the first
    START_SAMPLES accelerometer samples, the first encoder sample, the first fix and heading if the
    log has them; the heading known to 10° around `heading` [rad], None: `start_heading`).  A robot
    already moving at the start (`moving_at_start`) starts with speeds of σ MOVING_RATE_SIGMA
    instead of at rest.  `progress(done, total)` is called every 1000 times.  `covariance_every` = k
    (a whole number >= 1) keeps the whole covariance at every k-th row (`Estimate.P`).  `accel_noise`:
    `ekf_noise`'s accelerometer rule ("held", the default, "largest", "each") when `noise` is None.  `constrained`:
    the filter's observability constraint (`Ekf`'s; docs/estimation.md, "Observability constraint"),
    None: on when the log has neither fixes nor a heading (nothing that sees the heading and the
    position), off otherwise.  `make_filter`: what makes the filter from the start rule's arguments (another
    filter with `Ekf`'s methods, such as runtime.estimation.surrogate's recording reference)."""
    if constrained is not None and not isinstance(constrained, bool):
        raise ValueError(f"constrained: expected True, False or None (on without fixes and heading), got {constrained!r}")
    if covariance_every is not None and (isinstance(covariance_every, bool) or not isinstance(
            covariance_every, (int, np.integer)) or covariance_every < 1):
        raise ValueError(f"covariance_every: expected a whole number >= 1, got {covariance_every!r}")
    params = params if params is not None else claimed_params(log)
    model = Model(params)
    sensors = log.sensors
    if noise is None:
        hold = torque_period(log) if accel_noise == "held" else None
        noise = ekf_noise(sensors, params, accel_axes=accel_noise, hold=hold)
    events = [(log.imu, "imu"), (log.encoders, "encoders"), (log.fixes, "fixes"), (log.heading, "heading")]
    events = [(table, kind) for table, kind in events if table is not None and len(table)]
    if constrained is None:
        constrained = not any(kind in ("fixes", "heading") for _, kind in events)
    start = {"accel": log.imu.select("accel_x", "accel_y", "accel_z")[:START_SAMPLES],
             "encoders": log.encoders.data[0]}
    if log.fixes is not None and len(log.fixes):
        start["fix"] = log.fixes.select("x", "y")[0]
    if log.heading is not None and len(log.heading):
        start["heading"] = float(log.heading["psi"][0])
    ekf = make_filter(model, noise=noise, mount=sensors.imu.mount, gate=gate,
                      heading_prior=start_heading(log) if heading is None else heading,
                      rate_sigma=MOVING_RATE_SIGMA if moving_at_start(log) else 0.01,
                      method=prediction_method(log), constrained=constrained, **start)
    late = []                                   # (t_measured, index) of the fixes that arrive late
    if log.fixes is not None and len(log.fixes):
        measured = log.fixes["t_measured"]
        late = sorted((float(measured[j]), j) for j in range(len(log.fixes))
                      if log.torques.t[0] <= measured[j] < log.fixes.t[j])
    times = np.unique(np.concatenate([log.torques.t] + [table.t for table, _ in events] + [[m for m, _ in late]]))
    times = times[times >= log.torques.t[0]]
    cursor = {kind: 0 for _, kind in events}
    slot_of, next_late = {}, 0
    out_x, out_sigma, out_b = np.empty((len(times), NX)), np.empty((len(times), 18)), np.empty((len(times), 6))
    P_rows = None if covariance_every is None else np.arange(0, len(times), covariance_every)
    out_P = None if P_rows is None else np.empty((len(P_rows), 18, 18))
    t_now = times[0]
    for i, t in enumerate(times):
        if t > t_now:
            ekf.predict(log.torque_at(t_now), float(t - t_now))
            t_now = t
        while next_late < len(late) and late[next_late][0] <= t:
            free = sorted(set(range(DELAYED_SLOTS)) - set(slot_of.values()))
            if not free:
                raise ValueError(f"fixes: more than {DELAYED_SLOTS} fixes measured and not yet arrived at "
                                 f"t = {t:g} s; the filter holds {DELAYED_SLOTS}")
            slot_of[late[next_late][1]] = free[0]
            ekf.mark_position(free[0])
            next_late += 1
        u = log.torque_at(t)
        for table, kind in events:
            j = cursor[kind]
            while j < len(table) and table.t[j] <= t:
                if table.t[j] == t:
                    row = table.data[j]
                    if kind == "imu":
                        ekf.update_imu(row, u)
                    elif kind == "encoders":
                        ekf.update_encoders(row)
                    elif kind == "fixes" and j in slot_of:
                        ekf.update_position_delayed(slot_of.pop(j), row[1:3])   # (t_measured, x, y)
                    elif kind == "fixes":
                        ekf.update_position(row[1:3])
                    else:
                        ekf.update_heading(float(row[0]))
                j += 1
            cursor[kind] = j
        out_x[i], out_sigma[i], out_b[i] = ekf.x, ekf.sigma, ekf.biases
        if out_P is not None and i % covariance_every == 0:
            out_P[i // covariance_every] = ekf.P
        if progress is not None and i % 1000 == 0:
            progress(i, len(times))
    return Estimate(t=times, x=out_x, sigma=out_sigma, biases=out_b, counters=ekf.counters, P=out_P, P_rows=P_rows)


def _tilt_and_heading(model, x, mount):
    """Per state: the gravity direction in the IMU's body frame (n, 3) and the heading [rad] (n,)."""
    R = x[:, IDX_RS].reshape(-1, 3, 3)
    if mount.body in ("yoke", "pendulum"):                        # the joints' rotations are relative
        R = R @ x[:, IDX_RY].reshape(-1, 3, 3)
    if mount.body == "pendulum":
        R = R @ x[:, IDX_RP].reshape(-1, 3, 3)
    up = R[:, 2, :]                                               # R_Bᵀ e_z, R_B's third row
    psi = np.array([heading_of(model, xi, mount) for xi in x])
    return up, psi


def _rms(e):
    return float(np.sqrt(np.mean(np.square(e)))) if e.size else math.nan


def _velocity(params, x):
    """The shell centre's velocity on the floor (n, 2): q̇ = r P R_S ω_S, P (v_y, −v_x)."""
    R = x[:, IDX_RS].reshape(-1, 3, 3)
    w = np.einsum("nij,nj->ni", R, x[:, IDX_WS])
    return params.r * np.column_stack([w[:, 1], -w[:, 0]])


def errors(log, result, params=None):
    """The error metrics against the log's truth (None without one), from SETTLE_S on: RMS of the
    position [m], heading [deg] (of the IMU's x axis), tilt [deg] (the angle between the estimated
    and the true gravity direction in the IMU's body frame), forward speed [m/s] (the shell
    centre's speed on the floor), joint angles [deg]; and the share of samples whose true error lies within ±3σ, per
    error coordinate of the position, heading (ξ_S,z) and joints."""
    if log.truth is None:
        return None
    params = params if params is not None else claimed_params(log)
    model = Model(params)
    truth = log.truth_states()
    i = np.clip(np.searchsorted(log.truth.t, result.t), 0, len(log.truth.t) - 1)
    keep = (np.abs(log.truth.t[i] - result.t) < 1e-9) & (result.t >= min(SETTLE_S, result.t[-1] / 2))
    est, tru, sig = result.x[keep], truth[i[keep]], result.sigma[keep]
    mount = log.sensors.imu.mount
    up_e, psi_e = _tilt_and_heading(model, est, mount)
    up_t, psi_t = _tilt_and_heading(model, tru, mount)
    tilt = np.degrees(np.arccos(np.clip(np.einsum("ni,ni->n", up_e, up_t), -1.0, 1.0)))
    dpsi = np.degrees(np.angle(np.exp(1j * (psi_e - psi_t))))
    dq = est[:, IDX_Q][:, :2] - tru[:, IDX_Q][:, :2]
    speed = np.linalg.norm(_velocity(params, est), axis=1) - np.linalg.norm(_velocity(params, tru), axis=1)
    joints = np.degrees(np.column_stack([np.angle(np.exp(1j * (yoke_angle(est) - yoke_angle(tru)))),
                                         np.angle(np.exp(1j * (pendulum_angle(est) - pendulum_angle(tru))))]))
    inside = {"q_x": dq[:, 0], "q_y": dq[:, 1], "xi_S_z": np.radians(dpsi),
              "theta_Y": np.radians(joints[:, 0]), "theta_P": np.radians(joints[:, 1])}
    return {"scored_from_s": float(min(SETTLE_S, result.t[-1] / 2)), "samples": int(keep.sum()),
            "position_rms_m": _rms(np.linalg.norm(dq, axis=1)), "heading_rms_deg": _rms(dpsi),
            "tilt_rms_deg": _rms(tilt), "forward_speed_rms_m_s": _rms(speed),
            "theta_Y_rms_deg": _rms(joints[:, 0]), "theta_P_rms_deg": _rms(joints[:, 1]),
            "within_3_sigma": {name: float(np.mean(np.abs(e) <= 3 * sig[:, ERROR_NAMES.index(name)]))
                               for name, e in inside.items()}}


def table(result):
    """estimate.csv's rows (n, 1 + 35 + 18 + 6) and header: t, the state as trajectory.csv names it,
    sigma_<error coordinate>, the biases."""
    header = ("t", *STATE_COLUMNS, *(f"sigma_{n}" for n in ERROR_NAMES), *ERROR_NAMES[12:])
    return header, np.column_stack([result.t, result.x[:, COLUMN_INDEX], result.sigma, result.biases])


def figure(log, result, path):
    """estimate.png: position, heading, tilt and speed errors with ±3σ against the truth (or the
    estimate alone without truth)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    t = result.t
    if log.truth is not None:
        truth = log.truth_states()
        i = np.clip(np.searchsorted(log.truth.t, t), 0, len(log.truth.t) - 1)
        for ax, k, name in ((axes[0], 0, "q_x"), (axes[1], 1, "q_y")):
            ax.plot(t, result.x[:, IDX_Q][:, k] - truth[i][:, IDX_Q][:, k], label=f"{name} error")
            s = 3 * result.sigma[:, ERROR_NAMES.index(name)]
            ax.fill_between(t, -s, s, alpha=0.25, label="±3σ")
            ax.set_ylabel("m")
            ax.legend(loc="upper right")
    else:
        axes[0].plot(result.x[:, IDX_Q][:, 0], result.x[:, IDX_Q][:, 1])
        axes[0].set_ylabel("q_y (m)")
    axes[2].semilogy(t, 3 * result.sigma[:, ERROR_NAMES.index("xi_S_z")], label="3σ heading (rad)")
    axes[2].semilogy(t, 3 * result.sigma[:, ERROR_NAMES.index("xi_S_x")], label="3σ tilt x (rad)")
    axes[2].legend(loc="upper right")
    axes[2].set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


# -- python -m runtime estimate --------------------------------------------------------------------
def build_parser():
    """The argument parser of `python -m runtime estimate`."""
    import argparse
    import pathlib

    def degrees(value):
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not math.isfinite(number):
            raise argparse.ArgumentTypeError(f"expected a finite angle in degrees, got {value!r}")
        return number

    parser = argparse.ArgumentParser(
        prog="python -m runtime estimate",
        description="Run the error-state EKF over a sensor log and write estimate.csv (the state with "
                    "trajectory.csv's columns, the standard deviations, the biases), estimate.png and "
                    "summary.json (the error metrics when the log has truth) into OUT (docs/estimation.md).")
    parser.add_argument("log", type=pathlib.Path, help="a log folder (python -m runtime sense writes one)")
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the output folder (created if missing)")
    parser.add_argument("--sensors", metavar="FILE", help="a sensors file or shipped set (default: the log's)")
    parser.add_argument("--heading", type=degrees, metavar="DEG",
                        help="the IMU's heading at the start, known to 10 deg (default: the log's, else 0)")
    parser.add_argument("--accel-noise", choices=ACCEL_AXES, default="held",
                        help="the filter's accelerometer noise rule (runtime.sensor_sim.ekf_noise; 'held', the "
                             "default: the torque disturbance the accelerometer reads modelled; 'largest', "
                             "'each': its share of the reading in the accelerometer's sigma)")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return parser


def main(argv):
    """`python -m runtime estimate`: exit status 2 on a bad argument, log or file."""
    import json
    import sys

    from ..atomic import atomic_path, write_text
    from ..errors import KernelError
    from ..sensor_set import load_sensor_set
    from .logs import read_log
    args = build_parser().parse_args(argv)
    try:
        if args.out.exists() and not args.out.is_dir():
            raise ValueError(f"{args.out}: is a file, expected a folder")
        sensors = load_sensor_set(args.sensors) if args.sensors else None
        log = read_log(args.log, sensors=sensors)
        try:
            result = estimate_log(log, heading=None if args.heading is None else math.radians(args.heading),
                                  accel_noise=args.accel_noise)
        except KernelError as exc:
            raise ValueError(f"{args.log}: the filter failed: {exc}") from None
        metrics = errors(log, result)
        args.out.mkdir(parents=True, exist_ok=True)
        header, rows = table(result)
        with atomic_path(args.out / "estimate.csv") as path:
            np.savetxt(path, rows, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
        with atomic_path(args.out / "estimate.png") as path:
            figure(log, result, path)
        summary = {"log": str(args.log), "accel_noise": args.accel_noise, "samples": int(len(result.t)),
                   "counters": result.counters,
                   "skipped": log.skipped, "gaps": len(log.gaps), "errors": metrics}
        write_text(args.out / "summary.json", json.dumps(summary, indent=2) + "\n")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if not args.quiet:
        print(json.dumps(metrics if metrics is not None else result.counters, indent=2))
    return 0
