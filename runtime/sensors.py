"""What the robot's sensors read, and the Jacobians an estimator needs (C: c/include/sr_sensors.h).

    from runtime import Model, Params, initial_state
    from runtime.sensors import Mount, imu, imu_jacobian
    model = Model(Params.paper_simulation())
    x = initial_state(theta_P=0.3)
    y = imu(model, x, u=(0.1, 0.0))                  # (6,): gyroscope [rad/s], accelerometer [m/s²]
    y, H = imu_jacobian(model, x, (0.1, 0.0))        # H (6, 18): columns d (12), b_g, b_a

An IMU sits on a body ("shell", "yoke" or "pendulum") at a lever arm (body frame, from the shell
centre) with its axes `rotation` in the body's frame (`Mount`; the default is the yoke, at
(0, 0, −0.05) m, axes along the yoke's).  The conventions (frames, signs, units, the slope) are
those of docs/estimation.md.  Jacobians are in the estimator's error state: the 12 error
coordinates of `Model.retract` (`runtime.state.NE`), then the biases b_g, b_a (`NEB` = 18
columns).  Single states, and the `*_batch` functions over many (the loop in C); every argument is checked (a ValueError names it) before C runs.
"""
import dataclasses

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .errors import KernelError
from .state import NV
from .validation import check_finite, real_array

#: Body name -> SR_BODY_* code.
BODIES = {"shell": lib.SR_BODY_shell, "yoke": lib.SR_BODY_yoke, "pendulum": lib.SR_BODY_pendulum}
#: Sizes: the mount array, the biases, an IMU reading, the estimator's error state.
NMOUNT, NBIAS, NIMU, NEB = lib.SR_NMOUNT, lib.SR_NBIAS, lib.SR_NIMU, lib.SR_NEB
#: Index slices of an IMU reading and of the estimator's error state's bias blocks.
IDX_GYRO = slice(lib.SR_IMU_gyro, lib.SR_IMU_gyro + 3)
IDX_ACCEL = slice(lib.SR_IMU_accel, lib.SR_IMU_accel + 3)
IDX_EB_BG = slice(lib.SR_EB_b_g, lib.SR_EB_b_g + 3)
IDX_EB_BA = slice(lib.SR_EB_b_a, lib.SR_EB_b_a + 3)
#: Below this horizontal length of the sensor's x axis the heading is refused (C: SR_ERR_SINGULAR).
HEADING_MIN_HORIZONTAL = float(lib.SR_HEADING_MIN_HORIZONTAL)



@dataclasses.dataclass(frozen=True)
class Mount:
    """Where a sensor sits: `body`, `lever` (3,) [m] in the body's frame from the shell centre,
    `rotation` (3, 3), the sensor's axes in the body's frame (a rotation matrix)."""
    body: str = "yoke"
    lever: tuple = (0.0, 0.0, -0.05)
    rotation: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def __post_init__(self):
        if not isinstance(self.body, str) or self.body not in BODIES:
            raise ValueError(f"mount.body: expected one of {sorted(BODIES)}, got {self.body!r}")
        lever = real_array(self.lever, "mount.lever", (3,), batch=False)
        rotation = real_array(self.rotation, "mount.rotation", (3, 3), batch=False)
        check_finite(lever, "mount.lever")
        check_finite(rotation, "mount.rotation")
        array = np.concatenate([lever, rotation.ravel()])
        status = lib.sr_check_mount(BODIES[self.body], pointer(array))
        if status == lib.SR_ERR_NOT_ROTATION:
            raise ValueError("mount.rotation: not a rotation matrix (orthonormal with det +1 to "
                             f"{float(lib.SR_ROTATION_TOL):g})")
        if status != lib.SR_OK:
            raise KernelError("mount", status)
        object.__setattr__(self, "lever", tuple(lever))
        object.__setattr__(self, "rotation", tuple(map(tuple, rotation)))

    def as_array(self):
        """The C mount array: lever (SR_MOUNT_lever), then the rotation row-major (SR_MOUNT_R_m)."""
        out, rotation = np.empty(NMOUNT), np.ravel(self.rotation)
        out[lib.SR_MOUNT_lever:lib.SR_MOUNT_lever + 3] = self.lever
        out[lib.SR_MOUNT_R_m:lib.SR_MOUNT_R_m + rotation.size] = rotation
        return out


