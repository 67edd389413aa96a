"""`python -m runtime sweep-bench` (`make sweep-bench`, run by `make bench`): what a sweep costs.

On the first N samples of the shipped sweep (t-shape, +-10 % in every mass and damping):

* the C batch called directly: one `simulate_many` over inputs prepared beforehand;
* the same tasks run in this process (inputs drawn per task, no Dask, no files);
* the whole sweep on an embedded LocalCluster of 1 and of 2 single-threaded worker processes
  (Parquet chunk files and the final results file included; cluster start-up excluded and
  timed separately), as simulations per second: speedup 2 vs 1 worker, overhead of 1 worker
  against the direct C batch;
* Dask's own cost per task: a round trip of many no-op tasks on the 1-worker cluster;
* bytes per result: a task's pickled columns and the Parquet file, per sample.

From these, a scaling model (docs/sweeps.md): wall time of n samples on W workers in tasks of
k samples ~ n c / W + (n / k) o / W, with c the cost of one sample and o the per-task cost; the
scheduler hands out at most about 1 / o_s tasks per second.  Every run is written to its own
file under bench/results/sweep/ (never overwritten), with the CPU it ran on.
"""
import argparse
import datetime
import os
import pathlib
import pickle
import sys
import tempfile
import time

from ..batch import simulate_many
from .report import write_results
from .timing import cpu_name
from ..sweep.runner import dask_client, run_sweep
from ..sweep.spec import load_sweep, sample_inputs
from ..sweep.store import RESULTS, SweepStore
from ..sweep.task import run_chunk

#: The sweep the numbers are for.
SWEEP = "t-shape-uncertainty"


def _seconds(fn):
    start = time.perf_counter()
    out = fn()
    return time.perf_counter() - start, out


def _noop(i):
    return i


def _cpu_seconds(client):
    """CPU seconds used so far by this process and every worker process: unlike wall time, the
    cost of the Dask path stays measurable when other jobs share the cores."""
    return time.process_time() + sum(client.run(time.process_time).values())


def measure(samples, per_task, noop_tasks, rounds, progress):
    """Best of `rounds` of every timing; the rounds alternate the paths, so a host busy for a while
    slows each of them in some round rather than one path in all."""
    spec = load_sweep(SWEEP).with_samples(samples)
    s = spec.scenario
    chunks = [(a, min(a + per_task, samples)) for a in range(0, samples, per_task)]
    res = {"sweep": SWEEP, "samples": samples, "samples_per_task": per_task, "tasks": len(chunks),
           "steps_per_sample": s.steps, "method": s.method, "rounds": rounds}
    best = {}

    def keep(key, seconds):
        best[key] = min(best.get(key, float("inf")), seconds)

    clusters = {}
    try:
        for workers in (1, 2):
            progress(f"starting a LocalCluster with {workers} worker(s)")
            context = dask_client(workers=workers)
            seconds, client = _seconds(context.__enter__)
            clusters[workers] = (context, client)
            client.wait_for_workers(workers)
            res[f"dask_{workers}_workers_startup_s"] = seconds
            client.gather(client.map(_noop, range(50)))           # warm up: imports, connections
        for r in range(rounds):
            progress(f"round {r + 1} of {rounds}")
            seconds, inputs = _seconds(lambda: sample_inputs(spec, 0, samples))
            keep("inputs_s", seconds)
            params, x0, u, _ = inputs
            cpu = time.process_time()
            keep("direct_c_batch_s", _seconds(lambda: simulate_many(params, x0, s.dt, s.steps, u, method=s.method))[0])
            keep("direct_c_batch_cpu_s", time.process_time() - cpu)
            keep("serial_tasks_s", _seconds(lambda: [run_chunk(spec, a, b) for a, b in chunks])[0])
            for workers, (_, client) in clusters.items():
                with tempfile.TemporaryDirectory() as tmp:
                    cpu = _cpu_seconds(client)
                    seconds, table = _seconds(lambda: run_sweep(spec, f"{tmp}/out", samples_per_task=per_task,
                                                                progress=False, client=client))
                    keep(f"dask_{workers}_workers_s", seconds)
                    keep(f"dask_{workers}_workers_cpu_s", _cpu_seconds(client) - cpu)
                    assert table.num_rows == samples
                    res["parquet_bytes_per_sample"] = (pathlib.Path(tmp) / "out" / RESULTS).stat().st_size / samples
                    store = SweepStore(pathlib.Path(tmp) / "out", spec, per_task)
                    columns = run_chunk(spec, *chunks[0])
                    keep("parquet_write_per_task_s", _seconds(lambda: store.write_chunk(*chunks[0], columns))[0])
            client = clusters[1][1]
            keep("dask_seconds_per_noop_task",
                 _seconds(lambda: client.gather(client.map(_noop, range(r * noop_tasks, (r + 1) * noop_tasks))))[0]
                 / noop_tasks)
    finally:
        for context, _ in clusters.values():
            context.__exit__(None, None, None)
    res.update(best)
    columns = run_chunk(spec, *chunks[0])
    res["pickled_bytes_per_sample"] = len(pickle.dumps(columns)) / (chunks[0][1] - chunks[0][0])
    return res


