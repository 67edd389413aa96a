"""One BLAS thread: linear algebra whose last bits do not depend on the process's thread count.

NumPy and SciPy each load their own OpenBLAS, which starts one thread per core unless the
environment says otherwise (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS).  On more than one thread
some of its routines round differently: SciPy's `expm` of the 14 × 14 matrix that discretises
the LQR's model with the path's states (runtime/control/lqr_design.py, `discretize`; its Padé
step solves with 14 right-hand sides) differs in the last bit at every point of the LQR's grid,
and the Riccati solutions carry that to the path and tight gains (by up to 2e-9).  A closed loop
turns such a difference into a different run.  Dask's nannies start their workers with those
variables at 1, so a sweep's rows are one-thread results; `one_thread()` gives the same wherever
a run is made (the client's serial mode, `--rerun`, a worker started without a nanny).  The
controllers' designs are cached per process (runtime/control/lqr.py): a design made before, on
more threads, is kept.  The identification's fit runs on one thread for speed (its products are
small).
"""
import functools

import scipy.linalg  # noqa: F401  (loads SciPy's OpenBLAS before the pools are listed)
import threadpoolctl


@functools.cache
def _pools():
    """The process's thread pools (threadpoolctl), found once: finding them walks every loaded
    library, 30 ms of CPU.  NumPy's and SciPy's OpenBLAS are loaded by then (the imports above)."""
    return threadpoolctl.ThreadpoolController()


def one_thread():
    """A context manager under which every BLAS pool (NumPy's and SciPy's) runs one thread; the
    counts before it are restored after."""
    return _pools().limit(limits=1, user_api="blas")

