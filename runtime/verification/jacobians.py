"""Checks of the Jacobians against two independent sources.

* CasADi AD of the independent reference (`runtime.verification.reference`, a Lagrange–d'Alembert
  model in coordinates that imports neither derive/ nor the kernels): its accelerations at the
  state x ⊕ d, written here with CasADi's own exponential, differentiated in d and w at 0.
* Central differences of the kernels through `Model.retract`, Richardson-extrapolated (error
  O(h⁴) instead of O(h²)).

Each check takes the Jacobian under test as a function, so that a test can hand it a perturbed
one and see the check fail.
"""
import casadi as ca
import numpy as np

from ..model import Model
from ..params import Params
from ..state import NE, NU, NV
from .reference import _NU, _Q, _RP, _RS, _RY, STATE_DIM, ReferenceModel, _expm_series, _mat_rowmajor, _rot_x, _rot_y
from .sampling import random_inputs, random_state


def _rowmajor(R):
    return ca.reshape(R.T, 9, 1)


def reference_accel_jacobian(ref):
    """CasADi Function (x, u) -> (Ja 5x12, Jb 5x2) by AD of the reference's accelerations at
    x ⊕ d, u + w; ⊕ as runtime/group.py defines it (R_S Exp(⟦δξ⟧), R_Y rot_x(δθ_Y), R_P rot_y(δθ_P),
    q + (δq, 0), ν + δν)."""
    x0, u0 = ca.SX.sym("x", STATE_DIM), ca.SX.sym("u", 2)
    d, w = ca.SX.sym("d", 12), ca.SX.sym("w", 2)
    x = ca.vertcat(_rowmajor(_mat_rowmajor(x0[_RS]) @ _expm_series(d[0:3])),
                   _rowmajor(_mat_rowmajor(x0[_RY]) @ _rot_x(d[3])),
                   _rowmajor(_mat_rowmajor(x0[_RP]) @ _rot_y(d[4])),
                   x0[_Q] + ca.vertcat(d[5], d[6], 0), x0[_NU] + d[7:12])
    K, rhs = ref._f_kkt(x, u0 + w)
    sol = ca.solve(K, rhs)
    J, b0 = ref._f_conv(x)
    accel = ca.vertcat(J @ sol[:7] + b0, sol[3:5])
    at_zero = [ca.substitute(e, ca.vertcat(d, w), ca.DM.zeros(14))
               for e in (ca.jacobian(accel, d), ca.jacobian(accel, w))]
    return ca.Function("reference_accel_jacobian", [x0, u0], at_zero)


def richardson_accel_jacobian(model, x, u, h=2e-3):
    """(Ja, Jb) by central differences of model.accel along x ⊕ (±h e_k) and u ± h e_k,
    Richardson-extrapolated from steps h and h/2."""
    def central(f, n, step):
        return np.column_stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)])

    def extrapolated(f, n):
        return (4 * central(f, n, h / 2) - central(f, n, h)) / 3

    Ja = extrapolated(lambda d: model.accel(model.retract(x, d), u), NE)
    Jb = extrapolated(lambda w: model.accel(x, u + w), NU)
    return Ja, Jb


def _relative(ours, theirs):
    err = float(np.abs(ours - theirs).max())
    return err, err / max(float(np.abs(theirs).max()), 1e-300)


def accel_jacobian_checks(n_states=1000, seed=5, jacobian=None, params=None, n_difference=50):
    """Rows of `make verify`: accel_jacobian vs CasADi AD of the reference (n_states random
    states and inputs, ≤ 1e-10 relative) and vs Richardson central differences (n_difference
    of them, ≤ 1e-8 relative).  `jacobian(model, x, u)` is the function under test (default
    Model.accel_jacobian).  Returns (name, worst abs, worst rel, tolerance) rows for verify.py."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    jacobian = jacobian or (lambda m, x, u: m.accel_jacobian(x, u))
    rng = np.random.default_rng(seed)
    X = np.array([random_state(rng, params) for _ in range(n_states)])
    U = random_inputs(rng, n_states)
    Ja_ref, Jb_ref = reference_accel_jacobian(ReferenceModel(params.as_dict())).map(n_states)(X.T, U.T)
    Ja_ref = np.asarray(Ja_ref).reshape(NV, n_states, NE).transpose(1, 0, 2)
    Jb_ref = np.asarray(Jb_ref).reshape(NV, n_states, NU).transpose(1, 0, 2)
    worst_ad, worst_fd = (0.0, 0.0), (0.0, 0.0)
    for i in range(n_states):
        Ja, Jb = jacobian(model, X[i], U[i])
        worst_ad = max(worst_ad, _relative(np.hstack([Ja, Jb]), np.hstack([Ja_ref[i], Jb_ref[i]])), key=lambda e: e[1])
        if i < n_difference:
            fd = np.hstack(richardson_accel_jacobian(model, X[i], U[i]))
            worst_fd = max(worst_fd, _relative(np.hstack([Ja, Jb]), fd), key=lambda e: e[1])
    return [(f"accel_jacobian vs CasADi AD of the reference ({n_states} states)", *worst_ad, 1e-10),
            (f"accel_jacobian vs Richardson central differences ({min(n_difference, n_states)} states)",
             *worst_fd, 1e-8)]


def richardson_step_jacobian(model, x, u, dt, method, h=1e-3):
    """(F, G) by central differences of the C step through model.retract and model.local,
    Richardson-extrapolated from steps h and h/2."""
    y0 = model.step(x, u, dt, method)

    def error(d, w):
        return model.local(y0, model.step(model.retract(x, d), u + w, dt, method))

    def central(f, n, step):
        return np.column_stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)])

    def extrapolated(f, n):
        return (4 * central(f, n, h / 2) - central(f, n, h)) / 3

    return (extrapolated(lambda d: error(d, np.zeros(NU)), NE), extrapolated(lambda w: error(np.zeros(NE), w), NU))


STEP_METHODS = ("lie-euler", "rkmk4", "cf4")


def step_jacobian_checks(n_states=20, seed=7, jacobian=None, params=None, dt=0.01):
    """Rows of `make verify` for step_jacobian, per method:

    * against Richardson central differences of the C step through retract/local (≤ 1e-8
      relative; the Jacobian under test is the C kernel of every method, the differences are
      those of the C step itself through retract/local);
    * its derivative in dt at 0 against `linearize` (C accel_jacobian plus the kinematics):
      (F(h) − I)/h → A and G(h)/h → B as h → 0, Richardson-extrapolated from h = 1e-5 and 5e-6
      (≤ 1e-6 relative: truncation O(h²|A|²), rounding 1e-16/h).
    `jacobian(model, x, u, dt, method)` is the function under test (default Model.step_jacobian)."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    jacobian = jacobian or (lambda m, x, u, dt_, method: m.step_jacobian(x, u, dt_, method))
    rng = np.random.default_rng(seed)
    X = np.array([random_state(rng, params) for _ in range(n_states)])
    U = random_inputs(rng, n_states)
    rows = []
    for method in STEP_METHODS:
        worst_fd, worst_lin = (0.0, 0.0), (0.0, 0.0)
        for x, u in zip(X, U):
            F, G = jacobian(model, x, u, dt, method)
            worst_fd = max(worst_fd, _relative(np.hstack([F, G]), np.hstack(richardson_step_jacobian(model, x, u, dt, method))),
                           key=lambda e: e[1])
            derivative = [np.hstack([(Fh - np.eye(NE)) / h, Gh / h]) for h in (1e-5, 5e-6)
                          for Fh, Gh in [jacobian(model, x, u, h, method)]]
            A, B = model.linearize(x, u)
            worst_lin = max(worst_lin, _relative(2 * derivative[1] - derivative[0], np.hstack([A, B])),
                            key=lambda e: e[1])
        rows.append((f"step_jacobian {method} vs Richardson central differences of the C step ({n_states} states)",
                     *worst_fd, 1e-8))
        rows.append((f"step_jacobian {method}: d/dt at 0 vs linearize ({n_states} states)", *worst_lin, 1e-6))
    return rows


