"""Excitation design: a torque program that makes the named parameters identifiable
(docs/identification.md, "Excitation").

    python -m runtime excite [--robot FILE] --params NAMES --duration S --out FILE

The program is a band-limited multisine per motor, held piecewise constant over `hold` seconds
and scaled so that its largest torque is the limit u_max:

    s_m(t) = Σ_k a_mk cos(2π f_k t) + b_mk sin(2π f_k t),   u_m = u_max s_m / max_t |s_m|,

f_k integer multiples of 1/duration spread over [f_low, f_high].  Its coefficients maximise the
D-optimality criterion, log det of the Fisher information of the default sensor set's readings
in the named parameters (relative: each scaled by its nominal value),

    I = Σ_samples (∂y/∂p)ᵀ Σ⁻¹ (∂y/∂p),   ∂y/∂p = H_x S_k + H_ν̇ ∂ν̇/∂p  (the IMU's ν̇),

with S_k the trajectory's sensitivities (runtime.param_derivatives: S_{k+1} = F_k S_k + J_p,k,
the step Jacobian and the analytic step-parameter Jacobian, both batched in C), H_x the sensors'
Jacobians (runtime.sensors) and Σ their noises (gyroscope, accelerometer, the encoders'
quantisation, the fixes); the start at rest is known, the biases are not modelled.  The readings
are taken every `sample` seconds with each weighted by the sensor samples it stands for.  SciPy's
L-BFGS-B maximises it from a random-phase multisine; then the whole program's amplitude is
reduced, if need be, until the pendulum's inclination stays inside the flip-over envelope
(`max_lean`, below the horizontal where it flips over, runtime.control.envelope).

That information ignores the process noise, which is what limits the fit: `process_information`
is the bound it leaves (a damping's information is ∫ (k ω)² dt / q²), and its σ predicts the
sensor fit's.  So the last `push` of the program is a damping phase (`damping_phase`): the yoke's
torque held at the limit, the pendulum's a sine at the frequency that maximises
`weighted_criterion` (log det plus the dampings' own information, weighted), scaled into the
envelope.  The output is a scenario file (`[[torque]]` windows of `hold` seconds) that
`python -m runtime run` runs.
"""
import argparse
import dataclasses
import math
import os
import pathlib
import time

import numpy as np

from ..atomic import output_file, write_text
from ..model import Model
from ..param_derivatives import PARAMETER_NAMES
from ..params import SHAPES, Params, flat_names
from ..scenario import load_robot
from ..sensor_set import SensorSet
from ..sensors import BODIES, NEB, NIMU, encoders_jacobian, imu_partials, position_jacobian
from ..state import NE, absolute_inclinations, initial_state

#: The integrator and step of the designed program (the scenario's own).
METHOD, DT = "rkmk4", 0.01
#: Defaults: torque limit [N m] (the controllers' DEFAULT_U_MAX), the flip-over envelope's largest
#: pendulum inclination [rad] (60°, well inside the horizontal where it flips over).
U_MAX, MAX_LEAN = 0.5, math.pi / 3


