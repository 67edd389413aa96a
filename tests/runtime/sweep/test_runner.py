"""Running sweeps (runtime/sweep/runner.py, store.py, task.py): the same rows serially, on an
embedded LocalCluster and on a real `dask scheduler` with two `dask worker` processes; a killed
sweep resumes to the same file; rows equal independent per-sample runs."""
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pyarrow.parquet as pq
import pytest

from runtime import Model, Params, SimulationStopped
from runtime.batch import METRIC_NAMES
from runtime.state import IDX_Q, IDX_WS
from runtime.sweep.runner import SERIAL, run_sweep
from runtime.sweep.spec import load_sweep, sample_inputs
from runtime.sweep.store import RESULTS


from .conftest import SWEEP, write_sweep

pytest.importorskip("distributed")


def same_rows(a, b):
    """Equal column names and values, NaN (the metrics of a failed sample) equal to NaN."""
    a, b = a.to_pydict(), b.to_pydict()
    return list(a) == list(b) and all(np.array_equal(np.asarray(a[k], dtype=float), np.asarray(b[k], dtype=float),
                                                     equal_nan=True) for k in a)


def results_bytes(folder):
    return (folder / RESULTS).read_bytes()


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    folder = tmp_path_factory.mktemp("serial")
    spec = load_sweep(write_sweep(folder))
    return spec, run_sweep(spec, folder / "out", scheduler=SERIAL, progress=False), folder / "out"


def test_serial_rows_equal_independent_runs_sample_by_sample(serial):
    spec, table, _ = serial
    rows = table.to_pydict()
    params, x0, u, _ = sample_inputs(spec, 0, spec.samples)
    s = spec.scenario
    assert rows["sample"] == list(range(spec.samples))
    failures = 0
    for i in range(spec.samples):
        try:
            model = Model(Params.from_array(params[i]))
        except ValueError:
            failures += 1
            assert rows["status"][i] != 0 and rows["steps_done"][i] == 0
            assert all(np.isnan(rows[name][i]) for name in METRIC_NAMES + ("end_x", "end_y"))
            continue
        try:
            traj = model.simulate(x0[i], s.dt, s.steps, u[i], method=s.method)
        except SimulationStopped as stop:      # a guard stopped it (a tiny pendulum mass is stiff)
            failures += 1
            assert (rows["status"][i], rows["steps_done"][i]) == (stop.status, stop.step - 1)
            continue
        q, w = traj[:, IDX_Q], traj[:, IDX_WS]
        assert rows["status"][i] == 0 and rows["steps_done"][i] == s.steps
        assert (rows["end_x"][i], rows["end_y"][i]) == (q[-1, 0], q[-1, 1])
        assert rows["path_length"][i] == pytest.approx(np.linalg.norm(np.diff(q, axis=0), axis=1).sum(), rel=1e-12)
        assert rows["max_distance"][i] == pytest.approx(np.linalg.norm(q - q[0], axis=1).max(), rel=1e-12)
        assert rows["max_shell_rate"][i] == pytest.approx(np.linalg.norm(w, axis=1).max(), rel=1e-12)
        assert rows["final_energy"][i] == pytest.approx(model.energy(traj[-1]), rel=1e-12)
    assert 0 < failures < spec.samples     # the file draws some invalid masses: they fail alone


def test_rows_do_not_depend_on_the_task_size(serial, tmp_path):
    spec, table, _ = serial
    assert same_rows(run_sweep(spec, tmp_path / "out", scheduler=SERIAL, samples_per_task=7, progress=False), table)


def test_the_row_comparison_sees_another_seed(serial, tmp_path):
    spec, table, _ = serial
    other = load_sweep(write_sweep(tmp_path, SWEEP.replace("seed = 7", "seed = 8")))
    assert same_rows(table, table)
    assert not same_rows(run_sweep(other, tmp_path / "out", scheduler=SERIAL, progress=False), table)


