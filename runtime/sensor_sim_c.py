"""The sensor simulation of runtime/sensor_sim.py in C (c/include/sr_sim.h), feeding the C EKF: the
plant, its sensors and the filter between two controller samples in one call.

    sim = SensorSimulation(plant, sensors, dt, steps, method, seed)     # the seeding and the biases
    run = SensorRunC(sim, estimator, steps)         # estimator: a runtime.control.estimator.SensorEkf
    run.advance(k, n, x, u, traj_rows)              # steps k..k+n-1 under u: x and traj_rows written

Every random number is drawn here beforehand from `sim`'s own seeded streams, in the order the
Python simulation draws them (one row per step for the process, per sample for each sensor), and
the IMU's biases are `sim`'s: one seed gives the readings of `SensorSimulation.advance`, which stays
the reference (tests/runtime/test_sensor_sim_c.py holds them equal).
"""
import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .errors import KernelError
from .ekf import KINDS as FILTER_KINDS
from .ekf import METHODS
from .sensor_sim import KINDS, WIDTH
from .sensors import BODIES
from .state import NX

#: The filter's name of each simulated kind (the C EKF counts fixes as "position").
_FILTER_KIND = dict(zip(KINDS, ("imu", "encoders", "position", "heading")))
assert all(_FILTER_KIND[k] in FILTER_KINDS for k in KINDS)



def imu_biases(sim):
    """(rows (n, 6), stride): the IMU's biases at each of its samples, one row for the run when
    they hold constant (stride 0)."""
    if not np.any(sim.bias_step_std):
        return np.ascontiguousarray(np.atleast_2d(sim.bias), dtype=np.float64), 0
    # The walk is drawn as SensorSimulation.advance draws it, one row per plant step from its own
    # stream, and summed in the same order; a sample reads the bias at the start of its step.
    steps = len(sim._walk) - 1
    walk = np.zeros((steps + 1, 6))
    walk[1:] = np.cumsum(sim.rng["bias_walk"].normal(0.0, 1.0, (steps, 6)) * sim.bias_step_std, axis=0)
    t = sim.times["imu"]
    step = np.minimum(np.floor((t + 1e-9 * sim.dt) / sim.dt).astype(int), steps)
    return np.ascontiguousarray(sim._bias0 + walk[step], dtype=np.float64), 6


class SensorRunC:
    """The C run (sr_sim) of the SensorSimulation `sim` on the filter of `estimator` (a
    runtime.control.estimator.SensorEkf) over `steps` plant steps: `advance` steps it; `readings` holds what was read,
    `order` the (kind, index) of each sample in the order the filter got them."""

    def __init__(self, sim, estimator, steps):
        self.sim, self.estimator, self.plant, self.steps = sim, estimator, sim.plant, steps
        s, f = sim.sensors, estimator.filter
        c = self._c = ffi.new("sr_sim *")
        keep = self._keep = []

        def buf(arr):
            arr = np.ascontiguousarray(arr, dtype=np.float64)
            keep.append(arr)
            return pointer(arr)

        c.steps, c.dt, c.method = self.steps, sim.dt, METHODS[sim.method]
        c.process = buf(sim.rng["process"].normal(0.0, 1.0, (self.steps, 5)))
        c.q_std = list(sim.q_std)
        c.disturbance_in_accel = int(sim.disturbance_in_accel)
        bias, stride = imu_biases(sim)
        c.bias, c.bias_stride = buf(bias), stride
        c.filter_method = METHODS[f.method]
        c.filter_process = f._process[0]
        c.filter_hold = f.noise.torque_hold     # > 0: the IMU through sr_ekf_update_imu_held, as runtime.ekf
        c.filter_time = estimator.t
        self.readings = {}
        total = 0
        for index, kind in enumerate(KINDS):
            st = c.stream[index]
            if kind not in sim.times:
                st.n = 0
                continue
            t = sim.times[kind]
            n = len(t)
            total += n
            st.n = n
            st.time = buf(t)
            st.arrival = buf(np.array([sim.arrival(kind, i) for i in range(n)]) if kind == "fixes" else t)
            self.readings[kind] = np.empty((n, WIDTH[kind]))
            st.reading = pointer(self.readings[kind])
            width = WIDTH[kind]
            if kind == "imu":
                st.draw = buf(sim.rng["imu"].normal(0.0, 1.0, (n, 6)))
                st.body, st.mount = BODIES[s.imu.mount.body], list(s.imu.mount.as_array())
                st.noise = list(np.repeat([s.imu.gyro_noise, s.imu.accel_noise], 3))
                st.range = list(np.repeat([s.imu.gyro_range, s.imu.accel_range], 3))
                st.sigma = list(f._imu_sigma)
                st.filter_body, st.filter_mount = BODIES[f.mount.body], list(f._imu_mount)
            elif kind == "encoders":
                st.range = [s.encoders.step] + [0.0] * 5
                st.sigma = [f.noise.encoder] + [0.0] * 5
            elif kind == "fixes":
                st.draw = buf(sim.rng["fixes"].normal(0.0, 1.0, (n, width)))
                st.noise = [s.fixes.noise] + [0.0] * 5
                st.sigma = [f.noise.position] + [0.0] * 5
            else:
                st.draw = buf(sim.rng["heading"].normal(0.0, 1.0, (n, width)))
                st.body, st.mount = BODIES[s.imu.mount.body], list(s.imu.mount.as_array())
                st.noise = [s.heading.noise] + [0.0] * 5
                st.sigma = [f.noise.heading] + [0.0] * 5
                st.filter_body, st.filter_mount = BODIES[f.heading_mount.body], list(f._heading_mount)
            st.gate = f.gate[_FILTER_KIND[kind]]
        self.order = np.zeros((max(total, 1), 2), dtype=np.int64)
        keep.append(self.order)
        c.order = ffi.cast("long *", ffi.from_buffer(self.order))
        status = lib.sr_sim_check(c)
        if status != lib.SR_OK:
            raise ValueError(f"sensors: the C simulation refuses the set "
                             f"({ffi.string(lib.sr_status_string(status)).decode()})")

    @property
    def applied(self):
        """How many samples the filter has been given."""
        return int(self._c.applied)

    def advance(self, step, count, x, u, traj=None):
        """Steps step..step+count-1 from x (35,), overwritten with the state after them, under the
        torques u (2,); traj: None, or (count, 35) rows for the states after each step.  The
        filter is taken at the estimator's time and left at the last sample's."""
        u = np.ascontiguousarray(u, dtype=np.float64)
        self._c.filter_time = self.estimator.t
        status = lib.sr_sim_advance(self._c, self.plant._model, self.estimator.filter._ekf,
                                    self.estimator.filter.model._model, step, count, pointer(x), pointer(u),
                                    ffi.NULL if traj is None else pointer(traj))
        self.estimator.t = float(self._c.filter_time)
        if status != lib.SR_OK:
            raise KernelError("x", status, f" (the C sensor simulation, steps {step}..{step + count - 1})")

    def samples(self, ticks, counts):
        """The closed loop's sample list (time, kind, reading) in the order applied, the controller's
        sample at each of `ticks` as (t, "tick", None) before the `counts[i]` samples applied after it."""
        out, done = [], 0
        for t, n in zip(ticks, counts):
            out.append((float(t), "tick", None))
            for kind_index, i in self.order[done:done + n]:
                kind = KINDS[kind_index]
                out.append((self.sim.arrival(kind, int(i)), kind, self.readings[kind][i]))
            done += n
        return out


assert NX == lib.SR_NX
