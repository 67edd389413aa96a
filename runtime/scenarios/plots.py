"""The figures of a scenario run (PNG), after the paper's Figs. 2-7.

The centre's path on the plane (start marked with an open circle), the
relative inclinations θ_Y (yoke relative to the shell) and θ_P (pendulum
relative to the yoke), the absolute inclinations (yoke plane normal and
pendulum shaft against the vertical) and the energy.  Each function takes a
`ScenarioResult` (runtime/scenario.py) and returns a figure;
`save_figure` writes it atomically.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

from ..state import IDX_Q, absolute_inclinations, pendulum_angle, yoke_angle  # noqa: E402
from ..atomic import atomic_path  # noqa: E402

FIGURE_DPI = 100


def save_figure(fig, target, dpi=FIGURE_DPI):
    """Save a matplotlib figure as PNG atomically, then close it."""
    try:
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)
    finally:
        plt.close(fig)


def _title(result, what):
    return f"{result.scenario.name}: {what}"


def trajectory_figure(result, size=(5.0, 4.5)):
    """The centre's path on the plane, start as an open circle (Figs. 2, 4, 6)."""
    q = result.trajectory[:, IDX_Q]
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    ax.plot(q[:, 0], q[:, 1], lw=1.5, color="C0", label="centre q")
    ax.plot(q[0, 0], q[0, 1], "o", mfc="white", mec="k", ms=8, label="start")
    ax.plot(q[-1, 0], q[-1, 1], "s", color="C3", ms=5, label=f"end (t = {result.time[-1]:g} s)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(_title(result, "trajectory of the centre"), fontsize=10)
    return fig


def _torque_shading(ax, result):
    """Shade the time spans where a motor is on (yoke orange, pendulum green)."""
    t = result.time
    for column, color in ((0, "C1"), (1, "C2")):
        on = result.torques[:, column] != 0
        edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
        for start, stop in zip(edges[::2], edges[1::2]):
            ax.axvspan(t[start], t[min(stop, len(t) - 1)], color=color, alpha=0.12, lw=0)


def _time_figure(result, size):
    """A figure against time with the motor windows shaded; the caller draws, then `_finish_time_axes`."""
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    _torque_shading(ax, result)
    return fig, ax


def _finish_time_axes(ax, result, ylabel, what, legend=True):
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)
    ax.set_title(_title(result, what), fontsize=10)


def inclinations_figure(result, size=(6.0, 3.6)):
    """θ_Y (yoke relative to the shell) and θ_P (pendulum relative to the yoke) against time (Figs. 3, 7).

    The angles are unwrapped (continuous through ±π), so a joint that turns
    over shows as a ramp rather than a saw-tooth.
    """
    fig, ax = _time_figure(result, size)
    ax.plot(result.time, np.unwrap(yoke_angle(result.trajectory)), label="yoke rel. to shell θ_Y")
    ax.plot(result.time, np.unwrap(pendulum_angle(result.trajectory)), label="pendulum rel. to yoke θ_P")
    _finish_time_axes(ax, result, "angle [rad]", "relative inclinations")
    return fig


def absolute_inclinations_figure(result, size=(6.0, 3.6)):
    """Yoke plane normal and pendulum shaft against the vertical (Fig. 5)."""
    yoke, pendulum = absolute_inclinations(result.trajectory)
    fig, ax = _time_figure(result, size)
    ax.plot(result.time, yoke, label="yoke plane normal vs vertical")
    ax.plot(result.time, pendulum, "--", label="pendulum shaft vs vertical")
    _finish_time_axes(ax, result, "angle [rad]", "absolute inclinations")
    return fig


def energy_figure(result, size=(6.0, 3.6)):
    """The total energy of a result against time, as a matplotlib figure."""
    fig, ax = _time_figure(result, size)
    ax.plot(result.time, result.energy, color="k")
    _finish_time_axes(ax, result, "E [J]", "kinetic + potential energy", legend=False)
    return fig


#: Figure files written for every run, and the function drawing each.
FIGURES = {
    "trajectory.png": trajectory_figure,
    "inclinations.png": inclinations_figure,
    "absolute_inclinations.png": absolute_inclinations_figure,
    "energy.png": energy_figure,
}
