"""Outputs of a scenario run: trajectory.csv, summary.json, the figures (PNG) and the animation (GIF).

Every file is written atomically: first to a temporary file in the same
folder, then moved over the target with os.replace, so a reader (or a crash
half-way through rendering) never sees a partial file.

    files = write_outputs(result, pathlib.Path("out/t-shape"), gif=True)

The figures follow the paper's Figs. 2-7: the centre's path on the plane
(start marked with an open circle), the relative inclinations θ_Y (yoke
relative to the shell) and θ_P (pendulum relative to the yoke), the absolute
inclinations (yoke plane normal and pendulum shaft against the vertical) and
the energy.  Nothing here simulates: see runtime/scenario.py.
"""
import contextlib
import json
import os
import pathlib
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402

from .state import IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, pendulum_angle, yoke_angle  # noqa: E402

FIGURE_DPI = 100
GIF_SECONDS = 10.0
GIF_FPS = 20           # 50 ms per frame: GIF delays are whole centiseconds

#: Columns of trajectory.csv, in order (matrices row-major: R_S_12 is row 1, column 2).
CSV_COLUMNS = (["t", "q_x", "q_y", "q_z"]
               + [f"{m}_{i}{j}" for m in ("R_S", "R_Y", "R_P") for i in (1, 2, 3) for j in (1, 2, 3)]
               + ["w_S_x", "w_S_y", "w_S_z", "w_Y", "w_P", "u_Y", "u_P", "E"])


