"""Derivatives in the robot's parameters, the regressor form of the equations of motion and its
base parameters.

* `param_jacobian(x, u)`: ∂ν̇/∂p, (5, 31) in the parameters' C order (`PARAMETER_NAMES`);
* `step_param_jacobian(x, u, dt, method)`: step(x, u; p + δp) ⊖ step(x, u; p) = Jp δp + O(|δp|²),
  (12, 31), for Lie–Euler and RKMK4;
* `regressor(x, nudot)`: Y (5, 27) with M ν̇ − f(u = 0) = Y π, π the inertial parameters and
  dampings (`PI_NAMES`, `inertial_parameters`); along a motion Y π = (0, 0, 0, u_Y, u_P).

All three are C (c/src/sr_param_jacobians.c, from derive/param_derivatives.py), batches looped in
C.  `base_parameters` finds the combinations of π that the equations of motion determine at all:
the row space of Y stacked over many states (any excitation can identify those, no excitation
anything else).
"""
import dataclasses

import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .params import FLAT_FIELDS, SHAPES, flat_names, parameter_order
from .so3 import random_rotation
from .state import NE, NV, NX, initial_state
from .validation import choice, check_finite, real_array



def _parameter_names():
    names = [n for name, shape in SHAPES.items() for n in flat_names(name, shape)]
    return parameter_order(tuple(names))


PARAMETER_NAMES = _parameter_names()
"""The entries of the C parameter vector (`Params.as_array()`), in order: the columns of the
parameter Jacobians."""
NPARAM = len(FLAT_FIELDS)

_PI = (("m_S", None), ("j_S", None), ("k_S", None),
       ("m_Y", None), *((f"mc_Y_{a}", None) for a in "xyz"),
       *((f"JO_Y_{k}", None) for k in ("xx", "yy", "zz", "xy", "xz", "yz")), ("k_Y", None),
       ("m_P", None), *((f"mc_P_{a}", None) for a in "xyz"),
       *((f"JO_P_{k}", None) for k in ("xx", "yy", "zz", "xy", "xz", "yz")), ("k_P", None),
       ("j_mY", None), ("j_mP", None))
PI_NAMES = parameter_order(tuple(n for n, _ in _PI), prefix="SR_PI_", size="SR_NPI")
"""The inertial parameters π, the regressor's columns: m_S, j_S, k_S; per yoke and pendulum its
mass, first moment m·c (mc_*, body frame), standard tensor about the shell centre O (JO_*:
J + m(|c|² I − c cᵀ)) and damping; the rotors' axial inertias j_mY, j_mP."""
NPI = len(PI_NAMES)

STEP_METHODS = {"lie-euler": "SR_LIE_EULER", "rkmk4": "SR_RKMK4"}


def inertial_parameters(params):
    """π of a `Params` (in `PI_NAMES` order): the masses, m·c, J + m(|c|² I − c cᵀ), the dampings
    and the rotors' inertias."""
    values = {"m_S": params.m_S, "j_S": params.j_S, "k_S": params.k_S, "j_mY": params.j_mY, "j_mP": params.j_mP}
    for body in ("Y", "P"):
        m, c, J = getattr(params, f"m_{body}"), np.asarray(getattr(params, f"c_{body}")), np.asarray(getattr(params, f"J_{body}"))
        JO = J + m * (c @ c * np.eye(3) - np.outer(c, c))
        values[f"m_{body}"] = m
        values[f"k_{body}"] = getattr(params, f"k_{body}")
        values.update({f"mc_{body}_{a}": m * c[i] for i, a in enumerate("xyz")})
        values.update({f"JO_{body}_{k}": JO[i, j] for k, i, j in
                       (("xx", 0, 0), ("yy", 1, 1), ("zz", 2, 2), ("xy", 0, 1), ("xz", 0, 2), ("yz", 1, 2))})
    return np.array([float(values[n]) for n in PI_NAMES])


