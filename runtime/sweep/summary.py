"""What a finished sweep looks like: a summary figure and a percentile table of its results."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

from ..scenarios.plots import save_figure  # noqa: E402

#: Columns of the percentile table, with their units, and the percentiles shown.
TABLE_COLUMNS = (("end_x", "m"), ("end_y", "m"), ("path_length", "m"), ("max_distance", "m"),
                 ("max_shell_rate", "rad/s"), ("final_energy", "J"))
PERCENTILES = (1, 5, 25, 50, 75, 95, 99)


def _ok_columns(table):
    cols = table.to_pydict() if hasattr(table, "to_pydict") else table
    ok = np.asarray(cols["status"]) == 0
    return {k: np.asarray(v, dtype=float)[ok] if k != "status" else np.asarray(v) for k, v in cols.items()}, ok


def summary_figure(table, title, colour_by=None, colour_label=None, nominal=None, size=(9.5, 4.2)):
    """End points of the shell centre (coloured by the column `colour_by`, its colour bar labelled
    `colour_label`), the nominal end point `nominal` (x, y) if given, and the path lengths."""
    cols, ok = _ok_columns(table)
    fig, (ax, hist) = plt.subplots(1, 2, figsize=size, layout="constrained", width_ratios=(1.3, 1))
    colour = cols[colour_by] if colour_by else None
    dots = ax.scatter(cols["end_x"], cols["end_y"], c=colour, s=4, cmap="viridis", alpha=0.7, linewidths=0)
    if colour_by:
        fig.colorbar(dots, ax=ax, label=colour_label or colour_by)
    if nominal is not None:
        ax.plot(*nominal, "r*", ms=12, mec="k", label="nominal parameters")
        ax.legend(loc="best", fontsize=8)
    ax.set_xlabel("end point x [m]")
    ax.set_ylabel("end point y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    failed = int((~ok).sum())
    ax.set_title(f"{title}: {ok.sum()} samples" + (f" ({failed} failed, not shown)" if failed else ""))
    hist.hist(cols["path_length"], bins=50, color="C0")
    hist.set_xlabel("path length of the centre [m]")
    hist.set_ylabel("samples")
    return fig


def write_summary_figure(table, target, title, colour_by=None, colour_label=None, nominal=None):
    """Draws the sweep's summary figure of `table` and saves it to `target`."""
    save_figure(summary_figure(table, title, colour_by, colour_label, nominal), target)


def percentile_table(table):
    """Markdown table: percentiles of the end point and the metrics over the samples that ran."""
    cols, ok = _ok_columns(table)
    head = "| quantity | " + " | ".join(f"p{p}" for p in PERCENTILES) + " |"
    lines = [f"{int(ok.sum())} of {len(ok)} samples ran to the end.", "", head,
             "|---|" + "---:|" * len(PERCENTILES)]
    for name, unit in TABLE_COLUMNS:
        values = np.percentile(cols[name], PERCENTILES) if len(cols[name]) else [np.nan] * len(PERCENTILES)
        lines.append(f"| {name} [{unit}] | " + " | ".join(f"{v:.4g}" for v in values) + " |")
    return "\n".join(lines)
