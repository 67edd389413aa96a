"""A replay page in Debian's chromium, driven headless by selenium: for the browser test and the screenshot.

Only the system's browser and driver are used (/usr/bin/chromium and
/usr/bin/chromedriver, from Debian's chromium and chromium-driver packages;
`.ci/install-chromium` installs them where it can).  The driver's path is
given explicitly, so selenium never asks its selenium-manager to download one.
WebGL (plotly's 3-D view) runs on chromium's software renderer, SwiftShader.

    with open_replay(pathlib.Path("out/t-shape/replay.html")) as driver:
        driver.execute_script("return window.replay.time")
"""
import contextlib
import pathlib
import shutil
import time

CHROMIUM = pathlib.Path("/usr/bin/chromium")
CHROMEDRIVER = pathlib.Path("/usr/bin/chromedriver")
INSTALL_SCRIPT = pathlib.Path(__file__).resolve().parents[2] / ".ci" / "install-chromium"

#: Headless, as root in a container (no sandbox, small /dev/shm), WebGL in software.
CHROMIUM_ARGUMENTS = ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                      "--enable-unsafe-swiftshader", "--hide-scrollbars")


def missing():
    """What is missing to drive the browser (a sentence), or None when everything is there."""
    for path, package in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not path.is_file():
            return f"{path} not found (Debian package {package}; .ci/install-chromium installs it as root)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "the Python package selenium is not installed (pip install -e '.[dev]')"
    return None


def start(width=1280, height=1400):
    """A headless chromium under selenium, its console log kept (all levels)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for argument in (*CHROMIUM_ARGUMENTS, f"--window-size={width},{height}"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(executable_path=str(CHROMEDRIVER)), options=options)


def wait_until_ready(driver, timeout=180.0):
    """Wait for the page's `window.replay.ready` (plotly inflated, plots drawn); TimeoutError with the
    page's status line if it does not come."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if driver.execute_script("return Boolean(window.replay && window.replay.ready)"):
            return
        time.sleep(0.2)
    status = driver.execute_script("const s = document.getElementById('status'); return s && s.textContent")
    raise TimeoutError(f"the replay page was not ready after {timeout:g} s (status: {status!r})")


@contextlib.contextmanager
def open_replay(page, width=1280, height=1400, timeout=180.0):
    """A headless chromium showing `page` (a replay.html), ready; closed afterwards."""
    driver = start(width, height)
    try:
        driver.get(pathlib.Path(page).resolve().as_uri())
        wait_until_ready(driver, timeout)
        yield driver
    finally:
        driver.quit()


def console_errors(driver):
    """The browser console's messages of level SEVERE since the last call (errors, uncaught exceptions)."""
    return [entry for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


def screenshot(page, target, width=1280, height=1560):
    """Save a PNG of `page` as a user first sees it, one moment into the run (frame at a third of it)."""
    from ..atomic import atomic_path

    with open_replay(page, width, height) as driver:
        driver.execute_script("const s = document.getElementById('time');"
                              "s.value = Math.round(s.max / 3); s.dispatchEvent(new Event('input'));")
        time.sleep(1.0)                      # let the cursor's relayout finish
        with atomic_path(target) as tmp:
            if not driver.save_screenshot(str(tmp)):
                raise RuntimeError(f"{target}: chromium returned no screenshot")


def have_apt_as_root():
    """True when this process is root and apt-get is on the PATH."""
    import os

    return hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get") is not None
