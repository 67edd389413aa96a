"""An extended Kalman filter on the group: the controller's view of a robot measured with noise.

The state is a point x of SO(3) × SO(2) × SO(2) × ℝ² × ℝ⁵ and the filter's uncertainty lives in
its tangent space, in the right-trivialised error coordinates δ ∈ ℝ¹² of runtime/group.py (x ⊕ δ,
y ⊖ x: runtime/group.py), as in the invariant / error-state filters of the estimation literature
(and manif's and SymForce's examples).  One sample of period T, torques u held:

    predict   x⁻ = step(x̂, u, T)                 one RKMK4 step (c/sr_steppers.c)
              P⁻ = F P Fᵀ + G_w Σ_w G_wᵀ T        F = ∂step/∂δ, the exact step Jacobian
    correct   e  = y ⊖ x⁻                          the measurement's error coordinates
              K  = P⁻ (P⁻ + R)⁻¹,  x̂ = x⁻ ⊕ K e,  P = (I − K) P⁻

The measurement is the whole state with noise (what the closed loop's sensors give: position,
the shell's attitude, the joint encoders, the rates), so its Jacobian is the identity in these
coordinates.  The process noise Σ_w is a white acceleration on the five rates (model mismatch:
a heavier robot, other dampings); G_w puts it on ν.  The model is the controller's (its nominal
parameters), never the plant's.

`SensorEkf` is the robot's own filter instead: the C EKF (runtime/ekf.py) on an IMU, the encoders
and optional fixes and heading (a task's `[sensors]`), which never sees the state itself.
"""
import dataclasses

import numpy as np

from ..ekf import Ekf as CEkf
from ..model import Model
from ..schema import check_arguments
from ..sensor_sim import ekf_noise
from ..sensors import NEB
from .ranges import ESTIMATOR_RANGES
from ..state import IDX_E_NU, IDX_E_Q, IDX_E_TH_P, IDX_E_TH_Y, IDX_E_XI_S, NE


@dataclasses.dataclass(frozen=True)
class EkfSettings:
    """`[estimator]` keys: the sensors' standard deviations the filter assumes, and the process noise."""
    position_m: float = 0.005           # q_x, q_y
    attitude_rad: float = 0.005         # R_S, each axis
    joint_rad: float = 1e-4             # the encoders of θ_Y, θ_P
    rate_rad_s: float = 0.02            # ω_S, ω_Y, ω_P
    accel_rad_s2: float = 0.05          # process noise: white angular acceleration on the rates [rad/s²/√Hz]
    rate: float = 0.0                   # the sensors' rate [Hz], a whole multiple of the controller's; 0: the controller's

    def __post_init__(self):
        check_arguments(dataclasses.asdict(self), ESTIMATOR_RANGES)


SETTING_NAMES = tuple(f.name for f in dataclasses.fields(EkfSettings))


class Ekf:
    """`reset(y)` with the first measurement, then `update(y, u, period)` once per sample -> x̂."""
    kind = "ekf"

    def __init__(self, params, settings=EkfSettings(), method="rkmk4"):
        self.model, self.settings, self.method = Model(params), settings, method
        self.rate = settings.rate         # the closed loop runs `update` at this rate (0: the controller's)
        s = settings
        r = np.zeros(NE)
        r[IDX_E_XI_S] = s.attitude_rad ** 2
        r[IDX_E_TH_Y] = r[IDX_E_TH_P] = s.joint_rad ** 2
        r[IDX_E_Q] = s.position_m ** 2
        r[IDX_E_NU] = s.rate_rad_s ** 2
        self.R = np.diag(r)
        self.x, self.P = None, None

    def reset(self, y):
        """Start from the first measurement, as uncertain as the sensors."""
        self.x, self.P = np.array(y, dtype=np.float64), self.R.copy()
        return self.x

    def update(self, y, u, period):
        """x̂ after the sample: the prediction over `period` with torques u, corrected by y."""
        if self.x is None:
            raise ValueError("estimator: update before reset")
        x_pred = self.model.step(self.x, u, period, self.method)
        F, _ = self.model.step_jacobian(self.x, u, period, self.method)
        Q = np.zeros((NE, NE))
        Q[IDX_E_NU, IDX_E_NU] = self.settings.accel_rad_s2 ** 2 * period * np.eye(IDX_E_NU.stop - IDX_E_NU.start)
        P = F @ self.P @ F.T + Q
        e = self.model.local(x_pred, y)
        K = np.linalg.solve((P + self.R).T, P.T).T          # P (P + R)⁻¹, P and R symmetric
        self.x = self.model.retract(x_pred, K @ e)
        I_K = np.eye(NE) - K
        self.P = I_K @ P @ I_K.T + K @ self.R @ K.T          # Joseph form: stays symmetric positive
        return self.x