def _column_list(columns):
    """`columns` as an integer array of parameter indices, or a ValueError naming it."""
    cols = np.asarray(columns)
    if cols.ndim != 1 or len(cols) == 0 or not np.issubdtype(cols.dtype, np.integer) \
            or cols.min() < 0 or cols.max() >= NPARAM:
        raise ValueError(f"columns: expected a non-empty list of parameter indices in [0, {NPARAM}), got {columns!r}")
    return cols


class ParamDerivativeMethods:
    """`param_jacobian`, `step_param_jacobian` and `regressor` of `Model` (which provides _model,
    _check, _state_and_input, _valid_states, _dt)."""

    def _rows(self, single, batch, x, out, *arrays, field="x"):
        if x.ndim == 1:
            self._check(field, single(self._model, *arrays, pointer(out)))
            return out
        failed = ffi.new("long *")
        status = batch(self._model, x.shape[0], *arrays, pointer(out), failed)
        self._check(f"{field}[{failed[0]}]" if failed[0] >= 0 else field, status)
        return out

    def param_jacobian(self, x, u=None, columns=None):
        """∂ν̇/∂p with the state and the torques held: ν̇(x, u; p + δp) = ν̇(x, u; p) + J δp + O(|δp|²).

        J (5, 31), columns `PARAMETER_NAMES` (the order of `Params.as_array()`); (B, 5, 31) for x
        (B, 35), u (B, 2) or None.  From M ν̇ = f: J = −M⁻¹ ∂(M ν̇ − f)/∂p, ν̇ held in the bracket.
        `columns`: indices into `PARAMETER_NAMES`; only those columns, in that order, computed alone
        (C: sr_accel_param_jacobian_cols_batch)."""
        x, u = self._state_and_input(x, u)
        if columns is not None:
            return self._columns(lib.sr_accel_param_jacobian_cols_batch, x, u, NV, columns)
        out = np.empty(x.shape[:-1] + (NV, NPARAM))
        return self._rows(lib.sr_accel_param_jacobian, lib.sr_accel_param_jacobian_batch, x, out, pointer(x), pointer(u))

    def step_param_jacobian(self, x, u=None, dt=0.01, method="lie-euler", columns=None):
        """Jp (12, 31): step(x, u; p + δp) ⊖ step(x, u; p) = Jp δp + O(|δp|²), the exact derivative of
        one step of `method` ("lie-euler" or "rkmk4") as implemented, in the error coordinates of
        `retract`/`local`; columns `PARAMETER_NAMES`.  Batches: x (B, 35), u (B, 2) or None give
        (B, 12, 31).  Chaining steps: Jp of n steps = F_n (Jp of n − 1 steps) + Jp_n, with F of
        `step_jacobian`.  `columns`: indices into `PARAMETER_NAMES`; only those columns, in that
        order, at the cost of those alone (C: sr_step_param_jacobian_cols_batch)."""
        choice(method, "method", STEP_METHODS, "integrator with a parameter Jacobian")
        x, u = self._state_and_input(x, u)
        dt = self._dt(dt)
        code = getattr(lib, STEP_METHODS[method])
        if columns is not None:
            return self._columns(lib.sr_step_param_jacobian_cols_batch, x, u, NE, columns, (code, dt))
        out = np.empty(x.shape[:-1] + (NE, NPARAM))
        if x.ndim == 1:
            self._check("x", lib.sr_step_param_jacobian(self._model, code, pointer(x), pointer(u), dt, pointer(out)))
            return out
        failed = ffi.new("long *")
        status = lib.sr_step_param_jacobian_batch(self._model, code, x.shape[0], pointer(x), pointer(u), dt, pointer(out), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 else "x", status)
        return out

    def step_and_param_jacobian(self, x, u=None, dt=0.01, method="lie-euler", columns=None):
        """(x_next, Jp): the step of `method` from x (35,) or (B, 35) and the columns `columns` of
        `step_param_jacobian` (default all) from one pass of the stages (C:
        sr_step_and_param_jacobian_cols_batch); x_next equals `step`'s to rounding (the stages solve
        for ν̇ by the parameter path's factorisation).  What a fit needs at each evaluation, the
        prediction and its sensitivity, for the cost of the sensitivity alone."""
        return self._with_columns(lib.sr_step_and_param_jacobian_cols_batch, (NX,), x, u, dt, method, columns)

    def step_jacobians(self, x, u=None, dt=0.01, method="lie-euler", columns=None):
        """(F, Jp) at once: F of `step_jacobian` (12, 12) and the columns `columns` of
        `step_param_jacobian` (12, len(columns); default all), at the same states; batches
        x (B, 35), u (B, 2) or None give (B, 12, 12), (B, 12, len(columns)).  One pass of the
        parameter stages carries F's columns too, so each stage's derivative kernel and
        factorisation serve both (C: sr_step_jacobian_param_cols_batch); F equals `step_jacobian`'s
        to rounding."""
        return self._with_columns(lib.sr_step_jacobian_param_cols_batch, (NE, NE), x, u, dt, method, columns)

    def _with_columns(self, batch, first_shape, x, u, dt, method, columns):
        """(first, Jp) of a step's C batch `batch` that writes an array of `first_shape` per state,
        then the parameter columns `columns` (default all), for one state or a batch."""
        choice(method, "method", STEP_METHODS, "integrator with a parameter Jacobian")
        x, u = self._state_and_input(x, u)
        dt = self._dt(dt)
        cols = _column_list(np.arange(NPARAM) if columns is None else columns)
        xb = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
        ub = np.ascontiguousarray(u.reshape(-1, u.shape[-1]))
        first = np.empty((xb.shape[0], *first_shape))
        Jp = np.empty((xb.shape[0], NE, len(cols)))
        failed = ffi.new("long *")
        status = batch(self._model, getattr(lib, STEP_METHODS[method]), xb.shape[0], pointer(xb), pointer(ub), dt, len(cols),
                       ffi.new("int[]", [int(c) for c in cols]), pointer(first), pointer(Jp), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 and x.ndim > 1 else "x", status)
        return (first, Jp) if x.ndim > 1 else (first[0], Jp[0])

    def _columns(self, batch, x, u, rows, columns, step=()):
        """The columns `columns` of a parameter Jacobian with `rows` rows by the C batch `batch`, for
        one state or a batch; `step`: a step's (method code, dt)."""
        cols = _column_list(columns)
        xb = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
        ub = np.ascontiguousarray(u.reshape(-1, u.shape[-1]))
        out = np.empty((xb.shape[0], rows, len(cols)))
        failed = ffi.new("long *")
        status = batch(self._model, *step[:1], xb.shape[0], pointer(xb), pointer(ub), *step[1:], len(cols),
                       ffi.new("int[]", [int(c) for c in cols]), pointer(out), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 and x.ndim > 1 else "x", status)
        return out if x.ndim > 1 else out[0]

    def step_param_jacobian_fd(self, x, u=None, dt=0.01, method="lie-euler", columns=None):
        """`step_param_jacobian` by finite differences in C, batched (C: sr_step_param_jacobian_fd_batch):
        per parameter the robot at p ± h and one batch step of all the states each side, central
        differences (one-sided second-order ones for a parameter at a bound of its rule).  `columns`:
        indices into `PARAMETER_NAMES` (default all); x (B, 35) or (35,) gives (B, 12, len(columns))
        or (12, len(columns)).  The reference the analytic sensitivity is measured against, and a
        fit's Jacobian without it (`runtime.identification.fit.identify(..., jacobian="fd")`)."""
        choice(method, "method", STEP_METHODS, "integrator with a parameter Jacobian")
        x, u = self._state_and_input(x, u)
        dt = self._dt(dt)
        cols = np.arange(NPARAM) if columns is None else _column_list(columns)
        xb = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
        ub = np.ascontiguousarray(u.reshape(-1, u.shape[-1]))
        out = np.empty((xb.shape[0], NE, len(cols)))
        work = np.empty(xb.shape[0] * (4 * xb.shape[1] + 2 * NE))
        cint = ffi.new("int[]", [int(c) for c in cols])
        failed = ffi.new("long *")
        status = lib.sr_step_param_jacobian_fd_batch(self._model, getattr(lib, STEP_METHODS[method]), xb.shape[0],
                                                     pointer(xb), pointer(ub), dt, len(cols), cint, pointer(out), pointer(work),
                                                     failed)
        if status == lib.SR_ERR_PARAM:
            raise ValueError("columns: a parameter has no valid robot on either side of its value, no difference exists")
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 else "x", status)
        return out if x.ndim > 1 else out[0]

    def regressor(self, x, nudot):
        """Y (5, 27), columns `PI_NAMES`: M(x) ν̇ − f(x, u = 0) = Y(x, ν̇) π for this robot's π
        (`inertial_parameters(model.params)`), so that along a motion Y π = (0, 0, 0, u_Y, u_P).
        Y depends on the parameters only through r, n_Y, n_P, g and slope.  Batches: x (B, 35),
        nudot (B, 5) give (B, 5, 27)."""
        x = self._valid_states(x)
        nudot = real_array(nudot, "nudot", (NV,))
        if nudot.shape[:-1] != x.shape[:-1]:
            raise ValueError(f"nudot: shape {nudot.shape} does not match x of shape {x.shape}")
        check_finite(nudot, "nudot")
        out = np.empty(x.shape[:-1] + (NV, NPI))
        return self._rows(lib.sr_regressor, lib.sr_regressor_batch, x, out, pointer(x), pointer(nudot))


