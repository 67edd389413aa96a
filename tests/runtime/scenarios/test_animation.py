"""The animation of a run (runtime/scenarios/animation.py): frames, and the fast drawing path's pictures."""
import numpy as np
import pytest

from runtime.scenarios import animation


def test_gif_is_an_animation_with_the_requested_frames(tmp_path, results):
    from PIL import Image

    target = tmp_path / "robot.gif"
    seen = []
    animation.write_gif(results["tilted-yoke"], target, frames=4, progress=lambda done, total: seen.append(total))
    with Image.open(target) as gif:
        assert gif.format == "GIF" and gif.n_frames == 4
    assert seen and set(seen) == {4}
    assert [p.name for p in tmp_path.iterdir()] == ["robot.gif"]


def test_default_gif_is_ten_seconds_at_twenty_frames_per_second(tmp_path, results):
    from PIL import Image

    target = tmp_path / "robot.gif"
    animation.write_gif(results["tilted-yoke"], target)
    with Image.open(target) as gif:
        durations = []
        for i in range(gif.n_frames):
            gif.seek(i)
            durations.append(gif.info["duration"])
    assert len(durations) == 200 and set(durations) == {50}


def test_frame_samples_span_the_run_evenly():
    samples = animation.frame_samples(10001)
    assert len(samples) == 200 and samples[0] == 0 and samples[-1] == 10000
    assert np.ptp(np.diff(samples)) <= 1


def _full_redraw(scene, k):
    """The picture of sample k drawn the slow way: every artist redrawn by a full canvas draw."""
    scene.render(k)                               # sets the moving artists' data for sample k
    for artist in scene.moving:
        artist.set_animated(False)
    scene.fig.canvas.draw()
    picture = np.asarray(scene.fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    for artist in scene.moving:
        artist.set_animated(True)
    return picture


def _differing_fraction(a, b, below_row):
    """Fraction of pixels (below the title band, rows >= below_row) whose colour differs by more than 8."""
    return float(np.mean(np.abs(a[below_row:] - b[below_row:]).max(axis=2) > 8))


@pytest.mark.parametrize("name", ["t-shape", "tilted-pendulum"])
def test_blitted_frame_is_the_picture_a_full_redraw_gives(results, name):
    """The fast path (background kept, moving artists drawn on it) against matplotlib's full draw.

    The title is written by Pillow on the fast path, so the band above the axes is left out.  The same
    comparison against a full redraw of another sample must fail: the check can tell pictures apart.
    """
    scene = animation.RobotScene(results[name])
    try:
        title_band = int(scene.fig.bbox.height - scene.ax.bbox.y1) + 40
        k, other = len(scene.q) // 20, 0                    # 5 s in (the robot moving), and the start
        fast = np.asarray(scene.render(k)).astype(int)
        assert _differing_fraction(fast, _full_redraw(scene, k), title_band) < 0.002
        assert _differing_fraction(fast, _full_redraw(scene, other), title_band) > 0.005
    finally:
        scene.close()


def test_time_title_is_drawn_on_every_frame(results):
    scene = animation.RobotScene(results["t-shape"])
    try:
        top = int(scene.title_anchor[1]) + 4
        first, later = (np.asarray(scene.render(k))[:top].astype(int) for k in (0, 5000))
        assert (first < 128).any()                          # dark text in the title band
        assert np.abs(first - later).max() > 100            # ... and it changes with the time
    finally:
        scene.close()
