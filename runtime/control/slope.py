"""A slope in any direction for the LQR: its feedforward, and its estimate from the measured rates.

The model carries a slope along the plane's x axis only (`Params.slope`), but the dynamics do not
change when the robot and the slope turn together about the floor's normal: a robot heading ψ on a
slope whose uphill direction is β moves as one heading ψ − β on the model's slope.  So one slope
model serves every direction, and a small slope acts through two numbers, the world's slope vector

    s = α (cos β, sin β)      [rad]: the inclination α, uphill towards β,

read against the reference's heading ψ as its components along the path, s·t, and to the right of
it, s_x sin ψ − s_y cos ψ (= α sin(ψ − β)).

Feedforward.  At each point (v, κ) of the LQR's design grid, the operating point (z*, u*) of the
flat design moves, to first order in α, by α (cos(ψ − β) D_up + sin(ψ − β) D_right): D_up and D_right
the derivatives of the operating point (Newton on the reduced field, runtime/control/lqr_design.py)
on the model's slope with the reference heading up it and across it (uphill on the right).  The law
u = u* − K (z − z*) then gains Δu* + K Δz*.  On a line that is the exact steady state to first order;
on a circle the pull turns with the heading and this holds the operating point of the moment.

Estimate.  Between two samples the torques are held, so the rates one period later are those the
model predicts plus what the slope adds, linear in s: ν⁺ − ν̂⁺(flat) ≈ G_x s_x + G_y s_y, G the
model's step on a slope along x (for s_y: with the state turned by −π/2 about the normal) less the
flat one, per radian.  `SlopeEstimator` solves these with exponential forgetting (time constant τ).

A slope and a pendulum unlike the model's.  A pendulum heavier than the model's, or with its centre
of mass moved, pulls on the rates too, and fitted with the slope and a torque offset alone it is read
as a slope (in a transient, tens of times the slope the table's plants stand on) that the
feedforward then acts on; so does a pendulum joint damped unlike the model's (k_P ∓20 %: 5 and 7
times the table's slope on the circle).  But they pull as a change of the model's parameters does:
through the pendulum's swing and lean, fixed to the robot, where a slope's pull turns with the
heading relative to the fall line and acts on the whole robot.  So the estimate carries the
pendulum's mass, centre of mass and joint damping as well, their columns the model's one-period
rates with each moved, less the flat ones (the identification's parameter sensitivities, here by
differences); the slope fed forward is the part the pendulum does not explain.  The LQR with `pendulum_feedforward` > 0 feeds the
pendulum's part forward too, as the slope's: the operating point's derivatives with respect to m_P
and c_P (`PendulumSchedule`), the steady torques and lean a pendulum unlike the model's needs.
Without it the controllers' integrals and torque offset hold the pendulum's part as they do without
an estimate.  Until the samples tell the
pendulum from the slope and d (rolling straight from the start, its columns lie nearly in their
span), the slope and d are fitted alone with the pendulum held, so the slope is read as early as
without it.
"""
import dataclasses
import math

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from ..model import Model
from ..so3 import rot_z
from ..state import IDX_NU, IDX_Q, IDX_RS, NV, NX
from . import lqr_design as design
from .lqr_design import Schedule

#: The slope [rad] at which the operating points' derivatives are taken (small: first order; large
#: enough that Newton's tolerance is far below the change).
PROBE_SLOPE = 1e-3
#: The model's time step [s] of the estimator's one-period prediction is at most this.
PREDICT_DT = 0.005
#: The torque step [N m] of the estimator's derivatives with respect to the torques.
TORQUE_PROBE = 1e-3
#: The pendulum's parameters estimated with the slope: their steps (relative for the mass, metres
#: for the centre of mass) and the sizes their columns are scaled to (a tenth of the mass, 1 cm).
MASS_PROBE, CENTRE_PROBE_M = 1e-3, 1e-4
MASS_SCALE, CENTRE_SCALE_M = 0.1, 0.01
#: The pendulum joint's damping k_P, estimated with them: its step and its column's scale [N m s]
#: (absolute: a robot may have no damping in its model).
DAMPING_PROBE, DAMPING_SCALE = 1e-4, 0.01
#: The weighted fit's (`prior_scale` > 0) prior: the standard deviations of θ = (s_x, s_y [rad], d_1,
#: d_2 [N m], the pendulum's Δm_P, Δc_P x, y, z and Δk_P in their columns' scales: 20 % of m_P, 1 cm,
#: 1 cm, 1 cm, 0.01 N m s), each times `prior_scale`; and the least variance of a rate's prediction
#: error [(rad/s)²] its weights divide by.
PRIOR_SD = (5e-3, 5e-3, 0.05, 0.05, 2.0, 1.0, 1.0, 1.0, 1.0)
VARIANCE_FLOOR = 1e-10


