"""The interactive replay of a scenario run: one self-contained HTML page, `replay.html`.

The page shows the shell (wireframe, red marker), the yoke, the pendulum and
the centre's path in 3-D (plotly: the user turns and zooms the camera), a time
slider, play/pause and playback speed, and below it the inclinations, speeds,
torques and energy against time with a cursor at the time shown.  It needs no
network: plotly's JavaScript is embedded, gzip-compressed and base64-encoded
(the browser inflates it with DecompressionStream), which keeps a 100 s run
near 3 MB where the plain library alone would be 4.8 MB.

The run is decimated to at most MAX_FRAMES samples, evenly spaced in steps, the
last sample always included.  The numbers go into the page as float64 in
base64, so a frame's time and state are the simulated doubles, equal to the
matching row of trajectory.csv.  The page's script (replay_page.html, beside
this file) computes the bodies' positions from R_S, R_Y, R_P and q.

    write_replay(result, pathlib.Path("out/t-shape/replay.html"))
"""
import base64
import functools
import gzip
import json
import pathlib

import numpy as np

from ..state import IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, absolute_inclinations, pendulum_angle, \
    yoke_angle
from .animation import _sphere_wireframe
from ..atomic import write_text
from .outline import rod_tip, yoke_outline

#: At most this many samples go into the page (a 100 s run at dt = 0.01 s: every 5th step).
MAX_FRAMES = 2001
TEMPLATE = pathlib.Path(__file__).with_name("replay_page.html")

#: The time series below the 3-D view: (panel title, unit, [(series key, legend label), ...]).
PANELS = (
    ("relative inclinations", "rad", [("theta_Y", "yoke rel. to shell θ_Y"),
                                      ("theta_P", "pendulum rel. to yoke θ_P")]),
    ("absolute inclinations", "rad", [("yoke_to_vertical", "yoke plane normal vs vertical"),
                                      ("pendulum_to_vertical", "pendulum shaft vs vertical")]),
    ("speeds", "rad/s", [("w_S_norm", "shell |ω_S|"), ("w_Y", "yoke ω_Y"), ("w_P", "pendulum ω_P")]),
    ("torques", "N·m", [("u_Y", "yoke motor u_Y"), ("u_P", "pendulum motor u_P")]),
    ("energy", "J", [("E", "kinetic + potential E")]),
)


def frame_indices(sample_count, max_frames=MAX_FRAMES):
    """Sample indices shown: every `stride`-th sample, stride the smallest keeping at most `max_frames`
    (the last sample always included, so the page ends where the run ends)."""
    if sample_count < 1:
        raise ValueError(f"sample_count: a replay needs at least one sample, got {sample_count}")
    if max_frames < 2:
        raise ValueError(f"max_frames: must be at least 2, got {max_frames}")
    stride = max(1, -(-(sample_count - 1) // (max_frames - 1)))
    indices = np.arange(0, sample_count, stride)
    return indices if indices[-1] == sample_count - 1 else np.append(indices, sample_count - 1)


def _float64_base64(values):
    """Little-endian float64 bytes of `values`, in base64 (the page decodes them with a DataView)."""
    return base64.b64encode(np.ascontiguousarray(values, dtype="<f8").tobytes()).decode("ascii")


def replay_data(result, max_frames=MAX_FRAMES):
    """The page's data (a dict ready for JSON): the frames' sample indices, their times and states, the
    plotted series, and the bodies' shapes in their own frames."""
    s, x = result.scenario, result.trajectory
    p = s.params
    rows = frame_indices(len(x), max_frames)
    xs = x[rows]
    yoke_abs, pendulum_abs = absolute_inclinations(xs)
    series = {
        "theta_Y": np.unwrap(yoke_angle(xs)), "theta_P": np.unwrap(pendulum_angle(xs)),
        "yoke_to_vertical": yoke_abs, "pendulum_to_vertical": pendulum_abs,
        "w_S_norm": np.linalg.norm(xs[:, IDX_WS], axis=1), "w_Y": xs[:, IDX_WY], "w_P": xs[:, IDX_WP],
        "u_Y": result.torques[rows, 0], "u_P": result.torques[rows, 1], "E": result.energy[rows],
    }
    return {
        "name": s.name,
        "description": s.description,
        "method": s.method,
        "dt": s.dt,
        "steps": s.steps,
        "frames": len(rows),
        "rows": rows.tolist(),
        "arrays": {
            "t": _float64_base64(result.time[rows]),
            "q": _float64_base64(xs[:, IDX_Q]),
            "R_S": _float64_base64(xs[:, IDX_RS]),
            "R_Y": _float64_base64(xs[:, IDX_RY]),
            "R_P": _float64_base64(xs[:, IDX_RP]),
            **{key: _float64_base64(values) for key, values in series.items()},
        },
        "panels": [{"title": title, "unit": unit, "series": [{"key": k, "label": label} for k, label in lines]}
                   for title, unit, lines in PANELS],
        "bodies": {
            "r": p.r,
            # Sphere wireframe: polylines separated by NaN rows (breaks); JSON has no NaN, so null.
            "wire": [[None if np.isnan(v) else float(v) for v in point] for point in _sphere_wireframe(p.r)],
            "marker": (p.r * np.ones(3) / np.sqrt(3.0)).tolist(),
            "yoke": yoke_outline(p).tolist(),
            "bob": rod_tip(p).tolist(),
        },
    }


@functools.lru_cache(maxsize=1)
def plotly_js_gzip_base64():
    """plotly.js (shipped inside the plotly package), gzip-compressed (deterministic: no time stamp), base64."""
    from plotly.offline import get_plotlyjs

    return base64.b64encode(gzip.compress(get_plotlyjs().encode("utf-8"), 6, mtime=0)).decode("ascii")


def _script_safe_json(data):
    """JSON that may sit inside a <script> element: no "</" can close it early."""
    return json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")


def replay_html(result, max_frames=MAX_FRAMES):
    """The whole page as a string."""
    page = TEMPLATE.read_text(encoding="utf-8")
    title = f"{result.scenario.name}: replay"
    for key, value in (("{{TITLE}}", title.replace("&", "&amp;").replace("<", "&lt;")),
                       ("{{DATA}}", _script_safe_json(replay_data(result, max_frames))),
                       ("{{PLOTLY_GZIP_BASE64}}", plotly_js_gzip_base64())):
        page = page.replace(key, value)
    return page


def write_replay(result, target, progress=None, max_frames=MAX_FRAMES):
    """Write replay.html for `result` (atomically).  `progress` is accepted for a uniform writer signature
    (runtime/scenarios/report.py WRITERS) and not called: the page is one unit of work."""
    write_text(target, replay_html(result, max_frames))
