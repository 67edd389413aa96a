"""`python -m runtime identify-coverage`: are the fit's 95 % intervals honest?  Seeded logs of a
robot whose parameters differ from the nominal ones, each fitted; the fraction of fits whose
interval holds the truth, per parameter (docs/identification.md, "Measured").

The robot is robots/battery-geared.toml; the truth scales the named entries by factors drawn
uniformly in [1 − spread, 1 + spread] per fit (the entries not named held at their true values).
The torques are a scenario's torque program (`--excitation FILE`, e.g. one `python -m runtime
excite` designed), or else piecewise constant, uniform within ±0.3 N m (yoke) and ±0.15 N m
(pendulum), new every 0.25 s.  Each log is the default sensor set's (IMU, encoders, fixes) and is
fitted as a sensor log, or by its truth table with `--full-state`; `--jobs` fits run at once.
"""
import dataclasses
import json
import os
import time

import numpy as np
import scipy.stats

from ..atomic import write_text
from ..estimation.sense import simulate_log
from ..param_derivatives import PARAMETER_NAMES, PI_NAMES
from ..params import Params
from ..scenario import TorqueWindow, load_scenario
from ..sensor_set import SensorSet
from .first_guess import _pi_of
from .fit import STARTS, free_parameters, identify

#: The within-tolerance target of the combinations (relative; a vector's error relative to its norm).
COMBINATION_TOLERANCE = 0.02


def combinations_of(p):
    """{name: values (k,)} of the combinations a sensor log of this robot determines although the
    entries inside them may not be (both hinges sit at the shell centre), of a parameter vector p
    (`PARAMETER_NAMES` order, need not be physical): the total mass, the pendulum's first moment
    m_P c_P (3,), the pendulum's inertia about its hinge JO_P_yy, the inertia about the yoke's axis
    with the reflected rotor JO_Y_xx + JO_P_zz + n_Y² j_mY, and the three dampings."""
    pi = dict(zip(PI_NAMES, _pi_of(p)))
    v = dict(zip(PARAMETER_NAMES, p))
    return {"m_S + m_Y + m_P": np.array([v["m_S"] + v["m_Y"] + v["m_P"]]),
            "m_P c_P": np.array([pi["mc_P_x"], pi["mc_P_y"], pi["mc_P_z"]]),
            "JO_P_yy": np.array([pi["JO_P_yy"]]),
            "JO_Y_xx + JO_P_zz + n_Y^2 j_mY": np.array([pi["JO_Y_xx"] + pi["JO_P_zz"] + v["n_Y"] ** 2 * v["j_mY"]]),
            "k_S": np.array([v["k_S"]]), "k_Y": np.array([v["k_Y"]]), "k_P": np.array([v["k_P"]])}


def combination_errors(fit, truth):
    """Per combination (`combinations_of`) of a fit's robot against the true robot: {"truth",
    "estimate", "relative_error" (|estimate − truth| / |truth|, the vector's norms), "within"
    (COMBINATION_TOLERANCE), "inside" (the truth inside the estimate's 95 % region: the
    Mahalanobis distance under the delta method's covariance, by the chi-square quantile of its
    rank; None for a combination no free entry moves), "sigma" (per component)}."""
    idx = [PARAMETER_NAMES.index(n) for n in fit.names]
    p = fit.params.as_array()
    est, true = combinations_of(p), combinations_of(truth.as_array())
    sigma = np.where(np.isfinite(fit.sigma), fit.sigma, 0.0)
    cov = np.nan_to_num(fit.correlation) * np.outer(sigma, sigma)
    grads = {name: np.zeros((len(v), len(idx))) for name, v in est.items()}
    for c, i in enumerate(idx):         # the combinations are polynomials in p: central differences
        step = 1e-6 * max(abs(p[i]), 1e-9)
        hi, lo = p.copy(), p.copy()
        hi[i] += step
        lo[i] -= step
        up, down = combinations_of(hi), combinations_of(lo)
        for name in grads:
            grads[name][:, c] = (up[name] - down[name]) / (2 * step)
    out = {}
    for name, e in est.items():
        t, G = true[name], grads[name]
        C = G @ cov @ G.T
        rank = int(np.linalg.matrix_rank(C, tol=1e-12 * max(float(np.abs(C).max()), 1e-300))) if np.any(C) else 0
        d = e - t
        Cp = np.linalg.pinv(C, rcond=1e-12)
        # outside the region too: an error along a direction the covariance says is known exactly
        inside = None if not rank else bool(d @ Cp @ d <= scipy.stats.chi2.ppf(0.95, rank)
                                            and np.linalg.norm(d - C @ Cp @ d) <= 1e-6 * np.linalg.norm(d))
        rel = float(np.linalg.norm(d) / np.linalg.norm(t)) if np.linalg.norm(t) > 0 else float(np.linalg.norm(d))
        out[name] = {"truth": t.tolist(), "estimate": e.tolist(), "sigma": np.sqrt(np.clip(np.diag(C), 0, None)).tolist(),
                     "relative_error": rel, "within": rel <= COMBINATION_TOLERANCE, "inside": inside}
    return out


