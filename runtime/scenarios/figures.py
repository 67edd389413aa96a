"""`python -m runtime figures [--out DIR]`: regenerate the committed figures under docs/figures/.

One trajectory figure per paper scenario (the paper's Figs. 2, 4, 6) and the
relative inclinations of the t-shape run (Fig. 7), at 100 dpi so the PNGs
stay small; and a screenshot of the t-shape run's replay page in headless
chromium (runtime/scenarios/browser.py), when chromium is installed.  The numbers quoted in docs/scenarios.md come from the same runs
(see each run's summary.json, `python -m runtime run all`).
"""
import argparse
import pathlib
import sys
import tempfile

from . import browser, plots
from .replay import write_replay
from ..scenario import PAPER_SCENARIOS, load_scenario, run_scenario

DEFAULT_OUT = pathlib.Path(__file__).resolve().parents[2] / "docs" / "figures"

#: (scenario, figure function, file name suffix) of every committed figure.
COMMITTED = [(name, plots.trajectory_figure, "trajectory") for name in PAPER_SCENARIOS]
COMMITTED.append(("t-shape", plots.inclinations_figure, "inclinations"))


def main(argv):
    """`python -m runtime figures`: run the paper's scenarios and rewrite the committed figures."""
    parser = argparse.ArgumentParser(prog="python -m runtime figures", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=DEFAULT_OUT, help=f"folder (default: {DEFAULT_OUT})")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    results = {name: run_scenario(load_scenario(name)) for name in PAPER_SCENARIOS}
    for name, draw, suffix in COMMITTED:
        target = args.out / f"{name}-{suffix}.png"
        plots.save_figure(draw(results[name]), target, dpi=plots.FIGURE_DPI)
        print(target)
    target = args.out / "replay-t-shape.png"
    why_not = browser.missing()
    if why_not:
        print(f"{target}: not redrawn: {why_not}", file=sys.stderr)
        return 0
    with tempfile.TemporaryDirectory() as folder:
        page = pathlib.Path(folder) / "replay.html"
        write_replay(results["t-shape"], page)
        browser.screenshot(page, target)
    print(target)
    return 0