class _Turned:
    """A model seen from a frame turned by ψ about the floor's normal: `accel` of the state turned by ψ
    (the body rates and the joints are unchanged by the turn; only the shell's attitude moves)."""

    def __init__(self, model, psi):
        self.params, self._model, self._turn = model.params, model, rot_z(psi)

    def accel(self, x, u):
        y = np.array(x, dtype=float)
        y[IDX_RS] = (self._turn @ y[IDX_RS].reshape(3, 3)).ravel()
        return self._model.accel(y, u)


def turned_state(x, psi):
    """The state x turned by ψ about the floor's normal (attitude and position; rates are body-frame)."""
    y = np.array(x, dtype=float)
    y[IDX_RS] = (rot_z(psi) @ y[IDX_RS].reshape(3, 3)).ravel()
    q = y[IDX_Q]
    y[IDX_Q.start:IDX_Q.start + 2] = rot_z(psi)[:2, :2] @ q[:2]
    return y


def _interpolated(speeds, curvatures, a, b, v, kappa):
    """(a, b) (each (nv, nk, ...)) interpolated bilinearly in (v, κ) as the LQR's schedule is."""
    zero = np.zeros(a.shape[:2] + (2, design.NZ))
    return Schedule(speeds, curvatures, a, b, zero, zero).at(v, kappa)[:2]


@dataclasses.dataclass(frozen=True)
class SlopeSchedule:
    """The operating point's derivatives per radian of slope on the LQR's grid: dz_up, dz_right
    (nv, nk, NZ), du_up, du_right (nv, nk, 2)."""
    speeds: np.ndarray
    curvatures: np.ndarray
    dz_up: np.ndarray
    du_up: np.ndarray
    dz_right: np.ndarray
    du_right: np.ndarray

    def at(self, v, kappa, up, right):
        """(Δz*, Δu*) for the slope components `up` (along the path) and `right` [rad], interpolated
        bilinearly in (v, κ) as the LQR's schedule is."""
        a = _interpolated(self.speeds, self.curvatures, self.dz_up, self.du_up, v, kappa)
        b = _interpolated(self.speeds, self.curvatures, self.dz_right, self.du_right, v, kappa)
        return up * a[0] + right * b[0], up * a[1] + right * b[1]


@dataclasses.dataclass(frozen=True)
class PendulumSchedule:
    """The operating point's derivatives with respect to the pendulum's parameters on the LQR's grid,
    in the units of `SlopeEstimator.pendulum` (Δm_P [kg], Δc_P (3,) [m]): dz (nv, nk, 4, NZ),
    du (nv, nk, 4, 2)."""
    speeds: np.ndarray
    curvatures: np.ndarray
    dz: np.ndarray
    du: np.ndarray

    def at(self, v, kappa, pendulum):
        """(Δz*, Δu*) of the pendulum's departure `pendulum` (4,), interpolated bilinearly in (v, κ)."""
        dz, du = _interpolated(self.speeds, self.curvatures, self.dz, self.du, v, kappa)
        return np.asarray(pendulum) @ dz, np.asarray(pendulum) @ du


def slope_components(slope_vector, psi):
    """(along the heading ψ, to its right) [rad] of the world's slope vector s = α (cos β, sin β)."""
    s_x, s_y = slope_vector
    return s_x * math.cos(psi) + s_y * math.sin(psi), s_x * math.sin(psi) - s_y * math.cos(psi)


def design_slope_schedule(params, schedule):
    """The SlopeSchedule of the flat LQR schedule `schedule` designed on `params` (slope 0)."""
    key = (params.as_array().tobytes(), schedule.speeds.tobytes(), schedule.curvatures.tobytes())
    if key not in _SLOPE_SCHEDULES:
        _SLOPE_SCHEDULES[key] = _design(params, schedule)
    return _SLOPE_SCHEDULES[key]


_SLOPE_SCHEDULES = {}


