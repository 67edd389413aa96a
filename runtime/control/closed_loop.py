"""Closed-loop simulation: the plant on the C steppers, the controller sampled with a zero-order hold.

Every controller period the controller reads the measured state (the plant's state, plus sensor
noise if asked) or, with an estimator (`[estimator]` in a task file), the estimator's state
after that measurement; its torques are held constant, and the plant advances by
`Model.simulate` (the guarded C loop) for the period's steps.  The plant may have other
parameters than the controller's model (`[plant]` in a task file).

On sensors (`simulate_on_sensors`, a task's `[sensors]`), the controller never sees the plant's
state: the plant steps one step at a time under the set's process noise while runtime/sensor_sim.py
reads its sensors, every sample goes to the C EKF (`estimator.SensorEkf`) when it arrives, and the
controller reads the filter's estimate predicted to its sample time.  A sample taken at a
controller's sample time is read under that sample's new torques, so it reaches the filter just
after the controller has used the estimate: the firmware's order (estimate, control, then read).
"""
import dataclasses
import heapq
import time

import numpy as np
from tqdm.auto import tqdm

from ..model import Model
from ..sensor_sim import KINDS, SensorSimulation
from ..state import IDX_Q, NU
from ..validation import project_state
from .geometry import heading


@dataclasses.dataclass(frozen=True)
class Noise:
    """Sensor noise (standard deviations, Gaussian, independent per sample; seeded)."""
    position_m: float = 0.0      # on q_x, q_y
    attitude_rad: float = 0.0    # a small random rotation of R_S (re-projected onto SO(3))
    rate_rad_s: float = 0.0      # on ω_S, ω_Y, ω_P
    seed: int = 0

    @property
    def active(self):
        """True when any of the measurement noises is non-zero."""
        return self.position_m > 0 or self.attitude_rad > 0 or self.rate_rad_s > 0


@dataclasses.dataclass(frozen=True)
class ClosedLoopResult:
    """Row n of `trajectory` belongs to `time[n]`; `torques[n]` acts from time[n] to time[n+1]."""
    time: np.ndarray            # (n+1,) [s]
    trajectory: np.ndarray      # (n+1, 35), the plant's true states
    torques: np.ndarray         # (n+1, 2) [N m]; the last row repeats the one before
    control_time: np.ndarray    # (k,) [s] the controller's sample times
    saturated_fraction: float
    solve_s: np.ndarray         # (k,) [s] the controller's computation time per sample
    wall_time_s: float
    estimates: np.ndarray | None = None   # (k, 35): what the controller was given, when an estimator ran
    samples: list | None = None           # on sensors: (time [s], kind, reading) in the order applied, the
    #                                       controller's samples among them as (t, "tick", None)


def _measure(x, r, noise, rng):
    if not noise.active:
        return x
    from ..so3 import exp
    from ..state import IDX_NU, IDX_RS
    y = x.copy()
    y[IDX_Q.start:IDX_Q.start + 2] += rng.normal(0.0, noise.position_m, 2) if noise.position_m > 0 else 0.0
    if noise.attitude_rad > 0:
        y[IDX_RS] = (x[IDX_RS].reshape(3, 3) @ exp(rng.normal(0.0, noise.attitude_rad, 3))).ravel()
    if noise.rate_rad_s > 0:
        y[IDX_NU] += rng.normal(0.0, noise.rate_rad_s, IDX_NU.stop - IDX_NU.start)
    return project_state(y, r)


def _period_steps(controller, dt):
    per = round(controller.period / dt)
    if per < 1 or abs(per * dt - controller.period) > 1e-9 * controller.period:
        raise ValueError(f"controller.rate: the period 1/{controller.rate:g} s is not a whole number of "
                         f"plant steps dt = {dt:g} s")
    return per


def _target(reference, controller, t, y):
    target = reference.target(t, y[IDX_Q], float(heading(y)))
    if getattr(reference, "is_path", False) and hasattr(controller, "preview_distances"):
        target = dataclasses.replace(target, curvature_ahead=reference.curvature_ahead(
            controller.preview_distances(target)))
    return target


#: How `simulate_on_sensors` steps the plant, its sensors and the filter between the controller's
#: samples: "python", runtime/sensor_sim.py's SensorSimulation (the reference), or "c", the same in
#: one C call per controller period (runtime/sensor_sim_c.py), with the same readings, or "c-loop", the
#: controller and the reference's target in C too (runtime/control/loop_c.py: the LQR on a path, one
#: C call per chunk of samples).
ENGINES = ("python", "c", "c-loop")


