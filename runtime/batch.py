"""`simulate_many`: many robots in one C call (c/sr_batch.c), each its own parameters, initial
state and torque program, with a status per sample: one failing sample never spoils the others.

    result = simulate_many([Params(m_P=m) for m in (0.9, 1.0, 1.1)], initial_state(), dt=0.01, steps=1000)
    result.status          # (3,) SR_* codes, 0 = ok
    result.final           # (3, 35) final states (NaN rows for failed samples)
    result.metrics["path_length"]

The C loop runs with the GIL released (cffi releases it around every call into C), so
threads (a Dask worker's, for instance) can run batches side by side.  Sample i is bit for bit
`Model(params[i]).simulate(x0[i], dt, steps, u[i], method, energy_tol)`: the same chunks of
`model.CHUNK_STEPS` steps, the same energy guard carried across them.
"""
import dataclasses

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from . import memory
from . import model as _model
from .params import Params
from .state import NU, NX
from .validation import real_array

METRIC_NAMES = tuple(name for _, name in sorted({
    lib.SR_BATCH_PATH_LENGTH: "path_length",          # length of the path of the shell centre [m]
    lib.SR_BATCH_MAX_DISTANCE: "max_distance",        # largest |q_k − q_0| [m]
    lib.SR_BATCH_MAX_SHELL_RATE: "max_shell_rate",    # largest |ω_S| [rad/s]
    lib.SR_BATCH_FINAL_ENERGY: "final_energy",        # energy of the final state [J]
}.items()))
"""Summary metrics of every sample, by the index C writes them at (c/spherical_robot.h, SR_BATCH_*)."""
assert len(METRIC_NAMES) == lib.SR_BATCH_NMETRICS


@dataclasses.dataclass
class BatchResult:
    """Outcome of `simulate_many` for n samples.

    status (n,) SR_* status codes (0: ok); steps_done (n,) steps completed; final (n, 35) the
    final states; metrics {name: (n,)} for the names of METRIC_NAMES; trajectories
    (n, steps+1, 35) when asked for, else None.  Failed samples have NaN in final and metrics
    (their status says why) and, in trajectories, the rows computed before the failure.
    """
    status: np.ndarray
    steps_done: np.ndarray
    final: np.ndarray
    metrics: dict
    trajectories: np.ndarray | None = None

    @property
    def ok(self):
        """(n,) bool: the samples that ran to the end."""
        return self.status == lib.SR_OK

    def message(self, i):
        """Why sample i failed, in words ("ok" when it did not)."""
        return ffi.string(lib.sr_status_string(int(self.status[i]))).decode()


def _params_array(params):
    """(B, SR_NPARAM) or (SR_NPARAM,) float64 from a Params, a sequence of Params, or an array in
    the C library's order (SR_P_*)."""
    if isinstance(params, Params):
        return params.as_array()
    if isinstance(params, (list, tuple)) and params and all(isinstance(p, Params) for p in params):
        return np.stack([p.as_array() for p in params])
    return real_array(params, "params", (lib.SR_NPARAM,))


def _sample_count(arrays):
    """The batch size n: the leading size of every batched argument (they must agree), else 1."""
    sizes = {name: arr.shape[0] for name, (arr, single_ndim) in arrays.items() if arr.ndim > single_ndim}
    if len(set(sizes.values())) > 1:
        raise ValueError("params, x0, u: batch sizes differ: "
                         + ", ".join(f"{name} has {size}" for name, size in sizes.items()))
    return next(iter(sizes.values()), 1)


def simulate_many(params, x0, dt, steps, u=None, method="lie-euler", energy_tol=_model.ENERGY_TOL,
                  trajectories=False):
    """Simulate n robots in one C call; returns a `BatchResult`.

    params: a Params (shared), a sequence of n Params, or an array (12,) / (n, 12) in the order
    of runtime.params.NAMES (an array may hold invalid values: those samples fail alone, with
    SR_ERR_PARAM or SR_ERR_NONFINITE).  x0: (35,) shared or (n, 35).  u: None (zero torque),
    (steps, 2) shared or (n, steps, 2); row k−1 acts on step k.  dt, steps, method, energy_tol:
    as in `Model.simulate`.  trajectories=True also returns every trajectory (n, steps+1, 35).

    With trajectories=True the memory they take is estimated first: beyond runtime.memory's
    budget, MemoryBudgetExceeded (a ValueError) naming `trajectories`.

    Wrong types and shapes raise ValueError naming the argument; a sample whose values are bad
    (parameters out of range, an invalid x0, a NaN torque) or whose run stops at a guard gets
    its status instead, and the others run as if it were not there.
    """
    dt = _model.Model._dt(dt)
    steps = _model.step_count(steps)
    code = _model._method(method)
    tol = _model.Model._energy_tol(energy_tol)
    p = _params_array(params)
    x = real_array(x0, "x0", (NX,))
    arrays = {"params": (p, 1), "x0": (x, 1)}
    if u is not None:
        u = real_array(u, "u", (steps, NU))
        arrays["u"] = (u, 2)
    n = _sample_count(arrays)
    if trajectories:     # before anything is allocated, as a scenario's run
        memory.check("trajectories", {f"{n} trajectories of {steps + 1} states": n * (steps + 1) * memory.STATE_ROW_BYTES,
                                      "final states": n * memory.STATE_ROW_BYTES})
    stride = {name: (arr[0].size if arr.ndim > single_ndim else 0) for name, (arr, single_ndim) in arrays.items()}

    status = np.full(n, -1, dtype=np.intc)
    steps_done = np.zeros(n, dtype=np.int_)
    final = np.full((n, NX), np.nan)
    metrics = np.full((n, lib.SR_BATCH_NMETRICS), np.nan)
    traj = np.full((n, steps + 1, NX), np.nan) if trajectories else None
    work = None if trajectories else np.empty((_model.CHUNK_STEPS + 1, NX))
    rc = lib.sr_simulate_batch(
        code, n, pointer(p), stride["params"], pointer(x), stride["x0"], dt, steps,
        ffi.NULL if u is None else pointer(u), stride.get("u", 0), tol, _model.CHUNK_STEPS,
        ffi.NULL if work is None else pointer(work), ffi.NULL if traj is None else pointer(traj),
        pointer(final), pointer(metrics), ffi.cast("int *", ffi.from_buffer(status)),
        ffi.cast("long *", ffi.from_buffer(steps_done)))
    if rc != lib.SR_OK:   # every argument was checked above: a failure here is a bug, not bad input
        raise RuntimeError(f"sr_simulate_batch: {ffi.string(lib.sr_status_string(rc)).decode()}")
    return BatchResult(status=status, steps_done=steps_done, final=final,
                       metrics={name: metrics[:, i].copy() for i, name in enumerate(METRIC_NAMES)},
                       trajectories=traj)