@dataclasses.dataclass(frozen=True)
class Design:
    """What shapes a program: the parameters it is for (`names`, entries of PARAMETER_NAMES), its
    duration [s], the torque limit u_max [N m], the flip-over envelope max_lean [rad], the band
    [f_low, f_high] [Hz] with `harmonics` frequencies per motor, the torque hold [s], the
    information's sampling [s], the fraction of the duration at the end given to the damping phase
    (`push`, 0 for none: the yoke's torque held, the pendulum driven at one frequency) and the
    weight of the dampings in the criterion (`weighted_criterion`)."""
    names: tuple
    duration: float
    u_max: float = U_MAX
    max_lean: float = MAX_LEAN
    f_low: float = 0.1
    f_high: float = 2.0
    harmonics: int = 4
    hold: float = 0.05
    sample: float = 0.02
    push: float = 0.5
    damping_weight: float = 2.0

    def __post_init__(self):
        object.__setattr__(self, "names", parameter_names(self.names))
        for name, low, high in (("duration", DT, 600.0), ("u_max", 0.0, 100.0), ("max_lean", 0.0, math.pi / 2),
                                ("f_low", 0.0, 50.0), ("f_high", 0.0, 50.0), ("hold", DT, 10.0),
                                ("sample", DT, 10.0), ("push", -1e-12, 0.9), ("damping_weight", -1e-12, 100.0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name}: expected a finite number, got {value!r}")
            if not low < value <= high:
                raise ValueError(f"{name}: {value:g} is outside ({low:g}, {high:g}]")
            object.__setattr__(self, name, float(value))
        if isinstance(self.harmonics, bool) or not isinstance(self.harmonics, int) or not 1 <= self.harmonics <= 50:
            raise ValueError(f"harmonics: expected a whole number in 1..50, got {self.harmonics!r}")
        if self.push > 0 and round(self.push * self.duration / self.hold) < 1:
            raise ValueError(f"push: {self.push:g} of {self.duration:g} s is shorter than one hold of {self.hold:g} s")
        if self.f_low >= self.f_high:
            raise ValueError(f"f_low, f_high: need f_low < f_high, got {self.f_low:g}, {self.f_high:g}")
        for name in ("hold", "sample"):
            if abs(getattr(self, name) / DT - round(getattr(self, name) / DT)) > 1e-9:
                raise ValueError(f"{name}: {getattr(self, name):g} s is not a whole number of steps of {DT} s")
        if self.duration < 2 * self.hold or abs(self.duration / self.hold - round(self.duration / self.hold)) > 1e-9:
            raise ValueError(f"duration: {self.duration:g} s is not a whole number (at least 2) of holds of "
                             f"{self.hold:g} s")
        if self.f_high > 0.5 / self.hold:
            raise ValueError(f"f_high: {self.f_high:g} Hz is above the hold's Nyquist frequency {0.5 / self.hold:g} Hz")

    @property
    def steps(self):
        """Steps of DT in the program."""
        return round(self.duration / DT)

    def frequencies(self):
        """The multisine's frequencies [Hz]: `harmonics` distinct multiples of 1/duration, spread
        geometrically over [f_low, f_high]."""
        base = 1.0 / self.duration
        lo, hi = max(math.ceil(self.f_low / base - 1e-9), 1), math.floor(self.f_high / base + 1e-9)
        if hi - lo + 1 < self.harmonics:
            raise ValueError(f"harmonics: {self.harmonics} distinct frequencies do not fit in [{self.f_low:g}, "
                             f"{self.f_high:g}] Hz at a resolution of 1/duration = {base:g} Hz")
        k = np.round(np.geomspace(lo, hi, self.harmonics)).astype(int)
        for i in range(1, len(k)):          # distinct: push collisions up, then back under hi
            k[i] = max(k[i], k[i - 1] + 1)
        for i in range(len(k) - 1, -1, -1):
            k[i] = min(k[i], hi if i == len(k) - 1 else k[i + 1] - 1)
        return k * base


def parameter_names(names):
    """The entries of PARAMETER_NAMES that `names` (a comma-separated string or a sequence) stand
    for: an entry ("c_P_z") or a whole field ("c_P" is its three entries); ValueError("params: ...")
    for an unknown, repeated or empty list."""
    if isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    out = []
    for name in names:
        if name in PARAMETER_NAMES:
            entries = [name]
        elif name in SHAPES:
            entries = list(flat_names(name, SHAPES[name]))
        else:
            raise ValueError(f"params: unknown parameter {name!r}; the parameters are "
                             f"{', '.join(PARAMETER_NAMES)} (or a whole field: {', '.join(SHAPES)})")
        for entry in entries:
            if entry in out:
                raise ValueError(f"params: {entry} is named twice")
            out.append(entry)
    if not out:
        raise ValueError("params: name at least one parameter")
    return tuple(out)


# -- the program ---------------------------------------------------------------------------------
def torques(design, coefficients, amplitude=1.0):
    """(steps, 2) torques of the program: each motor's multisine sampled at the start of each hold,
    scaled to the peak amplitude·u_max, held over the hold's steps.  coefficients (2, harmonics, 2):
    per motor and frequency (a, b) of a cos + b sin."""
    c = np.asarray(coefficients, dtype=float).reshape(2, design.harmonics, 2)
    per_hold = round(design.hold / DT)
    t = np.arange(round(design.duration / design.hold)) * design.hold
    phase = 2 * np.pi * np.outer(t, design.frequencies())
    s = np.cos(phase) @ c[:, :, 0].T + np.sin(phase) @ c[:, :, 1].T      # (holds, 2)
    peak = np.abs(s).max(axis=0)
    s = s / np.where(peak > 0, peak, 1.0)
    return np.repeat(amplitude * design.u_max * s, per_hold, axis=0)


def random_coefficients(design, seed=0):
    """A random-phase multisine of equal amplitudes: the naive program and the search's start."""
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, size=(2, design.harmonics))
    return np.stack([np.cos(phase), np.sin(phase)], axis=-1)