def _design(params, schedule):
    sloped = Model(params.replace(slope=PROBE_SLOPE))
    shape = schedule.z_star.shape[:2]
    out = {name: np.zeros(shape + (n,)) for name, n in
           (("dz_up", design.NZ), ("du_up", 2), ("dz_right", design.NZ), ("du_right", 2))}
    for i, v in enumerate(schedule.speeds):
        for j, kappa in enumerate(schedule.curvatures):
            flat = (schedule.z_star[i, j], schedule.u_star[i, j])
            # heading ψ − β = 0: up the slope; π/2: uphill on the robot's right
            for name, psi in (("up", 0.0), ("right", math.pi / 2)):
                z, u = design.operating_point(_Turned(sloped, psi), v, kappa, start=flat)
                out[f"dz_{name}"][i, j] = (z - flat[0]) / PROBE_SLOPE
                out[f"du_{name}"][i, j] = (u - flat[1]) / PROBE_SLOPE
    return SlopeSchedule(schedule.speeds, schedule.curvatures, **out)


def pendulum_probes(params):
    """[(the model's parameters with one pendulum parameter moved, the step in the units of
    `SlopeEstimator.pendulum`)] for Δm_P, Δc_P,x, Δc_P,y, Δc_P,z; the slope 0."""
    flat = params.replace(slope=0.0)
    c_P = np.asarray(params.c_P, dtype=float)
    return [(flat.replace(m_P=params.m_P * (1 + MASS_PROBE)), MASS_PROBE * params.m_P)] + \
        [(flat.replace(c_P=tuple(c_P + CENTRE_PROBE_M * e)), CENTRE_PROBE_M) for e in np.eye(3)]


def design_pendulum_schedule(params, schedule):
    """The PendulumSchedule of the flat LQR schedule `schedule` designed on `params` (slope 0):
    Newton's operating point of the model with each pendulum parameter moved, less the flat one."""
    key = (params.as_array().tobytes(), schedule.speeds.tobytes(), schedule.curvatures.tobytes())
    if key not in _PENDULUM_SCHEDULES:
        probes = pendulum_probes(params)
        shape = schedule.z_star.shape[:2]
        dz, du = np.zeros(shape + (len(probes), design.NZ)), np.zeros(shape + (len(probes), 2))
        for k, (moved, step) in enumerate(probes):
            model = Model(moved)
            for i, v in enumerate(schedule.speeds):
                for j, kappa in enumerate(schedule.curvatures):
                    flat = (schedule.z_star[i, j], schedule.u_star[i, j])
                    z, u = design.operating_point(model, v, kappa, start=flat)
                    dz[i, j, k], du[i, j, k] = (z - flat[0]) / step, (u - flat[1]) / step
        _PENDULUM_SCHEDULES[key] = PendulumSchedule(schedule.speeds, schedule.curvatures, dz, du)
    return _PENDULUM_SCHEDULES[key]


_PENDULUM_SCHEDULES = {}


def _prior_scale(value):
    """`prior_scale` (the LQR's `slope_prior`) as a float, refused by name unless finite and >= 0."""
    scale = float(value)
    if not (math.isfinite(scale) and scale >= 0):
        raise ValueError(f"slope_prior: must be a finite number >= 0 (0: the unweighted fit), got {value!r}")
    return scale