def test_embedded_local_cluster_writes_the_serial_file(serial, tmp_path):
    spec, _, serial_out = serial
    run_sweep(spec, tmp_path / "out", workers=2, progress=False)
    assert results_bytes(tmp_path / "out") == results_bytes(serial_out)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def dask_cluster(tmp_path):
    """`dask scheduler` and two `dask worker` processes on 127.0.0.1; they stop by themselves
    after two minutes idle or alive (and are killed at teardown)."""
    address = f"tcp://127.0.0.1:{free_port()}"
    dask = [sys.executable, "-m", "dask"]
    common = dict(cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    procs = [subprocess.Popen(dask + ["scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
                                      "--no-dashboard", "--idle-timeout", "120"], **common)]
    for _ in range(2):
        procs.append(subprocess.Popen(dask + ["worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                                              "--no-dashboard", "--lifetime", "120", "--death-timeout", "60"],
                                      **common))
    try:
        from distributed import Client
        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
        yield address
    finally:
        for p in procs:
            with __import__("contextlib").suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=10)


def test_embedded_cluster_workers_run_without_the_statistical_profiler_and_tick_slowly():
    """Dask's periodic work competes with the C loops for the cores (runner.dask_client)."""
    import dask
    from runtime.sweep.runner import EMBEDDED_CLUSTER_CONFIG, dask_client
    with dask_client(workers=1) as client:
        seen = client.run(lambda: {key: dask.config.get(key) for key in EMBEDDED_CLUSTER_CONFIG})
        assert list(seen.values()) == [EMBEDDED_CLUSTER_CONFIG]
        assert all("profile" not in name for names in client.run(
            lambda dask_worker: list(dask_worker.periodic_callbacks)).values() for name in names)


def test_a_dask_scheduler_with_two_workers_writes_the_serial_file(serial, dask_cluster, tmp_path):
    spec, _, serial_out = serial
    run_sweep(spec, tmp_path / "out", scheduler=dask_cluster, progress=False)
    assert results_bytes(tmp_path / "out") == results_bytes(serial_out)


def test_a_sweep_killed_midway_and_restarted_writes_the_uninterrupted_file(tmp_path):
    # 250 tasks of a few ms each: a window of seconds to kill it in, even on a busy host
    path = write_sweep(tmp_path, SWEEP.replace("samples = 24", "samples = 1000").replace(
        "samples_per_task = 5", "samples_per_task = 4"))
    command = [sys.executable, "-m", "runtime", "sweep", str(path), "--out", str(tmp_path / "killed"),
               "--scheduler", SERIAL, "--no-progress"]
    chunks = tmp_path / "killed" / "chunks"
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while len(list(chunks.glob("part-*.parquet"))) < 5 if chunks.is_dir() else True:
            assert proc.poll() is None and time.monotonic() < deadline, "the sweep ended before it was killed"
            time.sleep(0.005)
        proc.kill()
    finally:
        proc.kill()
        proc.wait(timeout=30)
    written = len(list(chunks.glob("part-*.parquet")))
    assert 5 <= written < 250 and not (tmp_path / "killed" / RESULTS).exists()
    assert subprocess.run(command, stdout=subprocess.DEVNULL, timeout=300).returncode in (0, 1)
    spec = load_sweep(path)
    run_sweep(spec, tmp_path / "whole", scheduler=SERIAL, progress=False)
    assert results_bytes(tmp_path / "killed") == results_bytes(tmp_path / "whole")
    assert pq.read_table(tmp_path / "killed" / RESULTS).num_rows == 1000


def test_a_folder_of_another_sweep_is_refused(serial, tmp_path):
    spec, _, serial_out = serial
    with pytest.raises(ValueError, match="--out: .* different sweep"):
        run_sweep(spec.with_samples(25), serial_out, scheduler=SERIAL, progress=False)


def test_a_non_empty_folder_without_a_sweep_is_refused(serial, tmp_path):
    spec, _, _ = serial
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="not empty"):
        run_sweep(spec, tmp_path, scheduler=SERIAL, progress=False)