def derive(res):
    """Throughputs, ratios and the scaling model from the measured times."""
    n = res["samples"]
    out = {
        "direct_c_batch_per_second": n / res["direct_c_batch_s"],
        "serial_tasks_per_second": n / res["serial_tasks_s"],
        "dask_1_worker_per_second": n / res["dask_1_workers_s"],
        "dask_2_workers_per_second": n / res["dask_2_workers_s"],
    }
    out["speedup_2_vs_1_workers"] = res["dask_1_workers_s"] / res["dask_2_workers_s"]
    out["dask_1_worker_overhead_vs_direct"] = res["dask_1_workers_s"] / res["direct_c_batch_s"] - 1
    out["dask_1_worker_cpu_overhead_vs_direct"] = res["dask_1_workers_cpu_s"] / res["direct_c_batch_cpu_s"] - 1
    out["dask_2_workers_cpu_overhead_vs_direct"] = res["dask_2_workers_cpu_s"] / res["direct_c_batch_cpu_s"] - 1
    c = res["direct_c_batch_s"] / n                 # one sample in C
    i = res["inputs_s"] / n                         # drawing one sample's inputs
    o = res["dask_seconds_per_noop_task"]           # Dask's round trip of one task
    w = res["parquet_write_per_task_s"]             # writing one chunk file
    out.update(seconds_per_sample=c, seconds_inputs_per_sample=i)
    # 10^6 samples on 64 workers, tasks of about 2 s of work: compute and per-task costs divide by
    # the workers; the one scheduler hands out tasks one after another, the one client writes them.
    k = max(1, round(2.0 / (c + i)))
    tasks = -(-10**6 // k)
    compute = 10**6 * (c + i) / 64
    out["model_1e6_on_64"] = {
        "samples_per_task": k, "tasks": tasks, "compute_s": compute,
        "per_task_overhead_s": tasks * o / 64, "scheduler_and_client_s": tasks * (o + w),
        "result_bytes": 10**6 * res["parquet_bytes_per_sample"],
        "wall_s": max(compute + tasks * o / 64, tasks * (o + w)),
    }
    return out


def format_report(result):
    """The sweep benchmark's result as the printed text report."""
    r, d = result["measured"], result["derived"]
    m = d["model_1e6_on_64"]
    lines = [f"sweep benchmark, {result['date']}, CPU: {result['cpu']} ({result['cores']} cores, load average "
             f"{result['load_average_at_start'][0]:.1f} at the start), best of {r['rounds']} rounds",
             f"{r['samples']} samples of {r['sweep']} ({r['steps_per_sample']} {r['method']} steps each), "
             f"{r['tasks']} tasks of {r['samples_per_task']}",
             f"  direct C batch (simulate_many):  {d['direct_c_batch_per_second']:8.1f} simulations/s",
             f"  tasks in this process:           {d['serial_tasks_per_second']:8.1f} simulations/s",
             f"  Dask LocalCluster, 1 worker:     {d['dask_1_worker_per_second']:8.1f} simulations/s "
             f"(overhead vs direct {100 * d['dask_1_worker_overhead_vs_direct']:+.1f} %)",
             f"  Dask LocalCluster, 2 workers:    {d['dask_2_workers_per_second']:8.1f} simulations/s "
             f"(speedup {d['speedup_2_vs_1_workers']:.2f}x)",
             f"  CPU time (client + workers) against the direct C batch's: 1 worker "
             f"{100 * d['dask_1_worker_cpu_overhead_vs_direct']:+.1f} %, 2 workers "
             f"{100 * d['dask_2_workers_cpu_overhead_vs_direct']:+.1f} %",
             f"  cluster start-up: {r['dask_1_workers_startup_s']:.1f} s (1 worker), "
             f"{r['dask_2_workers_startup_s']:.1f} s (2 workers)",
             f"  per sample: C {1e3 * d['seconds_per_sample']:.2f} ms, inputs {1e6 * d['seconds_inputs_per_sample']:.0f} us; "
             f"per task: Dask round trip {1e3 * r['dask_seconds_per_noop_task']:.2f} ms, "
             f"Parquet chunk file {1e3 * r['parquet_write_per_task_s']:.2f} ms",
             f"  bytes per result: {r['pickled_bytes_per_sample']:.0f} pickled, "
             f"{r['parquet_bytes_per_sample']:.0f} in Parquet",
             f"  model, 10^6 samples on 64 workers: tasks of {m['samples_per_task']} ({m['tasks']} tasks), "
             f"compute {m['compute_s']:.0f} s + per-task {m['per_task_overhead_s']:.1f} s, scheduler and client "
             f"{m['scheduler_and_client_s']:.1f} s, wall ~{m['wall_s']:.0f} s, results {m['result_bytes'] / 1e6:.0f} MB",
             "  targets: speedup >= 1.8: " + ("met" if d["speedup_2_vs_1_workers"] >= 1.8 else "MISSED")
             + "; Dask overhead <= 10 %: " + ("met" if d["dask_1_worker_overhead_vs_direct"] <= 0.10 else "MISSED")]
    return "\n".join(lines)


def main(argv=None):
    """`python -m runtime.sweep.bench`: time the sweep on Dask and write the result file."""
    p = argparse.ArgumentParser(prog="python -m runtime sweep-bench", description=__doc__.split("\n\n")[0])
    p.add_argument("--samples", type=int, default=4000, help="samples of the shipped sweep (default 4000)")
    p.add_argument("--samples-per-task", type=int, default=250,
                   help="task size (default 250: 16 tasks of ~0.5 s; real sweeps size them to ~2 s)")
    p.add_argument("--noop-tasks", type=int, default=1000, help="no-op tasks for Dask's per-task cost")
    p.add_argument("--rounds", type=int, default=3, help="rounds; every time is the best of them (default 3)")
    p.add_argument("--out", default="bench/results/sweep", help="results folder (default bench/results/sweep)")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args(argv)
    for name in ("samples", "samples_per_task", "noop_tasks", "rounds"):
        if getattr(args, name) < 1:
            p.error(f"--{name.replace('_', '-')}: expected a positive integer")

    def progress(msg):
        if not args.quiet:
            print(f"sweep-bench: {msg}", file=sys.stderr, flush=True)

    date, load = datetime.datetime.now().isoformat(timespec="seconds"), os.getloadavg()
    measured = measure(args.samples, args.samples_per_task, args.noop_tasks, args.rounds, progress)
    result = {"date": date, "cpu": cpu_name(), "cores": os.cpu_count(), "load_average_at_start": load,
              "load_average_at_end": os.getloadavg(), "measured": measured,
              "derived": derive(measured)}
    print(format_report(result))
    print(f"\nwritten: {write_results(result, args.out)}")
    return 0