def chirp(design):
    """(steps, 2) a linear chirp from f_low to f_high on each motor at the full limit, the pendulum's a
    quarter period behind: the other naive program."""
    t = np.arange(design.steps) * DT
    phase = 2 * np.pi * (design.f_low * t + 0.5 * (design.f_high - design.f_low) * t ** 2 / design.duration)
    return design.u_max * np.stack([np.sin(phase), np.cos(phase)], axis=1)


# -- the information ------------------------------------------------------------------------------
def _noise(sensors):
    """Standard deviations of the readings: IMU (6), encoders (2), fixes (2), and the sensors' rates."""
    imu, enc = sensors.imu, sensors.encoders
    sd_imu = np.array([imu.gyro_noise] * 3 + [imu.accel_noise] * 3)
    sd_enc = np.full(2, enc.step / math.sqrt(12.0))
    return sd_imu, sd_enc


def information(model, design, u, sensors=None):
    """(I, peak lean): the Fisher information (n, n) of the sensor set's readings (default set) in the
    design's parameters, each relative to its nominal value (absolute for a zero one), along the
    program u (steps, 2) from rest; and the largest pendulum inclination [rad] along it."""
    sensors = SensorSet.default() if sensors is None else sensors
    columns = [PARAMETER_NAMES.index(n) for n in design.names]
    p = model.params.as_array()
    scale = np.where(np.abs(p[columns]) > 0, np.abs(p[columns]), 1.0)
    x0 = initial_state(r=model.params.r)
    X = model.simulate(x0, DT, design.steps, u=u, method=METHOD, energy_tol=None)
    lean = float(np.max(absolute_inclinations(X)[1]))
    F, _ = model.step_jacobian(X[:-1], u, DT, METHOD)
    Jp = model.step_param_jacobian(X[:-1], u, DT, METHOD)[:, :, columns] * scale
    stride = round(design.sample / DT)
    sd_imu, sd_enc = _noise(sensors)
    w_imu, w_enc = sensors.imu.rate * design.sample, sensors.encoders.rate * design.sample
    fixes = sensors.fixes
    fix_stride = None if fixes is None else max(1, round(fixes.period / DT))
    rows = np.arange(stride, design.steps + 1, stride)
    U_rows = u[np.minimum(rows, design.steps - 1)]
    nudot = model.accel(X[rows], U_rows)
    dnu = model.param_jacobian(X[rows], U_rows)[:, :, columns] * scale
    # The encoders and the fixes read error coordinates one to one: constant Jacobians.
    He = encoders_jacobian(model, x0)[1][:, :NE] / sd_enc[:, None]
    Hq = position_jacobian(model, x0)[1][:, :NE] / (1.0 if fixes is None else fixes.noise)
    imu_partials(model, X[0], nudot[0], mount=sensors.imu.mount)    # the arguments' checks, once
    imu_rows = _imu_rows(model, sensors.imu.mount)
    S = np.zeros((NE, len(columns)))
    info = np.zeros((len(columns), len(columns)))
    sample = 0
    for k in range(design.steps):
        S = F[k] @ S + Jp[k]
        n = k + 1
        if n % stride == 0:
            H, Hn = imu_rows(X[n], nudot[sample])
            D = (H[:, :NE] @ S + Hn @ dnu[sample]) / sd_imu[:, None]
            E = He @ S
            info += w_imu * D.T @ D + w_enc * E.T @ E
            sample += 1
        if fix_stride and n % fix_stride == 0:
            D = Hq @ S
            info += D.T @ D
    return info, lean


