"""`Model`: the compiled kernels behind a NumPy interface (shapes and checks here, loops in C)."""
import numpy as np

from bindings._fastcall import Kernels
from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .errors import KernelError, SimulationStopped
from .derivatives import DerivativeMethods
from .param_derivatives import ParamDerivativeMethods
from .step_jacobian import StepJacobianMethods
from .group import GroupMethods
from .params import FLAT_FIELDS, Params
from .state import NU, NV, NX
from .validation import ROTATION_TOL, check_finite, check_states, choice, describe_state, project_state, real_array

METHODS = {"lie-euler": lib.SR_LIE_EULER, "rkmk4": lib.SR_RKMK4, "cf4": lib.SR_CF4,
           "rkmk4-projected": lib.SR_RKMK4 | lib.SR_PROJECT, "cf4-projected": lib.SR_CF4 | lib.SR_PROJECT}
"""Integrator names accepted by `Model.step`, `Model.simulate` and scenario files.
lie-euler: eq. (111), order 1.  rkmk4: Runge–Kutta–Munthe-Kaas (RK4 tableau in the Lie
algebra, dexp⁻¹ correction), order 4.  cf4: commutator-free method of Celledoni–Marthinsen–
Owren, order 4.  All keep R_S, R_Y, R_P on SO(3) by construction (c/spherical_robot.h);
the "-projected" variants add one Newton–Schulz correction per step (SR_PROJECT), for very
long runs at rest, where rounding drifts the same way every step."""

ENERGY_TOL = 0.5
"""Default of `Model.simulate(energy_tol=...)`: the energy may rise over a torque-free stretch
by at most this fraction of the stretch's energy scale (kinetic energy at its start + m_P g l)
before the run is stopped (SR_ERR_ENERGY).  The exact flow never gains energy without input
(damping >= 0).  Measured (docs/robustness.md): the shipped scenarios gain at most 0.0018 of
the scale with Lie–Euler at dt = 0.01 s, 0.25 at dt = 0.05 s, RKMK4 nothing; frictionless
Lie–Euler gains 0.14 in 100 s at dt = 0.001 s, 2.0 at dt = 0.01 s, 19 at dt = 0.1 s.
Half the scale gained from nowhere (the pendulum could swing up half its range by itself)
means the results are no longer physics: stop there."""

CHUNK_STEPS = 2000
"""Steps per C call of `Model.simulate` (between calls the progress callback runs)."""

MAX_STEPS = 10_000_000
"""Largest number of steps of one run (`Model.simulate`, `simulate_many`, scenario files, the
CLI): the trajectory is held in memory (35 float64 a row, so 10^7 steps take 2.8 GB).  A
larger count is a ValueError naming `steps`, not a MemoryError."""


def step_count(steps, name="steps"):
    """`steps` as an int in 0..MAX_STEPS, else ValueError naming `name`."""
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
        raise ValueError(f"{name}: expected a non-negative integer, got {steps!r}")
    if steps > MAX_STEPS:
        raise ValueError(f"{name}: {int(steps)} is more than MAX_STEPS = {MAX_STEPS} (the trajectory is kept "
                         f"in memory: {int(steps) + 1} rows of 35 float64)")
    return int(steps)


def _address(cdata):
    """The address of a cffi pointer as an int (handed to bindings._fastcall)."""
    return int(ffi.cast("uintptr_t", cdata))


def _double_array(value, field, shape_tail):
    """`value` as a C-contiguous float64 array whose trailing shape is `shape_tail` (see validation.real_array)."""
    return real_array(value, field, shape_tail)



def _method(method, allowed=METHODS):
    """The C code of the integrator named `method`, one of `allowed` (ValueError naming `method`)."""
    return METHODS[choice(method, "method", allowed, "integrator")]


_PARAM_MESSAGES = {
    lib.SR_ERR_SINGULAR: "params: the generalized inertia M is not positive definite at the reference state "
                         "in floating point (a value so small that the inertias underflow, or so large that "
                         "their products overflow)",
    lib.SR_ERR_PARAM: "params: the model overflows at the reference state (masses, lengths or g so "
                      "large that M or the energy is not finite)",
}


