"""What a robustness sweep found: success fractions with their confidence intervals, the distribution,
the worst runs (with what reruns them) and which perturbation goes with failure; and its figure."""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from scipy import stats  # noqa: E402

from ..scenarios.plots import save_figure  # noqa: E402
from .robustness import APART_REASONS  # noqa: E402

#: Confidence level of the success fractions' intervals (Clopper-Pearson, exact).
CONFIDENCE = 0.95
#: Worst runs listed per task and controller.
WORST = 3
#: An estimate whose position RMS exceeds this [m] is counted as off (the filter lost the robot).
ESTIMATE_OFF_M = 0.03
#: The causes a failed run is counted under (`failure_causes`), in the order they are tried.
FAILURES = ("stopped", "estimate lost", "stall", "offset")
#: Inputs whose rank correlation with the cross-track RMS is reported (and derived ones, below).
CAUSES = ("m_S", "m_b", "m_h", "m_P", "k_S", "k_Y", "k_P", "c_P_dx_m", "c_P_dy_m", "c_P_dz_m")


def _columns(table):
    cols = table.to_pydict() if hasattr(table, "to_pydict") else table
    return {k: np.asarray(v) for k, v in cols.items()}


def derived_inputs(cols, spec):
    """{name: values} of the inputs a cause is sought in: the drawn factors and shifts, the slope's
    size |slope_fraction|, its part across a line (|slope_fraction sin(line heading − up-slope)|,
    NaN off the line), and the start errors' sizes."""
    out = {name: cols[name].astype(float) for name in CAUSES}
    out["|slope_fraction|"] = np.abs(cols["slope_fraction"])
    across = np.full(len(cols["sample"]), np.nan)
    for t, name in enumerate(spec.tasks):
        from .robustness import _task
        spec_ref = _task(name, spec.controllers[0], spec.sensors, spec.duration).reference_spec
        if spec_ref["kind"] == "line":
            on = cols["task"] == t
            angle = spec_ref.get("heading", 0.0) + cols["slope_direction_rad"][on]
            across[on] = np.abs(cols["slope_fraction"][on] * np.sin(angle))
    out["|slope across the line|"] = across
    out["|start position error|"] = np.hypot(cols["dx0_m"], cols["dy0_m"])
    out["|start heading error|"] = np.abs(cols["dpsi0_rad"])
    return out


def group_stats(table, spec):
    """One dict per (task, controller): runs, counted apart, stopped, successes among the rest, the
    fraction and its interval, RMS percentiles, the worst runs and the inputs that rank with the RMS."""
    cols = _columns(table)
    inputs = derived_inputs(cols, spec)
    out = []
    for t, task in enumerate(spec.tasks):
        for c, kind in enumerate(spec.controllers):
            on = (cols["task"] == t) & (cols["controller"] == c)
            apart = on & (cols["counted_apart"] != 0)
            counted = on & ~apart
            n, k = int(counted.sum()), int((cols["success"][counted] == 1).sum())
            ci = stats.binomtest(k, n).proportion_ci(CONFIDENCE, method="exact") if n else None
            rms = cols["cross_track_rms_m"][counted]
            ran = np.isfinite(rms)
            order = np.argsort(np.where(np.isfinite(rms), -rms, -np.inf))   # stopped runs first, then worst RMS
            idx = np.flatnonzero(counted)[order[:WORST]]
            causes = []
            if ran.sum() > 2:
                for name, values in inputs.items():
                    v = values[counted][ran]
                    if np.all(np.isfinite(v)) and np.ptp(v) > 0:
                        rho = stats.spearmanr(v, rms[ran]).statistic
                        causes.append((name, float(rho)))
                causes.sort(key=lambda nr: -abs(nr[1]))
            out.append({"task": task, "controller": kind, "runs": int(on.sum()), "apart": int(apart.sum()),
                        "stopped": int((cols["status"][counted] != 0).sum()), "n": n, "success": k,
                        "fraction": k / n if n else math.nan, "ci": (ci.low, ci.high) if ci else (math.nan,) * 2,
                        "rms": rms[ran], "progress": cols["progress"][counted],
                        "estimate_off": int((cols["estimate_position_rms_m"][counted] > ESTIMATE_OFF_M).sum()),
                        "worst": [{name: cols[name][i].item() for name in cols} for i in idx],
                        "causes": causes[:3], "apart_reasons": {code: int((cols["counted_apart"][on] == code).sum())
                                                                for code in APART_REASONS},
                        "failures": failure_causes(cols, counted, spec)})
    return out