def simulate_on_sensors(plant_params, controller, reference, x0, duration, dt, estimator, sensors, method="rkmk4",
                        seed=0, progress=False, engine="python", record_samples=True, read_truth=False):
    """Run `controller` on `reference` from x0 for `duration` s on the estimate of `estimator`
    (an `estimator.SensorEkf`) from the sensors `sensors` (a runtime.sensor_set.SensorSet) of the
    plant, seeded by `seed`; the plant steps by `dt`, the controller's period a whole number of steps.
    `engine`: one of ENGINES; `record_samples=False`: the result's `samples` is None (with the C
    engine, building that list costs a tenth of the run).  `read_truth`: the controller (and the reference's
    target) reads the plant's state at its samples instead of the estimate, the filter running and
    recorded as before on the same plant, process noise and readings (what the estimate costs the loop)."""
    if engine not in ENGINES:
        raise ValueError(f"engine: expected one of {', '.join(ENGINES)}, got {engine!r}")
    per = _period_steps(controller, dt)
    samples = round(duration / controller.period)
    if samples < 1:
        raise ValueError(f"duration: {duration:g} s is shorter than one controller period")
    steps = samples * per
    sim = SensorSimulation(Model(plant_params), sensors, dt, steps, method, seed)
    if engine == "c-loop":
        if read_truth:
            raise ValueError('read_truth: the C loop\'s controller reads the estimate only (engine "c" or "python")')
        from .loop_c import run
        return ClosedLoopResult(**run(sim, controller, reference, x0, estimator, per, samples, record_samples,
                                      progress))
    if engine == "c":
        return _on_sensors_c(sim, controller, reference, x0, estimator, per, samples, progress, record_samples,
                             read_truth)
    traj = np.empty((steps + 1, x0.size))
    torques = np.empty((steps + 1, NU))
    estimates = np.empty((samples, x0.size))
    applied, pending = [], []
    traj[0] = x = x0
    u = np.zeros(NU)
    start = estimator.at(0.0, u)
    controller.reset(x0 if read_truth else start)
    if hasattr(reference, "reset"):
        reference.reset()
    started = time.perf_counter()
    for k in tqdm(range(samples), disable=not progress or None, unit="sample", leave=False):
        t = k * controller.period
        y = estimates[k] = estimator.at(t, u)
        applied.append((t, "tick", None))
        if read_truth:
            y = x.copy()
        u = controller.update(t, y, _target(reference, controller, t, y))
        torques[k * per:(k + 1) * per] = u
        for s in range(k * per, (k + 1) * per):
            x, new = sim.advance(s, x, u)
            traj[s + 1] = x
            for kind, i in new:
                heapq.heappush(pending, (sim.arrival(kind, i), KINDS.index(kind), i, kind))
            while pending and pending[0][0] < (s + 1) * dt - 1e-9 * dt:
                arrival, _, i, kind = heapq.heappop(pending)
                estimator.sample(kind, arrival, sim.readings[kind][i], u)
                applied.append((arrival, kind, sim.readings[kind][i]))
    torques[-1] = torques[-2]
    return ClosedLoopResult(time=np.arange(len(traj)) * dt, trajectory=traj, torques=torques,
                            control_time=np.arange(samples) * controller.period,
                            saturated_fraction=controller.saturated_fraction,
                            solve_s=np.asarray(controller.solve_s), wall_time_s=time.perf_counter() - started,
                            estimates=estimates, samples=applied if record_samples else None)