def random_torques(duration, rng, period=0.25, yoke=0.3, pendulum=0.15):
    """Piecewise-constant torques, uniform within ±yoke and ±pendulum [N m], new every `period` s."""
    n = int(round(duration / period))
    return tuple(TorqueWindow(i * period, (i + 1) * period, float(rng.uniform(-yoke, yoke)),
                              float(rng.uniform(-pendulum, pendulum))) for i in range(n))


def planted(nominal, names, rng, spread):
    """`nominal` with each free entry of `names` scaled by a factor in [1 − spread, 1 + spread]; a
    draw that is not a physical robot is drawn again."""
    entries = free_parameters(names)
    for _ in range(100):
        p = nominal.as_array()
        for e in entries:
            p[PARAMETER_NAMES.index(e)] *= rng.uniform(1 - spread, 1 + spread)
        try:
            return Params.from_array(p)
        except ValueError:
            continue
    raise ValueError(f"params: no physical robot within ±{spread:g} of the nominal one for {names}")


def simulated_log(names, duration, seed, spread=0.3, excitation=None):
    """(log, nominal, truth): a seeded log of the battery-geared robot with the entries `names`
    planted within ±spread of its values, with the default sensor set, under the torque program of
    the scenario file `excitation` (its first `duration` s; its own robot is not used) or else
    `random_torques`."""
    rng = np.random.default_rng(seed)
    scenario = load_scenario("battery-geared")
    nominal = scenario.params
    truth = planted(nominal, names, rng, spread)
    if excitation is None:
        program = random_torques(duration, rng)
    else:
        program = load_scenario(excitation).torques
        if max(w.t_to for w in program) < duration - 1e-9:
            raise ValueError(f"excitation: {excitation} drives {max(w.t_to for w in program):g} s, shorter than the "
                             f"{duration:g} s asked")
    run = dataclasses.replace(scenario, params=truth, torques=program, steps=int(round(duration / scenario.dt)))
    return simulate_log(run, SensorSet.default(), seed=seed), nominal, truth


def trial(names, duration, seed, spread=0.3, full_state=False, segment=0.5, max_nfev=60, excitation=None,
          start="regressor"):
    """One seeded fit: {"seed", "names", "truth", "start", "estimate", "sigma", "inside", "rms",
    "passed" (the residual check), "converged", "evaluations", "combinations" (`combination_errors`), "wall_time_s", "cpu_time_s" (the fit's, without the log's
    simulation), "load_average" (the machine's, over the last minute, at the fit's end)}."""
    log, nominal, truth = simulated_log(names, duration, seed, spread, excitation)
    started, cpu = time.perf_counter(), time.process_time()
    fit = identify(log, nominal, names, segment=segment, full_state=full_state, max_nfev=max_nfev, start=start)
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu
    true = np.array([truth.as_array()[PARAMETER_NAMES.index(n)] for n in fit.names])
    return {"seed": seed, "names": list(fit.names), "truth": true.tolist(), "start": fit.start.tolist(),
            "estimate": fit.estimate.tolist(), "sigma": fit.sigma.tolist(),
            "inside": (np.abs(fit.estimate - true) <= 1.959964 * fit.sigma).tolist(),
            "rms": fit.residual_check["rms"], "passed": fit.residual_check["passed"],
            "converged": fit.converged, "evaluations": fit.nfev,
            "combinations": combination_errors(fit, truth), "wall_time_s": wall, "cpu_time_s": cpu, "load_average": os.getloadavg()[0]}


