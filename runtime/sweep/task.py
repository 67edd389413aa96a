"""One Dask task: samples start..stop-1 of a sweep in one C batch call, as columns of result rows.

A task is a plain function of (spec, start, stop) with no state: any worker, or the client
itself (the serial mode), computes the same rows for the same samples.
"""
import numpy as np

from ..batch import METRIC_NAMES, simulate_many
from ..state import IDX_Q
from .spec import sample_inputs

#: Columns of every result row after the sample index and the varied quantities.
OUTCOME_COLUMNS = ("status", "steps_done") + METRIC_NAMES + ("end_x", "end_y")


def column_names(spec):
    """The columns of the result table, in order: sample, the quantities by name, the outcome."""
    if hasattr(spec, "columns"):              # a robustness sweep has its own outcome
        return spec.columns()
    return ("sample",) + tuple(q.name for q in spec.quantities) + OUTCOME_COLUMNS


def run_chunk(spec, start, stop):
    """{column: (stop-start,) array} for samples start..stop-1 (failed samples: NaN metrics)."""
    if hasattr(spec, "run_chunk"):            # a robustness sweep: closed loops, not one C batch
        return spec.run_chunk(start, stop)
    params, x0, u, values = sample_inputs(spec, start, stop)
    s = spec.scenario
    result = simulate_many(params, x0, s.dt, s.steps, u, method=s.method)
    q_end = result.final[:, IDX_Q]
    columns = {"sample": np.arange(start, stop, dtype=np.int64)}
    columns.update(values)
    columns["status"] = result.status.astype(np.int32)
    columns["steps_done"] = result.steps_done.astype(np.int64)
    columns.update(result.metrics)
    columns["end_x"], columns["end_y"] = q_end[:, 0].copy(), q_end[:, 1].copy()
    assert tuple(columns) == column_names(spec)
    return columns
