"""The whole closed loop on sensors in C (c/include/sr_loop.h): plant, sensors, filter, the path's
target and the LQR, one C call per chunk of controller samples.

    if supports(controller, reference):
        result = run(sim, controller, reference, x0, estimator, per, samples, record_samples)

It does what runtime/control/closed_loop.py's Python loop does with the LQR (runtime/control/lqr.py)
on a path reference, sample for sample: the filter predicted to the sample, the target at the
estimate's position, the operating curvature the mean over the controller's preview, the C law,
the run advanced one period; with a slope's feedforward, the C slope estimate updated before the law
(or the model's slope fed forward).  That loop stays the reference it is tested against.
"""
import dataclasses
import time

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from ..errors import KernelError
from ..sensor_sim_c import SensorRunC
from ..state import IDX_Q, NU
from .lqr import Lqr
from .reference import SEARCH_AHEAD_M, SEARCH_BACK_M, Path, Target
from .slope import SlopeEstimatorC

#: Controller samples per C call (a progress bar moves between calls).
CHUNK = 500


def supports(controller, reference):
    """True when the C loop runs this pair: the LQR exactly (not a subclass with its own Python), its
    slope estimate, if any, the C one (`SlopeEstimatorC`: the loop updates it), on a path reference."""
    return (type(controller) is Lqr and (controller._estimator is None or type(controller._estimator) is SlopeEstimatorC)
            and type(reference) is Path)


def c_path(reference, keep):
    """The path `reference` as the C struct sr_path (cffi), searching from its current hint; its
    arrays are appended to `keep` (they must outlive the struct)."""
    arrays = [np.ascontiguousarray(a, dtype=np.float64)
              for a in (reference.points, reference.s, reference.tangent, reference.curvature)]
    keep.extend(arrays)
    c = ffi.new("sr_path *")
    c.n = len(reference.s)
    c.points, c.s, c.tangent, c.curvature = (pointer(a) for a in arrays)
    c.speed, c.search_back, c.search_ahead, c.hint = reference.speed, SEARCH_BACK_M, SEARCH_AHEAD_M, reference._hint
    status = lib.sr_path_check(c)
    if status != lib.SR_OK:
        raise ValueError(f"reference: the path is not valid for the C loop "
                         f"({ffi.string(lib.sr_status_string(status)).decode()})")
    return c


class PathTargets:
    """`targets(t, y)` -> the Target of the path `reference` at the estimate y, with the curvature
    ahead at `controller`'s preview distances: what closed_loop.py's Python target gives, read in C
    (sr_path_target, sr_path_curvature_ahead) for the closed loop whose controller stays in Python.
    The reference's hint follows."""

    def __init__(self, reference, controller):
        self.reference, self.controller = reference, controller
        self._keep = []
        self._path = c_path(reference, self._keep)
        self._target = ffi.new("sr_lqr_target *")
        self._preview = hasattr(controller, "preview_distances")
        self._distances, self._ahead = None, None

    def __call__(self, t, y):
        """The target at time t [s] for the estimate y (35,)."""
        y = np.ascontiguousarray(y, dtype=np.float64)
        status = lib.sr_path_target(self._path, pointer(y) + IDX_Q.start, self._target)
        if status != lib.SR_OK:
            raise ValueError(f"reference: {ffi.string(lib.sr_status_string(status)).decode()} at t = {t:g} s")
        self.reference._hint = int(self._path.hint)
        c = self._target
        target = Target(c.speed, c.heading, c.curvature, c.cross_track)
        if not self._preview:
            return target
        distances = np.ascontiguousarray(self.controller.preview_distances(target), dtype=np.float64)
        if self._ahead is None or len(self._ahead) != len(distances):
            self._ahead = np.empty(len(distances))
        lib.sr_path_curvature_ahead(self._path, pointer(distances), len(distances), pointer(self._ahead))
        return dataclasses.replace(target, curvature_ahead=tuple(self._ahead.tolist()))


