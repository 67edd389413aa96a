"""`Model`: the compiled kernels behind a NumPy interface (shapes and checks here, loops in C)."""
import numpy as np

from bindings._sr import ffi, lib

from .params import Params
from .state import NU, NV, NX

#: Integrator names accepted by `Model.step`, `Model.simulate` and scenario files.
#: lie-euler: eq. (111), order 1.  rkmk4: Runge–Kutta–Munthe-Kaas (RK4 tableau in the Lie
#: algebra, dexp⁻¹ correction), order 4.  cf4: commutator-free method of Celledoni–Marthinsen–
#: Owren, order 4.  All keep R_S, R_Y, R_P on SO(3) by construction (c/spherical_robot.h);
#: the "-projected" variants add one Newton–Schulz correction per step (SR_PROJECT), for very
#: long runs at rest, where rounding drifts the same way every step.
METHODS = {"lie-euler": lib.SR_LIE_EULER, "rkmk4": lib.SR_RKMK4, "cf4": lib.SR_CF4,
           "rkmk4-projected": lib.SR_RKMK4 | lib.SR_PROJECT, "cf4-projected": lib.SR_CF4 | lib.SR_PROJECT}

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

    def simulate_adaptive(self, x0, t_end, dt_out, rtol=1e-8, atol=1e-10, u=None, method="rkmk4",
                          max_steps=10_000_000, return_stats=False):
        """Adaptive-step trajectory on the grid t_k = k·dt_out, k = 0..n (n = t_end/dt_out): shape (n+1, 35).

        The steps are chosen by an error estimate and land exactly on every grid
        point (no interpolation).  method: "rkmk4" or "rkmk4-projected": RKMK4
        with an embedded 3rd-order estimate (the RK4(3) pair sharing the stage
        at the new point; about 4 accelerations per step).  Every step's
        estimate satisfies |e_i| <= atol + rtol·s_i (max norm; s_i = 1 for the
        rotation angles, max(|old|, |new|) for q and ν); the 4th-order solution
        is kept, and the global error is typically about 3·rtol.

        u: None (zero torque); an array (n, 2) whose row k is held over
        [t_k, t_k+1); or a callable u(t, x) -> (2,) evaluated at every grid
        time on the grid state and held until the next one (a sampled,
        zero-order-hold controller).  max_steps bounds the step attempts.
        With return_stats=True, returns (traj, stats) where stats is a dict of
        accepted, rejected, evaluations (acceleration calls) and h_next.
        """
        x0 = _double_array(x0, "x0", (NX,))
        if x0.ndim != 1:
            raise ValueError(f"x0: expected shape ({NX},), got {x0.shape}")
        try:
            dt_out = float(dt_out)
        except (TypeError, ValueError):
            raise ValueError(f"dt_out: expected a positive number, got {dt_out!r}") from None
        if not (dt_out > 0 and np.isfinite(dt_out)):
            raise ValueError(f"dt_out: expected a positive finite number, got {dt_out!r}")
        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise ValueError(f"t_end: expected a non-negative number, got {t_end!r}") from None
        if not (t_end >= 0 and np.isfinite(t_end)):
            raise ValueError(f"t_end: expected a non-negative finite number, got {t_end!r}")
        n_out = int(round(t_end / dt_out))
        if abs(n_out * dt_out - t_end) > 1e-9 * max(t_end, dt_out):
            raise ValueError(f"t_end: must be a whole multiple of dt_out = {dt_out:g}, got {t_end:g}")
        for name, tol in (("rtol", rtol), ("atol", atol)):
            if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) \
                    or not (np.isfinite(tol) and tol >= 0):
                raise ValueError(f"{name}: expected a non-negative finite number, got {tol!r}")
        if rtol + atol <= 0:
            raise ValueError("rtol, atol: at least one must be positive")
        adaptive = ("rkmk4", "rkmk4-projected")
        if method not in adaptive:
            raise ValueError(f"method: adaptive stepping supports {', '.join(adaptive)}; got {method!r}")
        if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) or max_steps <= 0:
            raise ValueError(f"max_steps: expected a positive integer, got {max_steps!r}")
        code = _method(method)
        traj = np.empty((n_out + 1, NX))
        stats = ffi.new("sr_adaptive_stats *")
        totals = {"accepted": 0, "rejected": 0, "evaluations": 0, "h_next": 0.0}

        def run(x_start, rows, u_rows, h_init, out, k0):
            status = lib.sr_simulate_adaptive(self._model, code, _ptr(x_start), dt_out, rows,
                                              ffi.NULL if u_rows is None else _ptr(u_rows),
                                              float(rtol), float(atol), h_init, max_steps, _ptr(out), stats)
            for key in ("accepted", "rejected", "evaluations"):
                totals[key] += getattr(stats, key)
            totals["h_next"] = stats.h_next
            if status != lib.SR_OK:
                k = k0 + max(stats.rows_done - 1, 0)
                why = {lib.SR_ERR_STEP_SIZE: "step size underflow (the solution is too stiff or "
                                             "singular for this tolerance)",
                       lib.SR_ERR_MAX_STEPS: f"more than max_steps = {max_steps} step attempts"}
                if status in why:
                    raise KernelError("x", status, f": {why[status]}, in [{k * dt_out:g}, "
                                                   f"{(k + 1) * dt_out:g}] s")
                raise KernelError("x", status, f" in [{k * dt_out:g}, {(k + 1) * dt_out:g}] s")

        if callable(u):
            traj[0] = x0
            h = 0.0
            for k in range(n_out):
                uk = _double_array(u(k * dt_out, traj[k].copy()), "u(t, x)", (NU,))
                if uk.ndim != 1:
                    raise ValueError(f"u(t, x): expected shape ({NU},), got {uk.shape}")
                if not np.all(np.isfinite(uk)):
                    raise ValueError(f"u(t, x): returned NaN or infinity at t = {k * dt_out:g}")
                run(traj[k], 1, uk.reshape(1, NU), h, traj[k:k + 2], k)
                h = stats.h_next
        else:
            if u is not None:
                u = _double_array(u, "u", (NU,))
                if u.shape != (n_out, NU):
                    raise ValueError(f"u: expected shape ({n_out}, {NU}) for {n_out} output intervals, "
                                     f"got {u.shape}")
                if not np.all(np.isfinite(u)):
                    raise ValueError("u: contains NaN or infinity")
            run(x0, n_out, u, 0.0, traj, 0)
        return (traj, totals) if return_stats else traj

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
