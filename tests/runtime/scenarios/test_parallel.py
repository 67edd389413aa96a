"""Writing several runs' files in parallel processes (runtime/scenarios/parallel.py)."""
import pytest

from runtime.scenarios import parallel, report
from runtime.scenario import load_scenario, run_scenario


@pytest.fixture(scope="module")
def short_runs():
    return [run_scenario(load_scenario(name).with_overrides(steps=300)) for name in ("t-shape", "tilted-yoke")]


def test_parallel_processes_write_the_same_files_as_one_process(tmp_path, short_runs):
    runs = [(result, tmp_path / "parallel" / result.scenario.name) for result in short_runs[:1]]
    written = parallel.write_runs(runs, quiet=True, workers=2)
    for (result, folder), files in zip(runs, written):
        alone = tmp_path / "alone" / result.scenario.name
        report.write_outputs(result, alone)
        assert [f.name for f in files] == report.planned_files() + ["summary.json"]
        assert sorted(p.name for p in folder.iterdir()) == sorted(p.name for p in alone.iterdir())
        for name in report.planned_files():           # summary.json differs: it holds wall times
            assert (folder / name).read_bytes() == (alone / name).read_bytes(), name


def test_one_worker_writes_in_this_process(tmp_path, short_runs):
    runs = [(short_runs[1], tmp_path / "yoke")]
    written = parallel.write_runs(runs, gif=False, replay=False, quiet=True, workers=1)
    assert [f.name for f in written[0]] == report.planned_files(gif=False, replay=False) + ["summary.json"]


def test_outputs_of_an_earlier_run_that_this_one_does_not_write_are_deleted(tmp_path, short_runs):
    folder = tmp_path / "yoke"
    folder.mkdir()
    (folder / "robot.gif").write_bytes(b"an earlier run's animation")
    (folder / "notes.txt").write_text("mine")
    parallel.write_runs([(short_runs[1], folder)], gif=False, replay=False, quiet=True, workers=2)
    names = {p.name for p in folder.iterdir()}
    assert "robot.gif" not in names and "notes.txt" in names and "energy.png" in names


def test_an_error_in_a_worker_is_raised_and_no_summary_is_written(tmp_path, short_runs, monkeypatch):
    def broken(result, target, progress=None):
        raise RuntimeError("renderer crashed")

    monkeypatch.setitem(report.WRITERS, "energy.png", broken)   # the forked workers inherit it
    folder = tmp_path / "yoke"
    with pytest.raises(RuntimeError, match="renderer crashed"):
        parallel.write_runs([(short_runs[1], folder)], gif=False, replay=False, quiet=True, workers=2)
    assert not (folder / "summary.json").exists()


def test_progress_bars_stay_quiet_when_stderr_is_not_a_terminal(tmp_path, short_runs, capsys):
    parallel.write_runs([(short_runs[1], tmp_path / "yoke")], gif=False, replay=False, quiet=False, workers=2)
    assert capsys.readouterr().err == ""


def test_progress_counts_every_frame_and_file(short_runs):
    result = short_runs[0]
    units = sum(report.progress_units(result, name) for name in report.planned_files())
    assert units == 200 + len(report.planned_files()) - 1          # the GIF's frames, one per other file


def test_worker_count_is_at_least_one_and_at_most_one_per_task():
    assert parallel.worker_count(1) == 1
    assert 1 <= parallel.worker_count(100) <= 100


def _threads_started_by(bar_class):
    import os
    import threading

    before = {thread.ident for thread in threading.enumerate()}
    with open(os.devnull, "w") as sink, bar_class(total=3, disable=False, file=sink) as bar:
        bar.update(1)
        return [thread for thread in threading.enumerate() if thread.ident not in before]


def test_progress_bars_start_no_thread_that_the_pool_would_fork():
    from tqdm import tqdm

    assert _threads_started_by(parallel.RunBar) == []

    class Monitored(tqdm):                 # plain tqdm, with a monitor slot of its own: it starts one
        monitor = None

    started = _threads_started_by(Monitored)
    try:
        assert len(started) == 1
    finally:
        Monitored.monitor.exit()
