"""The LQR controller: gain-scheduled on the reference's speed and curvature (runtime/control/lqr_design.py).

At every sample: the error coordinates z of the measured state against the reference (speed v_ref,
heading ψ_ref, curvature κ, cross-track error e_y), the operating point (z*, u*) and gain K
interpolated bilinearly in (v_ref, κ) over the design grid, u = u* − K (z − z*), then the
integrators (∫e_y, ∫ of the rolling-rate error) advance by one period at any error, each unless its
step would push a clipped torque further past its limit (conditional integration: the anti-windup),
and ∫e_y only while the error is steady, |ė_y| ≤ `steady_rate_m_s` (a moving error is a transient).
On a slope (the model's own, or one estimated online: `slope_estimate_s`) the torques gain the
slope's feedforward (runtime/control/slope.py), the schedule being designed on the flat model, and
with `pendulum_feedforward` the estimated pendulum's (its steady torques and lean).
"""
import dataclasses
import typing

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from ..errors import KernelError
from ..model import Model
from ..schema import check_arguments
from .controller import DEFAULT_U_MAX, Controller
from .ranges import LQR_RANGES
from . import lqr_design as design
from .lqr_design import Schedule
from .slope import SlopeEstimatorC, SlopeFeedforward, slope_components


@dataclasses.dataclass(frozen=True)
class LqrGains:
    """Tuning of `Lqr` (the `[controller]` keys of a task file): Bryson's-rule error sizes, the
    design grid, and how fast the operating point follows the path's curvature.

    Bryson's rule: Q = diag(1/e_i²), R = I/u_max²: e_i is the error in coordinate i that is worth
    the full torque.  Tuned on the shipped tasks (docs/control.md, "LQR")."""
    tilt_rad: float = 1.0             # E_x: the yoke's tilt about its hinge (the pendulum's lever), left loose
    attitude_rad: float = 0.1         # E_y, E_z: the yoke's lean and heading
    heading_rad: float = 0.0          # E_z alone (0: attitude_rad): the heading's own size, the lean left at attitude_rad
    pendulum_rad: float = 0.3         # θ_P
    rolling_rate_rad_s: float = 0.2   # Ω_x, the shell's rolling rate: the speed (v = r |Ω_x|)
    rate_rad_s: float = 0.5           # Ω_y, Ω_z
    joint_rate_rad_s: float = 2.0     # ω_Y, ω_P
    cross_track_m: float = 0.15       # e_y
    cross_track_integral_m_s: float = 1.0    # ∫e_y dt: removes a steady offset within about 10 s
    speed_integral_rad: float = 0.5   # ∫(Ω_x − Ω_x*) dt
    v_min: float = 0.1                # the design grid's speeds [m/s]: v_min .. v_max in n_speeds
    v_max: float = 0.5
    n_speeds: float = 5
    kappa_max: float = 0.5            # ... and curvatures −κ_max .. κ_max [1/m] in n_curvatures
    n_curvatures: float = 5
    kappa_rate: float = 0.3           # how fast the operating point follows the path's curvature [1/(m s)]
    preview_m: float = 0.3            # the path's curvature is averaged over preview_m ± smoothing_m [m]
    smoothing_m: float = 0.5          # ... along the path from the nearest point (0: the curvature there)
    steady_rate_m_s: float = 0.01    # ∫e_y advances only while |ė_y| ≤ this [m/s] (above the wander's rate)
    slope_estimate_s: float = 0.0     # the slope estimate's time constant [s] (0: the model's slope only)
    pendulum_feedforward: float = 0.0  # the share of the estimated pendulum's operating-point move fed forward (needs the estimate)
    slope_prior: float = 0.0          # > 0: the slope estimate weighted by its rates' noise, with a prior this times slope.PRIOR_SD (0: unweighted)
    tight_cross_track_m: float = 0.03  # e_y of the tight path gains (the other sizes as above)
    tight_band_m: float = 0.1         # their weight is at most 1 − |e_y| / tight_band_m (0: no tight gains)
    tight_rise_s: float = 10.0        # ... and rises from 0 to 1 in no less than this [s]
    world_share: float = 0.0          # the share of ∫e_y held as a world vector along the path's normal
    tight_fall_s: float = 10.0        # ... and after a clipped torque falls by 1 in this [s] (0: it holds) ...
    tight_wait: float = 0.25          # ... to −tight_wait (below 0 the path's gains: a wait of up to tight_wait·tight_rise_s)
    heading_band_rad: float = 0.0     # heading references: stiffer heading gains' weight ≤ 1 − |heading error| / this (0: none)
    tight_heading_rad: float = 0.03   # ... designed with this heading size (the other sizes as above)
    heading_rise_s: float = 2.0       # ... rising from 0 to 1 in no less than this [s] (after a clip as tight_fall_s, tight_wait)
    recovery_cross_track_m: float = 0.0  # the law acts on e_y clipped to ± this; beyond it the robot recovers (0: neither)
    recovery_heading_rad: float = 0.0    # ... on the heading error clipped to ± this, beyond it recovering (0: neither)
    recovery_slow: float = 0.0        # recovering, the speed reference is lowered by this share at most (0: not at all) ...
    recovery_rise_s: float = 1.0      # ... reached in no less than this [s] and left as fast
    #: The ranges of the settings (runtime/control/ranges.py: those of a task file's keys).
    RANGES: typing.ClassVar[dict] = LQR_RANGES

    def __post_init__(self):
        check_arguments(dataclasses.asdict(self), self.RANGES)
        if self.n_speeds > 1 and not self.v_max > self.v_min:
            raise ValueError(f"v_max: must exceed v_min = {self.v_min!r} when n_speeds > 1, got {self.v_max!r}")
        if self.n_curvatures > 1 and not self.kappa_max > 0:
            raise ValueError(f"kappa_max: must be > 0 when n_curvatures > 1, got {self.kappa_max!r}")
        if self.pendulum_feedforward > 0 and not self.slope_estimate_s > 0:
            raise ValueError(f"pendulum_feedforward: feeds the slope estimate's pendulum forward, so needs "
                             f"slope_estimate_s > 0, got {self.pendulum_feedforward!r} with slope_estimate_s = 0")
        if self.slope_prior > 0 and not self.slope_estimate_s > 0:
            raise ValueError(f"slope_prior: weights the slope estimate, so needs slope_estimate_s > 0, "
                             f"got {self.slope_prior!r} with slope_estimate_s = 0")

    def tight_weights(self, u_max):
        """The tight path gains' Riccati weights: these bounds with the cross-track error `tight_cross_track_m`."""
        return dataclasses.replace(self.weights(u_max), cross_track_m=self.tight_cross_track_m)

    def tight_heading_weights(self, u_max):
        """The stiffer heading gains' Riccati weights: these bounds with the heading size `tight_heading_rad`."""
        return dataclasses.replace(self, heading_rad=self.tight_heading_rad).weights(u_max)

    def weights(self, u_max):
        """These bounds as the design's Riccati weights, with the torque bound `u_max` [N m]."""
        heading = self.heading_rad if self.heading_rad > 0 else self.attitude_rad
        return design.Weights(attitude_rad=(self.tilt_rad, self.attitude_rad, heading), pendulum_rad=self.pendulum_rad,
                              rate_rad_s=(self.rolling_rate_rad_s, self.rate_rad_s, self.rate_rad_s),
                              yoke_rate_rad_s=self.joint_rate_rad_s, pendulum_rate_rad_s=self.joint_rate_rad_s, cross_track_m=self.cross_track_m,
                              cross_track_integral_m_s=self.cross_track_integral_m_s,
                              speed_integral_rad=self.speed_integral_rad, torque_n_m=u_max)