class SlopeEstimator:
    """The world's slope vector s [rad], a torque offset d [N m] (the plant moving as the model under
    u + d: a motor's bias) and the pendulum's departure from the model (`pendulum`: Δm_P [kg], Δc_P
    (3,) [m]; `pendulum_damping`: Δk_P [N m s]) from the measured states and the torques held
    between them (see the module's docstring): least squares with exponential forgetting over `time_constant_s`.  What the torque
    offset or the pendulum explains is not read as a slope: they act on the rates along other
    directions, fixed to the robot, where the slope's pull turns with the heading.
    `pendulum_damping` (on by default; off only to show what it changes): the pendulum's damping k_P
    is a column too (the property `pendulum_damping`, Δk_P): a damping unlike the model's pulls only
    while the pendulum swings, and unfitted, that pull was read as a pendulum or a slope in the
    directions the samples hardly tell apart while rolling straight.

    `prior_scale` > 0 (opt-in; 0: the unweighted fit above): each rate's row is divided by the root of
    the variance of its one-period prediction error (against the last θ), estimated with the same
    forgetting, so that the rate the plant's process noise moves most (the pendulum's) does not decide
    the fit; and θ is the posterior's mode under a Gaussian prior of `PRIOR_SD` times `prior_scale`,
    solved at every sample (the prior keeps the system regular)."""

    def __init__(self, params, period, time_constant_s, pendulum_damping=True, prior_scale=0.0):
        self.period, self.time_constant_s = float(period), float(time_constant_s)
        self.prior_scale = _prior_scale(prior_scale)
        self._flat = Model(params.replace(slope=0.0))
        self._sloped = Model(params.replace(slope=PROBE_SLOPE))
        # (the model with one pendulum parameter moved, the step, the column's scale)
        self._pendulum = [(Model(moved), step, scale) for (moved, step), scale in
                          zip(pendulum_probes(params), (MASS_SCALE * params.m_P,) + 3 * (CENTRE_SCALE_M,))]
        if pendulum_damping:
            self._pendulum.append((Model(params.replace(slope=0.0, k_P=params.k_P + DAMPING_PROBE)), DAMPING_PROBE,
                                   DAMPING_SCALE))
        self._steps = max(1, math.ceil(self.period / PREDICT_DT - 1e-9))
        self._forget = math.exp(-self.period / self.time_constant_s)
        self.reset()

    def reset(self):
        """Forgets the samples and the estimate."""
        n = 4 + len(self._pendulum)
        self._normal, self._rhs = np.zeros((n, n)), np.zeros(n)
        self._last = None
        self.slope, self.torque_offset, self._moved = np.zeros(2), np.zeros(2), np.zeros(n - 4)
        self._variance_sum, self._variance_count, self._theta = np.zeros(NV), 0.0, np.zeros(n)

    @property
    def pendulum(self):
        """The pendulum's departure from the model: (Δm_P [kg], Δc_P (3,) [m])."""
        return self._moved[:4]

    @property
    def pendulum_damping(self):
        """Δk_P [N m s/rad] when the estimate carries the pendulum's damping, else 0."""
        return float(self._moved[4]) if len(self._moved) > 4 else 0.0

    def _rates(self, model, x, u):
        return model.simulate(x, self.period / self._steps, self._steps, np.tile(u, (self._steps, 1)),
                              method="rkmk4")[-1, IDX_NU]

    def update(self, x, u_applied_before):
        """The slope estimate after the measured state x, the torques `u_applied_before` held since
        the last one."""
        if self._last is not None:
            x0, u = self._last, np.asarray(u_applied_before, dtype=float)
            flat = self._rates(self._flat, x0, u)
            columns = [(self._rates(self._sloped, x0, u) - flat) / PROBE_SLOPE,
                       # a slope towards the world's +y is the model's (+x) with the world turned by −π/2
                       (self._rates(self._sloped, turned_state(x0, -math.pi / 2), u) - flat) / PROBE_SLOPE]
            columns += [(self._rates(self._flat, x0, u + TORQUE_PROBE * e) - flat) / TORQUE_PROBE for e in np.eye(2)]
            columns += [(self._rates(model, x0, u) - flat) * (scale / step) for model, step, scale in self._pendulum]
            G = np.stack(columns, axis=1)
            residual = np.asarray(x)[IDX_NU] - flat
            if self.prior_scale > 0:
                error = residual - G @ self._theta
                self._variance_sum = self._forget * self._variance_sum + error * error
                self._variance_count = self._forget * self._variance_count + 1
                weight = 1 / np.sqrt(np.maximum(self._variance_sum / self._variance_count, VARIANCE_FLOOR))
                G, residual = G * weight[:, None], residual * weight
            self._normal = self._forget * self._normal + G.T @ G
            self._rhs = self._forget * self._rhs + G.T @ residual
            scales = np.array([scale for _, _, scale in self._pendulum])
            if self.prior_scale > 0:
                sd = self.prior_scale * np.array(PRIOR_SD[:len(self._theta)])
                theta = np.linalg.solve(self._normal + np.diag(1 / (sd * sd)), self._rhs)
                self._theta = theta
                self.slope, self.torque_offset, self._moved = theta[:2], theta[2:4], theta[4:] * scales
            elif np.linalg.cond(self._normal) < 1e10:
                theta = np.linalg.solve(self._normal, self._rhs)
                self.slope, self.torque_offset, self._moved = theta[:2], theta[2:4], theta[4:] * scales
            elif np.linalg.cond(self._normal[:4, :4]) < 1e10:
                # Until the samples tell the pendulum from the slope and d (rolling straight at the
                # start), the slope and d alone, the pendulum held: the slope's estimate arrives as
                # soon as it would without the pendulum.
                held = self._rhs[:4] - self._normal[:4, 4:] @ (self._moved / scales)
                theta = np.linalg.solve(self._normal[:4, :4], held)
                self.slope, self.torque_offset = theta[:2], theta[2:]
        self._last = np.array(x, dtype=float)
        return self.slope