def failure_causes(cols, rows, spec):
    """{cause: runs} of the failed runs among `rows` (a mask), each under its first cause:
    "stopped" (a kernel refused a state), "estimate lost" (the filter's position RMS above
    ESTIMATE_OFF_M), "stall" (progress below the coverage), "offset" (the RMS above the limit)."""
    failed = rows & (cols["success"] == 0)
    stopped = failed & (cols["status"] != 0)
    lost = failed & ~stopped & (cols["estimate_position_rms_m"] > ESTIMATE_OFF_M)
    stall = failed & ~stopped & ~lost & (cols["progress"] < spec.coverage)
    offset = failed & ~stopped & ~lost & ~stall
    return {"stopped": int(stopped.sum()), "estimate lost": int(lost.sum()), "stall": int(stall.sum()),
            "offset": int(offset.sum())}


def _mm(value):
    return "—" if not np.isfinite(value) else f"{1e3 * value:.1f}"


def summary_text(table, spec, command):
    """Markdown: the table of success fractions, the RMS distribution, the worst runs, the causes."""
    groups = group_stats(table, spec)
    plants = len(np.unique(_columns(table)["plant"]))
    lines = [f"{len(_columns(table)['sample'])} runs: {plants} plants, each on every task and controller "
             f"(seed {spec.seed}).  Success: second-half cross-track RMS ≤ {1e3 * spec.rms_m:g} mm and progress "
             f"along the path ≥ {100 * spec.coverage:g} % of the reference's; {100 * CONFIDENCE:g} % intervals "
             "Clopper–Pearson.", "",
             "| task | controller | runs | counted apart | stopped | succeed | fraction | 95 % interval | "
             "RMS p50 [mm] | p95 [mm] | max [mm] | progress p5 | least progress | estimate off > 3 cm |",
             "|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    for g in groups:
        rms = g["rms"]
        pct = np.percentile(rms, [50, 95]) if len(rms) else [math.nan] * 2
        low, high = g["ci"]
        done = g["progress"][np.isfinite(g["progress"])]
        least, p5 = (done.min(), np.percentile(done, 5)) if len(done) else (math.nan, math.nan)
        lines.append(f"| {g['task']} | {g['controller']} | {g['runs']} | {g['apart']} | {g['stopped']} | "
                     f"{g['success']} / {g['n']} | {100 * g['fraction']:.1f} % | "
                     f"{100 * low:.1f}–{100 * high:.1f} % | {_mm(pct[0])} | {_mm(pct[1])} | "
                     f"{_mm(rms.max() if len(rms) else math.nan)} | {p5:.3f} | {least:.3f} | {g['estimate_off']} |")
    lines += ["", "Why runs are counted apart, and why the others fail (each failure under its first cause: a "
              "stopped run, then an estimate more than "
              f"{1e3 * ESTIMATE_OFF_M:g} mm off, a stall below {100 * spec.coverage:g} % progress, an offset):", "",
              "| task | controller | " + " | ".join(f"apart: {r}" for r in APART_REASONS.values()) + " | "
              + " | ".join(FAILURES) + " |", "|---|---|" + "---:|" * (len(APART_REASONS) + len(FAILURES))]
    for g in groups:
        lines.append(f"| {g['task']} | {g['controller']} | "
                     + " | ".join(str(g["apart_reasons"][code]) for code in APART_REASONS) + " | "
                     + " | ".join(str(g["failures"][f]) for f in FAILURES) + " |")
    lines += ["", f"Worst runs (rerun one: `{command} --rerun SAMPLE`):", "",
              "| task | controller | sample | plant | RMS [mm] | progress | estimate's position RMS [mm] | "
              "slope [fraction of limit] | c_P shift [mm] | masses | dampings | start error [mm, deg] |",
              "|---|---|---:|---:|---:|---:|---:|---:|---|---|---|---|"]
    for g in groups:
        for w in g["worst"]:
            masses = ", ".join(f"{n} {w[n]:.2f}" for n in ("m_S", "m_b", "m_h", "m_P"))
            damp = ", ".join(f"{n} {w[n]:.2f}" for n in ("k_S", "k_Y", "k_P"))
            shift = ", ".join(f"{1e3 * w[n]:+.1f}" for n in ("c_P_dx_m", "c_P_dy_m", "c_P_dz_m"))
            lines.append(f"| {g['task']} | {g['controller']} | {w['sample']} | {w['plant']} | "
                         f"{_mm(w['cross_track_rms_m'])} | {w['progress']:.3f} | "
                         f"{_mm(w['estimate_position_rms_m'])} | {w['slope_fraction']:+.3f} "
                         f"(direction {math.degrees(w['slope_direction_rad']):.0f}°) | {shift} | {masses} | {damp} | "
                         f"{1e3 * w['dx0_m']:+.0f}, {1e3 * w['dy0_m']:+.0f}, {math.degrees(w['dpsi0_rad']):+.1f} |"
                         + ("" if w["status"] == 0 else f" status {w['status']}"))
    lines += ["", "Inputs that rank with the cross-track RMS (Spearman's ρ over the runs that ran):", ""]
    for g in groups:
        causes = "; ".join(f"{name} {rho:+.2f}" for name, rho in g["causes"]) or "—"
        lines.append(f"* {g['task']}, {g['controller']}: {causes}")
    return "\n".join(lines)


def robustness_figure(table, spec, size=(11.0, 4.0)):
    """Left: the distribution of the cross-track RMS per task and controller (the success limit
    marked); middle: RMS against the slope's size; right: success fractions with their intervals."""
    groups = group_stats(table, spec)
    cols = _columns(table)
    fig, (ecdf, slope, bars) = plt.subplots(1, 3, figsize=size, layout="constrained")
    for i, g in enumerate(groups):
        label = f"{g['task']}, {g['controller']}"
        rms = np.sort(g["rms"])
        if len(rms):
            ecdf.step(1e3 * rms, np.arange(1, len(rms) + 1) / len(rms), where="post", label=label,
                      color=f"C{i}")
        t, c = spec.tasks.index(g["task"]), spec.controllers.index(g["controller"])
        on = (cols["task"] == t) & (cols["controller"] == c)
        slope.scatter(np.abs(cols["slope_fraction"][on]), 1e3 * cols["cross_track_rms_m"][on], s=6,
                      color=f"C{i}", alpha=0.6, linewidths=0)
        low, high = g["ci"]
        bars.bar(i, 100 * g["fraction"], color=f"C{i}")
        bars.errorbar(i, 100 * g["fraction"], yerr=[[100 * (g["fraction"] - low)], [100 * (high - g["fraction"])]],
                      color="k", capsize=3)
    for ax in (ecdf, slope):
        ax.axvline(1e3 * spec.rms_m, color="0.4", ls="--", lw=0.8) if ax is ecdf else \
            ax.axhline(1e3 * spec.rms_m, color="0.4", ls="--", lw=0.8)
    ecdf.set_xscale("log")              # the RMS spans from the noise floor to runs the filter lost
    slope.set_yscale("log")
    ecdf.set_xlabel("second-half cross-track RMS [mm]")
    ecdf.set_ylabel("fraction of runs")
    ecdf.legend(fontsize=7)
    slope.set_xlabel(f"|slope| [fraction of the plant's climbing limit]")
    slope.set_ylabel("second-half cross-track RMS [mm]")
    bars.set_xticks(range(len(groups)), [f"{g['task']}\n{g['controller']}\n{g['success']}/{g['n']}"
                                         for g in groups], fontsize=7)
    bars.axhline(95, color="0.4", ls="--", lw=0.8)
    bars.set_ylabel(f"runs that succeed [%] ({100 * CONFIDENCE:g} % interval)")
    bars.set_ylim(0, 100)
    runs = len(cols["sample"])
    fig.suptitle(f"{spec.name}: {runs} runs on {len(np.unique(cols['plant']))} plants"
                 + ("" if runs >= spec.samples else f" (unfinished: {spec.samples} runs in all)"), fontsize=10)
    return fig


def write_robustness_figure(table, spec, target):
    """Draws the robustness figure of `table` and saves it to `target`."""
    save_figure(robustness_figure(table, spec), target)
