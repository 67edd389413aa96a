"""`python -m runtime view FOLDER`: open the replay page of a run (FOLDER/replay.html) in the browser.

FOLDER is a run's output folder (`out/t-shape`) or the page itself.  The page
is a local file and needs no network (runtime/scenarios/replay.py).  Exit
status 0 when a browser was asked to open it, 2 when there is no such page or
no browser could be started (the page's path is printed either way, so it
can be opened by hand).
"""
import argparse
import pathlib
import sys
import webbrowser

#: What every replay page carries in its head (runtime/scenarios/replay_page.html).
GENERATOR = b'<meta name="generator" content="runtime.scenarios.replay">'


def replay_page(path):
    """The replay.html of a run folder (or the page itself); ValueError naming what is missing."""
    path = pathlib.Path(path)
    page = path / "replay.html" if path.is_dir() else path
    hint = "run `python -m runtime run` first (without --no-replay)"
    if not page.is_file():
        if not path.exists():
            raise ValueError(f"{path}: no such folder; {hint}")
        raise ValueError(f"{page}: no replay page here; {hint}")
    try:
        with open(page, "rb") as f:
            head = f.read(1024)
    except OSError as exc:
        raise ValueError(f"{page}: cannot read the file ({exc.strerror or exc})") from None
    if GENERATOR not in head:     # any other file would open as if it were a run
        raise ValueError(f"{page}: not a replay page (written by `python -m runtime run`); {hint}")
    return page.resolve()


def main(argv):
    """`python -m runtime view`: open a run's replay page in the browser."""
    parser = argparse.ArgumentParser(prog="python -m runtime view",
                                     description="Open the interactive replay of a run in the browser.")
    parser.add_argument("folder", metavar="FOLDER", help="a run's output folder (e.g. out/t-shape) or its replay.html")
    args = parser.parse_args(argv)
    try:
        page = replay_page(args.folder)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"opening {page.as_uri()}")
    if not webbrowser.open(page.as_uri()):
        print("error: no browser could be started; open the page above by hand", file=sys.stderr)
        return 2
    return 0
