"""The sensors of a `SensorSet` read along a plant as it steps, with the set's process noise driving
it: what simulated logs (runtime/estimation/sense.py) and the closed loop on the estimator
(runtime/control/closed_loop.py) share; and `ekf_noise`, what a filter assumes of such a set.

    sim = SensorSimulation(Model(params), SensorSet.default(), dt=0.005, steps=n, method="rkmk4", seed=1)
    for k in range(n):
        x, new = sim.advance(k, x, u)        # new: the (kind, index) of the samples read in the step

Over each step dt a white torque disturbance w on the shell (three axes) and both joints, of
spectral densities q (`ProcessNoise`), is a constant generalized force of standard deviation q/√dt on
ν = (ω_S, ω_Y, ω_P).  Its velocity change M⁻¹ w τ after a time τ into the step is added to the step's
state (the first-order effect of the force), and the accelerometer reads its acceleration M⁻¹ w.
Every sensor samples at k/rate (k = 0, 1, ...) up to the end of the run; between steps the state is
the stepper's over the partial step.  Readings: runtime.sensors (the plant's robot), plus the
IMU's biases, white noise, the IMU's saturation at its full scale, the encoders' quantisation; a fix
measured at t arrives at t + latency (`arrival`).  Seeded: one seed gives the same readings.

The biases are drawn once per run, N(0, bias²) per axis, then walk as the IMU declares: each step
adds N(0, rw² dt) per axis (`gyro_bias_rw`, `accel_bias_rw`), the discrete form of the random walk
a filter's predict allows for over the same step.  The samples of a step read the bias of its start
(`bias`; `bias_at(k)` after the run).
"""
import math

import numpy as np

from .ekf import EkfNoise
from .model import Model
from .sensors import encoders, heading, imu, imu_partials, position
from .state import IDX_NU, initial_state

#: The random streams of a run, each its own child of the seed: changing one sensor's rate or noise
#: leaves the others' draws alone.  A new stream goes at the end: the others keep their draws.
STREAMS = ("process", "bias", "imu", "encoders", "fixes", "heading", "bias_walk")


def random_streams(seed):
    """{stream name: numpy Generator} of a run seeded `seed`, one independent stream per name in
    STREAMS (a stream's draws do not move when another stream draws more or less)."""
    return dict(zip(STREAMS, map(np.random.default_rng, np.random.SeedSequence(seed).spawn(len(STREAMS)))))
#: The sensor kinds, in the order samples of one time are applied.
KINDS = ("imu", "encoders", "fixes", "heading")
#: The numbers of one reading of each sensor.
WIDTH = {"imu": 6, "encoders": 2, "fixes": 2, "heading": 1}


def sample_times(rate, duration):
    """k / rate for k = 0, 1, ... up to `duration` (with a 1e-9 relative allowance)."""
    n = math.floor(duration * rate * (1 + 1e-12) + 1e-9) + 1
    return np.arange(n) / rate