def trajectory_sensitivities(model, x0, dt, steps, u=None, method="rkmk4"):
    """(X, S, Phi): the trajectory X (steps + 1, 35) of `method` from x0 under u (None or
    (steps, 2), row k held over step k + 1), its sensitivities S (steps + 1, 12, 32) to the
    parameters and Phi (steps + 1, 12, 12) to the initial state, in the error coordinates at each
    x_k: x_k(x0 ⊕ d, p + δp) ⊖ x_k = Phi_k d + S_k δp + O(2).  Chained step by step,
    S_{k+1} = F_k S_k + Jp_k and Phi_{k+1} = F_k Phi_k with F_k of `Model.step_jacobian` and Jp_k of
    `Model.step_param_jacobian` (a loop over C calls; what a prediction-error or a
    multiple-shooting fit needs)."""
    choice(method, "method", STEP_METHODS, "integrator with a parameter Jacobian")
    X = model.simulate(x0, dt, steps, u=u, method=method, energy_tol=None)
    U = np.zeros((steps, 2)) if u is None else np.asarray(u, dtype=float)
    S = np.zeros((steps + 1, NE, NPARAM))
    Phi = np.zeros((steps + 1, NE, NE))
    Phi[0] = np.eye(NE)
    for k in range(steps):
        F, _ = model.step_jacobian(X[k], U[k], dt, method)
        S[k + 1] = F @ S[k] + model.step_param_jacobian(X[k], U[k], dt, method)
        Phi[k + 1] = F @ Phi[k]
    return X, S, Phi


