"""The replay page in a real browser: Debian's chromium, headless, driven by selenium.

It loads the page of the t-shape run (100 s), checks that the console shows no
error and that nothing came from the network, moves the time slider (by the
keyboard, as a user would), reads the robot's position back from the plotted
3-D traces and compares it with the row of trajectory.csv at that time, plays
and pauses, and checks the cursor of the time plots.  Where chromium is not
installed, the test installs it (.ci/install-chromium: root and apt-get); it
skips, saying why, only where it cannot.
"""
import subprocess

import numpy as np
import pytest

from runtime.scenarios import browser
from runtime.scenarios import cli as scenario_cli


def _browser_or_skip():
    if browser.missing() and browser.have_apt_as_root():
        subprocess.run(["bash", str(browser.INSTALL_SCRIPT)], check=False, timeout=900)
    if not browser.CHROMIUM.is_file() or not browser.CHROMEDRIVER.is_file():
        reason = browser.missing()
        if not browser.have_apt_as_root():
            reason += "; cannot install it here (not root, or no apt-get)"
        pytest.skip(reason)


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    _browser_or_skip()
    out = tmp_path_factory.mktemp("out")
    assert scenario_cli.main(["t-shape", "--out", str(out), "--no-gif", "--quiet"]) == 0
    return out / "t-shape"


@pytest.fixture(scope="module")
def csv_rows(run_folder):
    lines = (run_folder / "trajectory.csv").read_text().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return {name: rows[:, i] for i, name in enumerate(header)}


@pytest.fixture(scope="module")
def page(run_folder):
    with browser.open_replay(run_folder / "replay.html") as driver:
        yield driver


def move_slider_to(driver, time):
    """Put the slider one frame before the page's frame for `time`, then press → once, as a user would."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    frame = driver.execute_script(
        "const k = window.replay.frameAt(arguments[0]), s = document.getElementById('time');"
        "s.value = k - 1; s.dispatchEvent(new Event('input')); return k;", time)
    driver.find_element(By.ID, "time").send_keys(Keys.ARROW_RIGHT)
    assert driver.execute_script("return window.replay.frame") == frame
    return frame


def drawn_points(driver):
    """World positions of what the 3-D view draws now: centre, marker on the shell, pendulum bob."""
    traces = driver.execute_script(
        "const d = document.getElementById('scene').data;"
        "const byName = (n) => d.find((t) => t.name === n);"
        "return ['centre q', 'marker on the shell', 'pendulum bob'].map((n) => {"
        "  const t = byName(n); return [t.x[0], t.y[0], t.z[0]]; });")
    return [np.array(p, dtype=float) for p in traces]


def expected_points(csv_rows, row, r, l):
    """Centre, marker and bob from row `row` of trajectory.csv (independent of the page's script)."""
    q = np.array([csv_rows[f"q_{c}"][row] for c in "xyz"])
    R = {m: np.array([[csv_rows[f"{m}_{i}{j}"][row] for j in (1, 2, 3)] for i in (1, 2, 3)])
         for m in ("R_S", "R_Y", "R_P")}
    marker = q + R["R_S"] @ (r * np.ones(3) / np.sqrt(3.0))
    bob = q + R["R_S"] @ R["R_Y"] @ R["R_P"] @ np.array([0.0, 0.0, -l])
    return [q, marker, bob]


def test_page_loads_without_console_errors_or_network(page):
    assert browser.console_errors(page) == []
    resources = page.execute_script("return performance.getEntriesByType('resource').map((e) => e.name)")
    assert [name for name in resources if not name.startswith(("file:", "data:", "blob:"))] == []
    assert page.execute_script("return document.getElementById('status').textContent") == ""


def test_slider_shows_the_csv_row_at_that_time(page, csv_rows):
    from runtime import Params

    p = Params.paper_simulation()
    move_slider_to(page, 37.5)
    shown = page.execute_script("return window.replay.time")
    assert shown == 37.5
    row = int(np.flatnonzero(csv_rows["t"] == shown)[0])
    drawn, expected = drawn_points(page), expected_points(csv_rows, row, p.r, p.paper_params.l)
    np.testing.assert_array_equal(drawn[0], expected[0])                   # the centre: the CSV's doubles
    for got, want in zip(drawn[1:], expected[1:]):                         # marker and bob: R p + q in JS
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    # The comparison can fail: the previous frame (5 steps earlier) is elsewhere.
    earlier = expected_points(csv_rows, row - 5, p.r, p.paper_params.l)
    assert all(np.abs(got - want).max() > 1e-6 for got, want in zip(drawn, earlier))
    assert "t = 37.50 s" in page.execute_script("return document.getElementById('readout').textContent")
    assert browser.console_errors(page) == []


def test_time_plots_cursor_follows_the_slider(page):
    move_slider_to(page, 62.0)
    cursor = "const s = document.getElementById('plots').layout.shapes[0]; return [s.x0, s.x1]"
    assert wait_for(page, cursor.replace("return [s.x0, s.x1]", "return s.x0 === 62 && s.x1 === 62"))
    assert page.execute_script(cursor) == [62.0, 62.0]


def wait_for(driver, script, timeout=30.0):
    import time

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if driver.execute_script(script):
            return True
        time.sleep(0.1)
    return False


def test_play_advances_and_pause_stops(page):
    import time

    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    # The slowest speed, and checks that do not depend on how fast frames come: in software WebGL on a
    # busy host a frame can take seconds, and the clock follows the wall, so at 5x a run played out
    # between two of our checks.  At 0.25x even 60 s of delays move it by 15 s of the 90 s left.
    move_slider_to(page, 10.0)
    Select(page.find_element(By.ID, "speed")).select_by_value("0.25")
    button = page.find_element(By.ID, "play")
    button.click()
    assert wait_for(page, "return window.replay.playing && window.replay.time > 10")   # it plays ...
    # Pause by a click from the page's own script: a playing page in software WebGL is so busy that a
    # synthetic mouse click can arrive long after it was sent.
    page.execute_script("document.getElementById('play').click()")
    assert wait_for(page, "return !window.replay.playing")                            # ... and pauses
    paused_at = page.execute_script("return window.replay.time")
    time.sleep(0.5)
    assert page.execute_script("return window.replay.time") == paused_at
    assert 10 < paused_at < 100
    assert browser.console_errors(page) == []


def test_screenshot_is_a_picture_of_the_page(page, tmp_path):
    from PIL import Image

    target = tmp_path / "replay.png"
    assert page.save_screenshot(str(target))
    with Image.open(target) as picture:
        colours = picture.convert("RGB").getcolors(maxcolors=1 << 20)
    assert picture.size[0] >= 1000 and len(colours) > 50        # not a blank or error page


def test_console_check_catches_an_error_of_a_broken_page(page, tmp_path):
    """The console check can fail: a page whose script throws shows a SEVERE entry (run last: it navigates)."""
    broken = tmp_path / "broken.html"
    broken.write_text("<!DOCTYPE html><html><body><script>throw new Error('replay broke');</script></body></html>")
    browser.console_errors(page)                                # forget what came before
    page.get(broken.as_uri())
    assert any("replay broke" in entry["message"] for entry in browser.console_errors(page))
