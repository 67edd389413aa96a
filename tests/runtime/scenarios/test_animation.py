"""The animation of a run (runtime/scenarios/animation.py)."""
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
