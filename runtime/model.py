"""`Model`: the compiled kernels behind a NumPy interface (shapes and checks here, loops in C)."""
import numpy as np

from bindings._sr import ffi, lib

from .params import Params
from .state import NU, NV, NX

#: Integrator names accepted by `Model.step`, `Model.simulate` and scenario files.
METHODS = {"lie-euler": lib.SR_LIE_EULER}

_STATUS_HINTS = {
    lib.SR_ERR_NONFINITE: "contains NaN or infinity",
    lib.SR_ERR_NOT_ROTATION: "holds a matrix that is not a rotation of the required kind "
                             "(R_S orthonormal with det +1, R_Y about x, R_P about y)",
    lib.SR_ERR_SINGULAR: "gives a singular generalized inertia",
    lib.SR_ERR_CONSTRAINT: "violates q_z = r",
}


class KernelError(ValueError):
    """A C kernel returned an error status."""

    def __init__(self, field, status, detail=""):
        self.status = status
        hint = _STATUS_HINTS.get(status, ffi.string(lib.sr_status_string(status)).decode())
        super().__init__(f"{field}: {hint}{detail}")


def _double_array(value, field, shape_tail):
    """`value` as a C-contiguous float64 array whose trailing shape is `shape_tail`."""
    try:
        arr = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{field}: expected an array of real numbers ({exc})") from None
    if arr.shape[arr.ndim - len(shape_tail):] != shape_tail or arr.ndim > len(shape_tail) + 1:
        want = " or ".join(str(s) for s in [shape_tail, ("B",) + shape_tail])
        raise ValueError(f"{field}: expected shape {want}, got {arr.shape}")
    return arr


def _ptr(arr):
    return ffi.cast("double *", ffi.from_buffer(arr))


def _method(method):
    try:
        return METHODS[method]
    except (KeyError, TypeError):
        raise ValueError(f"method: unknown integrator {method!r}; choose one of {sorted(METHODS)}") from None


