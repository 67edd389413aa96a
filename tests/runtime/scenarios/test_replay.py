"""The replay page (runtime/scenarios/replay.py): what goes into it, that it needs no network, its size.

The page in a real browser: test_replay_browser.py.
"""
import base64
import gzip
import json
import re

import numpy as np
import pytest

from runtime.scenarios import replay
from runtime.scenarios.report import trajectory_table, CSV_COLUMNS


def decode(b64):
    return np.frombuffer(base64.b64decode(b64), dtype="<f8")


def page_data(html):
    match = re.search(r'<script id="replay-data" type="application/json">(.*?)</script>', html, re.S)
    return json.loads(match.group(1))


def test_frame_indices_keep_at_most_max_frames_and_end_on_the_last_sample():
    for count, most in ((10001, 2001), (5001, 2001), (10001, 7), (3, 2001), (1, 2001), (10000, 2001)):
        rows = replay.frame_indices(count, most)
        assert len(rows) <= most and rows[0] == 0 and rows[-1] == count - 1
        assert len(set(np.diff(rows[:-1]).tolist())) <= 1                 # evenly spaced but for the end
    assert replay.frame_indices(10001).tolist() == list(range(0, 10001, 5))  # a 100 s run: every 5th step


def test_frame_indices_refuse_what_makes_no_page():
    with pytest.raises(ValueError, match="sample_count"):
        replay.frame_indices(0)
    with pytest.raises(ValueError, match="max_frames"):
        replay.frame_indices(100, 1)


def test_page_carries_the_simulated_rows_exactly(results):
    """Each frame's time and state in the page are the doubles of its row of trajectory.csv."""
    result = results["t-shape"]
    data = page_data(replay.replay_html(result))
    table = trajectory_table(result)
    rows = np.array(data["rows"])
    column = {name: i for i, name in enumerate(CSV_COLUMNS)}
    arrays = {key: decode(value) for key, value in data["arrays"].items()}
    assert data["frames"] == len(rows) == len(arrays["t"])
    np.testing.assert_array_equal(arrays["t"], table[rows, column["t"]])
    np.testing.assert_array_equal(arrays["q"].reshape(-1, 3), table[rows][:, [column[c] for c in ("q_x", "q_y", "q_z")]])
    for block in ("R_S", "R_Y", "R_P"):
        names = [f"{block}_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)]
        np.testing.assert_array_equal(arrays[block].reshape(-1, 9), table[rows][:, [column[c] for c in names]])
    for key in ("w_Y", "w_P", "u_Y", "u_P", "E"):
        np.testing.assert_array_equal(arrays[key], table[rows, column[key]])
    # The check can fail: the neighbouring frames' rows differ.
    assert not np.array_equal(arrays["q"].reshape(-1, 3), table[np.maximum(rows - 1, 0)][:, 1:4])


def test_every_panel_series_is_in_the_page(results):
    data = page_data(replay.replay_html(results["tilted-yoke"]))
    keys = [series["key"] for panel in data["panels"] for series in panel["series"]]
    assert [panel["title"] for panel in data["panels"]] == ["relative inclinations", "absolute inclinations",
                                                            "speeds", "torques", "energy"]
    for key in keys:
        assert len(decode(data["arrays"][key])) == data["frames"]


def test_page_needs_no_network(results):
    """plotly's code is inside the page; nothing is fetched from anywhere."""
    from plotly.offline import get_plotlyjs

    html = replay.replay_html(results["tilted-yoke"])
    embedded = re.search(r'<script id="plotly-gzip-base64" type="text/plain">(.*?)</script>', html, re.S).group(1)
    assert gzip.decompress(base64.b64decode(embedded)).decode("utf-8") == get_plotlyjs()
    outside = html.replace(embedded, "")
    assert not re.search(r"<(script|link|img|iframe)[^>]*\b(src|href)=", outside)
    assert "http://" not in outside and "https://" not in outside


def test_a_hundred_second_run_gives_a_page_under_5_MB(results, tmp_path):
    result = results["t-shape"]
    assert result.time[-1] == pytest.approx(100.0)
    target = tmp_path / "replay.html"
    replay.write_replay(result, target)
    assert target.stat().st_size < 5_000_000
    assert [p.name for p in tmp_path.iterdir()] == ["replay.html"]       # written atomically


def test_page_text_cannot_close_its_script_early(results):
    """A description holding "</script>" stays data: the JSON is escaped."""
    import dataclasses

    result = results["tilted-yoke"]
    scenario = dataclasses.replace(result.scenario, description="a </script><script>alert(1)</script> test")
    html = replay.replay_html(dataclasses.replace(result, scenario=scenario))
    assert html.count("</script>") == 3 and page_data(html)["description"] == scenario.description