GAIN_NAMES = tuple(f.name for f in dataclasses.fields(LqrGains))


def design_schedule(params, rate, u_max, gains=LqrGains()):
    """The schedule over the grid of `gains` (cached: tasks and tests design the same one often)."""
    key = (params.as_array().tobytes(), float(rate), float(u_max), gains)
    if key not in _SCHEDULES:
        _SCHEDULES[key] = _design(params, rate, u_max, gains)
    return _SCHEDULES[key]


_SCHEDULES = {}


def _design(params, rate, u_max, gains):
    model = Model(params)
    speeds = np.linspace(gains.v_min, gains.v_max, int(gains.n_speeds))
    curvatures = np.linspace(-gains.kappa_max, gains.kappa_max, int(gains.n_curvatures))
    nv, nk = len(speeds), len(curvatures)
    z_star, u_star = np.zeros((nv, nk, design.NZ)), np.zeros((nv, nk, 2))
    K_path, K_heading = np.zeros((nv, nk, 2, design.NZ)), np.zeros((nv, nk, 2, design.NZ))
    K_tight = np.zeros((nv, nk, 2, design.NZ)) if gains.tight_band_m > 0 else None
    K_heading_tight = np.zeros((nv, nk, 2, design.NZ)) if gains.heading_band_rad > 0 else None
    weights = gains.weights(u_max)
    # Each curvature's operating point starts from its neighbour's, outward from the straightest.
    order = np.argsort(np.abs(curvatures), kind="stable")
    for i, v in enumerate(speeds):
        solved = {}
        for j in order:
            near = min(solved, key=lambda k: abs(curvatures[k] - curvatures[j]), default=None)
            try:
                solved[j] = design.operating_point(model, v, curvatures[j],
                                                   start=None if near is None else solved[near])
            except ValueError:      # too far from the neighbour for Newton alone: continuation from level
                solved[j] = design.operating_point(model, v, curvatures[j])
            z_star[i, j], u_star[i, j] = solved[j]
            A, B = design.linearization(model, z_star[i, j], u_star[i, j], v, curvatures[j])
            K_path[i, j] = design.gains(A, B, 1.0 / rate, weights, path=True)
            K_heading[i, j] = design.gains(A, B, 1.0 / rate, weights, path=False)
            if K_tight is not None:
                K_tight[i, j] = tight_gain(K_path[i, j], design.gains(A, B, 1.0 / rate, gains.tight_weights(u_max)))
            if K_heading_tight is not None:
                K_heading_tight[i, j] = tight_gain(K_heading[i, j], design.gains(
                    A, B, 1.0 / rate, gains.tight_heading_weights(u_max), path=False))
    return Schedule(speeds, curvatures, z_star, u_star, K_path, K_heading, K_tight, K_heading_tight)