def process_information(model, design, u, sensors=None):
    """(I, peak lean): the information (n, n) in the design's relative parameters that the sensor
    set's process noise leaves, the bound on what any log of the program can hold.  The fit whitens
    every reading by the torque disturbances (white, density q per generalized force,
    `SensorSet.process`); with the velocities and accelerations read exactly, a parameter is seen
    only through the generalized force it moves, g = M ν̇ − f, against that disturbance averaged over
    each sample: I = Σ_samples sample · (M ∂ν̇/∂p)ᵀ diag(q)⁻² (M ∂ν̇/∂p).  A damping's column is its
    torque −k ω, so its information is ∫ (k ω)² dt / q²: the speeds the program reaches.  Its
    Cramér–Rao σ (`sigmas`) is what the sensor fit's σ comes to (docs/identification.md,
    "Excitation"); the sensors' own information (`information`) is far larger."""
    sensors = SensorSet.default() if sensors is None else sensors
    q = sensors.process.generalized()
    if not np.all(q > 0):
        raise ValueError(f"sensors: the process noise's densities must be > 0 for its information, got {q.tolist()}")
    columns = [PARAMETER_NAMES.index(n) for n in design.names]
    p = model.params.as_array()
    scale = np.where(np.abs(p[columns]) > 0, np.abs(p[columns]), 1.0)
    X = model.simulate(initial_state(r=model.params.r), DT, design.steps, u=u, method=METHOD, energy_tol=None)
    lean = float(np.max(absolute_inclinations(X)[1]))
    rows = np.arange(0, design.steps, round(design.sample / DT))
    G = np.einsum("bij,bjk->bik", model.inertia_batch(X[rows]),
                  model.param_jacobian(X[rows], u[rows], columns=columns) * scale) / q[None, :, None]
    return design.sample * np.einsum("bik,bil->kl", G, G), lean


def _imu_rows(model, mount):
    """(x, ν̇) -> (H (6, 18), Hn (6, 5)) of the IMU at `mount`: sr_imu_partials on buffers made once
    (the per-sample cost of runtime.sensors.imu_partials is its argument checks, done once by the
    caller on the first sample; the states are the simulator's own)."""
    from bindings._sr import ffi, lib
    from bindings.buffers import pointer
    m = np.ascontiguousarray(mount.as_array())
    b, y, H, Hn = np.zeros(6), np.empty(NIMU), np.empty((NIMU, NEB)), np.empty((NIMU, 5))
    fixed = (BODIES[mount.body], pointer(m), pointer(b), pointer(y), pointer(H), pointer(Hn))

    def rows(x, nudot, _keep=(m, b, y)):     # the buffers the pointers point into stay alive with rows
        x, nudot = np.ascontiguousarray(x), np.ascontiguousarray(nudot)
        status = lib.sr_imu_partials(model._model, pointer(x), pointer(nudot), *fixed)
        if status != lib.SR_OK:
            raise ValueError(f"x: the IMU's Jacobian failed ({ffi.string(lib.sr_status_string(status)).decode()})")
        return H, Hn
    return rows


def criterion(info):
    """(log det, condition number) of an information matrix; log det −inf when it is singular."""
    sign, logdet = np.linalg.slogdet(info)
    s = np.linalg.svd(info, compute_uv=False)
    return (float(logdet) if sign > 0 else -math.inf), (float(s[0] / s[-1]) if s[-1] > 0 else math.inf)


DAMPINGS = ("k_S", "k_Y", "k_P")
"""The dampings: their torques −k ω are what the damping weight of the criterion is for."""


def weighted_criterion(info, names, damping_weight):
    """log det I + w Σ_dampings −log (I⁻¹)_dd: D-optimality with each named damping's own
    Cramér–Rao variance weighted in by w (−inf when I is singular).  D-optimality alone trades a
    damping's σ for the volume of the whole confidence ellipsoid; the weight makes the dampings'
    marginal information count on top of it."""
    sign, logdet = np.linalg.slogdet(info)
    if sign <= 0:
        return -math.inf
    inverse = np.linalg.inv(info)
    dampings = [i for i, n in enumerate(names) if n in DAMPINGS]
    return float(logdet - damping_weight * sum(math.log(inverse[i, i]) for i in dampings))


def sigmas(info):
    """The Cramér–Rao standard deviations of the relative parameters, sqrt(diag I⁻¹) (inf when I is
    singular)."""
    try:
        return np.sqrt(np.diag(np.linalg.inv(info)))
    except np.linalg.LinAlgError:
        return np.full(len(info), math.inf)


def worst_sigma(info):
    """The largest Cramér–Rao standard deviation of the relative parameters, max sqrt(diag I⁻¹):
    what the least well determined parameter's relative error would be (inf when I is singular)."""
    try:
        return float(np.sqrt(np.max(np.diag(np.linalg.inv(info)))))
    except np.linalg.LinAlgError:
        return math.inf