class Model:
    """The spherical robot with parameters `params` (default: `Params()`, Section 5.2 as printed)."""

    def __init__(self, params=None):
        self.params = Params() if params is None else params
        if not isinstance(self.params, Params):
            raise ValueError(f"params: expected a runtime.Params, got {type(self.params).__name__}")
        self._p = self.params.as_array()
        self._model = ffi.new("sr_model *")
        status = lib.sr_model_init(self._model, _ptr(self._p))
        if status != lib.SR_OK:
            raise KernelError("params", status)

    # -- single-state kernels -------------------------------------------------
    def _state_and_input(self, x, u):
        x = _double_array(x, "x", (NX,))
        u = np.zeros(x.shape[:-1] + (NU,)) if u is None else _double_array(u, "u", (NU,))
        if u.shape[:-1] != x.shape[:-1]:
            raise ValueError(f"u: shape {u.shape} does not match x of shape {x.shape}")
        return x, u

    def accel(self, x, u=None):
        """ν̇ = (ω̇_S, ω̇_Y, ω̇_P): shape (5,) for x (35,), or (B, 5) for x (B, 35); u (2,) / (B, 2) or None."""
        x, u = self._state_and_input(x, u)
        if x.ndim == 1:
            out = np.empty(NV)
            self._check("x", lib.sr_accel(self._model, _ptr(x), _ptr(u), _ptr(out)))
            return out
        out = np.empty((x.shape[0], NV))
        failed = ffi.new("long *")
        status = lib.sr_accel_batch(self._model, x.shape[0], _ptr(x), _ptr(u), _ptr(out), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 else "x", status)
        return out

    def _single(self, fn, x, n, field="x"):
        x = _double_array(x, field, (NX,))
        if x.ndim != 1:
            raise ValueError(f"{field}: expected shape ({NX},), got {x.shape}")
        out = np.empty(n)
        self._check(field, fn(self._model, _ptr(x), _ptr(out)))
        return out

    def inertia(self, x):
        """Generalized inertia M (5, 5), symmetric positive definite; kinetic energy ½νᵀMν."""
        return self._single(lib.sr_inertia, x, NV * NV).reshape(NV, NV)

    def rhs(self, x, u=None):
        """f (5,) with M ν̇ = f."""
        x, u = self._state_and_input(x, u)
        if x.ndim != 1:
            raise ValueError(f"x: expected shape ({NX},), got {x.shape}")
        out = np.empty(NV)
        self._check("x", lib.sr_rhs(self._model, _ptr(x), _ptr(u), _ptr(out)))
        return out

    def energy(self, x):
        """Kinetic plus potential energy [J] (potential m_P g e_zᵀ(q + R_S R_Y R_P c̄_P))."""
        return float(self._single(lib.sr_energy, x, 1)[0])

    def equilibrium_residual(self, x):
        """Generalized gravity torques at rest (5,): zero exactly at the equilibria of eq. (108)."""
        return self._single(lib.sr_equilibrium_residual, x, NV)

    # -- time stepping ----------------------------------------------------------
    def step(self, x, u=None, dt=0.01, method="lie-euler"):
        """One step of `method` with torques u held constant; returns the new state (35,)."""
        x, u = self._state_and_input(x, u)
        if x.ndim != 1:
            raise ValueError(f"x: expected shape ({NX},), got {x.shape}")
        dt = self._dt(dt)
        out = np.empty(NX)
        self._check("x", lib.sr_step(self._model, _method(method), _ptr(x), _ptr(u), dt, _ptr(out)))
        return out

    def simulate(self, x0, dt, steps, u=None, method="lie-euler"):
        """Trajectory (steps+1, 35) from x0.

        u: None (zero torque), an array (steps, 2) whose row n−1 acts on step n
        (from t = (n−1)·dt to n·dt), or a callable u(t, x) -> (2,) evaluated at
        the start of every step (a feedback controller).
        """
        x0 = _double_array(x0, "x0", (NX,))
        if x0.ndim != 1:
            raise ValueError(f"x0: expected shape ({NX},), got {x0.shape}")
        dt = self._dt(dt)
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
            raise ValueError(f"steps: expected a non-negative integer, got {steps!r}")
        code = _method(method)
        traj = np.empty((steps + 1, NX))
        if callable(u):
            return self._simulate_feedback(x0, dt, steps, u, code, traj)
        if u is not None:
            u = _double_array(u, "u", (NU,))
            if u.shape != (steps, NU):
                raise ValueError(f"u: expected shape ({steps}, {NU}) for {steps} steps, got {u.shape}")
            if not np.all(np.isfinite(u)):
                raise ValueError("u: contains NaN or infinity")
        done = ffi.new("long *")
        status = lib.sr_simulate(self._model, code, _ptr(x0), dt, steps,
                                 ffi.NULL if u is None else _ptr(u), _ptr(traj), done)
        self._check_simulation(status, done[0], dt)
        return traj

    def _simulate_feedback(self, x0, dt, steps, control, code, traj):
        traj[0] = x0
        for n in range(steps):
            un = _double_array(control(n * dt, traj[n].copy()), "u(t, x)", (NU,))
            if un.ndim != 1:
                raise ValueError(f"u(t, x): expected shape ({NU},), got {un.shape}")
            status = lib.sr_step(self._model, code, _ptr(traj[n]), _ptr(un), dt, _ptr(traj[n + 1]))
            if status == lib.SR_OK and not np.all(np.isfinite(traj[n + 1])):
                status = lib.SR_ERR_NONFINITE
            self._check_simulation(status, n, dt)
        return traj

    # -- helpers ------------------------------------------------------------------
    @staticmethod
    def _dt(dt):
        try:
            dt = float(dt)
        except (TypeError, ValueError):
            raise ValueError(f"dt: expected a positive number, got {dt!r}") from None
        if not (dt > 0 and np.isfinite(dt)):
            raise ValueError(f"dt: expected a positive finite number, got {dt!r}")
        return dt

    @staticmethod
    def _check(field, status):
        if status != lib.SR_OK:
            raise KernelError(field, status)

    @staticmethod
    def _check_simulation(status, done, dt):
        if status != lib.SR_OK:
            raise KernelError("x", status, f" at step {done + 1} (t = {done * dt:g} s)")
