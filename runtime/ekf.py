"""The error-state EKF on the group, in C (c/include/sr_ekf.h): the state and the IMU's biases
from an IMU, the joint encoders, position fixes and a heading (docs/estimation.md, "The filter").

    from runtime import Model, Params
    from runtime.ekf import EkfNoise, start_from_measurements
    model = Model(Params.paper_simulation())
    ekf = start_from_measurements(model, accel=(0.0, 0.0, 9.81), encoders=(0.0, 0.0), fix=(0.0, 0.0))
    for each sample of period dt, torques u:
        ekf.predict(u, dt)
        ekf.update_imu(y_imu, u)                    # (6,): gyroscope [rad/s], accelerometer [m/s²]
        ekf.update_encoders((theta_Y, theta_P))     # as the samples arrive, any rate
        ekf.update_position((q_x, q_y))
    ekf.x, ekf.biases, ekf.sigma, ekf.counters

A fix that arrives `latency` after the instant it measures: `ekf.mark_position(slot)` at that
instant (after the predict to it), `ekf.update_position_delayed(slot, (q_x, q_y))` on arrival;
up to DELAYED_SLOTS fixes may wait at once.

Every call is one C call on a caller-owned `sr_ekf`; the arguments are checked here first (a
ValueError names the one that is wrong).  Each update returns True when the sample was applied,
False when the chi-square gate refused it (counted in `counters`).
"""
import dataclasses
import math

import numpy as np
from scipy.stats import chi2

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .errors import KernelError
from .model import Model
from .sensors import DEFAULT_MOUNT, BODIES, Mount, NEB
from .so3 import exp as so3_exp, rot_x, rot_y
from .state import IDX_E_NU, IDX_E_Q, IDX_E_TH_P, IDX_E_TH_Y, IDX_E_XI_S, NU, initial_state
from .validation import check_finite, choice, real_array

#: The sensor kinds, in the order of the C counters (SR_EKF_IMU ...).
KINDS = ("imu", "encoders", "position", "heading")
#: The stepping methods of the prediction.
METHODS = {"lie-euler": lib.SR_LIE_EULER, "rkmk4": lib.SR_RKMK4, "cf4": lib.SR_CF4}
#: The size of each kind's sample (the degrees of freedom of its gate).
SAMPLE_SIZES = {"imu": lib.SR_NIMU, "encoders": 2, "position": 2, "heading": 1}
#: How many delayed fixes may wait at once (the slots of `Ekf.mark_position`).
DELAYED_SLOTS = lib.SR_EKF_NDELAYED
#: The default recovery policy (`Ekf`'s `recover_after`): per sensor kind, the samples refused in a
#: row after which the next refused one is admitted with the prior inflated.
RECOVER_AFTER = {"imu": 10, "encoders": 10, "position": 4, "heading": 4}
#: The bias blocks of the error state.
IDX_EB_BG = slice(lib.SR_EB_b_g, lib.SR_EB_b_g + 3)
IDX_EB_BA = slice(lib.SR_EB_b_a, lib.SR_EB_b_a + 3)



@dataclasses.dataclass(frozen=True)
class EkfNoise:
    """What the filter assumes of its sensors and of the robot (plain numbers, SI units).

    Per-sample standard deviations of the readings, the biases' spread per run, their random
    walks (0: constant over the run), and the process noise: white generalized torques on the
    shell (each axis) and on both joints, one spectral density [N·m/√Hz].  `accel` is one number
    for the accelerometer's three axes or three (x, y, z of the sensor), kept as three.
    `torque_hold` [s] > 0: the torque disturbance is held over that period after each IMU sample,
    whose accelerometer reads the acceleration it gives (`sr_ekf_update_imu_held`: the sample's
    noise and the next predict's process noise correlated, `accel` then the readings' own noise);
    0: the accelerometer is taken to read the applied torques' acceleration alone."""
    gyro: float = 0.003                                   # rad/s, per axis and sample
    accel: float | tuple = 0.02                           # m/s², per sample: one for all axes, or (x, y, z)
    gyro_bias: float = 0.005                              # rad/s, 1σ of b_g per axis at the start
    accel_bias: float = 0.05                              # m/s², 1σ of b_a per axis at the start
    gyro_bias_rw: float = 0.0                             # rad/s/√s
    accel_bias_rw: float = 0.0                            # m/s²/√s
    encoder: float = 2 * math.pi / 4096 / math.sqrt(12)   # rad: a count's quantisation at 4096 counts/rev
    position: float = 0.01                                # m, per axis of a fix
    heading: float = 0.05                                 # rad
    torque_psd: float = 0.01                              # N·m/√Hz
    torque_hold: float = 0.0                              # s, 0: the disturbance not read by the IMU

    def __post_init__(self):
        accel = self.accel
        if isinstance(accel, (list, tuple, np.ndarray)):
            if len(accel) != 3:
                raise ValueError(f"accel: expected one number or three (x, y, z), got {len(accel)}")
            for i, value in enumerate(accel):
                _noise_number(value, f"accel[{i}]", zero_ok=False)
            object.__setattr__(self, "accel", tuple(float(v) for v in accel))
        else:
            _noise_number(accel, "accel", zero_ok=False)
            object.__setattr__(self, "accel", (float(accel),) * 3)
        for field in dataclasses.fields(self):
            if field.name == "accel":
                continue
            _noise_number(getattr(self, field.name), field.name,
                          zero_ok=field.name.endswith("_rw") or field.name in ("torque_psd", "torque_hold"))