class SlopeEstimatorC:
    """`SlopeEstimator` (with its damping column) in C: `sr_slope_update` (c/src/sr_slope.c) on a
    caller-held `sr_slope_estimator`, the same arithmetic to rounding (its condition number by Jacobi
    rotations, its solve by Gaussian elimination with partial pivoting); what the C closed loop runs."""

    def __init__(self, params, period, time_constant_s, prior_scale=0.0):
        self.period, self.time_constant_s = float(period), float(time_constant_s)
        self.prior_scale = _prior_scale(prior_scale)
        self._c = ffi.new("sr_slope_estimator *")
        p = np.ascontiguousarray(params.replace(slope=0.0).as_array(), dtype=np.float64)
        status = lib.sr_slope_init(self._c, pointer(p), self.period, self.time_constant_s)
        if status != lib.SR_OK:
            raise ValueError(f"slope_estimate_s: the C slope estimate refuses period {self.period!r} s and time "
                             f"constant {self.time_constant_s!r} s ({ffi.string(lib.sr_status_string(status)).decode()})")
        status = lib.sr_slope_weigh(self._c, self.prior_scale)
        if status != lib.SR_OK:
            raise ValueError(f"slope_prior: the C slope estimate refuses {self.prior_scale!r} "
                             f"({ffi.string(lib.sr_status_string(status)).decode()})")

    def reset(self):
        """Forgets the samples and the estimate."""
        lib.sr_slope_reset(self._c)

    @property
    def slope(self):
        """The world's slope vector [rad]."""
        return np.array(list(self._c.offsets.slope))

    @property
    def torque_offset(self):
        """The torque offset d [N m]."""
        return np.array(list(self._c.offsets.torque_offset))

    @property
    def pendulum(self):
        """The pendulum's departure from the model: (Δm_P [kg], Δc_P (3,) [m])."""
        return np.array(list(self._c.offsets.pendulum))

    @property
    def pendulum_damping(self):
        """Δk_P [N m s/rad]."""
        return float(self._c.pendulum_damping)

    def update(self, x, u_applied_before):
        """As `SlopeEstimator.update`: the slope estimate after the measured state x, the torques
        `u_applied_before` held since the last one."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        if x.shape != (NX,):
            raise ValueError(f"x: expected a state of {NX} entries, got shape {x.shape}")
        u = np.ascontiguousarray(u_applied_before, dtype=np.float64)
        if u.shape != (2,) or not np.all(np.isfinite(u)):
            raise ValueError(f"u_applied_before: expected 2 finite torques, got {u_applied_before!r}")
        status = lib.sr_slope_update(self._c, pointer(x),
                                     pointer(u))
        if status != lib.SR_OK:
            raise ValueError(f"x: the C slope estimate refuses the sample "
                             f"({ffi.string(lib.sr_status_string(status)).decode()})")
        return self.slope


class SlopeFeedforward:
    """What a controller on the flat model carries for a slope (the LQR's and the NMPC's): the
    model's slope vector, the feedforward's schedule when the model has a slope or the controller
    estimates one, the online estimate (`slope_estimate_s` > 0) and the torques held since the last
    sample, which the estimate's next prediction needs.  A mixin before `Controller`."""

    def _init_slope(self, params, flat, schedule, gains, estimator=None):
        """Sets the slope's parts from the robot `params`, its `flat` copy, the flat design's
        `schedule` and the controller's `gains`; after `Controller.__init__` (it reads the period).
        `estimator`: the estimate's class (`SlopeEstimator`, or `SlopeEstimatorC`; None: the first)."""
        self.model_slope = np.array([params.slope, 0.0])
        self._slope_schedule = design_slope_schedule(flat, schedule) \
            if params.slope != 0.0 or gains.slope_estimate_s > 0.0 else None
        self._estimator = (estimator or SlopeEstimator)(flat, self.period, gains.slope_estimate_s,
                                                        prior_scale=gains.slope_prior) \
            if gains.slope_estimate_s > 0.0 else None
        self._pendulum_schedule = design_pendulum_schedule(flat, schedule) if gains.pendulum_feedforward > 0.0 else None
        self._applied = np.zeros(2)

    def _reset_slope(self):
        """Starts a run: no torque held yet, the estimate forgotten."""
        self._applied = np.zeros(2)
        if self._estimator is not None:
            self._estimator.reset()

    @property
    def slope(self):
        """The world's slope vector α (cos β, sin β) [rad] the feedforward uses: the estimate when the
        controller estimates one (against the flat model: the whole slope), else the model's."""
        return self.model_slope if self._estimator is None else self._estimator.slope

    def after_limits(self, raw, u):
        """Keeps the torques applied: the slope estimate's next prediction holds them."""
        self._applied = np.array(u, dtype=float)
