"""The animation of a scenario run (GIF): the robot rolling, drawn with matplotlib.

Why it takes about a second and not half a minute: the camera and the axes
never move, so the axes, panes, ticks and labels are drawn once and kept as a
bitmap; each frame restores that bitmap and draws only the moving artists on
it (blitting), reads the pixels straight from the canvas (no second draw, as
matplotlib's animation writers do), and maps them onto one palette chosen
once for the whole animation (no per-frame colour quantization).  The
changing title (the time) is written with Pillow in matplotlib's own font, at
the place and size matplotlib gives it: laying out text was 40 % of a
matplotlib frame (profiled), Pillow does it in a fraction of a millisecond.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib import font_manager  # noqa: E402
from PIL import Image, ImageDraw, ImageFont  # noqa: E402

from ..state import IDX_Q, rotations  # noqa: E402
from ..atomic import atomic_path  # noqa: E402
from .outline import rod_tip, yoke_outline  # noqa: E402

GIF_SECONDS = 10.0
GIF_FPS = 20           # 50 ms per frame: GIF delays are whole centiseconds
GIF_DPI = 80           # 5 in x 80 dpi: 400 x 400 pixels
#: The path is drawn through at most this many samples (a polyline of 10^4 points adds nothing visible).
PATH_POINTS = 1000


def frame_samples(sample_count, seconds=GIF_SECONDS, fps=GIF_FPS, frames=None):
    """Indices of the samples shown, one per frame, spread evenly over the run (first and last included)."""
    count = frames if frames is not None else max(2, int(round(seconds * fps)))
    return np.unique(np.linspace(0, sample_count - 1, count).round().astype(int))


def _sphere_wireframe(r, meridians=8, parallels=5, points=41):
    """Points (body frame) of a sphere of radius r: meridians through the poles, then parallels, each a
    polyline, separated by rows of NaN (a break in the line), so that one artist draws them all."""
    s = np.linspace(0, 2 * np.pi, points)
    lines = []
    for phi in np.linspace(0, np.pi, meridians, endpoint=False):
        lines.append(r * np.stack([np.cos(phi) * np.sin(s), np.sin(phi) * np.sin(s), np.cos(s)], axis=1))
    for lat in np.linspace(-np.pi / 2, np.pi / 2, parallels + 2)[1:-1]:
        lines.append(r * np.stack([np.cos(lat) * np.cos(s), np.cos(lat) * np.sin(s),
                                   np.full_like(s, np.sin(lat))], axis=1))
    gap = np.full((1, 3), np.nan)
    return np.concatenate([part for line in lines for part in (line, gap)][:-1])


class RobotScene:
    """The robot of one run in a fixed 3-D view; `render(k)` gives the picture of sample k as RGB pixels.

    Shell: wireframe sphere turning with R_S, a red marker fixed on it; yoke:
    the b × h rectangle in its plane; pendulum: a rod of length l from the
    centre along −z of its frame; the centre's path drawn on the plane behind.
    """

    def __init__(self, result, dpi=GIF_DPI, size=(5, 5)):
        self.result = result
        x, p = result.trajectory, result.scenario.params
        self.R_S, self.R_Y, self.R_P = rotations(x)
        self.q = x[:, IDX_Q]
        q = self.q
        self.wire = _sphere_wireframe(p.r)
        self.marker_body = p.r * np.array([[1.0, 1.0, 1.0]]) / np.sqrt(3.0)
        self.yoke_body = yoke_outline(p)
        self.rod_body = np.array([np.zeros(3), rod_tip(p)])

        lo = q[:, :2].min(axis=0) - 1.2 * p.r
        hi = q[:, :2].max(axis=0) + 1.2 * p.r
        height = 2.2 * p.r
        self.fig = plt.figure(figsize=size, dpi=dpi)
        ax = self.ax = self.fig.add_subplot(projection="3d")
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
        # The moving artists are "animated": a full draw leaves them out, so the background holds none.
        self.path, = ax.plot([], [], [], color="C0", lw=1.5, animated=True)
        self.shell, = ax.plot([], [], [], color="0.55", lw=0.6, animated=True)
        self.marker, = ax.plot([], [], [], "o", color="C3", ms=6, animated=True)
        self.yoke, = ax.plot([], [], [], color="C1", lw=2.5, animated=True)
        self.rod, = ax.plot([], [], [], color="C2", lw=2.5, animated=True)
        self.bob, = ax.plot([], [], [], "o", color="C2", ms=6, animated=True)
        self.moving = [self.path, self.shell, self.marker, self.yoke, self.rod, self.bob]
        # The title: matplotlib places it (centre, baseline) once; Pillow writes it on every frame.
        title = ax.set_title(self._title(len(self.q) - 1), animated=True)
        self.fig.canvas.draw()                       # the one full draw: it also fixes the projection ax.M
        self.background = self.fig.canvas.copy_from_bbox(self.fig.bbox)
        renderer = self.fig.canvas.get_renderer()
        box = title.get_window_extent(renderer)
        properties = title.get_fontproperties()
        self.title_font = ImageFont.truetype(font_manager.findfont(properties),
                                             properties.get_size_in_points() * dpi / 72)
        _, _, descent = renderer.get_text_width_height_descent(title.get_text(), properties, ismath=False)
        self.title_anchor = (0.5 * (box.x0 + box.x1), self.fig.bbox.height - box.y0 - descent)

    def _title(self, k):
        return f"{self.result.scenario.name}   t = {self.result.time[k]:6.2f} s"

    def _place(self, points, rotation, k):
        world = points @ rotation.T + self.q[k]
        return world[:, 0], world[:, 1], world[:, 2]

    def render(self, k):
        """The picture of sample k: an RGB image (PIL)."""
        q, R_S = self.q, self.R_S[k]
        stride = max(1, k // PATH_POINTS)
        shown = np.append(np.arange(0, k, stride), k)
        self.path.set_data_3d(q[shown, 0], q[shown, 1], np.zeros(len(shown)))
        self.shell.set_data_3d(*self._place(self.wire, R_S, k))
        self.marker.set_data_3d(*self._place(self.marker_body, R_S, k))
        yoke_world = R_S @ self.R_Y[k]
        self.yoke.set_data_3d(*self._place(self.yoke_body, yoke_world, k))
        rod_world = self._place(self.rod_body, yoke_world @ self.R_P[k], k)
        self.rod.set_data_3d(*rod_world)
        self.bob.set_data_3d(*(c[-1:] for c in rod_world))

        canvas = self.fig.canvas
        canvas.restore_region(self.background)
        for artist in self.moving:
            self.ax.draw_artist(artist)
        picture = Image.fromarray(np.asarray(canvas.buffer_rgba())).convert("RGB")
        ImageDraw.Draw(picture).text(self.title_anchor, self._title(k), fill="black", font=self.title_font,
                                     anchor="ms")
        return picture

    def close(self):
        """Closes the scene's figure."""
        plt.close(self.fig)


def _palette_for(pictures):
    """One palette (a 'P' image) for the whole animation, from pictures that show every colour used."""
    montage = Image.fromarray(np.concatenate([np.asarray(picture) for picture in pictures], axis=0))
    return montage.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)


def write_gif(result, target, seconds=GIF_SECONDS, fps=GIF_FPS, frames=None, progress=None, dpi=GIF_DPI):
    """An animation of the robot rolling, `seconds` long at `fps` (frames subsampled evenly from the run).

    `progress(done_frames, total_frames)` is called as frames are drawn.
    """
    samples = frame_samples(len(result.trajectory), seconds, fps, frames)
    scene = RobotScene(result, dpi=dpi)
    try:
        # The last frame shows the whole path and the middle one the robot elsewhere: together with the
        # first they hold every colour the frames use, antialiased edges included.
        palette = _palette_for([scene.render(samples[i]) for i in (0, len(samples) // 2, -1)])
        images = []
        for done, k in enumerate(samples, start=1):
            images.append(scene.render(k).quantize(palette=palette, dither=Image.Dither.NONE))
            if progress is not None:
                progress(done, len(samples))
    finally:
        scene.close()
    with atomic_path(target) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                       duration=round(1000 / fps), loop=0)