DEFAULT_MOUNT = Mount()


def _mount(mount):
    if mount is None:
        return DEFAULT_MOUNT
    if not isinstance(mount, Mount):
        raise ValueError(f"mount: expected a runtime.sensors.Mount, got {type(mount).__name__}")
    return mount


def _vector(value, name, n, default_zero=False):
    if value is None and default_zero:
        return np.zeros(n)
    arr = real_array(value, name, (n,), batch=False)
    check_finite(arr, name)
    return arr


def _call(field, status, what=""):
    if status == lib.SR_ERR_SINGULAR and what:
        raise KernelError(field, status, message=f"{field}: {what}")
    if status == lib.SR_ERR_NONFINITE:
        raise KernelError(field, status, message=f"{field}: the result is not finite (overflow)")
    if status != lib.SR_OK:
        raise KernelError(field, status)


def _state(model, x):
    return model._valid_states(x, batch=False)


def imu(model, x, nu_dot=None, *, u=None, mount=None, bias=None):
    """The IMU's reading (6,): gyroscope R_mᵀ ω_B + b_g [rad/s], accelerometer R_mᵀ R_Bᵀ (p̈ − g⃗) + b_a
    [m/s²], in the sensor frame.  The accelerations ν̇ (5,) are given, or formed from the torques u
    (2,) (neither: zero torque).  bias (6,): (b_g, b_a), None for zero."""
    x = _state(model, x)
    m, b = _mount(mount), _vector(bias, "bias", NBIAS, default_zero=True)
    y = np.empty(NIMU)
    if nu_dot is not None:
        if u is not None:
            raise ValueError("u: give either nu_dot or u, not both")
        a = _vector(nu_dot, "nu_dot", NV)
        status = lib.sr_imu_measure(model._model, pointer(x), pointer(a), BODIES[m.body], pointer(m.as_array()), pointer(b), pointer(y))
    else:
        torque = _vector(u, "u", 2, default_zero=True)
        status = lib.sr_imu_measure_u(model._model, pointer(x), pointer(torque), BODIES[m.body], pointer(m.as_array()),
                                      pointer(b), pointer(y))
    _call("x", status, "the generalized inertia is singular")
    return y


def imu_partials(model, x, nu_dot, *, mount=None, bias=None):
    """(y (6,), H (6, 18), Hn (6, 5)): y(x ⊕ d, b + δb, ν̇ + e) = y + H (d, δb) + Hn e + O(2), ν̇ given."""
    x = _state(model, x)
    m, b = _mount(mount), _vector(bias, "bias", NBIAS, default_zero=True)
    a = _vector(nu_dot, "nu_dot", NV)
    y, H, Hn = np.empty(NIMU), np.empty((NIMU, NEB)), np.empty((NIMU, NV))
    _call("x", lib.sr_imu_partials(model._model, pointer(x), pointer(a), BODIES[m.body], pointer(m.as_array()), pointer(b),
                                   pointer(y), pointer(H), pointer(Hn)))
    return y, H, Hn


def _states(model, x):
    x = np.ascontiguousarray(model._valid_states(x, batch=True), dtype=float)
    return x.reshape(-1, x.shape[-1]), x.shape[:-1]


def _batch_call(model, x, status, failed):
    if status != lib.SR_OK and failed >= 0:
        _call(f"x[{failed}]", status)
    _call("x", status)


def imu_partials_batch(model, x, nu_dot, *, mount=None, bias=None):
    """`imu_partials` over many states, the loop in C: x (B, 35), nu_dot (B, 5) give y (B, 6),
    H (B, 6, 18), Hn (B, 6, 5); one mount and bias for all."""
    X, lead = _states(model, x)
    m, b = _mount(mount), _vector(bias, "bias", NBIAS, default_zero=True)
    a = np.ascontiguousarray(real_array(nu_dot, "nu_dot", (NV,)), dtype=float)
    if a.shape[:-1] != lead:
        raise ValueError(f"nu_dot: shape {a.shape} does not match x of shape {lead + (X.shape[-1],)}")
    check_finite(a, "nu_dot")
    n = X.shape[0]
    y, H, Hn = np.empty((n, NIMU)), np.empty((n, NIMU, NEB)), np.empty((n, NIMU, NV))
    failed = ffi.new("long *")
    status = lib.sr_imu_partials_batch(model._model, n, pointer(X), pointer(a), BODIES[m.body], pointer(m.as_array()), pointer(b),
                                       pointer(y), pointer(H), pointer(Hn), failed)
    _batch_call(model, X, status, failed[0])
    return y.reshape(lead + (NIMU,)), H.reshape(lead + (NIMU, NEB)), Hn.reshape(lead + (NIMU, NV))


