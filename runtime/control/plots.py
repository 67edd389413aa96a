"""Figure of one closed-loop run: path against reference, errors, torques."""
import numpy as np

from ..state import IDX_Q
from .geometry import forward_speed, heading, wrap_angle


def plot_run(result, reference, task, path):
    """Draws a closed-loop run (path, speed and heading, torques) against its reference and saves it to
    `path`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    x = result.trajectory
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(15, 4.5))
    q = x[:, IDX_Q]
    if reference.is_path:
        end = np.searchsorted(reference.s, reference.s[reference.nearest(q[-1, :2], None)[0]] + 0.5)
        a.plot(reference.points[:end, 0], reference.points[:end, 1], "k--", lw=1, label="reference")
    a.plot(q[:, 0], q[:, 1], label="robot")
    a.plot(q[0, 0], q[0, 1], "go")
    a.set_aspect("equal"), a.set_xlabel("x [m]"), a.set_ylabel("y [m]"), a.legend(), a.set_title(task.name)
    every = max(1, len(x) // 2000)
    t, xs = result.time[::every], x[::every]
    if reference.is_path:
        b.plot(t, reference.cross_track(xs[:, IDX_Q][:, :2]), label="cross-track [m]")
    else:
        b.plot(t, np.degrees(wrap_angle(reference.heading - heading(xs))), label="heading error [deg]")
    b.plot(t, forward_speed(xs, task.plant_params.r) - reference.speed, label="speed error [m/s]")
    b.axhline(0, color="k", lw=0.5), b.set_xlabel("t [s]"), b.legend(), b.set_title("errors")
    c.plot(result.time, result.torques[:, 0], label="u_Y")
    c.plot(result.time, result.torques[:, 1], label="u_P")
    for s in (-1, 1):
        c.axhline(s * task.u_max, color="r", lw=0.5, ls=":")
    c.set_xlabel("t [s]"), c.set_ylabel("torque [N m]"), c.legend(), c.set_title(f"torques ({task.controller_kind})")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def plot_estimate(result, reference, task, path):
    """Draws a run on sensors: the cross-track error the controller believed (on the estimate)
    against the true one (or, without a path, the estimated path against the true one), and the
    estimate's position and heading errors; saves it to `path`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    per = round((len(result.time) - 1) / len(result.control_time))
    true, est, t = result.trajectory[:-1:per], result.estimates, result.control_time
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    if reference.is_path:
        a.plot(t, reference.cross_track(true[:, IDX_Q][:, :2]), label="true")
        a.plot(t, reference.cross_track(est[:, IDX_Q][:, :2]), lw=1, label="on the estimate")
        a.set_xlabel("t [s]"), a.set_ylabel("cross-track [m]")
    else:
        a.plot(true[:, IDX_Q][:, 0], true[:, IDX_Q][:, 1], label="true path")
        a.plot(est[:, IDX_Q][:, 0], est[:, IDX_Q][:, 1], lw=1, label="estimated path")
        a.set_aspect("equal"), a.set_xlabel("x [m]"), a.set_ylabel("y [m]")
    a.legend(), a.set_title(f"{task.name} ({task.controller_kind})")
    b.plot(t, np.linalg.norm(est[:, IDX_Q][:, :2] - true[:, IDX_Q][:, :2], axis=1), label="position [m]")
    b.set_xlabel("t [s]"), b.set_ylabel("m"), b.set_title("estimate − truth")
    c = b.twinx()
    c.plot(t, np.degrees(np.abs(wrap_angle(heading(est) - heading(true)))), color="C1", lw=1, label="heading [deg]")
    c.set_ylabel("deg")
    b.legend(handles=b.lines + c.lines)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