def _noise_number(value, name, zero_ok):
    if not (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
            and math.isfinite(value) and (value >= 0 if zero_ok else value > 0)):
        raise ValueError(f"{name}: expected a finite number {'>= 0' if zero_ok else '> 0'}, got {value!r}")


def gate_threshold(probability, size):
    """The chi-square quantile of `probability` for a sample of `size` entries (1: no gate, +inf)."""
    return math.inf if probability == 1 else float(chi2.ppf(probability, size))


def _vector(value, name, n):
    arr = real_array(value, name, (n,), batch=False)
    check_finite(arr, name)
    return arr


class Ekf:
    """The filter on one robot (`model`), started at x0 with biases (6,) (None: zero) and either
    the covariance P0 (18, 18) or the standard deviations sigma (18,) of the error state (the 12
    error coordinates of `Model.retract`, then b_g, b_a).  `mount`: the IMU's (and the heading
    sensor's, unless `heading_mount`); `method`: the prediction's stepper; `gate`: the probability
    of the chi-square gate of every update (1: no gate); `recover_after`: the recovery policy, per
    kind ({"position": 4, ...}) the number of samples refused in a row after which the next refused
    one is admitted with the prior and its noise inflated (docs/estimation.md, "Recovery"); None:
    RECOVER_AFTER, {}: off.  `constrained`: the observability constraint (OC-EKF: the predict's F
    and the IMU's and encoders' H projected so that the heading and the position the sensors cannot
    see stay unseen; c/include/sr_ekf.h, docs/estimation.md "Observability constraint")."""

    def __init__(self, model, x0, *, P0=None, sigma=None, biases=None, noise=None, mount=None, heading_mount=None,
                 method="rkmk4", gate=0.999, recover_after=None, constrained=False):
        if not isinstance(model, Model):
            raise ValueError(f"model: expected a runtime.Model, got {type(model).__name__}")
        self.model = model
        self.noise = EkfNoise() if noise is None else noise
        if not isinstance(self.noise, EkfNoise):
            raise ValueError(f"noise: expected an EkfNoise, got {type(noise).__name__}")
        self.mount = _mount(mount, "mount")
        self.heading_mount = self.mount if heading_mount is None else _mount(heading_mount, "heading_mount")
        self.method = choice(method, "method", METHODS, "integrator")
        if not (isinstance(gate, (int, float)) and 0 < gate <= 1):
            raise ValueError(f"gate: expected a probability in (0, 1], got {gate!r}")
        self.gate = {kind: gate_threshold(gate, n) for kind, n in SAMPLE_SIZES.items()}
        x = model._valid_states(x0, "x0", batch=False)
        b = np.zeros(6) if biases is None else _vector(biases, "biases", 6)
        self._ekf = ffi.new("sr_ekf *")
        if (P0 is None) == (sigma is None):
            raise ValueError("P0, sigma: give exactly one of them")
        if P0 is not None:
            P = real_array(P0, "P0", (NEB, NEB), batch=False)
            check_finite(P, "P0")
            status = lib.sr_ekf_init(self._ekf, model._model, pointer(x), pointer(b), pointer(P))
            what = "P0"
        else:
            s = _vector(sigma, "sigma", NEB)
            if not (s > 0).all():
                raise ValueError(f"sigma: every standard deviation must be > 0, got {s.min()!r}")
            status = lib.sr_ekf_init_diagonal(self._ekf, model._model, pointer(x), pointer(b), pointer(s))
            what = "sigma"
        if status == lib.SR_ERR_ARG:
            raise ValueError("P0: not symmetric")
        if status == lib.SR_ERR_SINGULAR:
            raise ValueError(f"{what}: the covariance is not positive definite")
        _check(status, "x0")
        self.recover_after = _recovery(RECOVER_AFTER if recover_after is None else recover_after)
        for kind, after in self.recover_after.items():
            _check(lib.sr_ekf_set_recovery(self._ekf, KINDS.index(kind), after), "recover_after")
        if not isinstance(constrained, bool):
            raise ValueError(f"constrained: expected True or False, got {constrained!r}")
        self.constrained = constrained
        _check(lib.sr_ekf_set_observability_constraint(self._ekf, model._model, int(constrained)), "x0")
        n = self.noise
        self._process = ffi.new("sr_ekf_process *")
        self._process.torque_psd = [n.torque_psd] * 3
        self._process.gyro_bias_rw = n.gyro_bias_rw
        self._process.accel_bias_rw = n.accel_bias_rw
        self._imu_mount, self._heading_mount = self.mount.as_array(), self.heading_mount.as_array()
        self._imu_sigma = np.array([n.gyro] * 3 + list(n.accel))

    # -- the filter's equations ------------------------------------------------------------------
    def predict(self, u, dt):
        """One step of dt [s] > 0 under the torques u (2,) [N·m] (None: zero)."""
        torque = np.zeros(NU) if u is None else _vector(u, "u", NU)
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt: expected a finite number of seconds > 0, got {dt!r}")
        _check(lib.sr_ekf_predict(self._ekf, self.model._model, METHODS[self.method], pointer(torque), dt,
                                  self._process), "x")

    def _applied(self, kind, status, singular):
        if status == lib.SR_ERR_SINGULAR:
            raise KernelError("x", status, message=f"x: {singular}")
        _check(status, "x")
        k = KINDS.index(kind)
        return self._ekf.accepted[k] + self._ekf.recovered[k] > self._before

    def update_imu(self, y, u=None):
        """One IMU sample (6,): gyroscope [rad/s] then accelerometer [m/s²] in the sensor's axes,
        while the torques u (2,) act (None: zero)."""
        y = _vector(y, "y", 6)
        torque = np.zeros(NU) if u is None else _vector(u, "u", NU)
        self._before = self._ekf.accepted[0] + self._ekf.recovered[0]
        m = self.mount
        if self.noise.torque_hold > 0:
            status = lib.sr_ekf_update_imu_held(self._ekf, self.model._model, pointer(y), pointer(torque), BODIES[m.body],
                                                pointer(self._imu_mount), pointer(self._imu_sigma), self._process,
                                                self.noise.torque_hold, self.gate["imu"])
        else:
            status = lib.sr_ekf_update_imu_axes(self._ekf, self.model._model, pointer(y), pointer(torque), BODIES[m.body],
                                                pointer(self._imu_mount), pointer(self._imu_sigma), self.gate["imu"])
        return self._applied("imu", status, "the innovation covariance or the inertia is not positive definite")

    def update_encoders(self, y):
        """One encoder sample (θ_Y, θ_P) [rad]."""
        y = _vector(y, "y", 2)
        self._before = self._ekf.accepted[1] + self._ekf.recovered[1]
        status = lib.sr_ekf_update_encoders(self._ekf, self.model._model, pointer(y), self.noise.encoder,
                                            self.gate["encoders"])
        return self._applied("encoders", status, "the innovation covariance is not positive definite")

    def update_position(self, y):
        """One position fix (q_x, q_y) [m]."""
        y = _vector(y, "y", 2)
        self._before = self._ekf.accepted[2] + self._ekf.recovered[2]
        status = lib.sr_ekf_update_position(self._ekf, self.model._model, pointer(y), self.noise.position,
                                            self.gate["position"])
        return self._applied("position", status, "the innovation covariance is not positive definite")

    def mark_position(self, slot):
        """The instant a fix is measured that arrives later: what its update needs is kept in
        `slot` (0 ≤ slot < DELAYED_SLOTS; a slot still waiting forgets its fix)."""
        slot = _slot(slot)
        _check(lib.sr_ekf_mark_position(self._ekf, self.model._model, slot), "x")

    def update_position_delayed(self, slot, y):
        """The fix (q_x, q_y) [m] measured when `slot` was marked (the slot is free afterwards)."""
        slot = _slot(slot)
        if not self._ekf.delayed[slot].marked:
            raise ValueError(f"slot: {slot} waits for no fix (mark_position first)")
        y = _vector(y, "y", 2)
        self._before = self._ekf.accepted[2] + self._ekf.recovered[2]
        status = lib.sr_ekf_update_position_delayed(self._ekf, self.model._model, slot, pointer(y), self.noise.position,
                                                    self.gate["position"])
        return self._applied("position", status, "the innovation covariance is not positive definite")

    def waiting(self):
        """The slots whose fixes have not arrived yet."""
        return [k for k in range(DELAYED_SLOTS) if self._ekf.delayed[k].marked]

    def update_heading(self, y):
        """One heading sample [rad] of the heading sensor's x axis."""
        value = float(_vector([y], "y", 1)[0]) if np.ndim(y) == 0 else None
        if value is None:
            raise ValueError(f"y: expected one number (a heading in rad), got shape {np.shape(y)}")
        self._before = self._ekf.accepted[3] + self._ekf.recovered[3]
        m = self.heading_mount
        status = lib.sr_ekf_update_heading(self._ekf, self.model._model, value, BODIES[m.body],
                                           pointer(self._heading_mount), self.noise.heading, self.gate["heading"])
        return self._applied("heading", status, "the sensor's x axis is along the floor's normal or the "
                                                "innovation covariance is not positive definite")

    # -- what it holds -----------------------------------------------------------------------------
    @property
    def x(self):
        """The state estimate (35,)."""
        return np.frombuffer(ffi.buffer(self._ekf.x), dtype=np.float64).copy()

    @property
    def biases(self):
        """The IMU's bias estimate (6,): b_g [rad/s], b_a [m/s²]."""
        return np.frombuffer(ffi.buffer(self._ekf.bias), dtype=np.float64).copy()

    @property
    def P(self):
        """The covariance (18, 18) of the error state (d, b_g, b_a)."""
        return np.frombuffer(ffi.buffer(self._ekf.P), dtype=np.float64).reshape(NEB, NEB).copy()

    @property
    def sigma(self):
        """The standard deviations (18,) of the error state: √diag(P)."""
        return np.sqrt(np.diag(self.P))

    @property
    def counters(self):
        """Per kind ("imu", "encoders", "position", "heading"): {"accepted", "gated", "recovered",
        "nis"}: samples applied, refused by the gate, admitted by the recovery policy, and the last
        sample's normalised innovation squared."""
        e = self._ekf
        return {kind: {"accepted": int(e.accepted[i]), "gated": int(e.gated[i]), "recovered": int(e.recovered[i]),
                       "nis": float(e.nis[i])}
                for i, kind in enumerate(KINDS)}