def tight_gain(K_path, K_riccati):
    """The tight gain as the C law reads it: the tight design's K on the robot's and the path's
    coordinates, the shipped gain's (K_path's, or K_heading's for the heading gains) on the integrators
    (the law never moves the integrals' gains, so scheduling the tight gain in or out moves no torque
    through them)."""
    K = np.array(K_riccati, dtype=float)
    K[:, design.Z_IY:] = np.asarray(K_path)[:, design.Z_IY:]
    return K


def feedforward_tables(slope_schedule=None, pendulum_schedule=None):
    """(sr_lqr_slope_table *, sr_lqr_pendulum_table *) (cffi; None for a schedule that is None) of a
    SlopeSchedule and a PendulumSchedule (runtime/control/slope.py), grid point (i, j) at entry
    i * n_curvatures + j as `to_c` lays out the LQR's: what `to_c`'s `feedforward` points to (the
    caller keeps them alive as long as the struct)."""
    slope = pendulum = None
    if slope_schedule is not None:
        slope = ffi.new("sr_lqr_slope_table *")
        nv, nk = slope_schedule.dz_up.shape[:2]
        for name in ("dz_up", "du_up", "dz_right", "du_right"):
            table, values = getattr(slope, name), getattr(slope_schedule, name)
            for n in range(nv * nk):
                table[n][0:values.shape[-1]] = values[n // nk, n % nk].tolist()
    if pendulum_schedule is not None:
        pendulum = ffi.new("sr_lqr_pendulum_table *")
        nv, nk, n_entries = pendulum_schedule.dz.shape[:3]
        if n_entries != lib.SR_LQR_NPENDULUM:
            raise ValueError(f"controller: the pendulum's schedule has {n_entries} entries; the C controller "
                             f"feeds forward {lib.SR_LQR_NPENDULUM}")
        for n in range(nv * nk):
            for e in range(n_entries):
                pendulum.dz[n][e][0:design.NZ] = pendulum_schedule.dz[n // nk, n % nk, e].tolist()
                pendulum.du[n][e][0:2] = pendulum_schedule.du[n // nk, n % nk, e].tolist()
    return slope, pendulum


def to_c(schedule, period, u_max, kappa_rate, steady_rate, tight_band=0.0, tight_rise=1.0, world_share=0.0, tight_fall=0.0,
         tight_wait=0.0, heading_band=0.0, heading_rise=1.0, recovery=(0.0, 0.0, 0.0, 1.0), feedforward=(None, None, 0.0)):
    """The schedule as the C struct `sr_lqr` (cffi), checked by `sr_lqr_check`; `feedforward`: (the
    slope's table, the pendulum's, the pendulum's share) as `feedforward_tables` makes them (None:
    none), which the caller keeps alive as long as the struct; the tight gains are
    scheduled in within `tight_band` [m] of the path, over `tight_rise` [s] (and out by 1 per `tight_fall` [s]
    after a clipped torque, to a weight −`tight_wait`, below 0 K_path's; 0: held), when the schedule has them;
    `world_share` of the cross-track integral is held in the world frame; the stiffer heading gains, when
    the schedule has them, within `heading_band` [rad] of a heading reference's heading over `heading_rise` [s];
    `recovery`: (recovery_cross_track [m], recovery_heading [rad], recovery_slow, recovery_rise [s]) of the
    recovery at a large error (spherical_robot.h; zeros: off)."""
    nv, nk = len(schedule.speeds), len(schedule.curvatures)
    if nv > lib.SR_LQR_MAX_SPEEDS or nk > lib.SR_LQR_MAX_CURVATURES:
        raise ValueError(f"controller: the design grid has {nv} speeds and {nk} curvatures; the C controller "
                         f"holds at most {lib.SR_LQR_MAX_SPEEDS} and {lib.SR_LQR_MAX_CURVATURES}")
    c = ffi.new("sr_lqr *")
    c.n_speeds, c.n_curvatures = nv, nk
    c.speeds[0:nv] = schedule.speeds.tolist()
    c.curvatures[0:nk] = schedule.curvatures.tolist()
    for i in range(nv):
        for j in range(nk):
            n = i * nk + j
            c.z_star[n][0:design.NZ] = schedule.z_star[i, j].tolist()
            c.u_star[n][0:2] = schedule.u_star[i, j].tolist()
            c.K_path[n][0:2 * design.NZ] = schedule.K_path[i, j].ravel().tolist()
            c.K_heading[n][0:2 * design.NZ] = schedule.K_heading[i, j].ravel().tolist()
            if schedule.K_tight is not None:
                c.K_tight[n][0:2 * design.NZ] = schedule.K_tight[i, j].ravel().tolist()
            if schedule.K_heading_tight is not None:
                c.K_heading_tight[n][0:2 * design.NZ] = schedule.K_heading_tight[i, j].ravel().tolist()
    c.period, c.u_max, c.kappa_rate, c.steady_rate = period, u_max, kappa_rate, steady_rate
    c.tight_band = tight_band if schedule.K_tight is not None else 0.0
    c.tight_rise = tight_rise
    c.world_share = world_share
    c.tight_fall = tight_fall
    c.tight_wait = tight_wait
    c.heading_band = heading_band if schedule.K_heading_tight is not None else 0.0
    c.heading_rise = heading_rise
    c.recovery_cross_track, c.recovery_heading, c.recovery_slow, c.recovery_rise = recovery
    slope, pendulum, c.pendulum_share = feedforward
    c.slope = ffi.NULL if slope is None else slope
    c.pendulum = ffi.NULL if pendulum is None else pendulum
    status = lib.sr_lqr_check(c)
    if status != lib.SR_OK:
        raise ValueError(f"controller: the LQR schedule is not valid for the C controller "
                         f"({ffi.string(lib.sr_status_string(status)).decode()})")
    return c


def recovery_settings(gains):
    """The recovery's settings of `gains` as `to_c` takes them."""
    return (gains.recovery_cross_track_m, gains.recovery_heading_rad, gains.recovery_slow, gains.recovery_rise_s)


def c_target(target):
    """The target as the C library's sr_lqr_target (a path target when it has a cross-track error)."""
    t = ffi.new("sr_lqr_target *")
    t.speed, t.heading = target.speed, target.heading
    t.path = target.cross_track is not None
    if t.path:
        t.curvature, t.cross_track = target.curvature, target.cross_track
    return t


class Lqr(SlopeFeedforward, Controller):
    """The C controller `sr_lqr_control` (c/sr_control.c) on a schedule designed here."""
    kind = "lqr"

    def __init__(self, params, rate=50.0, u_max=DEFAULT_U_MAX, gains=LqrGains(), schedule=None):
        super().__init__(params, rate, u_max)
        self.gains = gains
        # A slope in the model is fed forward in whichever direction the path runs: the schedule is
        # the flat one, and the slope's direction (the model's +x) is a world vector.
        flat = params.replace(slope=0.0)
        self.schedule = schedule if schedule is not None else design_schedule(flat, rate, u_max, gains)
        # the slope estimate in C (sr_slope_update): what the C loop updates (runtime/control/slope.py's
        # SlopeEstimator, its NumPy reference, gives the same to rounding)
        self._init_slope(params, flat, self.schedule, gains, SlopeEstimatorC)
        # the feedforward's tables, which the C struct points to (kept here as long as it)
        self._tables = feedforward_tables(self._slope_schedule, self._pendulum_schedule)
        self._c = to_c(self.schedule, self.period, self.u_max, gains.kappa_rate, gains.steady_rate_m_s,
                       gains.tight_band_m, gains.tight_rise_s, gains.world_share, gains.tight_fall_s, gains.tight_wait,
                       gains.heading_band_rad, gains.heading_rise_s, recovery_settings(gains),
                       self._tables + (gains.pendulum_feedforward,))
        self._model = Model(flat)
        self._offsets = ffi.new("sr_lqr_offsets *")
        self._memory = ffi.new("sr_lqr_memory *")
        self._u, self._raw = np.zeros(2), np.zeros(2)

    def reset(self, x0):
        """Starts a run at x0: zeroes the controller's memory (integrals, operating curvature)."""
        super().reset(x0)
        lib.sr_lqr_reset(self._memory)
        self._reset_slope()

    def preview_distances(self, target):
        """Where the path's curvature is read (runtime/control/closed_loop.py fills
        target.curvature_ahead): 41 points over preview_m ± smoothing_m."""
        g = self.gains
        return g.preview_m + np.linspace(-g.smoothing_m, g.smoothing_m, 41)

    def operating_curvature(self, target):
        """The curvature the operating point is scheduled on: the path's, averaged over the preview
        window when the reference gave it (a figure eight's switch of turn direction then starts
        before the crossing, as the pendulum needs seconds to swing from one lean to the other)."""
        if target.cross_track is None:
            return 0.0
        if target.curvature_ahead is not None and len(target.curvature_ahead):
            return float(np.mean(target.curvature_ahead))
        return float(target.curvature)

    @property
    def tight_weight(self):
        """The tight path gains' weight in [0, 1] at the last sample (0 without them)."""
        return float(self._memory.tight)

    @property
    def integrals(self):
        """The controller's two integrals: the path's part of z[10] and z[11] of the C controller's
        error coordinates."""
        return np.array(list(self._memory.integrals))

    @property
    def world_integral(self):
        """The world part of ∫e_y (x, y) [m s]: z[10] adds its component along the path's left normal."""
        return np.array(list(self._memory.world))

    def compute(self, t, x, target):
        """The torques of one sample of the C controller (sr_lqr_control) for state x and the target."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        if self._estimator is not None:
            self._estimator.update(x, self._applied)
        if target.cross_track is not None:
            target = dataclasses.replace(target, curvature=self.operating_curvature(target))
        status = lib.sr_lqr_control_offsets(self._c, self._model._model, pointer(x),
                                            c_target(target), self.offsets(), self._memory,
                                            pointer(self._u),
                                            pointer(self._raw))
        if status == lib.SR_ERR_MODEL:
            raise KernelError("model", status, f" (controller lqr at t = {t:g} s)")
        if status != lib.SR_OK:
            raise ValueError(f"controller lqr: {ffi.string(lib.sr_status_string(status)).decode()} "
                             f"at t = {t:g} s")
        return self._raw.copy()

    def offsets(self):
        """The sr_lqr_offsets * (cffi) the C law feeds forward at this sample (`sr_lqr_control_offsets`:
        the slope `self.slope`, the estimate's torque offset and pendulum), or NULL without a slope's
        feedforward (the plain law)."""
        if self._slope_schedule is None:
            return ffi.NULL
        c = self._offsets
        c.slope[0:2] = [float(s) for s in self.slope]
        if self._estimator is not None:
            c.torque_offset[0:2] = [float(d) for d in self._estimator.torque_offset]
            c.pendulum[0:lib.SR_LQR_NPENDULUM] = [float(p) for p in self._estimator.pendulum]
        return c

    def numpy_feedforward(self, target):
        """What the C law adds for the offsets (`offsets`) at this sample, written out in NumPy (the
        tests' reference): the slope's feedforward, less the estimated torque offset, plus the share
        `pendulum_feedforward` of the pendulum's; zeros without a slope's feedforward.  Read after
        `compute` (the operating curvature of its sample)."""
        if self._slope_schedule is None:
            return np.zeros(2)
        ff = self.slope_feedforward(target)
        if self._estimator is not None:
            ff = ff - self._estimator.torque_offset
        if self._pendulum_schedule is not None:
            ff = ff + self.gains.pendulum_feedforward * self.pendulum_feedforward(target)
        return ff

    def _moved(self, target, at):
        """Δu* + K Δz* (2,) [N m] of the operating point's move (Δz*, Δu*) = at(v, κ), at the
        reference's speed and the operating curvature of the last sample."""
        kappa = float(self._memory.kappa) if target.cross_track is not None else 0.0
        dz, du = at(target.speed, kappa)
        _, _, K_path, K_heading = self.schedule.at(target.speed, kappa)
        return du + (K_path if target.cross_track is not None else K_heading) @ dz

    def slope_feedforward(self, target):
        """Δu* + K Δz* (2,) [N m]: the operating point's move on the slope `self.slope`."""
        up, right = slope_components(self.slope, target.heading)
        return self._moved(target, lambda v, kappa: self._slope_schedule.at(v, kappa, up, right))

    def pendulum_feedforward(self, target):
        """Δu* + K Δz* (2,) [N m]: the operating point's move for the estimated pendulum's departure
        from the model (Δm_P, Δc_P), fixed to the robot: the steady torques and lean it needs."""
        pendulum = self._estimator.pendulum
        return self._moved(target, lambda v, kappa: self._pendulum_schedule.at(v, kappa, pendulum))