def _on_sensors_c(sim, controller, reference, x0, estimator, per, samples, progress, record_samples, read_truth):
    from ..sensor_sim_c import SensorRunC
    steps = samples * per
    run = SensorRunC(sim, estimator, steps)
    traj = np.empty((steps + 1, x0.size))
    torques = np.empty((steps + 1, NU))
    estimates = np.empty((samples, x0.size))
    counts = np.empty(samples, dtype=np.int64)
    traj[0] = x0
    x = np.array(x0, dtype=np.float64)
    u = np.zeros(NU)
    start = estimator.at(0.0, u)
    controller.reset(x0 if read_truth else start)
    if hasattr(reference, "reset"):
        reference.reset()
    # A path's target and preview read in C, as the whole C loop reads them.
    from .loop_c import PathTargets
    from .reference import Path
    target_of = PathTargets(reference, controller) if type(reference) is Path else \
        (lambda t, y: _target(reference, controller, t, y))
    started = time.perf_counter()
    for k in tqdm(range(samples), disable=not progress or None, unit="sample", leave=False):
        t = k * controller.period
        y = estimates[k] = estimator.at(t, u)
        if read_truth:
            y = x.copy()
        u = controller.update(t, y, target_of(t, y))
        torques[k * per:(k + 1) * per] = u
        before = run.applied
        run.advance(k * per, per, x, u, traj[k * per + 1:(k + 1) * per + 1])
        counts[k] = run.applied - before
    torques[-1] = torques[-2]
    ticks = np.arange(samples) * controller.period
    return ClosedLoopResult(time=np.arange(len(traj)) * sim.dt, trajectory=traj, torques=torques,
                            control_time=ticks, saturated_fraction=controller.saturated_fraction,
                            solve_s=np.asarray(controller.solve_s), wall_time_s=time.perf_counter() - started,
                            estimates=estimates,
                            samples=run.samples(ticks, counts) if record_samples else None)


def simulate_closed_loop(plant_params, controller, reference, x0, duration, dt, method="rkmk4",
                         noise=Noise(), progress=False, estimator=None):
    """Run `controller` on `reference` from x0 for `duration` s; the plant steps by `dt`.

    The controller period must be a whole number of plant steps.  `estimator` (e.g.
    runtime.control.estimator.Ekf): `reset(y)` and `update(y, u, period)` -> the state the
    controller and the reference are given instead of the measurement y.  An estimator with a
    `rate` (> 0; a whole multiple of the controller's, its period a whole number of plant steps)
    reads the sensors at that rate, between the controller's samples too, as a filter on a
    faster sensor bus would; without one it runs once per controller sample.
    """
    per = _period_steps(controller, dt)
    sub = 1                     # estimator samples per controller sample
    if estimator is not None and getattr(estimator, "rate", 0):
        sub = round(controller.period * estimator.rate)
        if sub < 1 or abs(sub - controller.period * estimator.rate) > 1e-9 * sub:
            raise ValueError(f"estimator.rate: {estimator.rate:g} Hz is not a whole multiple of the controller's "
                             f"{controller.rate:g} Hz")
        if per % sub:
            raise ValueError(f"estimator.rate: the period 1/{estimator.rate:g} s is not a whole number of plant "
                             f"steps dt = {dt:g} s")
    per_e, period_e = per // sub, controller.period / sub
    samples = round(duration / controller.period)
    if samples < 1:
        raise ValueError(f"duration: {duration:g} s is shorter than one controller period")
    plant = Model(plant_params)
    rng = np.random.default_rng(noise.seed)
    traj = np.empty((samples * per + 1, x0.size))
    torques = np.empty((samples * per + 1, NU))
    traj[0] = x0
    controller.reset(_measure(x0, plant_params.r, noise, rng))
    if hasattr(reference, "reset"):
        reference.reset()
    estimates = np.empty((samples, x0.size)) if estimator is not None else None
    started = time.perf_counter()
    for k in tqdm(range(samples), disable=not progress or None, unit="sample", leave=False):
        x = traj[k * per]
        y = _measure(x, plant_params.r, noise, rng)
        if estimator is not None:
            y = estimator.reset(y) if k == 0 else estimator.update(y, u, period_e)
            estimates[k] = y
        u = controller.update(k * controller.period, y, _target(reference, controller, k * controller.period, y))
        torques[k * per:(k + 1) * per] = u
        for j in range(sub):    # the estimator's samples between the controller's, u held
            at = k * per + j * per_e
            if j > 0:
                estimator.update(_measure(traj[at], plant_params.r, noise, rng), u, period_e)
            traj[at:at + per_e + 1] = plant.simulate(traj[at], dt, per_e, np.tile(u, (per_e, 1)), method=method)
    torques[-1] = torques[-2]
    return ClosedLoopResult(time=np.arange(len(traj)) * dt, trajectory=traj, torques=torques,
                            control_time=np.arange(samples) * controller.period,
                            saturated_fraction=controller.saturated_fraction,
                            solve_s=np.asarray(controller.solve_s), wall_time_s=time.perf_counter() - started,
                            estimates=estimates)
