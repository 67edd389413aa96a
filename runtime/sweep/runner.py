"""Run a sweep: its tasks on Dask distributed (an embedded LocalCluster, or any scheduler), or
serially in this process; each finished task's rows go to disk at once (see store.py).

The client process submits every missing task, writes the rows of each as it completes, and
shows a progress bar; the workers only compute (they need this package installed, not the
output folder).
"""
import concurrent.futures
import contextlib
import logging
import os
import re
import sys
import time

from tqdm.auto import tqdm

from bindings._sr import lib

from .. import memory
from ..state import NU, NX
from .store import BadRows, SweepStore
from .task import column_names, run_chunk

#: Default wall time of one task: long against Dask's per-task cost (about a millisecond, see
#: docs/sweeps.md), short enough that a lost worker or an interrupt costs little.
TASK_SECONDS = 2.0
#: `scheduler` value that runs the tasks in this process, without Dask.
SERIAL = "serial"
#: Seconds to wait for a scheduler given by address to answer (Dask's own default is 30 s).
CONNECT_TIMEOUT = 10.0
#: Protocols of Dask scheduler addresses (distributed.comm); inproc:// is local to a process.
PROTOCOLS = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
_HOST_PORT = re.compile(r"(?P<host>\[[0-9A-Fa-f:.]+\]|[^\[\]:/\s]+):(?P<port>[^:]*)")


def scheduler_address(text):
    """`text` if it is a Dask scheduler address (HOST:PORT or PROTOCOL://HOST:PORT), else ValueError."""
    expected = f"expected HOST:PORT, tcp://HOST:PORT or '{SERIAL}'"
    protocol, sep, location = text.rpartition("://")
    if sep and protocol not in PROTOCOLS:
        raise ValueError(f"{text!r}: unknown protocol {protocol!r} (Dask's: {', '.join(PROTOCOLS)}); {expected}")
    if protocol == "inproc":
        return text
    match = _HOST_PORT.fullmatch(location)
    if not match:
        raise ValueError(f"{text!r} is not a scheduler address ({expected})")
    port = match["port"]
    if not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ValueError(f"{text!r}: the port {port!r} is not a number from 1 to 65535 ({expected})")
    return text


def memory_estimate(spec, samples_per_task, at_once=1):
    """{what: bytes} of a sweep's largest arrays here (runtime/memory.py): the result table (the
    chunks read back, their concatenation and the Parquet file's buffers: three copies of one
    float64 per sample and column) and the arrays of `at_once` tasks of `samples_per_task`
    samples running at once (parameters, initial and final states, a torque program per sample
    when a torque factor varies, the result columns), and the unvaried scenario's run that the
    summary's figure marks."""
    if hasattr(spec, "memory_estimate"):      # a robustness sweep sizes its own runs
        return spec.memory_estimate(samples_per_task, at_once)
    columns = len(column_names(spec))
    steps = spec.scenario.steps
    per_sample = 8 * (lib.SR_NPARAM + 2 * NX + columns + 2 * (len(spec.quantities) + 1))
    if any(q.name.startswith("torque.") for q in spec.quantities):
        per_sample += 8 * NU * steps
    return {"result table": 3 * 8 * spec.samples * columns,
            "tasks": at_once * min(samples_per_task, spec.samples) * per_sample,
            "torque program": 8 * NU * (steps + 1),
            "nominal run": memory.trajectory_bytes(steps)}


def check_memory(spec, samples_per_task, at_once=1, budget=None):
    """The bytes a sweep needs here, or memory.MemoryBudgetExceeded naming the sweep file when they
    exceed `budget` (default: the memory budget)."""
    return memory.check(spec.source, memory_estimate(spec, samples_per_task, at_once), budget)


def warn(message):
    """The default `notify` of run_sweep: one line on stderr."""
    print(f"warning: {message}", file=sys.stderr, flush=True)


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
def dask_client(scheduler=None, workers=None, connect_timeout=CONNECT_TIMEOUT):
    """A distributed.Client: on `scheduler` (an address; ConnectionError if it does not answer
    within `connect_timeout` seconds), or on a new LocalCluster of `workers` single-threaded
    worker processes (default: one per core)."""
    from distributed import Client, LocalCluster
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=connect_timeout)
        except OSError as exc:
            raise ConnectionError(f"--scheduler: no Dask scheduler answered at {scheduler} within "
                                  f"{connect_timeout:g} s ({exc})".replace("\n", " ")) from None
        with client:
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


def run_sweep(spec, out, scheduler=None, workers=None, samples_per_task=None, progress=True, client=None,
              connect_timeout=CONNECT_TIMEOUT, notify=warn):
    """Run `spec` into the folder `out` (resuming what is there); returns the results table.

    scheduler: None (an embedded LocalCluster of `workers` processes), SERIAL (this process,
    no Dask), or the address of a running Dask scheduler ("tcp://host:8786"), which must answer
    within `connect_timeout` seconds (else ConnectionError).
    samples_per_task: None for the sweep file's, else measured for TASK_SECONDS.
    client: a distributed.Client to use instead (the benchmark reuses one cluster).
    notify(message): called with each chunk file that fails verification (it is recomputed)
    and each task whose rows are refused (they are not written).

    Raises store.SweepIncomplete, writing no results file, unless every sample has verified
    rows; ValueError for a bad argument or output folder; ConnectionError when the scheduler
    cannot be reached or the cluster fails (the finished tasks are kept for a rerun).
    """
    if scheduler is not None and scheduler != SERIAL:
        try:
            scheduler_address(scheduler)
        except ValueError as exc:
            raise ValueError(f"--scheduler: {exc}") from None
    per_task = samples_per_task or spec.samples_per_task
    at_once = 1 if scheduler == SERIAL else (workers or os.cpu_count() or 1) if scheduler is None else 1
    check_memory(spec, per_task or 1, at_once)
    store = SweepStore.open(out, spec, lambda: per_task or measure_samples_per_task(spec))
    check_memory(spec, store.samples_per_task, at_once)
    todo, bad = store.verify()
    for path, why in bad:
        notify(f"{path}: {why}; recomputing it")

    def keep(a, b, columns):
        try:
            store.write_chunk(a, b, columns)
        except BadRows as exc:
            notify(str(exc))

    done = spec.samples - sum(b - a for a, b in todo)
    with tqdm(total=spec.samples, initial=done, unit="sample", desc=spec.name, disable=not progress or None,
              smoothing=0.1) as bar:
        if todo and scheduler == SERIAL:
            for a, b in todo:
                keep(a, b, run_chunk(spec, a, b))
                bar.update(b - a)
        elif todo:
            from distributed import KilledWorker, as_completed
            try:
                with (contextlib.nullcontext(client) if client is not None
                      else dask_client(scheduler, workers, connect_timeout)) as client:
                    futures = {client.submit(run_chunk, spec, a, b, pure=False): (a, b) for a, b in todo}
                    for future in as_completed(futures):
                        a, b = futures.pop(future)
                        keep(a, b, future.result())
                        future.release()
                        bar.update(b - a)
            except (KilledWorker, concurrent.futures.CancelledError) as exc:
                raise ConnectionError(f"the Dask cluster failed ({type(exc).__name__}: {exc}); the finished "
                                      "tasks are kept, rerun the same command to resume".replace("\n", " ")) from None
    return store.combine()
