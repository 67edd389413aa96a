"""`python -m runtime identify LOG --params NAMES --out DIR`: fit a robot's parameters to a log and
write what the fit found (docs/identification.md, "Identifying a robot from a log").

DIR receives estimates.csv (each named entry: nominal, estimate, sigma, 95 % interval, identified,
on a bound), correlation.csv, report.md (the identifiability report: rank, conditioning, the
combinations), residuals.png, params.toml (the estimated robot as a robot file, ready for
scenarios) and summary.json.  The exit status is 0 when the fit passes its residual check, 1 when
it does not (the log does not look like the claimed robot with these parameters free), 2 on a bad
argument, log or parameter set.
"""
import json
import math
import pathlib
import sys
import time

import numpy as np

from ..atomic import write_text
from ..params import SHAPES, Params
from .fit import RESIDUAL_TOLERANCE, STARTS, Z95, identify

REPORT_FILES = ("estimates.csv", "correlation.csv", "report.md", "residuals.png", "params.toml", "summary.json")


def robot_toml(params, header=""):
    """`params` as a robot file (docs/robots.md): every general parameter, c_* as [x, y, z], J_* as
    three rows; `header` as comment lines on top."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    for name, shape in SHAPES.items():
        value = getattr(params, name)
        if shape == ():
            lines.append(f"{name} = {float(value)!r}")
        elif shape == (3,):
            lines.append(f"{name} = [{', '.join(repr(float(v)) for v in value)}]")
        else:
            rows = ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in value)
            lines.append(f"{name} = [{rows}]")
    return "\n".join(lines) + "\n"


def estimates_csv(fit):
    """One row per free entry."""
    lines = ["name,nominal,estimate,sigma,low_95,high_95,identified,on_bound"]
    for i, name in enumerate(fit.names):
        lines.append(",".join([name, repr(float(fit.nominal[i])), repr(float(fit.estimate[i])),
                               repr(float(fit.sigma[i])), repr(float(fit.low[i])), repr(float(fit.high[i])),
                               str(bool(fit.identified[i])).lower(), fit.on_bound.get(name, "")]))
    return "\n".join(lines) + "\n"


def correlation_csv(fit):
    """The correlation matrix of the identified entries (NaN where one is not identified)."""
    lines = ["name," + ",".join(fit.names)]
    for i, name in enumerate(fit.names):
        lines.append(name + "," + ",".join(f"{v:.6g}" for v in fit.correlation[i]))
    return "\n".join(lines) + "\n"


def report_md(fit, log_path):
    """The identifiability report as Markdown."""
    check = fit.residual_check
    verdict = "passes" if check["passed"] else "FAILS"
    out = [f"# Identification of {log_path}", "",
           f"Fit: {fit.mode} log, {len(fit.names)} free entries, {fit.nfev} evaluations; solver: {fit.message}", "",
           f"Residual check {verdict}: whitened residual RMS {check['rms']:.3f} (passes within "
           f"{check['tolerance']:g} of 1), chi-square {check['chi2']:.1f} on {check['dof']} degrees of freedom "
           f"(p = {check['p_value']:.3g}).", ""]
    if not fit.converged:
        out += ["**The fit did not converge**: the solver stopped at its evaluation budget short of the optimum, "
                "so the estimates and intervals below are not the optimum's (run it again with a larger "
                "`--max-evaluations`).", ""]
    if not check["passed"]:
        out += ["The residuals are not what the sensors' noise explains: the log does not look like the claimed "
                "robot with only these parameters free (another robot, a parameter held at a wrong value, a "
                "sensor set that does not match). The intervals below assume the model is right and do not "
                "hold.", ""]
    out += [f"Information: rank {fit.rank} of {len(fit.names)}, condition number {fit.condition:.3g} "
            "(the Fisher information of the named entries, each scaled by its nominal value, the start "
            "states and the IMU's biases eliminated).", "",
            "| parameter | nominal | estimate | 95 % interval | identified |", "|---|---|---|---|---|"]
    for i, name in enumerate(fit.names):
        interval = (f"[{fit.low[i]:.6g}, {fit.high[i]:.6g}]" if fit.identified[i] else "—")
        status = "yes" if fit.identified[i] else "only in a combination"
        if name in fit.on_bound:
            status += f"; on its {fit.on_bound[name]} bound (the interval does not hold there)"
        out.append(f"| `{name}` | {fit.nominal[i]:.6g} | {fit.estimate[i]:.6g} | {interval} | {status} |")
    out += ["", "The base parameters these entries enter (runtime.param_derivatives.base_parameters):", "",
            "| combination | nominal | estimate | 95 % interval | determined by this log |", "|---|---|---|---|---|"]
    for c in fit.combinations:
        interval = f"± {Z95 * c['sigma']:.3g}" if c["identified"] else "—"
        out.append(f"| `{c['name']}` | {c['nominal']:.6g} | {c['value']:.6g} | {interval} | "
                   f"{'yes' if c['identified'] else 'no'} |")
    if fit.null_directions:
        out += ["", "Combinations this log cannot separate (directions of the information's null space, "
                "in units of each entry's nominal value):", ""]
        for v in fit.null_directions:
            out.append("* " + " ".join(f"{w:+.3f}·{n}" for n, w in v.items()))
    if fit.mode == "sensors":
        out += ["", "IMU biases: gyroscope " + ", ".join(f"{b:.4g}" for b in fit.biases[:3]) + " rad/s, accelerometer "
                + ", ".join(f"{b:.4g}" for b in fit.biases[3:]) + " m/s²."]
    return "\n".join(out) + "\n"


def residual_figure(fit, path):
    """The whitened residuals against time (unit white noise when the model is right), one panel per
    sensor, with their RMS."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    kinds = list(fit.residuals)
    fig, axes = plt.subplots(len(kinds), 1, figsize=(9, 2.4 * len(kinds)), sharex=True, squeeze=False)
    for ax, kind in zip(axes[:, 0], kinds):
        t, r = fit.residuals[kind]
        ax.plot(t, r, lw=0.4)
        ax.axhline(2, color="k", lw=0.5, ls=":")
        ax.axhline(-2, color="k", lw=0.5, ls=":")
        ax.set_ylabel(f"{kind}\n[whitened]")
        ax.set_title(f"{kind}: RMS {math.sqrt(float(np.mean(r ** 2))):.3f}", fontsize=9)
    axes[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def summary(fit, wall, log_path, robot_source):
    """The numbers of summary.json."""
    def num(v):
        return None if not np.isfinite(v) else float(v)
    return {"log": str(log_path), "robot": robot_source, "mode": fit.mode, "wall_time_s": wall,
            "evaluations": fit.nfev, "solver_status": fit.status, "solver_message": fit.message,
            "converged": fit.converged,
            "start": dict(zip(fit.names, map(float, fit.start))),
            "rank": fit.rank, "condition": num(fit.condition),
            "parameters": [{"name": n, "nominal": float(fit.nominal[i]), "estimate": float(fit.estimate[i]),
                            "sigma": num(fit.sigma[i]), "low_95": num(fit.low[i]), "high_95": num(fit.high[i]),
                            "identified": bool(fit.identified[i]), "on_bound": fit.on_bound.get(n)}
                           for i, n in enumerate(fit.names)],
            "combinations": [{k: (num(v) if isinstance(v, float) else v) for k, v in c.items()}
                             for c in fit.combinations],
            "null_directions": fit.null_directions,
            "biases": [num(b) for b in fit.biases], "bias_sigma": [num(b) for b in fit.bias_sigma],
            "residual_check": fit.residual_check, "files": list(REPORT_FILES)}


def build_parser():
    """The argument parser of `python -m runtime identify`."""
    import argparse

    from ..cli_types import positive_number as positive, whole_number

    count = whole_number(1)

    parser = argparse.ArgumentParser(
        prog="python -m runtime identify",
        description="Fit the named parameters of a robot, with the initial state and the IMU's biases, to a sensor "
                    "log (or a full-state log) and write the estimates, their 95 %% intervals, the identifiability "
                    "report, residual plots and a robot file into OUT (docs/identification.md).")
    parser.add_argument("log", metavar="LOG", type=pathlib.Path, help="a log folder (python -m runtime sense writes one)")
    parser.add_argument("--robot", metavar="FILE", help="the nominal robot file (default: the robot the log claims, "
                                                        "else the paper's simulation robot)")
    parser.add_argument("--sensors", metavar="FILE", help="a sensors file or shipped set (default: the log's)")
    parser.add_argument("--params", required=True, metavar="NAMES",
                        help="comma-separated parameters to fit: fields (m_P, c_P, J_P, k_S, j_mY) or entries "
                             "(c_P_z, J_P_yy); the others are held at the robot file's values")
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the output folder (created if missing)")
    parser.add_argument("--full-state", action="store_true", help="fit to the log's truth table (a full-state log)")
    parser.add_argument("--segment", type=positive, default=0.5, help="multiple-shooting segment length [s] (0.5)")
    parser.add_argument("--max-evaluations", type=count, default=60,
                        help="the solver's evaluation budget, of each of a sensor fit's two joint stages (60)")
    parser.add_argument("--start", choices=STARTS, default="regressor",
                        help="where the parameters start: the regressor's linear least-squares first guess "
                             "(default) or the nominal robot")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, print nothing but errors")
    return parser


def main(argv):
    """`python -m runtime identify`: exit 0 when the fit passes its residual check, 1 when it does not,
    2 on a bad argument, log or parameter set."""
    from tqdm import tqdm

    from ..estimation.logs import read_log
    from ..scenario import load_robot
    from ..sensor_set import load_sensor_set
    args = build_parser().parse_args(argv)
    try:
        if args.out.exists() and not args.out.is_dir():
            raise ValueError(f"{args.out}: is a file, expected a folder")
        sensors = load_sensor_set(args.sensors) if args.sensors else None
        log = read_log(args.log, sensors=sensors)
        if args.robot:
            params, source = load_robot(args.robot), args.robot
        else:
            params = log.params() or Params.paper_simulation()
            source = "the log's robot" if log.params() is not None else "Params.paper_simulation()"
        bar = tqdm(desc="identify", unit=" evaluations", disable=args.quiet, file=sys.stderr)
        started, cpu = time.perf_counter(), time.process_time()
        try:
            fit = identify(log, params, args.params, segment=args.segment, full_state=args.full_state,
                           max_nfev=args.max_evaluations, progress=lambda: bar.update(1), start=args.start)
        finally:
            bar.close()
        wall, cpu = time.perf_counter() - started, time.process_time() - cpu
        args.out.mkdir(parents=True, exist_ok=True)
        write_text(args.out / "estimates.csv", estimates_csv(fit))
        write_text(args.out / "correlation.csv", correlation_csv(fit))
        write_text(args.out / "report.md", report_md(fit, args.log))
        residual_figure(fit, args.out / "residuals.png")
        write_text(args.out / "params.toml", robot_toml(
            fit.params, f"Identified from {args.log} ({', '.join(fit.names)} fitted; the rest from {source}).\n"
                        f"Residual check {'passed' if fit.residual_check['passed'] else 'FAILED'}: RMS "
                        f"{fit.residual_check['rms']:.3f}.  Intervals: estimates.csv."))
        write_text(args.out / "summary.json",
                   json.dumps({**summary(fit, wall, args.log, source), "cpu_time_s": cpu}, indent=2) + "\n")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    check = fit.residual_check
    if not args.quiet:
        print(f"{args.log}: {len(fit.names)} parameters in {wall:.1f} s, rank {fit.rank}; residual RMS "
              f"{check['rms']:.3f}; wrote {args.out}/")
    if not fit.converged:
        print(f"the fit did not converge in its evaluations: {fit.message}", file=sys.stderr)
    if not check["passed"]:
        print(f"residual check failed: whitened residual RMS {check['rms']:.3f} is not within "
              f"{RESIDUAL_TOLERANCE:g} of 1 (p = {check['p_value']:.3g}): the log does not look like this robot "
              f"with only {', '.join(fit.names)} free", file=sys.stderr)
        return 1
    return 0
