"""`python -m runtime identify-coverage`: are the fit's 95 % intervals honest?  Seeded logs of a
robot whose parameters differ from the nominal ones, each fitted; the fraction of fits whose
interval holds the truth, per parameter (docs/identification.md, "Measured").

The robot is robots/battery-geared.toml; the truth scales the named entries by factors drawn
uniformly in [1 − spread, 1 + spread] per fit (the entries not named held at their true values); the
torques are piecewise constant, uniform within ±0.3 N m (yoke) and ±0.15 N m (pendulum), new every
0.25 s: a rich program while the excitation design is not in use.
"""
import dataclasses
import json
import time

import numpy as np

from ..atomic import write_text
from ..estimation.sense import simulate_log
from ..param_derivatives import PARAMETER_NAMES
from ..params import Params
from ..scenario import TorqueWindow, load_scenario
from ..sensor_set import SensorSet
from .fit import free_parameters, identify


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


def simulated_log(names, duration, seed, spread=0.3):
    """(log, nominal, truth): a seeded log of the battery-geared robot with the entries `names`
    planted within ±spread of its values, under `random_torques`, with the default sensor set."""
    rng = np.random.default_rng(seed)
    scenario = load_scenario("battery-geared")
    nominal = scenario.params
    truth = planted(nominal, names, rng, spread)
    run = dataclasses.replace(scenario, params=truth, torques=random_torques(duration, rng),
                              steps=int(round(duration / scenario.dt)))
    return simulate_log(run, SensorSet.default(), seed=seed), nominal, truth


def trial(names, duration, seed, spread=0.3, full_state=False, segment=0.5, max_nfev=20):
    """One seeded fit: {"names", "truth", "estimate", "sigma", "inside", "rms", "wall_time_s", "cpu_time_s"}."""
    log, nominal, truth = simulated_log(names, duration, seed, spread)
    started, cpu = time.perf_counter(), time.process_time()
    fit = identify(log, nominal, names, segment=segment, full_state=full_state, max_nfev=max_nfev)
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu
    true = np.array([truth.as_array()[PARAMETER_NAMES.index(n)] for n in fit.names])
    return {"names": list(fit.names), "truth": true.tolist(), "estimate": fit.estimate.tolist(),
            "sigma": fit.sigma.tolist(), "inside": (np.abs(fit.estimate - true) <= 1.959964 * fit.sigma).tolist(),
            "rms": fit.residual_check["rms"], "wall_time_s": wall, "cpu_time_s": cpu}


def coverage(names, duration, fits, seed=0, **options):
    """`fits` trials with seeds seed, seed + 1, ...: the trials and, per entry, the fraction inside."""
    trials = [trial(names, duration, seed + i, **options) for i in range(fits)]
    inside = np.array([t["inside"] for t in trials], dtype=float)
    return {"names": trials[0]["names"], "coverage": inside.mean(axis=0).tolist(), "trials": trials}


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
    """`python -m runtime identify-coverage --params NAMES [--fits N] [--duration S] [--full-state] --out FILE
    [--figure PNG]`."""
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
    parser.add_argument("--out", required=True, type=pathlib.Path, help="the JSON file of the results")
    parser.add_argument("--figure", type=pathlib.Path, help="also draw the calibration figure (PNG)")
    args = parser.parse_args(argv)
    try:
        result = coverage(args.params, args.duration, args.fits, args.seed, full_state=args.full_state)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    write_text(args.out, json.dumps(result, indent=1) + "\n")
    if args.figure:
        calibration_figure(result, args.figure, _title(result, args))
    for name, c in zip(result["names"], result["coverage"]):
        print(f"{name}: truth inside the 95 % interval in {100 * c:.0f} % of {args.fits} fits")
    return 0


def _title(result, args):
    kind = "full-state" if args.full_state else "sensor"
    return f"{len(result['trials'])} seeded {kind} fits of {args.duration:g} s logs of the battery-geared robot"