# -- atomic writing -------------------------------------------------------------------------
def _current_umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _current_umask()


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path next to `target`; on success move it onto `target`, on error delete it.

    The temporary name keeps the target's extension (writers such as Pillow
    choose the format from it) and starts with a dot.
    """
    target = pathlib.Path(target)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.stem}.", suffix=f".tmp{target.suffix}")
    os.close(fd)
    try:
        yield pathlib.Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)       # mkstemp makes 0600; give the file the usual permissions
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(target, text):
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")


def save_figure(fig, target, dpi=FIGURE_DPI):
    """Save a matplotlib figure as PNG atomically, then close it."""
    try:
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)
    finally:
        plt.close(fig)


# -- derived quantities ---------------------------------------------------------------------
def rotations(trajectory):
    """R_S, R_Y, R_P as arrays (N, 3, 3)."""
    return tuple(trajectory[:, idx].reshape(-1, 3, 3) for idx in (IDX_RS, IDX_RY, IDX_RP))


def _angle_to_vertical(axis):
    """Angle [rad] between unit vectors `axis` (N, 3) and e_z, accurate near 0 and π."""
    return np.arctan2(np.hypot(axis[:, 0], axis[:, 1]), axis[:, 2])


def absolute_inclinations(trajectory):
    """(yoke, pendulum) [rad] against the vertical, as in Fig. 5.

    Yoke: the angle between the normal of the yoke plane, R_S R_Y e_z, and e_z.
    Pendulum: the angle between the shaft, R_S R_Y R_P (−e_z), and −e_z.
    Both are unsigned, in [0, π].
    """
    R_S, R_Y, R_P = rotations(trajectory)
    yoke = R_S @ R_Y
    return _angle_to_vertical(yoke[:, :, 2]), _angle_to_vertical((yoke @ R_P)[:, :, 2])


def dissipated_power(result):
    """Power taken by the dampers [W] at every sample: k_S|ω_S|² + k_Y ω_Y² + k_P ω_P²."""
    p, x = result.scenario.params, result.trajectory
    return p.k_S * np.sum(x[:, IDX_WS] ** 2, axis=1) + p.k_Y * x[:, IDX_WY] ** 2 + p.k_P * x[:, IDX_WP] ** 2


def motor_power(result):
    """Power the motors put in [W] at every sample: u_Y ω_Y + u_P ω_P."""
    x = result.trajectory
    return result.torques[:, 0] * x[:, IDX_WY] + result.torques[:, 1] * x[:, IDX_WP]


def summary(result, extra_wall_time=None):
    """The numbers of summary.json (SI units, angles in rad)."""
    s, x = result.scenario, result.trajectory
    q = x[:, IDX_Q]
    excursion = np.hypot(q[:, 0] - q[0, 0], q[:, 1] - q[0, 1])
    yoke_abs, pendulum_abs = absolute_inclinations(x[-1:])
    dt = s.dt
    # Rectangle rule with the state at the start of each step, matching the explicit integrator.
    dissipated = float(np.sum(dissipated_power(result)[:-1]) * dt)
    motor_work = float(np.sum(motor_power(result)[:-1]) * dt)
    out = {
        "scenario": s.name,
        "source": s.source,
        "description": s.description,
        "method": s.method,
        "dt_s": s.dt,
        "steps": s.steps,
        "duration_s": s.duration,
        "params": s.params.as_dict(),
        "start_position_m": q[0, :2].tolist(),
        "final_position_m": q[-1, :2].tolist(),
        "final_displacement_m": float(excursion[-1]),
        "largest_excursion_m": float(excursion.max()),
        "largest_excursion_time_s": float(result.time[int(excursion.argmax())]),
        "final_inclinations_rad": {
            "yoke_relative_to_shell": float(yoke_angle(x[-1])),
            "pendulum_relative_to_yoke": float(pendulum_angle(x[-1])),
            "yoke_normal_to_vertical": float(yoke_abs[0]),
            "pendulum_shaft_to_vertical": float(pendulum_abs[0]),
        },
        "energy_J": {
            "initial": float(result.energy[0]),
            "final": float(result.energy[-1]),
            "dissipated": dissipated,
            "motor_work": motor_work,
            # initial + motor work − dissipated − final: zero for the exact flow, O(dt) for Lie–Euler.
            "balance_residual": float(result.energy[0] + motor_work - dissipated - result.energy[-1]),
        },
        "wall_time_s": {"simulation": result.wall_time_s},
    }
    if extra_wall_time:
        out["wall_time_s"].update(extra_wall_time)
    return out


# -- files ------------------------------------------------------------------------------------
def trajectory_table(result):
    """The rows of trajectory.csv as an array (steps+1, len(CSV_COLUMNS))."""
    x = result.trajectory
    return np.column_stack([result.time, x[:, IDX_Q], x[:, IDX_RS], x[:, IDX_RY], x[:, IDX_RP],
                            x[:, IDX_WS], x[:, IDX_WY], x[:, IDX_WP], result.torques, result.energy])


def write_csv(result, target):
    """trajectory.csv: one header line naming the columns, then one row per sample.

    Numbers are written in Python's shortest round-trip form (repr), so
    reading them back gives the simulated doubles exactly.
    """
    lines = [",".join(CSV_COLUMNS)]
    lines += [",".join(map(repr, row)) for row in trajectory_table(result).tolist()]
    write_text(target, "\n".join(lines) + "\n")


def write_summary(summary_dict, target):
    write_text(target, json.dumps(summary_dict, indent=2) + "\n")


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


# -- animation ----------------------------------------------------------------------------------
def _sphere_wireframe(r, meridians=8, parallels=5, points=41):
    """Polylines (body frame) of a sphere of radius r: meridians through the poles, then parallels."""
    s = np.linspace(0, 2 * np.pi, points)
    lines = []
    for phi in np.linspace(0, np.pi, meridians, endpoint=False):
        lines.append(r * np.stack([np.cos(phi) * np.sin(s), np.sin(phi) * np.sin(s), np.cos(s)], axis=1))
    for lat in np.linspace(-np.pi / 2, np.pi / 2, parallels + 2)[1:-1]:
        lines.append(r * np.stack([np.cos(lat) * np.cos(s), np.cos(lat) * np.sin(s),
                                   np.full_like(s, np.sin(lat))], axis=1))
    return lines


def write_gif(result, target, seconds=GIF_SECONDS, fps=GIF_FPS, frames=None, progress=None, dpi=80):
    """An animation of the robot rolling, `seconds` long (frames subsampled evenly from the run).

    Shell: wireframe sphere turning with R_S, a red marker fixed on it; yoke:
    the b × h rectangle in its plane; pendulum: a rod of length l from the
    centre along −z of its frame; the centre's path drawn on the plane behind.
    `progress(done_frames, total_frames)` is called as frames are drawn.
    """
    s, x = result.scenario, result.trajectory
    p = s.params
    count = frames if frames is not None else max(2, int(round(seconds * fps)))
    samples = np.unique(np.linspace(0, len(x) - 1, count).round().astype(int))
    R_S, R_Y, R_P = rotations(x)
    q = x[:, IDX_Q]

    wire = _sphere_wireframe(p.r)
    marker_body = p.r * np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0)
    yoke_body = np.array([[p.h / 2, p.b / 2, 0], [-p.h / 2, p.b / 2, 0], [-p.h / 2, -p.b / 2, 0],
                          [p.h / 2, -p.b / 2, 0], [p.h / 2, p.b / 2, 0]])
    rod_body = np.array([[0, 0, 0], [0, 0, -p.l]])

    lo = q[:, :2].min(axis=0) - 1.2 * p.r
    hi = q[:, :2].max(axis=0) + 1.2 * p.r
    height = 2.2 * p.r

    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(0, height)
    ax.set_zticks([0, p.r, 2 * p.r])
    # Equal scales on the three axes, so the sphere stays round.
    ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], height), zoom=1.2)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.view_init(elev=30, azim=-60)
    ax.plot([q[0, 0]], [q[0, 1]], [0], "o", mfc="white", mec="k")
    path, = ax.plot([], [], [], color="C0", lw=1.5)
    shell = [ax.plot([], [], [], color="0.55", lw=0.6)[0] for _ in wire]
    marker, = ax.plot([], [], [], "o", color="C3", ms=6)
    yoke, = ax.plot([], [], [], color="C1", lw=2.5)
    rod, = ax.plot([], [], [], color="C2", lw=2.5)
    bob, = ax.plot([], [], [], "o", color="C2", ms=6)
    label = ax.set_title("")

    def place(points, rotation, k):
        world = points @ rotation.T + q[k]
        return world[:, 0], world[:, 1], world[:, 2]

    def draw(frame):
        k = samples[frame]
        path.set_data_3d(q[:k + 1, 0], q[:k + 1, 1], np.zeros(k + 1))
        for line, points in zip(shell, wire):
            line.set_data_3d(*place(points, R_S[k], k))
        marker.set_data_3d(*place(marker_body[None], R_S[k], k))
        yoke_world = R_S[k] @ R_Y[k]
        yoke.set_data_3d(*place(yoke_body, yoke_world, k))
        rod_world = place(rod_body, yoke_world @ R_P[k], k)
        rod.set_data_3d(*rod_world)
        bob.set_data_3d(*(c[-1:] for c in rod_world))
        label.set_text(f"{s.name}   t = {result.time[k]:6.2f} s")
        if progress is not None:
            progress(frame + 1, len(samples))
        return [path, marker, yoke, rod, bob, label, *shell]

    animation = FuncAnimation(fig, draw, frames=len(samples), blit=False)
    try:
        with atomic_path(target) as tmp:
            animation.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    finally:
        plt.close(fig)


# -- everything for one run --------------------------------------------------------------------
#: Files a stopped run writes instead of the outputs (marked by name: never mistaken for a full run).
PARTIAL_FILES = ("trajectory.partial.csv", "summary.partial.json")

#: Every file name a run may write into its folder: a folder holding any of them "holds outputs".
OUTPUT_FILES = ("trajectory.csv", *FIGURES, "robot.gif", "summary.json", *PARTIAL_FILES)


def existing_outputs(folder):
    """The OUTPUT_FILES already present in `folder` (sorted; empty if the folder does not exist)."""
    folder = pathlib.Path(folder)
    return sorted(name for name in OUTPUT_FILES if (folder / name).exists())


def remove_stale(folder, keep):
    """Delete the OUTPUT_FILES in `folder` that are not in `keep` (paths just written), so that the
    folder holds only what the latest run produced.  Nothing else in the folder is touched."""
    keep = {pathlib.Path(k).name for k in keep}
    for name in OUTPUT_FILES:
        if name not in keep:
            with contextlib.suppress(FileNotFoundError):
                (pathlib.Path(folder) / name).unlink()


def write_outputs(result, folder, gif=True, progress=None):
    """Write trajectory.csv, the FIGURES, robot.gif (if `gif`) and summary.json (last) into `folder`.

    `progress(what, done, total)` reports the GIF's frames.  Returns the paths written.
    Whether an existing folder may be overwritten is the caller's decision (the CLI's --force).
    """
    started = time.perf_counter()
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = [folder / "trajectory.csv"]
    write_csv(result, written[-1])
    for filename, draw in FIGURES.items():
        written.append(folder / filename)
        save_figure(draw(result), written[-1])
    timings = {"csv_and_figures": time.perf_counter() - started}
    if gif:
        gif_started = time.perf_counter()
        written.append(folder / "robot.gif")
        write_gif(result, written[-1],
                  progress=None if progress is None else (lambda done, total: progress("gif", done, total)))
        timings["gif"] = time.perf_counter() - gif_started
    written.append(folder / "summary.json")
    write_summary(summary(result, timings), written[-1])
    return written


def write_partial_outputs(result, folder, stopped):
    """What a run stopped by a guard computed: trajectory.partial.csv (the valid rows, same columns as
    trajectory.csv) and summary.partial.json (the summary of those rows, plus "stopped": step, time
    and reason).  No figures.  `stopped` is the runtime.model.SimulationStopped exception."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    csv_path, summary_path = (folder / name for name in PARTIAL_FILES)
    write_csv(result, csv_path)
    info = summary(result)
    info["steps_computed"] = len(result.trajectory) - 1
    info["stopped"] = {"step": stopped.step, "time_s": stopped.time, "status": stopped.status,
                       "reason": str(stopped)}
    write_summary(info, summary_path)
    return [csv_path, summary_path]