def _within_envelope(model, design, coefficients):
    """The largest amplitude in (0, 1] (halving, then bisection to 1 %) whose program keeps the
    pendulum inside max_lean; its torques, information and lean."""
    amplitude, best = 1.0, None
    lo, hi = 0.0, None
    for _ in range(12):
        u = torques(design, coefficients, amplitude)
        try:
            info, lean = information(model, design, u)
        except ValueError:      # a program that throws the robot into a singular state is outside too
            info, lean = None, math.inf
        if lean <= design.max_lean:
            best, lo = (amplitude, u, info, lean), amplitude
            if hi is None or hi - lo < 0.01:
                break
        else:
            hi = amplitude
        amplitude = 0.5 * (lo + hi) if lo > 0 else 0.5 * amplitude
    if best is None:
        raise ValueError(f"max_lean: no amplitude down to {amplitude:g} of u_max keeps the pendulum within "
                         f"{design.max_lean:g} rad")
    return best


@dataclasses.dataclass(frozen=True)
class Result:
    """A designed program and what it is compared against: torques (steps, 2), its amplitude
    (fraction of u_max after the envelope), its information's log det and condition number, its
    peak lean, the number of evaluations of the information, its worst relative standard deviation
    (`worst_sigma`), and the same numbers of the naive programs (name -> (log det, condition, lean,
    amplitude, worst sigma)); `sigmas`: program name -> (weighted criterion, σ per parameter) of
    the process-noise bound (`process_information`), the damping phase's first when it was kept."""
    design: Design
    torques: np.ndarray
    amplitude: float
    logdet: float
    condition: float
    lean: float
    naive: dict
    evaluations: int
    sigma: float = math.nan
    sigmas: dict = dataclasses.field(default_factory=dict)


def _process_numbers(model, design, u):
    """(weighted criterion, σ per parameter, lean) of a program from `process_information`."""
    info, lean = process_information(model, design, u)
    return weighted_criterion(info, design.names, design.damping_weight), sigmas(info), lean


