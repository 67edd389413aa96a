"""runtime/blas.py: under `one_thread()` every BLAS pool runs one thread, so linear algebra gives
what a process started on one thread (a Dask worker: OPENBLAS_NUM_THREADS=1) gives, bit for bit."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg
import threadpoolctl

from runtime.blas import one_thread

#: SciPy's expm of a 14 x 14 matrix (the size the LQR's discretisation takes): its Pade solve
#: rounds differently on two OpenBLAS threads.
EXPM = ("import json, numpy as np, scipy.linalg; "
        "M = np.random.default_rng(1).normal(size=(14, 14)) * 0.05; "
        "print(json.dumps(scipy.linalg.expm(M).tolist()))")


def _blas_threads():
    return [info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"]


def test_under_one_thread_every_blas_pool_runs_one_thread_and_the_counts_come_back_after():
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        before = _blas_threads()
        with one_thread():
            assert _blas_threads() == [1] * len(before)
        assert _blas_threads() == before


def _expm_in_a_process(threads):
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    env.update(OPENBLAS_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    out = subprocess.run([sys.executable, "-c", EXPM], env=env, capture_output=True, text=True, check=True)
    return np.array(json.loads(out.stdout))


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="OpenBLAS runs one thread on one core")
def test_expm_under_one_thread_equals_a_process_started_on_one_thread_and_two_threads_do_not():
    M = np.random.default_rng(1).normal(size=(14, 14)) * 0.05
    on_one = _expm_in_a_process(1)
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        with one_thread():
            assert np.array_equal(scipy.linalg.expm(M), on_one)
        # the check sees the threads: two give other last bits
        assert not np.array_equal(scipy.linalg.expm(M), on_one)
    assert not np.array_equal(_expm_in_a_process(2), on_one)