@dataclasses.dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of π: base parameter k is π[independent[k]] + Σ_j
    combination[k, j] π[dependent[j]]; `rank` of them; `singular_values` of the stacked,
    column-scaled regressor (the gap after `rank` shows how clear the decision is)."""
    rank: int
    independent: tuple
    dependent: tuple
    combination: np.ndarray
    singular_values: np.ndarray
    null_space: np.ndarray

    def names(self, digits=6):
        """Each base parameter as text, e.g. "m_S + m_Y + m_P"."""
        out = []
        for k, i in enumerate(self.independent):
            terms = [PI_NAMES[i]]
            for j, c in zip(self.dependent, self.combination[k]):
                if abs(c) > 10 ** -digits:
                    terms.append(f"{'+' if c > 0 else '-'} {_number(abs(c), digits)}{PI_NAMES[j]}")
            out.append(" ".join(terms))
        return out

    def identifiable(self, c, tol=1e-8):
        """Whether the combination cᵀπ (c of length NPI) is determined by the equations of motion:
        c orthogonal to the regressor's null space (relative to |c|)."""
        c = np.asarray(c, dtype=float)
        return bool(np.abs(self.null_space.T @ c).max(initial=0.0) <= tol * np.abs(c).max())

    def values(self, pi):
        """The base parameters' values for π."""
        pi = np.asarray(pi, dtype=float)
        return pi[list(self.independent)] + self.combination @ pi[list(self.dependent)]