def _pair_batch(model, x, function):
    X, lead = _states(model, x)
    n = X.shape[0]
    y, H = np.empty((n, 2)), np.empty((n, 2, NEB))
    failed = ffi.new("long *")
    _batch_call(model, X, function(model._model, n, pointer(X), pointer(y), pointer(H), failed), failed[0])
    return y.reshape(lead + (2,)), H.reshape(lead + (2, NEB))


def encoders_jacobian_batch(model, x):
    """`encoders_jacobian` over many states (x (B, 35)): y (B, 2), H (B, 2, 18), the loop in C."""
    return _pair_batch(model, x, lib.sr_encoders_jacobian_batch)


def position_jacobian_batch(model, x):
    """`position_jacobian` over many states (x (B, 35)): y (B, 2), H (B, 2, 18), the loop in C."""
    return _pair_batch(model, x, lib.sr_position_jacobian_batch)


def imu_jacobian(model, x, u=None, *, mount=None, bias=None):
    """(y (6,), H (6, 18)) under the torques u: ν̇ moves with the state (H = H|ν̇ + Hn Ja)."""
    x = _state(model, x)
    m, b = _mount(mount), _vector(bias, "bias", NBIAS, default_zero=True)
    torque = _vector(u, "u", 2, default_zero=True)
    y, H = np.empty(NIMU), np.empty((NIMU, NEB))
    _call("x", lib.sr_imu_jacobian(model._model, pointer(x), pointer(torque), BODIES[m.body], pointer(m.as_array()), pointer(b),
                                   pointer(y), pointer(H)), "the generalized inertia is singular")
    return y, H


def _pair(model, x, measure, jacobian):
    x = _state(model, x)
    y = np.empty(2)
    if not jacobian:
        _call("x", measure(model._model, pointer(x), pointer(y)))
        return y
    H = np.empty((2, NEB))
    _call("x", measure(model._model, pointer(x), pointer(y), pointer(H)))
    return y, H


def encoders(model, x):
    """(θ_Y, θ_P) (2,) [rad] in (−π, π]: the joint angles of R_Y about x and R_P about y."""
    return _pair(model, x, lib.sr_encoders_measure, False)


def encoders_jacobian(model, x):
    """(y (2,), H (2, 18))."""
    return _pair(model, x, lib.sr_encoders_jacobian, True)


def position(model, x):
    """(q_x, q_y) (2,) [m]: the shell centre on the floor."""
    return _pair(model, x, lib.sr_position_measure, False)


def position_jacobian(model, x):
    """(y (2,), H (2, 18))."""
    return _pair(model, x, lib.sr_position_jacobian, True)


_VERTICAL = "the sensor's x axis is along the floor's normal: the heading is undefined"


def heading(model, x, mount=None):
    """The heading [rad] in (−π, π] of the sensor's x axis on the floor: atan2(h_y, h_x) of
    h = R_B R_m e_x, counter-clockwise from the inertial x axis (up the slope)."""
    x, m = _state(model, x), _mount(mount)
    out = ffi.new("double *")
    _call("x", lib.sr_heading_measure(model._model, pointer(x), BODIES[m.body], pointer(m.as_array()), out), _VERTICAL)
    return float(out[0])


def heading_jacobian(model, x, mount=None):
    """(heading, H (18,))."""
    x, m = _state(model, x), _mount(mount)
    out, H = ffi.new("double *"), np.empty(NEB)
    _call("x", lib.sr_heading_jacobian(model._model, pointer(x), BODIES[m.body], pointer(m.as_array()), out, pointer(H)),
          _VERTICAL)
    return float(out[0]), H