def _param_message(params, status):
    """Why `sr_model_init` refused parameters that pass every rule one by one: the status's reason,
    and the parameter farthest from 1 in magnitude (each rule holds, so it is the scale that fails)."""
    values = np.abs(params.as_array())
    scale = np.where(values > 0, np.abs(np.log10(np.where(values > 0, values, 1.0))), -1.0)
    name, entry = FLAT_FIELDS[int(np.argmax(scale))]
    where = name if entry is None else f"{name}[{', '.join(map(str, np.atleast_1d(entry)))}]"
    shown = float(params.as_array()[int(np.argmax(scale))])
    return f"{_PARAM_MESSAGES[status]}; the most extreme value is Params.{where} = {shown:g}"


class Model(GroupMethods, DerivativeMethods, StepJacobianMethods, ParamDerivativeMethods):
    """The spherical robot with parameters `params` (default: `Params()`, Section 5.2 as printed).

    Every method validates its input in full (c/spherical_robot.h, `sr_check_state`; the rules
    are in runtime/validation.py) and raises ValueError naming the argument, the entry and the
    rule; `KernelError` (a ValueError) carries the C status code.  `retract` and `local` (the
    error coordinates of the Jacobians) come from `runtime.group.GroupMethods`, `accel_jacobian`
    and `linearize` from `runtime.derivatives.DerivativeMethods`.
    """

    def __init__(self, params=None):
        self.params = Params() if params is None else params
        if not isinstance(self.params, Params):
            raise ValueError(f"params: expected a runtime.Params, got {type(self.params).__name__}")
        self._p = self.params.as_array()
        self._model = ffi.new("sr_model *")
        status = lib.sr_model_init(self._model, pointer(self._p))
        if status != lib.SR_OK:
            raise KernelError("params", status,
                              message=_param_message(self.params, status) if status in _PARAM_MESSAGES else None)
        # The one-state fast path of accel and step (bindings/fastcall.c); it keeps self._model alive.
        self._fast = Kernels(_address(self._model), _address(ffi.addressof(lib, "sr_py_accel")),
                             _address(ffi.addressof(lib, "sr_py_step")), self._model)

    def project(self, x):
        """The nearest valid state to x (35,) or (B, 35): see `runtime.validation.project_state`."""
        return project_state(x, self.params.r)

    # -- single-state kernels -------------------------------------------------
    def _valid_states(self, x, name="x", batch=True):
        x = real_array(x, name, (NX,), batch=batch)
        check_states(self._model, x, self.params.r, name)
        return x

    def _input(self, u, x, name="u"):
        if u is None:
            return np.zeros(x.shape[:-1] + (NU,))
        u = real_array(u, name, (NU,))
        if u.shape[:-1] != x.shape[:-1]:
            raise ValueError(f"{name}: shape {u.shape} does not match x of shape {x.shape}")
        check_finite(u, name)
        return u

    def _state_and_input(self, x, u, batch=True):
        x = self._valid_states(x, batch=batch)
        return x, self._input(u, x)

    def accel(self, x, u=None):
        """ν̇ = (ω̇_S, ω̇_Y, ω̇_P): shape (5,) for x (35,), or (B, 5) for x (B, 35); u (2,) / (B, 2) or None."""
        # The fast path (one float64 state): C checks everything in one call (sr_check_state and
        # the kernel's own checks; bindings/fastcall.c); None when it does not apply or C refuses,
        # and then the full path checks again in Python's terms to raise the precise message.
        out = self._fast.accel(x, u)
        if out is not None:
            return out
        return self._accel(x, u)

    def _accel(self, x, u):
        """`accel` for every input: converted and checked in Python's terms, then C."""
        x = real_array(x, "x", (NX,))
        if x.ndim == 1:
            x, u = self._state_and_input(x, u, batch=False)
            out = np.empty(NV)
            self._check("x", lib.sr_accel(self._model, pointer(x), pointer(u), pointer(out)))
            return out
        # A batch: C checks every state in full and solves, both vectorised (sr_checked_accel_batch);
        # the state it stops at is checked again here, for the message that names what is wrong.
        u = None if u is None else self._input(u, x)
        out = np.empty((x.shape[0], NV))
        failed = ffi.new("long *")
        status = lib.sr_checked_accel_batch(self._model, x.shape[0], pointer(x), ffi.NULL if u is None else pointer(u),
                                            pointer(out), failed)
        self._check_batch(x, status, failed[0])
        return out

    def contact_force(self, x, u=None):
        """The floor's force on the shell [N], plane frame (x up the slope, z the floor's normal):
        shape (3,) for x (35,), or (B, 3) for x (B, 35); u (2,) / (B, 2) or None.  F_z is the normal
        force, (F_x, F_y) the friction that rolling without slipping needs (docs/model.md)."""
        x = real_array(x, "x", (NX,))
        if x.ndim == 1:
            x, u = self._state_and_input(x, u, batch=False)
            out = np.empty(3)
            self._check("x", lib.sr_contact_force(self._model, pointer(x), pointer(u), pointer(out)))
            return out
        u = None if u is None else self._input(u, x)
        out = np.empty((x.shape[0], 3))
        failed = ffi.new("long *")
        status = lib.sr_contact_force_batch(self._model, x.shape[0], pointer(x), ffi.NULL if u is None else pointer(u),
                                            pointer(out), failed)
        self._check_batch(x, status, failed[0])
        return out

    def _check_batch(self, x, status, row, detail=""):
        """A batch call's status: the state C stopped at (row) is checked again here, for the message
        that names what is wrong; then the status itself."""
        if status != lib.SR_OK:
            field = f"x[{row}]" if row >= 0 else "x"
            if row >= 0:
                check_states(self._model, x[row], self.params.r, field)
            self._check(field, status, detail)

    def _single(self, fn, x, n, field="x"):
        x = self._valid_states(x, field, batch=False)
        out = np.empty(n)
        self._check(field, fn(self._model, pointer(x), pointer(out)))
        return out

    def inertia(self, x):
        """Generalized inertia M (5, 5), symmetric positive definite; kinetic energy ½νᵀMν."""
        return self._single(lib.sr_inertia, x, NV * NV).reshape(NV, NV)

    def inertia_batch(self, x):
        """M (B, 5, 5) of the states x (B, 35)."""
        x = np.ascontiguousarray(self._valid_states(x))
        out = np.empty((x.shape[0], NV, NV))
        failed = ffi.new("long *")
        # the binding's loop over sr_inertia (bindings/build_sr.py); the states are checked in full above
        status = lib.sr_py_inertia_batch(self._model, x.shape[0], pointer(x), pointer(out), failed)
        self._check(f"x[{failed[0]}]", status)
        return out

    def rhs(self, x, u=None):
        """f (5,) with M ν̇ = f."""
        x, u = self._state_and_input(x, u, batch=False)
        out = np.empty(NV)
        self._check("x", lib.sr_rhs(self._model, pointer(x), pointer(u), pointer(out)))
        return out

    def energy(self, x):
        """Kinetic plus potential energy [J] (potential m_P g e_zᵀ(q + R_S R_Y R_P c̄_P))."""
        return float(self._single(lib.sr_energy, x, 1)[0])

    def equilibrium_residual(self, x):
        """Generalized gravity torques at rest (5,): zero exactly at the equilibria of eq. (108)."""
        return self._single(lib.sr_equilibrium_residual, x, NV)

    # -- time stepping ----------------------------------------------------------
    def step(self, x, u=None, dt=0.01, method="lie-euler"):
        """One step of `method` with torques u held constant: the new state (35,) for x (35,), or
        (B, 35) for a batch x (B, 35) of states of this robot, u (2,) / (B, 2) or None; each row
        is the single step's, bit for bit (C: sr_step_batch, vectorised across the states for
        Lie-Euler)."""
        code = METHODS.get(method) if method.__class__ is str else None
        if code is not None:               # the fast path, as in `accel` (C also checks dt and the method)
            out = self._fast.step(x, u, dt, code)
            if out is not None:
                return out
        return self._step(x, u, dt, method)

    def _step(self, x, u, dt, method):
        """`step` for every input: converted and checked in Python's terms, then C."""
        x = real_array(x, "x", (NX,))
        if x.ndim == 1:
            x, u = self._state_and_input(x, u, batch=False)
            dt = self._dt(dt)
            out = np.empty(NX)
            self._check("x", lib.sr_step(self._model, _method(method), pointer(x), pointer(u), dt, pointer(out)),
                        ": the step's result overflowed (dt too large for this state?)")
            return out
        # A batch: C checks every state in full and steps (sr_step_batch); the state it stops at
        # is checked again here, for the message that names what is wrong (as in `_accel`).
        u = None if u is None else self._input(u, x)
        dt = self._dt(dt)
        code = _method(method)
        out = np.empty((x.shape[0], NX))
        failed = ffi.new("long *")
        status = lib.sr_step_batch(self._model, code, x.shape[0], pointer(x), ffi.NULL if u is None else pointer(u), dt,
                                   pointer(out), failed)
        self._check_batch(x, status, failed[0], ": the step's result overflowed (dt too large for this state?)")
        return out

    def simulate(self, x0, dt, steps, u=None, method="lie-euler", energy_tol=ENERGY_TOL, progress=None):
        """Trajectory (steps+1, 35) from x0.

        u: None (zero torque), an array (steps, 2) whose row n−1 acts on step n
        (from t = (n−1)·dt to n·dt), or a callable u(t, x) -> (2,) evaluated at
        the start of every step (a feedback controller).

        Guards (docs/robustness.md): the run stops with `SimulationStopped` (a
        KernelError, hence a ValueError) naming the step and the time when the
        state becomes non-finite (checked every step), when R_S, R_Y, R_P or q_z
        drift beyond ROTATION_TOL (every SR_GUARD_INTERVAL = 16 steps and at the
        end), or when, over a stretch of zero torque, the energy rises by more
        than `energy_tol` times the stretch's energy scale (its kinetic energy at
        the start + m_P g l; checked with the same interval; None disables).  The
        exception's `.trajectory` holds the rows computed before the failure.
        `progress(done, steps)` is called every CHUNK_STEPS steps.
        """
        x0 = self._valid_states(x0, "x0", batch=False)
        dt = self._dt(dt)
        steps = step_count(steps)
        code = _method(method)
        guard = ffi.new("sr_energy_guard *")
        guard.tol = self._energy_tol(energy_tol)
        # NaN-filled, so that a row C never wrote (a step that failed before forming its state) shows.
        traj = np.full((steps + 1, NX), np.nan)
        if callable(u):
            return self._simulate_feedback(x0, dt, steps, u, code, traj, guard)
        if u is not None:
            u = real_array(u, "u", (NU,))
            if u.shape != (steps, NU):
                raise ValueError(f"u: expected shape ({steps}, {NU}) for {steps} steps, got {u.shape}")
            check_finite(u, "u")
        traj[0] = x0
        done = 0
        while True:   # chunks of CHUNK_STEPS; the guard struct carries the energy stretch across them
            n = min(CHUNK_STEPS, steps - done)
            self._guarded_run(code, dt, n, None if u is None else u[done:done + n], guard, traj, done)
            done += n
            if progress is not None:
                progress(done, steps)
            if done >= steps:
                return traj

    def _guarded_run(self, code, dt, n, u, guard, traj, first):
        """`n` steps from traj[first] into traj[first..first+n] by sr_simulate_guarded; raises SimulationStopped."""
        done = ffi.new("long *")
        status = lib.sr_simulate_guarded(self._model, code, pointer(traj[first]), dt, n,
                                         ffi.NULL if u is None else pointer(u), guard,
                                         pointer(traj[first:first + n + 1]), done)
        if status == lib.SR_ERR_MODEL:    # refused before any step: the model's fault, not the run's
            raise KernelError("model", status)
        if status != lib.SR_OK:
            step = first + done[0] + 1
            state = traj[step].copy() if step < len(traj) and not np.isnan(traj[step]).all() else None
            raise SimulationStopped(status, step, dt, traj[:step].copy(), state,
                                    self._stop_reason(status, state, guard))

    def _stop_reason(self, status, state, guard):
        if status == lib.SR_ERR_ENERGY:
            rise = guard.energy - guard.e_start
            return (f"the energy rose without input power from {guard.e_start:.6g} J to {guard.energy:.6g} J "
                    f"(+{rise:.3g} J = {rise / guard.scale if guard.scale > 0 else float('inf'):.3g} × the "
                    f"energy scale {guard.scale:.3g} J, tolerance energy_tol = {guard.tol:g}); the time step "
                    f"is too large for this method, or pass energy_tol=None to measure the drift")
        if state is not None and status in (lib.SR_ERR_NONFINITE, lib.SR_ERR_NOT_ROTATION, lib.SR_ERR_CONSTRAINT):
            described = describe_state(state, self.params.r, "x")
            if described is not None:
                what = described[len("x: "):].split("; Model.project")[0]
                kind = "became non-finite" if status == lib.SR_ERR_NONFINITE else "drifted off the constraints"
                return f"the state {kind}: {what}"
        if status == lib.SR_ERR_NONFINITE:
            return "the state or an intermediate result became non-finite"
        return ffi.string(lib.sr_status_string(status)).decode()

    def _simulate_feedback(self, x0, dt, steps, control, code, traj, guard):
        traj[0] = x0
        for n in range(steps):
            un = real_array(control(n * dt, traj[n].copy()), "u(t, x)", (NU,), batch=False)
            if not np.all(np.isfinite(un)):
                raise ValueError(f"u(t, x): returned {un.tolist()} at t = {n * dt:g} s (step {n + 1}), "
                                 f"expected finite torques")
            self._guarded_run(code, dt, 1, un.reshape(1, NU), guard, traj, n)
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
        x0 = self._valid_states(x0, "x0", batch=False)
        dt_out = self._dt(dt_out, "dt_out")
        t_end = self._dt(t_end, "t_end", allow_zero=True)
        if t_end / dt_out > MAX_STEPS + 0.5:
            raise ValueError(f"t_end: {t_end:g} s at dt_out = {dt_out:g} s is more than MAX_STEPS = {MAX_STEPS} rows "
                             f"(the trajectory is kept in memory)")
        n_out = int(round(t_end / dt_out))
        if abs(n_out * dt_out - t_end) > 1e-9 * max(t_end, dt_out):
            raise ValueError(f"t_end: must be a whole multiple of dt_out = {dt_out:g}, got {t_end:g}")
        for name, tol in (("rtol", rtol), ("atol", atol)):
            if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) \
                    or not (np.isfinite(tol) and tol >= 0):
                raise ValueError(f"{name}: expected a non-negative finite number, got {tol!r}")
        if rtol + atol <= 0:
            raise ValueError("rtol, atol: at least one must be positive")
        if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) or max_steps <= 0:
            raise ValueError(f"max_steps: expected a positive integer, got {max_steps!r}")
        code = _method(method, ("rkmk4", "rkmk4-projected"))    # the methods with an error estimate
        traj = np.empty((n_out + 1, NX))
        stats = ffi.new("sr_adaptive_stats *")
        totals = {"accepted": 0, "rejected": 0, "evaluations": 0, "h_next": 0.0}

        def run(x_start, rows, u_rows, h_init, out, k0):
            status = lib.sr_simulate_adaptive(self._model, code, pointer(x_start), dt_out, rows,
                                              ffi.NULL if u_rows is None else pointer(u_rows),
                                              float(rtol), float(atol), h_init, max_steps, pointer(out), stats)
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
                check_finite(u, "u")
            run(x0, n_out, u, 0.0, traj, 0)
        return (traj, totals) if return_stats else traj

    # -- helpers ------------------------------------------------------------------
    @staticmethod
    def _dt(value, name="dt", allow_zero=False):
        """A time argument as a float: finite and positive (or non-negative with allow_zero)."""
        kind = "non-negative" if allow_zero else "positive"
        if isinstance(value, (str, bytes, bool, np.bool_)):    # float("0.01") and float(True) would pass
            raise ValueError(f"{name}: expected a {kind} number, got {value!r}")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: expected a {kind} number, got {value!r}") from None
        if not (np.isfinite(value) and (value >= 0 if allow_zero else value > 0)):
            raise ValueError(f"{name}: expected a {kind} finite number, got {value!r}")
        return value

    @staticmethod
    def _energy_tol(energy_tol):
        if energy_tol is None:
            return -1.0
        if isinstance(energy_tol, bool) or not isinstance(energy_tol, (int, float, np.integer, np.floating)) \
                or not (np.isfinite(energy_tol) and energy_tol >= 0):
            raise ValueError(f"energy_tol: expected None or a non-negative finite number, got {energy_tol!r}")
        return float(energy_tol)

    @staticmethod
    def _check(field, status, detail=""):
        if status != lib.SR_OK:
            if status == lib.SR_ERR_NONFINITE:   # inputs were checked before: the result overflowed
                raise KernelError(field, status, message=f"{field}: the result is not finite (overflow){detail}")
            raise KernelError(field, status)