def _trial(args):
    names, duration, seed, options = args
    return trial(names, duration, seed, **options)


def coverage(names, duration, fits, seed=0, jobs=1, done=None, **options):
    """`fits` trials with seeds seed, seed + 1, ... (`jobs` processes at once): the trials (in
    seed order) and, per entry, the fraction inside its interval, with the fraction of fits that
    pass their residual check.  `done(result)` is called with the result so far after each trial."""
    work = [(names, duration, seed + i, options) for i in range(fits)]
    trials = []
    if jobs > 1:
        import concurrent.futures
        with concurrent.futures.ProcessPoolExecutor(jobs) as pool:
            for future in concurrent.futures.as_completed([pool.submit(_trial, w) for w in work]):
                trials.append(future.result())
                if done is not None:
                    done(summarise(trials))
    else:
        for w in work:
            trials.append(_trial(w))
            if done is not None:
                done(summarise(trials))
    return summarise(trials)


def summarise(trials):
    """{"names", "coverage" (per entry), "coverage_passed" (the same over the fits that pass their
    residual check), "spread" (`error_spread`), "passed", "combinations" ({name: {"coverage", "within",
    "fits"}}: of the fits whose free entries move the combination, the fractions whose 95 % region
    holds its truth and whose estimate is within COMBINATION_TOLERANCE of it), "trials" (in seed
    order)} of some trials."""
    trials = sorted(trials, key=lambda t: t["seed"])
    inside = np.array([t["inside"] for t in trials], dtype=float)
    combos = {}
    for name in trials[0].get("combinations", {}):      # those the free entries move
        rows = [t["combinations"][name] for t in trials if t["combinations"][name]["inside"] is not None]
        if rows:
            combos[name] = {"coverage": float(np.mean([c["inside"] for c in rows])),
                            "within": float(np.mean([c["within"] for c in rows])), "fits": len(rows)}
    passed = np.array([t["passed"] for t in trials], dtype=bool)
    return {"names": trials[0]["names"], "coverage": inside.mean(axis=0).tolist(),
            "coverage_passed": inside[passed].mean(axis=0).tolist() if passed.any() else None,
            "spread": error_spread(trials),
            "passed": float(np.mean(passed)), "combinations": combos, "trials": trials}


def error_spread(trials):
    """{"std", "robust_std"}: per entry, the standard deviation over the trials of the error in
    units of the reported σ, (estimate − truth)/σ, and the same from the median absolute value
    (/0.6745), which a few far misses do not move.  Honest intervals give 1 for both; a std well
    above a robust std near 1 says a few fits went wrong, not that every interval is too narrow."""
    z = np.array([(np.asarray(t["estimate"]) - np.asarray(t["truth"])) / np.asarray(t["sigma"]) for t in trials])
    return {"std": np.std(z, axis=0).tolist(), "robust_std": (np.median(np.abs(z), axis=0) / 0.6745).tolist()}


