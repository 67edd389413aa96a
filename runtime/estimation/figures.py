"""`python -m runtime estimation-figures [--out DIR]`: regenerate the figures of docs/estimation.md.

The frames and the default IMU mount (drawn from runtime.sensors.DEFAULT_MOUNT and the state's
attitudes, not by hand), and the estimate ± 3σ against the truth on the shipped circle, with the
default set and without fixes (seed 0, the first 40 s).  The consistency figures come from
`python -m runtime consistency` (`make consistency` copies them here).
"""
import argparse
import dataclasses
import pathlib

import numpy as np

DEFAULT_OUT = pathlib.Path(__file__).resolve().parents[2] / "docs" / "figures"
#: The estimate figures: (sensor set, file name).
ESTIMATES = (("default", "estimate-circle-default.png"), ("imu-encoders", "estimate-circle-imu-encoders.png"))
#: How long the estimate figures' runs are [s] (seed 0).
ESTIMATE_SECONDS = 40.0


def frames_figure(path, yoke_angle=0.5):
    """The inertial frame, the shell's, the yoke's (turned by `yoke_angle` about the shell's x axis)
    and the IMU's at the default mount, with gravity and the accelerometer's reading at rest."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..params import Params
    from ..sensors import DEFAULT_MOUNT
    from ..so3 import rot_x
    r = Params.paper_simulation().r
    R_S = np.eye(3)
    R_Y = R_S @ rot_x(yoke_angle)
    centre = np.array([0.0, 0.0, r])
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    u, v = np.mgrid[0:2 * np.pi:40j, 0:np.pi:20j]
    ax.plot_wireframe(centre[0] + r * np.cos(u) * np.sin(v), centre[1] + r * np.sin(u) * np.sin(v),
                      centre[2] + r * np.cos(v), color="0.85", lw=0.4)
    xs = np.linspace(-1.4 * r, 1.4 * r, 2)
    X, Y = np.meshgrid(xs, xs)
    ax.plot_surface(X, Y, 0 * X, color="tan", alpha=0.25)

    def frame(origin, R, length, colour, name):
        for k, axis in enumerate("xyz"):
            tip = origin + length * R[:, k]
            ax.quiver(*origin, *(length * R[:, k]), color=colour, arrow_length_ratio=0.12, lw=1.6)
            ax.text(*(tip + 0.02 * R[:, k]), f"{axis}{name}", color=colour, fontsize=9)

    frame(np.array([-1.3 * r, -1.3 * r, 0.0]), np.eye(3), 0.8 * r, "k", "")   # drawn aside: axes, not origin
    frame(centre, R_S, 1.1 * r, "tab:blue", "_S")
    frame(centre, R_Y, 0.7 * r, "tab:orange", "_Y")
    mount = DEFAULT_MOUNT
    R_B = R_Y                                                     # the default IMU sits on the yoke
    imu = centre + R_B @ np.asarray(mount.lever)
    ax.plot(*np.column_stack([centre, imu]), color="tab:red", lw=1)
    frame(imu, R_B @ np.asarray(mount.rotation), 0.35 * r, "tab:red", "_IMU")
    ax.quiver(*(centre + [0.9 * r, 0.0, 0.6 * r]), 0, 0, -0.4 * r, color="tab:purple", lw=1.6)
    ax.text(*(centre + [0.95 * r, 0.0, 0.35 * r]), "g", color="tab:purple")
    ax.text2D(0.02, 0.95, "inertial (black, drawn aside): x up the slope, z the floor's normal\n"
                          f"shell S (blue) at q; yoke Y (orange) = R_S R_Y, θ_Y = {yoke_angle:g} rad about x_S\n"
                          f"IMU (red) on the yoke at ρ = ({', '.join(f'{v:g}' for v in mount.lever)}) m, axes along the yoke's;\n"
                          "at rest the accelerometer reads +g along the upward normal",
              transform=ax.transAxes, fontsize=8, va="top")
    ax.set_box_aspect((1, 1, 1))
    lim = 1.4 * r
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_zlim(0, 2 * lim)
    ax.view_init(elev=18, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def estimate_figure(log, result, path, title):
    """Each estimated quantity's error (position, tilt, heading, joints, rates, biases) with the
    filter's ±3σ against the truth of `log`, at the rows where `result` (`estimate_log` with
    `covariance_every`) kept its covariance."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..model import Model
    from .consistency import COMPONENTS, transform
    from .estimate import claimed_params
    model = Model(claimed_params(log))
    rows = result.P_rows
    i = np.clip(np.searchsorted(log.truth.t, result.t[rows]), 0, len(log.truth.t) - 1)
    keep = np.abs(log.truth.t[i] - result.t[rows]) < 1e-9
    rows, i = rows[keep], i[keep]
    t, x = result.t[rows], result.x[rows]
    d = model.local(x, log.truth_states()[i])
    db = log.truth_biases()[i] - result.biases[rows]
    T = transform(x, log.sensors.imu.mount.body)
    e = np.einsum("nij,nj->ni", T, np.column_stack([d, db]))
    sigma = np.sqrt(np.diagonal(T @ result.P[keep] @ np.transpose(T, (0, 2, 1)), axis1=-2, axis2=-1))
    panels = (("q_x", "q_y"), ("tilt_x", "tilt_y"), ("heading",), ("theta_Y", "theta_P"),
              ("w_S_x", "w_Y"), ("b_g_z", "b_a_x"))
    units = ("m", "rad", "rad", "rad", "rad/s", "rad/s, m/s²")
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 1.8 * len(panels)), sharex=True)
    for ax, names, unit in zip(axes, panels, units):
        ax.set_ylabel(unit)
        for name, colour in zip(names, ("tab:blue", "tab:orange")):
            k = COMPONENTS.index(name)
            ax.plot(t, e[:, k], lw=0.7, color=colour, label=f"{name} error")
            ax.fill_between(t, -3 * sigma[:, k], 3 * sigma[:, k], color=colour, alpha=0.15)
        ax.legend(loc="upper right", fontsize=7, ncol=2)
        ax.set_ylim(*np.percentile(np.concatenate([-4 * sigma[len(t) // 10:, [COMPONENTS.index(n) for n in names]],
                                                   4 * sigma[len(t) // 10:, [COMPONENTS.index(n) for n in names]]]),
                                   [1, 99]))
    axes[0].set_title(title + " (shaded: ±3σ)", fontsize=10)
    axes[-1].set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv):
    """`python -m runtime estimation-figures`: rewrite the frames and the estimate figures."""
    from ..sensor_set import load_sensor_set
    from .estimate import estimate_log
    from .sense import load_run, simulate_log
    parser = argparse.ArgumentParser(prog="python -m runtime estimation-figures", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=DEFAULT_OUT, help=f"folder (default: {DEFAULT_OUT})")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    frames_figure(args.out / "estimation-frames.png")
    print(args.out / "estimation-frames.png")
    task = load_run("circle")
    task = dataclasses.replace(task, scenario=task.scenario.with_overrides(
        steps=round(ESTIMATE_SECONDS / task.scenario.dt)))
    for name, file in ESTIMATES:
        log = simulate_log(task, load_sensor_set(name), seed=0)
        estimate_figure(log, estimate_log(log, covariance_every=10), args.out / file, f"circle, sensor set '{name}', seed 0")
        print(args.out / file)
    return 0