def damping_phase(model, design, u):
    """The program u (steps, 2) with its last `push` of the duration replaced by the damping phase,
    and the whole scaled into the envelope: (torques, amplitude, weighted criterion, σ, lean).  A
    damping's information is ∫ (k ω)² dt / q² (`process_information`), so the phase holds the
    yoke's torque at the limit (the shell rolls on at the speed its dampings allow) and drives the
    pendulum's torque as a sine at the frequency, on a 0.1 Hz grid over [f_low, f_high], and the
    yoke's sign that maximise the weighted criterion; each candidate at the largest amplitude
    (bisection to 1 %) that keeps the pendulum inside max_lean.  Returns u itself (amplitude 1)
    when no candidate beats it or push is 0."""
    base = _process_numbers(model, design, u)
    best = (u, 1.0, *base)
    n = round(round(design.push * design.duration / design.hold) * design.hold / DT)
    if n == 0:
        return best
    per_hold = round(design.hold / DT)
    t = (np.arange(n) // per_hold) * per_hold * DT
    frequencies = np.arange(math.ceil(design.f_low / 0.1 - 1e-9), math.floor(design.f_high / 0.1 + 1e-9) + 1) * 0.1
    for f in frequencies[frequencies > 0]:
        for sign in (1.0, -1.0):
            program = u.copy()
            program[-n:] = design.u_max * np.stack([np.full(n, sign), np.sin(2 * np.pi * f * t)], axis=1)
            lo, hi, found = 0.0, 1.0, None
            for attempt in range(10):
                amplitude = 1.0 if attempt == 0 else 0.5 * (lo + hi)
                try:
                    numbers = _process_numbers(model, design, amplitude * program)
                except ValueError:
                    numbers = None
                if numbers is not None and numbers[2] <= design.max_lean:
                    lo, found = amplitude, (amplitude * program, amplitude, *numbers)
                    if amplitude == 1.0:
                        break
                else:
                    hi = amplitude
                if hi - lo < 0.01:
                    break
            if found is not None and found[2] > best[2]:
                best = found
    return best


def design_program(params, design, seed=0, max_iterations=10):
    """The D-optimal program of `design` for the robot `params` (a `Params`): L-BFGS-B on the
    multisine's coefficients from a random-phase start (finite-difference gradients of the
    criterion, each evaluation the analytic sensitivities), then the envelope.  Returns a Result
    with the naive programs' numbers (the random-phase start and a chirp, both inside the same
    limits and envelope)."""
    from scipy.optimize import minimize

    if not isinstance(params, Params):
        raise ValueError(f"params: expected a Params, got {type(params).__name__}")
    model = Model(params)
    start = random_coefficients(design, seed)
    count = [0]

    def objective(z):
        count[0] += 1
        u = torques(design, z)
        try:
            info, lean = information(model, design, u)
        except ValueError:
            return 1e6
        logdet, _ = criterion(info + 1e-12 * np.trace(info) * np.eye(len(info)))
        # Leaving the envelope costs more than any information gains (the amplitude is cut after).
        return -logdet + 100.0 * max(0.0, lean - design.max_lean) ** 2 / design.max_lean ** 2

    best = start.ravel()
    if max_iterations > 0:
        # The peak scaling and the envelope's penalty have kinks where line searches can stall: the
        # evaluations are capped at what max_iterations gradients and a few line-search steps need.
        budget = (best.size + 1) * (max_iterations + 2)
        best = minimize(objective, best, method="L-BFGS-B",
                        options={"maxiter": max_iterations, "maxfun": budget, "eps": 1e-3}).x
    naive = {}
    amplitude, u, info, lean = _within_envelope(model, design, start)
    naive["random multisine"] = (*criterion(info), lean, amplitude, worst_sigma(info))
    chirp_u = chirp(design)
    for scale in (1.0, 0.5, 0.25, 0.125):
        info_c, lean_c = information(model, design, scale * chirp_u)
        if lean_c <= design.max_lean:
            naive["chirp"] = (*criterion(info_c), lean_c, scale, worst_sigma(info_c))
            break
    amplitude, u, info, lean = _within_envelope(model, design, best)
    logdet, condition = criterion(info)
    if logdet < naive["random multisine"][0]:     # the search may only improve on where it started
        amplitude, u, info, lean = _within_envelope(model, design, start)
        logdet, condition = criterion(info)
    predicted = {"D-optimal multisine": _process_numbers(model, design, u)[:2]}
    for name, program in (("random multisine", torques(design, start, naive["random multisine"][3])),
                          ("chirp", naive["chirp"][3] * chirp_u if "chirp" in naive else None)):
        if program is not None:
            predicted[name] = _process_numbers(model, design, program)[:2]
    if design.push > 0:
        pushed, scale, weighted, sigma, lean_p = damping_phase(model, design, u)
        if scale != 1.0 or pushed is not u:
            u, amplitude, lean = pushed, amplitude * scale, lean_p
            info, _ = information(model, design, u)
            logdet, condition = criterion(info)
            predicted = {"with the damping phase": (weighted, sigma), **predicted}
    return Result(design, u, amplitude, logdet, condition, lean, naive, count[0], worst_sigma(info), predicted)


# -- the scenario file ------------------------------------------------------------------------------
def scenario_text(result, robot=None, out=None):
    """The scenario TOML of a designed program: the robot (a robot file, relative to the scenario's
    folder when `out` is given, or the paper's simulation preset), rest as the start, and one
    [[torque]] window per hold."""
    d = result.design
    per_hold = round(d.hold / DT)
    lines = [f"# An excitation for identifying {', '.join(d.names)}: a D-optimal multisine"
             + (f", its last {d.push:g} a damping phase," if d.push > 0 else "") + f" within |u| <= {d.u_max:g} N m",
             f"# and a pendulum lean of at most {d.max_lean:.4g} rad (python -m runtime excite; docs/identification.md).",
             f"# log det of the information {result.logdet:.4g}, condition number {result.condition:.3g}, "
             f"peak lean {result.lean:.3g} rad.",
             f'description = "excitation for {", ".join(d.names)}, {d.duration:g} s"',
             f"dt = {DT}", f"steps = {d.steps}", f'method = "{METHOD}"', "", "[params]"]
    if robot is None:
        lines.append('preset = "paper_simulation"')
    else:
        path = pathlib.Path(robot).resolve()
        if out is not None:
            try:
                path = pathlib.Path(os.path.relpath(path, pathlib.Path(out).resolve().parent))
            except ValueError:
                pass
        lines.append(f"robot = {_toml_string(str(path))}")
    for h in range(d.steps // per_hold):
        uY, uP = result.torques[h * per_hold]
        lines += ["", "[[torque]]", f"from_step = {h * per_hold + 1}", f"to_step = {(h + 1) * per_hold}",
                  f"u_Y = {float(uY)!r}", f"u_P = {float(uP)!r}"]
    return "\n".join(lines) + "\n"


def _toml_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def report(result):
    """The comparison as text: the designed program's log det and condition against the naive ones."""
    rows = [("designed program", result.logdet, result.condition, result.lean, result.amplitude, result.sigma)]
    rows += [(name, *values) for name, values in result.naive.items()]
    lines = [f"parameters: {', '.join(result.design.names)} (relative to their nominal values); "
             f"{result.design.duration:g} s, |u| <= {result.design.u_max:g} N m, lean <= {result.design.max_lean:.4g} rad",
             f"{'program':<22} {'log det I':>10} {'cond I':>10} {'peak lean':>10} {'amplitude':>10} {'worst sigma':>12}"]
    lines += [f"{name:<22} {logdet:>10.3f} {cond:>10.3g} {lean:>10.3f} {amp:>10.3g} {sig:>12.3g}"
              for name, logdet, cond, lean, amp, sig in rows]
    lines.append(f"({result.evaluations} evaluations of the information)")
    if result.sigmas:
        names = result.design.names
        lines.append(f"predicted sigma (relative, the process noise's bound), criterion = log det + "
                     f"{result.design.damping_weight:g} x the dampings' log information:")
        lines.append(f"{'program':<24} {'criterion':>10} " + " ".join(f"{n:>8}" for n in names))
        lines += [f"{name:<24} {weighted:>10.3f} " + " ".join(f"{100 * v:>7.3g}%" for v in sigma)
                  for name, (weighted, sigma) in result.sigmas.items()]
    return "\n".join(lines)


def main(argv):
    """`python -m runtime excite [--robot FILE] --params NAMES --duration S --out FILE`."""
    parser = argparse.ArgumentParser(prog="python -m runtime excite", description=__doc__.splitlines()[0])
    parser.add_argument("--robot", help="a robot file (docs/robots.md); default the paper's robot as simulated")
    parser.add_argument("--params", required=True,
                        help="the parameters to identify, comma-separated: entries (c_P_z) or whole fields (c_P)")
    parser.add_argument("--duration", type=float, required=True, help="the program's length [s]")
    parser.add_argument("--out", type=output_file, required=True, help="the scenario file to write (TOML)")
    parser.add_argument("--u-max", type=float, default=U_MAX, help=f"torque limit [N m] (default {U_MAX})")
    parser.add_argument("--max-lean", type=float, default=MAX_LEAN,
                        help="the flip-over envelope: largest pendulum inclination [rad] (default pi/3)")
    parser.add_argument("--harmonics", type=int, default=4, help="frequencies per motor (default 4)")
    parser.add_argument("--f-high", type=float, default=2.0, help="the band's top [Hz] (default 2)")
    parser.add_argument("--push", type=float, default=0.5,
                        help="the fraction of the duration at the end given to the damping phase (default 0.5; 0: none)")
    parser.add_argument("--damping-weight", type=float, default=2.0,
                        help="the dampings' weight in the criterion (default 2; 0: D-optimality alone)")
    parser.add_argument("--iterations", type=int, default=10, help="L-BFGS-B iterations at most (default 10)")
    parser.add_argument("--seed", type=int, default=0, help="the random-phase start (default 0)")
    args = parser.parse_args(argv)
    try:
        params = load_robot(args.robot) if args.robot else Params.paper_simulation()
        design = Design(args.params, args.duration, u_max=args.u_max, max_lean=args.max_lean,
                        harmonics=args.harmonics, f_high=args.f_high, push=args.push,
                        damping_weight=args.damping_weight)
        if args.iterations < 1:
            raise ValueError(f"iterations: expected a whole number >= 1, got {args.iterations}")
        if args.seed < 0:
            raise ValueError(f"seed: expected a whole number >= 0, got {args.seed}")
        started = time.perf_counter()
        result = design_program(params, design, seed=args.seed, max_iterations=args.iterations)
    except ValueError as exc:
        parser.exit(2, f"python -m runtime excite: error: {exc}\n")
    write_text(args.out, scenario_text(result, args.robot, args.out))
    print(report(result))
    print(f"designed in {time.perf_counter() - started:.1f} s")
    print(f"wrote {args.out}")
    return 0


__all__ = ["Design", "Result", "design_program", "information", "process_information", "weighted_criterion",
           "damping_phase", "sigmas", "DAMPINGS", "criterion", "worst_sigma", "torques", "chirp",
           "random_coefficients", "parameter_names", "scenario_text", "report", "main"]
