"""Writing the output files of several runs in parallel processes, with one progress bar per run.

Drawing is what takes the time (the simulations take a fraction of a second),
and every file of every run can be drawn independently: each file is one task
in a process pool as wide as the processors this process may use, the longest
(the GIFs) first, so the processors stay busy to the end.  The workers report
their progress through a queue; the parent owns the bars (tqdm: one per run,
quiet when stderr is not a terminal) and writes each run's summary.json once
all its other files are written.

    written = write_runs([(result, pathlib.Path("out/t-shape"))], gif=True, replay=True, quiet=False)
"""
import concurrent.futures
import multiprocessing
import os
import queue as queue_module

from tqdm import tqdm

from . import report

_progress_queue = None     # set in each worker by _start_worker


class RunBar(tqdm):
    """tqdm without its monitor thread: the pool forks its workers, and a fork should copy no thread
    that may hold a lock (tqdm's monitor only retunes the refresh rate of stalled bars)."""
    monitor_interval = 0


def _start_worker(progress_queue):
    global _progress_queue
    _progress_queue = progress_queue


def _reporting_increments(advance):
    """A progress(done, total) callback that passes on how many units were done since its last call."""
    reported = [0]

    def progress(done, total):
        advance(done - reported[0])
        reported[0] = done

    return progress


def _write_in_worker(run, result, folder, name):
    """One task: write file `name` of run number `run`; progress goes to the queue as (run, units)."""
    progress = _reporting_increments(lambda units: _progress_queue.put((run, units)))
    return run, name, report.write_file(result, folder, name, progress)


def worker_count(tasks):
    """Processes for `tasks` tasks: the processors this process may run on, at most one per task."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:           # not on Linux
        cpus = os.cpu_count() or 1
    return max(1, min(cpus, tasks))


def _context():
    # fork starts a worker in milliseconds with matplotlib already imported; elsewhere the default.
    return multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)


def write_runs(runs, gif=True, replay=True, quiet=False, workers=None):
    """Write every file of every run in `runs`, a list of (result, folder); returns the paths written,
    one list per run (summary.json last).  Stale outputs of earlier runs in those folders are deleted.
    An error in any task is raised here once the tasks already started have finished."""
    names = report.planned_files(gif, replay)
    tasks = [(run, name) for run in range(len(runs)) for name in names]
    # Longest first: the GIFs, then the replay pages, then the rest.
    order = {"robot.gif": 0, "replay.html": 1}
    tasks.sort(key=lambda task: order.get(task[1], 2))
    bars = [RunBar(total=sum(report.progress_units(result, name) for name in names), desc=result.scenario.name,
                 position=run, leave=True, disable=True if quiet else None, unit="part", dynamic_ncols=True)
            for run, (result, _) in enumerate(runs)]
    seconds = [{} for _ in runs]
    for _, folder in runs:
        folder.mkdir(parents=True, exist_ok=True)
    try:
        workers = workers or worker_count(len(tasks))
        if workers == 1:
            for run, name in tasks:
                result, folder = runs[run]
                seconds[run][name] = report.write_file(result, folder, name,
                                                       _reporting_increments(bars[run].update))
                if name != "robot.gif":
                    bars[run].update(1)
        else:
            _write_in_pool(runs, tasks, bars, seconds, workers)
        written = []
        for run, (result, folder) in enumerate(runs):
            ordered = {name: seconds[run][name] for name in names}
            written.append(report.finish_run(result, folder, ordered))
    finally:
        for bar in bars:
            bar.close()
    return written


def _write_in_pool(runs, tasks, bars, seconds, workers):
    context = _context()
    progress_queue = context.Queue()
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=context, initializer=_start_worker,
                                                initargs=(progress_queue,)) as pool:
        pending = {pool.submit(_write_in_worker, run, runs[run][0], runs[run][1], name) for run, name in tasks}
        try:
            while pending:
                done, pending = concurrent.futures.wait(pending, timeout=0.05,
                                                        return_when=concurrent.futures.FIRST_COMPLETED)
                _drain(progress_queue, bars)
                for future in done:
                    run, name, took = future.result()
                    seconds[run][name] = took
                    if name != "robot.gif":
                        bars[run].update(1)
        except BaseException:
            for future in pending:
                future.cancel()
            raise
    _drain(progress_queue, bars)


def _drain(progress_queue, bars):
    while True:
        try:
            run, units = progress_queue.get_nowait()
        except queue_module.Empty:
            return
        bars[run].update(units)