def track(reference, positions):
    """(signed cross-track errors (n,) [m], progress [m]) of positions (n, >= 2) matched in order on
    the path `reference` (from its start), in one C call (sr_path_cross_track): what
    `Path.cross_track` gives, and the arc length from the first position's nearest sample to the
    last one's."""
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    if positions.ndim != 2 or positions.shape[1] < 2 or len(positions) == 0:
        raise ValueError(f"positions: expected an (n, >= 2) array with n >= 1, got shape {positions.shape}")
    keep = []
    path = c_path(reference, keep)
    path.hint = 0
    out, first = np.empty(len(positions)), ffi.new("long *")
    status = lib.sr_path_cross_track(path, pointer(positions), len(positions), positions.shape[1], pointer(out), first)
    if status != lib.SR_OK:
        raise ValueError(f"positions: {ffi.string(lib.sr_status_string(status)).decode()}")
    return out, float(reference.s[path.hint] - reference.s[first[0]])



def run(sim, controller, reference, x0, estimator, per, samples, record_samples, progress=False):
    """The closed loop of `samples` controller samples of `per` plant steps each on the run `sim`
    (a SensorSimulation) with the filter of `estimator` (a SensorEkf): the fields of closed_loop.py's
    ClosedLoopResult, as a dict (closed_loop builds the result: it imports this module).  Its
    `solve_s` is the loop's own time spread evenly over the samples (the controller is not timed
    apart from the plant in C)."""
    from tqdm.auto import tqdm
    if not supports(controller, reference):
        raise ValueError(f"engine: the C loop runs the LQR (its slope estimate the C one) on a path reference, "
                         f"got {controller.kind} on {type(reference).__name__}")
    steps = samples * per
    sim_c = SensorRunC(sim, estimator, steps)
    traj = np.empty((steps + 1, x0.size))
    torques = np.empty((samples, NU))
    estimates = np.empty((samples, x0.size))
    applied = np.zeros(samples, dtype=np.int64)
    traj[0] = x0
    x = np.array(x0, dtype=np.float64)
    u = np.zeros(NU)
    controller.reset(estimator.at(0.0, u))
    reference.reset()
    keep = []
    path = c_path(reference, keep)
    preview = np.ascontiguousarray(controller.preview_distances(None), dtype=np.float64)
    saturated, done, failed_in = ffi.new("long *"), ffi.new("long *"), ffi.new("int *")
    # the slope estimate's struct, updated in C; else the model's slope fed forward (or nothing)
    estimate = ffi.NULL if controller._estimator is None else controller._estimator._c
    offsets = controller.offsets()
    sim_c._c.filter_time = estimator.t
    started = time.perf_counter()
    for first in tqdm(range(0, samples, CHUNK), disable=not progress or None, unit="chunk", leave=False):
        count = min(CHUNK, samples - first)
        status = lib.sr_loop_lqr(sim_c._c, sim.plant._model, estimator.filter._ekf, controller._model._model,
                                 controller._c, controller._memory, estimate, offsets, path, pointer(preview), len(preview),
                                 per, first, count, pointer(x), pointer(u), pointer(traj[first * per + 1:]), pointer(torques[first:]),
                                 pointer(estimates[first:]), ffi.cast("long *", ffi.from_buffer(applied[first:])),
                                 saturated, done, failed_in)
        estimator.t = float(sim_c._c.filter_time)
        reference._hint = int(path.hint)
        if status != lib.SR_OK:
            at = (first + done[0]) * controller.period
            if failed_in[0] == lib.SR_LOOP_CONTROL:
                if status == lib.SR_ERR_MODEL:
                    raise KernelError("model", status, f" (controller lqr at t = {at:g} s)")
                raise ValueError(f"controller lqr: {ffi.string(lib.sr_status_string(status)).decode()} at t = {at:g} s")
            raise KernelError("x", status, f" (the C closed loop at t = {at:g} s)")
    wall = time.perf_counter() - started
    controller.samples, controller.saturated = samples, int(saturated[0])
    controller.solve_s = [wall / samples] * samples
    steps_torques = np.empty((steps + 1, NU))
    steps_torques[:-1] = np.repeat(torques, per, axis=0)
    steps_torques[-1] = steps_torques[-2]
    ticks = np.arange(samples) * controller.period
    counts = np.diff(applied, prepend=0)
    return dict(time=np.arange(len(traj)) * sim.dt, trajectory=traj, torques=steps_torques,
                control_time=ticks, saturated_fraction=controller.saturated_fraction,
                solve_s=np.asarray(controller.solve_s), wall_time_s=wall, estimates=estimates,
                samples=sim_c.samples(ticks, counts) if record_samples else None)
