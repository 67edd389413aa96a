"""Run a sweep: its tasks on Dask distributed (an embedded LocalCluster, or any scheduler), or
serially in this process; each finished task's rows go to disk at once (see store.py).

The client process submits every missing task, writes the rows of each as it completes, and
shows a progress bar; the workers only compute (they need this package installed, not the
output folder).
"""
import contextlib
import logging
import os
import time

from tqdm.auto import tqdm

from .store import SweepStore
from .task import run_chunk

#: Default wall time of one task: long against Dask's per-task cost (about a millisecond, see
#: docs/sweeps.md), short enough that a lost worker or an interrupt costs little.
TASK_SECONDS = 2.0
#: `scheduler` value that runs the tasks in this process, without Dask.
SERIAL = "serial"


def measure_samples_per_task(spec, seconds=TASK_SECONDS):
    """Samples per task so that one task takes about `seconds` here: times the first few samples."""
    probe = min(spec.samples, 8)
    started = time.perf_counter()
    run_chunk(spec, 0, probe)
    per_sample = max((time.perf_counter() - started) / probe, 1e-6)
    return max(1, min(spec.samples, round(seconds / per_sample)))


#: What the embedded LocalCluster changes of Dask's defaults (see `dask_client`).
EMBEDDED_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """A distributed.Client: on `scheduler` (an address), or on a new LocalCluster of `workers`
    single-threaded worker processes (default: one per core)."""
    from distributed import Client, LocalCluster
    if scheduler is not None:
        with Client(scheduler) as client:
            yield client
        return
    import dask
    n = workers or os.cpu_count() or 1
    logging.getLogger("distributed").setLevel(logging.WARNING)   # no INFO lines when the cluster closes
    # Dask's own periodic work, for the dashboard and for spotting a blocked event loop, competes
    # with the C loops for the cores (AMD EPYC, 2 cores, make sweep-bench): the workers' statistical
    # profiler (a stack sample every 10 ms; CPU overhead of 1 worker against the C batch +16.7 %
    # with it, +5.7 % without) is off, and the event-loop tick (every 20 ms, in every process), the
    # system monitor (500 ms) and the nannies' memory monitor (100 ms) run less often: with them
    # at their defaults the tasks of 2 workers ran 7 % slower than those of 1 and the speedup was
    # 1.75-1.86x over eight runs, with these 1.87-1.91x over three.  The nannies get this config
    # and hand it to their workers; a cluster of the user's (--scheduler) keeps its own.
    with dask.config.set(EMBEDDED_CLUSTER_CONFIG), \
            LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",  # any free port
                         silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        yield client


def run_sweep(spec, out, scheduler=None, workers=None, samples_per_task=None, progress=True, client=None):
    """Run `spec` into the folder `out` (resuming what is there); returns the results table.

    scheduler: None (an embedded LocalCluster of `workers` processes), SERIAL (this process,
    no Dask), or the address of a running Dask scheduler ("tcp://host:8786").
    samples_per_task: None for the sweep file's, else measured for TASK_SECONDS.
    client: a distributed.Client to use instead (the benchmark reuses one cluster).
    """
    per_task = samples_per_task or spec.samples_per_task
    store = SweepStore.open(out, spec, lambda: per_task or measure_samples_per_task(spec))
    todo = store.missing()
    done = spec.samples - sum(b - a for a, b in todo)
    with tqdm(total=spec.samples, initial=done, unit="sample", desc=spec.name, disable=not progress or None,
              smoothing=0.1) as bar:
        if todo and scheduler == SERIAL:
            for a, b in todo:
                store.write_chunk(a, b, run_chunk(spec, a, b))
                bar.update(b - a)
        elif todo:
            from distributed import as_completed
            with (contextlib.nullcontext(client) if client is not None
                  else dask_client(scheduler, workers)) as client:
                futures = {client.submit(run_chunk, spec, a, b, pure=False): (a, b) for a, b in todo}
                for future in as_completed(futures):
                    a, b = futures.pop(future)
                    store.write_chunk(a, b, future.result())
                    future.release()
                    bar.update(b - a)
    return store.combine()