def _number(c, digits):
    return "" if abs(c - 1) < 10 ** -digits else f"{c:.{digits}g} "


def random_states(rng, n, r, max_speed=5.0):
    """n valid states (n, 35): uniform attitudes and joint angles, speeds up to max_speed."""
    w = rng.uniform(-max_speed, max_speed, size=(n, NV))
    return np.array([initial_state(theta_Y=rng.uniform(-np.pi, np.pi), theta_P=rng.uniform(-np.pi, np.pi),
                                   R_S=random_rotation(rng), q=(0.0, 0.0, r), w_S=wi[:3], w_Y=wi[3], w_P=wi[4], r=r)
                     for wi in w])


def stacked_regressor(model, n_states=60, seed=0, max_speed=5.0):
    """Y stacked over n_states random states and accelerations ((5 n_states, 27))."""
    rng = np.random.default_rng(seed)
    X = random_states(rng, n_states, model.params.r, max_speed)
    A = rng.uniform(-max_speed, max_speed, size=(n_states, NV))
    return model.regressor(X, A).reshape(-1, NPI)


#: The entries of p that the regressor Y itself reads (the others enter through π alone): robots
#: that agree in these have the same stacked regressor and so the same base parameters.
REGRESSOR_ENTRIES = ("r", "n_Y", "n_P", "g", "slope")
_BASE_CACHE = {}


def base_parameters(model, n_states=60, seed=0, rtol=1e-9):
    """The base parameters of `model`'s robot: the columns of the stacked regressor kept in
    `PI_NAMES` order when they add to the rank of those kept before them (singular values of the
    column-scaled block above rtol times the largest), each other column expressed in the kept
    ones by least squares.  Known r, n_Y, n_P, g, slope enter through Y.  Kept per
    `REGRESSOR_ENTRIES` and arguments (its arrays read-only): a fit asks for them of its start
    robot and of its estimate, which share those entries."""
    p = model.params.as_array()
    key = (tuple(float(p[PARAMETER_NAMES.index(n)]) for n in REGRESSOR_ENTRIES), n_states, seed, rtol)
    if key not in _BASE_CACHE:
        if len(_BASE_CACHE) >= 64:
            _BASE_CACHE.clear()
        _BASE_CACHE[key] = _base_parameters(model, n_states, seed, rtol)
    return _BASE_CACHE[key]


def _base_parameters(model, n_states, seed, rtol):
    Y = stacked_regressor(model, n_states, seed)
    scale = np.linalg.norm(Y, axis=0)
    scale[scale == 0] = 1.0
    Ys = Y / scale
    s_all = np.linalg.svd(Ys, compute_uv=False)
    kept = []
    for j in range(NPI):
        s = np.linalg.svd(Ys[:, kept + [j]], compute_uv=False)
        if s[-1] > rtol * s_all[0]:
            kept.append(j)
    dependent = [j for j in range(NPI) if j not in kept]
    coeffs = np.linalg.lstsq(Ys[:, kept], Ys[:, dependent], rcond=None)[0] if dependent else np.zeros((len(kept), 0))
    # Y_dep = Y_kept B  =>  Y π = Y_kept (π_kept + B π_dep) in the unscaled parameters:
    combination = coeffs * scale[dependent][None, :] / scale[kept][:, None]
    _, _, Vt = np.linalg.svd(Ys)
    null = Vt[len(kept):].T / scale[:, None]     # Y v = 0  <=>  Ys (scale v) = 0
    null /= np.maximum(np.linalg.norm(null, axis=0), 1e-300)
    for a in (combination, s_all, null):
        a.flags.writeable = False
    return BaseParameters(len(kept), tuple(kept), tuple(dependent), combination, s_all, null)