def _mount(mount, name):
    if mount is None:
        return DEFAULT_MOUNT
    if not isinstance(mount, Mount):
        raise ValueError(f"{name}: expected a runtime.sensors.Mount, got {type(mount).__name__}")
    return mount


def _recovery(policy):
    if not isinstance(policy, dict):
        raise ValueError(f"recover_after: expected a dict of sensor kind to a count, got {type(policy).__name__}")
    out = {}
    for kind, after in policy.items():
        if kind not in KINDS:
            raise ValueError(f"recover_after: unknown sensor kind {kind!r} (known: {', '.join(KINDS)})")
        if not (isinstance(after, (int, np.integer)) and not isinstance(after, bool) and after >= 0):
            raise ValueError(f"recover_after[{kind!r}]: expected a whole number >= 0, got {after!r}")
        out[kind] = int(after)
    return out


def _slot(slot):
    if not (isinstance(slot, (int, np.integer)) and not isinstance(slot, bool) and 0 <= slot < DELAYED_SLOTS):
        raise ValueError(f"slot: expected an integer in [0, {DELAYED_SLOTS}), got {slot!r}")
    return int(slot)


def _check(status, field):
    if status != lib.SR_OK:
        raise KernelError(field, status)


def _rotation_between(a, b):
    """The smallest rotation taking the unit vector a to the unit vector b."""
    axis, c = np.cross(a, b), float(a @ b)
    s = float(np.linalg.norm(axis))
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        other = np.eye(3)[int(np.argmin(np.abs(a)))]
        axis = np.cross(a, other)
        return so3_exp(np.pi * axis / np.linalg.norm(axis))
    return so3_exp(axis / s * math.atan2(s, c))