def calibration_figure(result, path, title=""):
    """The calibration of the intervals: per entry, the fraction of fits whose 95 % interval holds
    the truth, against the band a correct 95 % interval stays in over that many fits (the binomial
    2.5–97.5 % quantiles); and the standardised errors (estimate − truth)/σ of every fit against the
    unit normal they follow when the intervals are honest."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import scipy.stats

    names, trials = result["names"], result["trials"]
    n = len(trials)
    z = np.array([(np.array(t["estimate"]) - np.array(t["truth"])) / np.array(t["sigma"]) for t in trials])
    low, high = scipy.stats.binom.ppf([0.025, 0.975], n, 0.95) / n
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    x = np.arange(len(names))
    ax1.axhspan(low, high, color="0.85", label=f"a correct 95 % interval, {n} fits")
    ax1.axhline(0.95, color="k", lw=0.6)
    ax1.axhline(0.90, color="C3", lw=0.8, ls="--", label="90 %")
    ax1.plot(x, result["coverage"], "o", color="C0", label="truth inside the interval")
    ax1.set_xticks(x, names, rotation=30)
    ax1.set_ylim(min(0.8, min(result["coverage"]) - 0.02), 1.005)
    ax1.set_ylabel("fraction of fits")
    ax1.legend(fontsize=7, loc="lower left")
    grid = np.linspace(-4, 4, 200)
    for k, name in enumerate(names):
        ax2.hist(np.clip(z[:, k], -4, 4), bins=np.linspace(-4, 4, 17), density=True, histtype="step", label=name)
    ax2.plot(grid, scipy.stats.norm.pdf(grid), "k", lw=1.2, label="unit normal")
    ax2.set_xlabel("(estimate − truth) / σ")
    ax2.legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv):
    """`python -m runtime identify-coverage --params NAMES [--fits N] [--duration S] [--full-state]
    [--excitation FILE] [--start regressor|nominal] [--jobs N] --out FILE [--figure PNG]`."""
    import argparse
    import pathlib
    import sys

    from ..cli_types import duration, whole_number

    parser = argparse.ArgumentParser(prog="python -m runtime identify-coverage", description=__doc__.split("\n\n")[0])
    parser.add_argument("--params", required=True, help="comma-separated entries to plant and fit")
    parser.add_argument("--fits", type=whole_number(1), default=20, help="number of seeded fits (20)")
    parser.add_argument("--duration", type=duration, default=30.0, help="each log's length [s] (30)")
    parser.add_argument("--seed", type=whole_number(0), default=0, help="the first seed (0)")
    parser.add_argument("--full-state", action="store_true", help="fit the logs' truth (a full-state log)")
    parser.add_argument("--excitation", metavar="FILE", help="a scenario whose torque program drives every log "
                                                             "(python -m runtime excite writes one); default: "
                                                             "random piecewise-constant torques")
    parser.add_argument("--start", choices=STARTS, default="regressor",
                        help="the fits' start: the regressor's first guess (default) or the nominal robot")
    parser.add_argument("--max-evaluations", type=whole_number(1), default=60,
                        help="each fit's evaluation budget, of each of a sensor fit's two joint stages (60)")
    parser.add_argument("--jobs", type=whole_number(1), default=1, help="fits run at once, one process each (1)")
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the JSON file of the results")
    parser.add_argument("--figure", type=pathlib.Path, help="also draw the calibration figure (PNG)")
    args = parser.parse_args(argv)
    def done(result):       # the results so far, so that an interrupted run keeps its fits
        write_text(args.out, json.dumps(result, indent=1) + "\n")
        if args.figure:
            calibration_figure(result, args.figure, _title(result, args))

    try:
        result = coverage(args.params, args.duration, args.fits, args.seed, jobs=args.jobs, done=done,
                          full_state=args.full_state, excitation=args.excitation, start=args.start,
                          max_nfev=args.max_evaluations)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for name, c in zip(result["names"], result["coverage"]):
        print(f"{name}: truth inside the 95 % interval in {100 * c:.0f} % of {args.fits} fits")
    for name, c in result["combinations"].items():
        print(f"{name}: truth inside the 95 % region in {100 * c['coverage']:.0f} %, within "
              f"{100 * COMBINATION_TOLERANCE:g} % in {100 * c['within']:.0f} % of {c['fits']} fits")
    print(f"residual check passed in {100 * result['passed']:.0f} % of {args.fits} fits")
    print(f"converged: {sum(t.get('converged', True) for t in result['trials'])} of {args.fits} fits")
    return 0


def _title(result, args):
    kind = "full-state" if args.full_state else "sensor"
    program = "a designed excitation" if args.excitation else "random torques"
    return (f"{len(result['trials'])} seeded {kind} fits of {args.duration:g} s logs of the battery-geared robot "
            f"({program})")
