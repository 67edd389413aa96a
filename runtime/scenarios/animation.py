"""The animation of a scenario run (GIF): the robot rolling, drawn with matplotlib."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402

from ..state import IDX_Q, rotations  # noqa: E402
from .atomic import atomic_path  # noqa: E402

GIF_SECONDS = 10.0
GIF_FPS = 20           # 50 ms per frame: GIF delays are whole centiseconds


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