#: (h, h/2) per method for the variational check, and the order of the step Jacobian's local
#: error: Lie–Euler is first order (local error O(h²)), RKMK4 and CF4 fourth (O(h⁵)).
VARIATIONAL_STEPS = {"lie-euler": ((0.02, 0.01), 2), "rkmk4": ((0.05, 0.025), 5), "cf4": ((0.05, 0.025), 5)}


def variational_jacobian(model, x, u, h):
    """(Φ, Ψ) of the exact flow over time h from x with u held: the variational equations
    Φ' = A(x(t)) Φ, Ψ' = A(x(t)) Ψ + B(x(t)), Φ(0) = I, Ψ(0) = 0, with (A, B) = linearize (the
    continuous error dynamics in the same coordinates), integrated with x by solve_ivp (DOP853,
    rtol = atol = 1e-13)."""
    from scipy.integrate import solve_ivp

    from ..validation import project_state
    from .flow import state_derivative

    n = NE * (NE + NU)

    def rhs(_, y):
        xs = project_state(y[:STATE_DIM], model.params.r)
        A, B = model.linearize(xs, u)
        P = y[STATE_DIM:].reshape(NE, NE + NU)
        dP = A @ P
        dP[:, NE:] += B
        return np.concatenate([state_derivative(model, xs, u), dP.ravel()])

    y0 = np.concatenate([x, np.hstack([np.eye(NE), np.zeros((NE, NU))]).ravel()])
    sol = solve_ivp(rhs, (0.0, h), y0, method="DOP853", rtol=1e-13, atol=1e-13)
    P = sol.y[STATE_DIM:, -1].reshape(NE, NE + NU)
    assert P.size == n
    return P[:, :NE], P[:, NE:]


def variational_checks(n_states=3, seed=9, jacobian=None, params=None):
    """Rows of `make verify`: step_jacobian against the variational equations along the same step.
    The discrete map's Jacobian differs from the flow's by the method's local error, so the row
    measures the order of that difference from steps h and h/2 (Lie–Euler 2, RKMK4 and CF4 5) and
    passes when the measured order is at least the expected one minus 0.5 (worst over n_states).
    Returns (name, worst difference at h/2, worst |measured − expected| shortfall, tolerance) rows."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    jacobian = jacobian or (lambda m, x, u, dt_, method: m.step_jacobian(x, u, dt_, method))
    rng = np.random.default_rng(seed)
    X = np.array([random_state(rng, params, max_speed=2.0) for _ in range(n_states)])
    U = random_inputs(rng, n_states, max_torque=0.3)
    rows = []
    for method, ((h1, h2), order) in VARIATIONAL_STEPS.items():
        worst_order, worst_error = np.inf, 0.0
        for x, u in zip(X, U):
            errors = []
            for h in (h1, h2):
                F, G = jacobian(model, x, u, h, method)
                Phi, Psi = variational_jacobian(model, x, u, h)
                errors.append(float(np.abs(np.hstack([F, G]) - np.hstack([Phi, Psi])).max()))
            measured = np.log2(errors[0] / errors[1])
            worst_order, worst_error = min(worst_order, measured), max(worst_error, errors[1])
        shortfall = max(0.0, order - worst_order)
        rows.append((f"step_jacobian {method} vs the variational equations: local order {worst_order:.2f} "
                     f"(expected {order}; {n_states} states, h = {h1:g}, {h2:g} s)", worst_error, shortfall, 0.5))
    return rows