#: The start's standard deviations of the filter on sensors: the robot placed where its task says to
#: within 1 cm and 0.01 rad per axis, its rates known to 0.05 rad/s (it may start rolling).
START_POSITION_M, START_ATTITUDE_RAD, START_RATE_RAD_S = 0.01, 0.01, 0.05


def mismatch_torque_psd(params, sensors, *, slope_rad=0.0, centre_of_mass_m=0.0, damping=0.0, speed=0.0):
    """The process noise [N·m/√Hz] that stands for a declared model mismatch in a filter on the
    nominal model (`params`): the largest constant generalized force the mismatch can put on the
    robot rolling straight at `speed` [m/s], spread as a white torque over the fixes' period.

    The constant forces are the slope's pull on the shell (m_R g r sin `slope_rad`), the pendulum's
    weight about a centre of mass moved by `centre_of_mass_m` (m_P g δc) and a damping off by the
    fraction `damping` at the rolling rate (`damping` k_S v / r on the shell); a mass off its value
    adds only inertia, which at a steady roll is no force.  A constant force b acts as an impulse
    b τ over τ; a white torque of density q gives one of spread q √τ over τ, so q = b √τ with τ the
    fixes' period, over which the filter must absorb the force before a fix corrects the position
    it moved.  Without fixes nothing corrects it and the mismatch adds nothing (0)."""
    for name, value in (("slope_rad", slope_rad), ("centre_of_mass_m", centre_of_mass_m),
                        ("damping", damping), ("speed", speed)):
        if not (isinstance(value, (int, float)) and np.isfinite(value) and value >= 0):
            raise ValueError(f"{name}: expected a finite number >= 0, got {value!r}")
    if sensors.fixes is None:
        return 0.0
    force = (params.m_R * params.g * params.r * np.sin(min(slope_rad, np.pi / 2))
             + params.m_P * params.g * centre_of_mass_m + damping * params.k_S * speed / params.r)
    return float(force * np.sqrt(1.0 / sensors.fixes.rate))


class SensorEkf:
    """The C EKF (runtime.ekf) on the samples of a sensor set, on the controller's model (`params`),
    started at x0 (the task's initial state) with the START_* standard deviations and the set's
    biases' spread.  `sample(kind, t, row, u)` applies one sample at time t (the filter predicted
    there under the held torques u first); `at(t, u)` -> the estimate predicted to t.
    `mismatch_psd` [N·m/√Hz]: a white torque for the plant's difference from `params`
    (`mismatch_torque_psd`), added in quadrature to the set's process noise; 0: the set's alone.
    `accel_noise`: `ekf_noise`'s accelerometer rule, by default "held": the process noise a torque
    held over `hold` s (the plant's step; None: the IMU's period) that the accelerometer reads."""
    kind = "sensors"

    def __init__(self, params, sensors, x0, method="rkmk4", mismatch_psd=0.0, accel_noise="held", hold=None):
        noise = ekf_noise(sensors, params, accel_axes=accel_noise, hold=hold)
        if not (isinstance(mismatch_psd, (int, float)) and np.isfinite(mismatch_psd) and mismatch_psd >= 0):
            raise ValueError(f"mismatch_psd: expected a finite number >= 0 of N m/sqrt(Hz), got {mismatch_psd!r}")
        if mismatch_psd > 0:
            noise = dataclasses.replace(noise, torque_psd=float(np.hypot(noise.torque_psd, mismatch_psd)))
        sigma = np.empty(NEB)
        sigma[IDX_E_XI_S] = START_ATTITUDE_RAD
        sigma[IDX_E_TH_Y] = sigma[IDX_E_TH_P] = noise.encoder
        sigma[IDX_E_Q] = START_POSITION_M
        sigma[IDX_E_NU] = START_RATE_RAD_S
        sigma[NE:NE + 3], sigma[NE + 3:] = noise.gyro_bias, noise.accel_bias
        self.sigma0 = sigma                 # the start's standard deviations (the firmware example's too)
        self.filter = CEkf(Model(params), x0, sigma=sigma, noise=noise, mount=sensors.imu.mount, method=method)
        self.t = 0.0

    def at(self, t, u):
        """The state estimate (35,) at t [s] >= the last sample's time, predicted under u."""
        if t > self.t:
            self.filter.predict(u, t - self.t)
            self.t = t
        return self.filter.x

    def sample(self, kind, t, row, u):
        """Apply one sample of `kind` ("imu", "encoders", "fixes", "heading") taken at t [s] while u acts."""
        self.at(t, u)
        if kind == "imu":
            self.filter.update_imu(row, u)
        elif kind == "encoders":
            self.filter.update_encoders(row)
        elif kind == "fixes":
            self.filter.update_position(row)
        else:
            self.filter.update_heading(float(row[0]))