class SensorSimulation:
    """The readings of `sensors` along `plant` (a runtime.Model: the true robot) stepped by `dt` with
    `method` for `steps` steps, seeded by `seed`.  `times[kind]` (measurement times) and
    `readings[kind]` (rows) hold every sample; `advance` fills them step by step.  `bias` (6,) is the
    IMU's bias now (gyroscope, then accelerometer), `bias_at(k)` the bias of step k's samples.
    `disturbance_in_accel=False`: the accelerometer reads the acceleration of the applied torques
    alone (the disturbance still moves the plant)."""

    def __init__(self, plant, sensors, dt, steps, method, seed=0, disturbance_in_accel=True):
        self.plant, self.sensors, self.dt, self.method = plant, sensors, dt, method
        self.disturbance_in_accel = disturbance_in_accel
        duration = steps * dt
        self.rng = random_streams(seed)
        spec = sensors.imu
        self.bias = np.concatenate([self.rng["bias"].normal(0.0, spec.gyro_bias, 3),
                                    self.rng["bias"].normal(0.0, spec.accel_bias, 3)])
        self._bias0 = self.bias.copy()
        self.bias_step_std = np.repeat([spec.gyro_bias_rw, spec.accel_bias_rw], 3) * math.sqrt(dt)
        self._walk = np.zeros((steps + 1, 6))     # the bias's offset from its draw at each step's start
        self.q_std = sensors.process.generalized() / math.sqrt(dt)
        self.latency = sensors.fixes.latency if sensors.fixes is not None else 0.0
        self.times = {kind: sample_times(getattr(sensors, kind).rate, duration)
                      for kind in KINDS if getattr(sensors, kind) is not None}
        if "fixes" in self.times:                 # measured at k/rate, kept when they arrive within the run
            t = self.times["fixes"]
            self.times["fixes"] = t[t + self.latency <= duration * (1 + 1e-12) + 1e-9]
        self.readings = {kind: np.empty((len(t), WIDTH[kind])) for kind, t in self.times.items()}
        self.cursor = dict.fromkeys(self.times, 0)

    def bias_at(self, k):
        """The IMU's bias (6,) at the start of step k (the one its samples read), for k up to the
        steps advanced so far (and every step once the run is done)."""
        return self._bias0 + self._walk[k]

    def arrival(self, kind, i):
        """When sample i of `kind` reaches its reader [s]: its time, plus the latency of a fix."""
        return self.times[kind][i] + (self.latency if kind == "fixes" else 0.0)

    def _read(self, kind, i, xs, u, nu_dot_w):
        s, rng = self.sensors, self.rng
        if kind == "imu":
            a = self.plant.accel(xs, u) + (nu_dot_w if self.disturbance_in_accel else 0.0)
            y = imu(self.plant, xs, a, mount=s.imu.mount, bias=self.bias)
            y += rng["imu"].normal(0.0, 1.0, 6) * np.repeat([s.imu.gyro_noise, s.imu.accel_noise], 3)
            limits = np.repeat([s.imu.gyro_range, s.imu.accel_range], 3)
            self.readings[kind][i] = np.clip(y, -limits, limits)
        elif kind == "encoders":
            step = s.encoders.step
            self.readings[kind][i] = np.round(encoders(self.plant, xs) / step) * step
        elif kind == "fixes":
            self.readings[kind][i] = position(self.plant, xs) + rng["fixes"].normal(0.0, s.fixes.noise, 2)
        else:
            psi = heading(self.plant, xs, s.imu.mount) + rng["heading"].normal(0.0, s.heading.noise)
            self.readings[kind][i] = math.remainder(psi, 2 * math.pi)

    def advance(self, k, x, u, last=False):
        """Read every sample of [k dt, (k + 1) dt) along the step from x under the torques u, and
        return (the state after the step, the new samples as (kind, index) in the order read).
        `last`: the run's end at k dt, where no step starts: the samples at k dt only, and x back."""
        w = self.rng["process"].normal(0.0, 1.0, 5) * self.q_std if not last else np.zeros(5)
        nu_dot_w = np.linalg.solve(self.plant.inertia(x), w)
        t_k = k * self.dt
        end = t_k + self.dt if not last else math.inf
        new = []
        for kind, t in self.times.items():
            while self.cursor[kind] < len(t) and t[self.cursor[kind]] < end - 1e-9 * self.dt:
                i = self.cursor[kind]
                tau = t[i] - t_k
                if tau <= 1e-9 * self.dt:
                    xs = x
                else:
                    xs = self.plant.step(x, u, tau, method=self.method)
                    xs[IDX_NU] += nu_dot_w * tau
                self._read(kind, i, xs, u, nu_dot_w)
                new.append((kind, i))
                self.cursor[kind] += 1
        if last:
            return x, new
        x = self.plant.step(x, u, self.dt, method=self.method)
        x[IDX_NU] += nu_dot_w * self.dt
        if np.any(self.bias_step_std):            # a zero walk draws nothing: the bias stays its draw
            self._walk[k + 1] = self._walk[k] + self.rng["bias_walk"].normal(0.0, 1.0, 6) * self.bias_step_std
            self.bias = self._bias0 + self._walk[k + 1]
        return x, new


#: How `ekf_noise` spreads the process noise's share over the accelerometer's axes.
ACCEL_AXES = ("held", "largest", "each")


def ekf_noise(sensors, params, x0=None, accel_axes="held", hold=None):
    """The EkfNoise a sensor set declares.  `accel_axes` "held", the default: the filter models the
    process noise as `SensorSimulation` draws it, a torque held over each step of `hold` seconds (None:
    the IMU's period) whose acceleration the accelerometer reads (`torque_hold`; `accel` the white
    noise alone; the filter carries the correlation, runtime.ekf).  Otherwise the accelerometer's standard deviation adds
    to its white noise what the process noise puts into its reading at the IMU's rate (at x0: the
    robot at rest by default), the filter's measurement model seeing the applied torques only:
    "each", axis by axis; "largest", the largest axis's on all three (each axis's own
    makes the filter overconfident in the tilt: that share of the reading is correlated with the
    process noise; docs/estimation.md, "Consistency").  The biases' random walks are the IMU's."""
    if accel_axes not in ACCEL_AXES:
        raise ValueError(f"accel_axes: expected one of {', '.join(ACCEL_AXES)}, got {accel_axes!r}")
    model = Model(params)
    x0 = initial_state(r=params.r) if x0 is None else x0
    spec = sensors.imu
    if accel_axes == "held":
        if hold is not None and not (isinstance(hold, (int, float)) and math.isfinite(hold) and hold > 0):
            raise ValueError(f"hold: expected a finite number of seconds > 0, got {hold!r}")
        return _noise(sensors, accel=(spec.accel_noise,) * 3, torque_hold=1.0 / spec.rate if hold is None else hold)
    _, _, Hn = imu_partials(model, x0, np.zeros(5), mount=spec.mount)
    Minv = np.linalg.inv(model.inertia(x0))
    q2 = sensors.process.generalized() ** 2 * spec.rate             # (q/√dt)² at the IMU's period
    cov = Hn[3:] @ Minv @ np.diag(q2) @ Minv.T @ Hn[3:].T
    share = np.diag(cov) if accel_axes == "each" else np.full(3, np.max(np.diag(cov)))
    return _noise(sensors, accel=tuple(np.sqrt(spec.accel_noise ** 2 + share)))


def _noise(sensors, **accel):
    spec = sensors.imu
    return EkfNoise(gyro=spec.gyro_noise, **accel,
                    gyro_bias=spec.gyro_bias, accel_bias=spec.accel_bias,
                    gyro_bias_rw=spec.gyro_bias_rw, accel_bias_rw=spec.accel_bias_rw,
                    encoder=sensors.encoders.step / math.sqrt(12),
                    position=sensors.fixes.noise if sensors.fixes is not None else EkfNoise.position,
                    heading=sensors.heading.noise if sensors.heading is not None else EkfNoise.heading,
                    torque_psd=float(np.max(sensors.process.generalized())))
