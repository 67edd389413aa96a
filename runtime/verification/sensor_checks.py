"""Checks of the sensor models (c/include/sr_sensors.h, runtime.sensors) against two independent sources.

* The independent CasADi reference (`runtime.verification.sensor_reference`): the readings
  themselves (≤ 1e-12 relative) and their Jacobians, by its AD through its own ⊕ (≤ 1e-10).
* Central differences of the C readings through `Model.retract` (and in the biases and ν̇),
  Richardson-extrapolated (≤ 1e-9 relative): the Jacobians the estimator uses, ν̇ moving with the
  state (sr_imu_jacobian) included.

States, accelerations, mounts (body, lever arm, rotation) and biases are random.  Each check takes
the sensor API under test (`api`, default `runtime.sensors`) so that a test can hand it a perturbed
one and see the check fail.  Each returns (name, worst abs, worst rel, tolerance) rows for verify.py.
"""
import numpy as np

from .. import sensors as SENSORS
from ..model import Model
from ..params import Params
from ..so3 import random_rotation
from ..state import NE, NV
from .reference import ReferenceModel
from .sampling import random_inputs, random_state
from .sensor_reference import BODIES, SensorReference

#: Tolerances (relative to the largest entry of the reference): readings, AD Jacobians, differences.
VALUE_TOL, AD_TOL, DIFFERENCE_TOL = 1e-12, 1e-10, 1e-9


def random_mount(rng, body=None):
    """A mount on `body` (random if None): lever arm up to 0.2 m per axis, any rotation."""
    body = BODIES[rng.integers(len(BODIES))] if body is None else body
    return SENSORS.Mount(body, rng.uniform(-0.2, 0.2, 3), random_rotation(rng))