def start_from_measurements(model, accel, *, encoders=None, fix=None, heading=None, noise=None, mount=None,
                            rate_sigma=0.01, heading_sigma=math.radians(10), heading_prior=0.0, **ekf_options):
    """An `Ekf` started by the rule of docs/estimation.md: at rest (ν = 0, σ `rate_sigma` rad/s),
    the position at the first fix (x, y) or the origin (σ `noise.position`), the joints at the
    encoders' angles (None: 0, σ 1 rad), the tilt from the accelerometer (one sample (3,) or the
    mean of several (n, 3) taken at rest: at rest it reads +g along the upward vertical), the
    heading of the IMU's x axis from `heading` (σ `noise.heading`) or `heading_prior` [rad] (σ
    `heading_sigma`, 10°: what the operator knows),
    the biases 0 (σ `noise.gyro_bias`, `noise.accel_bias`).  `ekf_options` go to `Ekf`."""
    noise = EkfNoise() if noise is None else noise
    if not isinstance(noise, EkfNoise):
        raise ValueError(f"noise: expected an EkfNoise, got {type(noise).__name__}")
    mount = _mount(mount, "mount")
    for name, value in (("rate_sigma", rate_sigma), ("heading_sigma", heading_sigma)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name}: expected a finite number > 0, got {value!r}")
    a = real_array(accel, "accel", (3,), batch=True)
    check_finite(a, "accel")
    samples = 1 if a.ndim == 1 else a.shape[0]
    f = a if a.ndim == 1 else a.mean(axis=0)
    if not np.linalg.norm(f) > 0:
        raise ValueError("accel: a zero specific force gives no vertical")
    theta = np.zeros(2) if encoders is None else _vector(encoders, "encoders", 2)
    position = np.zeros(2) if fix is None else _vector(fix, "fix", 2)
    if heading is not None and not (isinstance(heading, (int, float)) and math.isfinite(heading)):
        raise ValueError(f"heading: expected a finite number of rad, got {heading!r}")
    p = model.params.as_array()
    r, g, slope = p[lib.SR_P_r], p[lib.SR_P_g], p[lib.SR_P_slope]
    up = np.array([math.sin(slope), 0.0, math.cos(slope)])
    R_m = np.array(mount.rotation)
    # The body's attitude R_B turns the measured vertical (in the body's axes) onto the world's,
    # then about that vertical until the sensor's x axis has the heading.
    R_B = _rotation_between(R_m @ (f / np.linalg.norm(f)), up)
    if not (isinstance(heading_prior, (int, float)) and math.isfinite(heading_prior)):
        raise ValueError(f"heading_prior: expected a finite number of rad, got {heading_prior!r}")
    target = float(heading_prior) if heading is None else float(heading)
    for _ in range(8):
        h = R_B @ R_m[:, 0]
        if math.hypot(h[0], h[1]) < 1e-6:
            break
        R_B = so3_exp(up * math.remainder(target - math.atan2(h[1], h[0]), 2 * math.pi)) @ R_B
    Q_B = {"shell": np.eye(3), "yoke": rot_x(theta[0]), "pendulum": rot_x(theta[0]) @ rot_y(theta[1])}[mount.body]
    R_S = R_B @ Q_B.T
    x0 = initial_state(theta[0], theta[1], R_S=R_S, q=(position[0], position[1], r), r=r)

    tilt = math.sqrt(max(noise.accel) ** 2 / samples + noise.accel_bias ** 2) / g if g > 0 else 1.0
    yaw = heading_sigma if heading is None else noise.heading
    e1 = np.cross(up, [0.0, 1.0, 0.0]) if abs(up[1]) < 0.9 else np.cross(up, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    U = np.column_stack([e1, np.cross(up, e1), up])
    world = U @ np.diag([tilt ** 2, tilt ** 2, yaw ** 2]) @ U.T
    P0 = np.zeros((NEB, NEB))
    P0[IDX_E_XI_S, IDX_E_XI_S] = R_S.T @ world @ R_S       # the shell's error is in its own axes
    joint = noise.encoder if encoders is not None else 1.0
    P0[IDX_E_TH_Y, IDX_E_TH_Y] = P0[IDX_E_TH_P, IDX_E_TH_P] = joint ** 2
    P0[IDX_E_Q, IDX_E_Q] = noise.position ** 2 * np.eye(2)
    P0[IDX_E_NU, IDX_E_NU] = rate_sigma ** 2 * np.eye(IDX_E_NU.stop - IDX_E_NU.start)
    P0[IDX_EB_BG, IDX_EB_BG] = noise.gyro_bias ** 2 * np.eye(3)
    P0[IDX_EB_BA, IDX_EB_BA] = noise.accel_bias ** 2 * np.eye(3)
    P0 = 0.5 * (P0 + P0.T)
    return Ekf(model, x0, P0=P0, noise=noise, mount=mount, **ekf_options)