def _samples(n, seed, params):
    """(x, ν̇, u, mount, bias) tuples; every body in turn."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        x = random_state(rng, params)
        out.append((x, rng.uniform(-20, 20, NV), random_inputs(rng, 1)[0], random_mount(rng, BODIES[i % 3]),
                    rng.uniform(-0.5, 0.5, 6)))
    return out


def _relative(ours, theirs):
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    err = float(np.abs(ours - theirs).max())
    return err, err / max(float(np.abs(theirs).max()), 1e-300)


def _worst(pairs):
    return max((_relative(a, b) for a, b in pairs), key=lambda e: e[1])


def _mount_array(mount):
    return mount.as_array()


def value_checks(n_states=200, seed=11, params=None, api=SENSORS):
    """The C readings against the reference at random states, ν̇, mounts and biases."""
    params = Params.paper_simulation() if params is None else params
    model, ref = Model(params), SensorReference(params.as_dict())
    imu, heading, other = [], [], []
    for x, a, _, mount, bias in _samples(n_states, seed, params):
        imu.append((api.imu(model, x, a, mount=mount, bias=bias), ref.imu(x, a, mount.body, _mount_array(mount), bias)))
        heading.append((api.heading(model, x, mount), ref.heading(x, mount.body, _mount_array(mount))))
        other.append((np.concatenate([api.encoders(model, x), api.position(model, x)]),
                      np.concatenate([ref.encoders(x), ref.position(x)])))
    return [(f"sensors: IMU (gyroscope, accelerometer) vs the CasADi reference ({n_states} states, mounts, ν̇)",
             *_worst(imu), VALUE_TOL),
            (f"sensors: heading vs the CasADi reference ({n_states} states, mounts)", *_worst(heading), VALUE_TOL),
            (f"sensors: encoders, position fix vs the CasADi reference ({n_states} states)", *_worst(other), VALUE_TOL)]


def ad_checks(n_states=200, seed=12, params=None, api=SENSORS):
    """The C Jacobians (ν̇ held, and along ν̇) against CasADi AD of the reference through its ⊕."""
    params = Params.paper_simulation() if params is None else params
    model, ref = Model(params), SensorReference(params.as_dict())
    imu, heading, other = [], [], []
    for x, a, _, mount, bias in _samples(n_states, seed, params):
        _, H, Hn = api.imu_partials(model, x, a, mount=mount, bias=bias)
        H_ref, Hn_ref = ref.imu_jacobians(x, a, mount.body, _mount_array(mount), bias)
        imu.append((np.hstack([H, Hn]), np.hstack([H_ref, Hn_ref])))
        heading.append((api.heading_jacobian(model, x, mount)[1], ref.heading_jacobian(x, mount.body, _mount_array(mount))))
        other.append((np.vstack([api.encoders_jacobian(model, x)[1], api.position_jacobian(model, x)[1]]),
                      np.vstack([ref.encoders_jacobian(x), ref.position_jacobian(x)])))
    return [(f"sensors: IMU Jacobians (ν̇ held; along ν̇) vs CasADi AD of the reference ({n_states} states)",
             *_worst(imu), AD_TOL),
            (f"sensors: heading Jacobian vs CasADi AD of the reference ({n_states} states)", *_worst(heading), AD_TOL),
            (f"sensors: encoder, position Jacobians vs CasADi AD of the reference ({n_states} states)",
             *_worst(other), AD_TOL)]


def _extrapolated(f, n, h):
    """Central differences of f along the n unit vectors, Richardson-extrapolated from h and h/2."""
    def central(step):
        return np.column_stack([(np.atleast_1d(f(step * e)) - np.atleast_1d(f(-step * e))) / (2 * step)
                                for e in np.eye(n)])
    return (4 * central(h / 2) - central(h)) / 3


def difference_checks(n_states=30, seed=13, params=None, api=SENSORS, h=1e-3):
    """The C Jacobians against Richardson central differences of the C readings: the IMU's with ν̇
    moving with the state under u (sr_imu_jacobian: x ⊕ d and the biases), the IMU's along ν̇, the
    heading's, through `Model.retract`."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    imu, along, heading = [], [], []
    for x, a, u, mount, bias in _samples(n_states, seed, params):
        def moved(e):
            return api.imu(model, model.retract(x, e[:NE]), u=u, mount=mount, bias=bias + e[NE:])
        imu.append((api.imu_jacobian(model, x, u, mount=mount, bias=bias)[1], _extrapolated(moved, NE + 6, h)))
        along.append((api.imu_partials(model, x, a, mount=mount, bias=bias)[2],
                      # y is affine in ν̇: a step of 1 is as exact as any and rounds least.
                      _extrapolated(lambda e: api.imu(model, x, a + e, mount=mount, bias=bias), NV, 1.0)))
        heading.append((api.heading_jacobian(model, x, mount)[1][:NE],
                        _extrapolated(lambda d: api.heading(model, model.retract(x, d), mount), NE, h)))
    return [(f"sensors: IMU Jacobian (ν̇ = accel(x, u) moving) vs Richardson differences through retract ({n_states} states)",
             *_worst(imu), DIFFERENCE_TOL),
            (f"sensors: IMU Jacobian along ν̇ vs Richardson differences ({n_states} states)", *_worst(along), DIFFERENCE_TOL),
            (f"sensors: heading Jacobian vs Richardson differences through retract ({n_states} states)",
             *_worst(heading), DIFFERENCE_TOL)]


def measured_accel_check(n_states=50, seed=14, params=None, api=SENSORS):
    """The IMU under torques (ν̇ from the C accel) against the reference's IMU at the reference's own
    ν̇ (ReferenceModel.accel): the sensors and the dynamics together, both independent (≤ 1e-10,
    the accel cross-check's tolerance)."""
    params = Params.paper_simulation() if params is None else params
    model, ref, dyn = Model(params), SensorReference(params.as_dict()), ReferenceModel(params.as_dict())
    pairs = [(api.imu(model, x, u=u, mount=mount, bias=bias),
              ref.imu(x, dyn.accel(x, u), mount.body, _mount_array(mount), bias))
             for x, _, u, mount, bias in _samples(n_states, seed, params)]
    return [(f"sensors: IMU under torques vs the reference's IMU at its own accel ({n_states} states)",
             *_worst(pairs), AD_TOL)]
