"""Jacobians of one step of each method in the error coordinates, by CasADi's AD of the
exported steps (runtime.casadi_model, generated/casadi/):

    step(x ⊕ d, u + w) ⊖ step(x, u) = F d + G w + O(|d|² + |w|²),  F (12, 12), G (12, 2).

The derivative of the discrete map as the C implements it (the SX steps agree with the C steps
to round-off), every exponential, one-axis rotation and dexp⁻¹ differentiated exactly.  ⊖ enters
only through its derivative at y = step(x, u), where Log(R₀ᵀR) = vee(skew(R₀ᵀR)) + O(|ε|²) and a
joint angle difference is sin(θ − θ₀) + O(|ε|³): the first-order forms below give F and G exactly.
Lie–Euler has a C kernel of its own (sr_step_jacobian_lie_euler: the right Jacobian of SO(3), the
rolling kinematics and sr_accel_jacobian), which the tests compare with this AD; RKMK4 and CF4
are AD only for now.
"""
import functools

import numpy as np

from .state import NE, NU, NX
from .validation import choice

STEPS = {"lie-euler": "sr_step_lie_euler", "rkmk4": "sr_step_rkmk4", "cf4": "sr_step_cf4"}


def _casadi():
    try:
        import casadi
    except ImportError:  # pragma: no cover - casadi is in the dev and casadi extras
        raise ValueError("step_jacobian needs CasADi: pip install 'spherical-robot-kernels[casadi]'") from None
    return casadi


def _retract(ca, x, d):
    """x ⊕ d in SX (runtime.group's convention): R_S Exp(⟦δξ⟧), R_Y, R_P turned by δθ_Y, δθ_P, q + (δq, 0), ν + δν."""
    from .state import IDX_E_NU, IDX_E_Q, IDX_E_TH_P, IDX_E_TH_Y, IDX_E_XI_S, IDX_NU, IDX_Q, IDX_RP, IDX_RS, IDX_RY

    def rows(v):
        return ca.reshape(v, 3, 3).T

    def flat(M):
        return ca.reshape(M.T, 9, 1)

    xi = d[IDX_E_XI_S]
    t2 = ca.dot(xi, xi)
    small = t2 < 1e-8
    safe = ca.if_else(small, 1.0, t2)
    t = ca.sqrt(safe)
    A = ca.if_else(small, 1 - t2 / 6, ca.sin(t) / t)
    B = ca.if_else(small, 0.5 - t2 / 24, (1 - ca.cos(t)) / safe)
    W = ca.skew(xi)
    E = ca.SX.eye(3) + A * W + B * ca.mtimes(W, W)
    ty, tp = d[IDX_E_TH_Y], d[IDX_E_TH_P]
    E_Y = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, ca.cos(ty), -ca.sin(ty)), ca.horzcat(0, ca.sin(ty), ca.cos(ty)))
    E_P = ca.vertcat(ca.horzcat(ca.cos(tp), 0, ca.sin(tp)), ca.horzcat(0, 1, 0), ca.horzcat(-ca.sin(tp), 0, ca.cos(tp)))
    q = x[IDX_Q.start:IDX_Q.stop] + ca.vertcat(d[IDX_E_Q.start], d[IDX_E_Q.start + 1], 0)
    nu = x[IDX_NU.start:IDX_NU.stop] + d[IDX_E_NU.start:IDX_E_NU.stop]
    return ca.vertcat(flat(ca.mtimes(rows(x[IDX_RS.start:IDX_RS.stop]), E)),
                      flat(ca.mtimes(rows(x[IDX_RY.start:IDX_RY.stop]), E_Y)),
                      flat(ca.mtimes(rows(x[IDX_RP.start:IDX_RP.stop]), E_P)), q, nu)


def _local_first_order(ca, y0, y):
    """y ⊖ y0 to first order at y = y0 (exact in value and first derivative there)."""
    from .state import IDX_NU, IDX_Q, IDX_RP, IDX_RS, IDX_RY
    R0, R = (ca.reshape(v[IDX_RS.start:IDX_RS.stop], 3, 3).T for v in (y0, y))
    S = ca.mtimes(R0.T, R)
    xi = 0.5 * ca.vertcat(S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1])
    ry, rp = IDX_RY.start, IDX_RP.start
    dth_y = y[ry + 7] * y0[ry + 4] - y[ry + 4] * y0[ry + 7]      # sin(θ − θ₀) from (c, s) = (R[4], R[7])
    dth_p = y[rp + 2] * y0[rp + 0] - y[rp + 0] * y0[rp + 2]      # from (c, s) = (R[0], R[2])
    return ca.vertcat(xi, dth_y, dth_p, y[IDX_Q.start:IDX_Q.start + 2] - y0[IDX_Q.start:IDX_Q.start + 2],
                      y[IDX_NU.start:IDX_NU.stop] - y0[IDX_NU.start:IDX_NU.stop])


@functools.lru_cache(maxsize=None)
def jacobian_function(method):
    """CasADi Function (x, u, dt, p) -> (F, G) of `method`'s step."""
    from . import casadi_model
    ca = _casadi()
    step = casadi_model.load(STEPS[method])
    x, u, dt = ca.SX.sym("x", NX), ca.SX.sym("u", NU), ca.SX.sym("dt")
    p = ca.SX.sym("p", step.size1_in(3))
    d, w = ca.SX.sym("d", NE), ca.SX.sym("w", NU)
    y0 = step(x, u, dt, p)
    e = _local_first_order(ca, y0, step(_retract(ca, x, d), u + w, dt, p))
    at_zero = [ca.substitute(J, ca.vertcat(d, w), ca.DM.zeros(NE + NU)) for J in (ca.jacobian(e, d), ca.jacobian(e, w))]
    return ca.Function(f"{STEPS[method]}_jacobian", [x, u, dt, p], at_zero, ["x", "u", "dt", "p"], ["F", "G"])


class StepJacobianMethods:
    """`step_jacobian` of `Model` (which provides params, _model, _check, _state_and_input, _dt)."""

    def step_jacobian(self, x, u=None, dt=0.01, method="lie-euler"):
        """(F, G), (12, 12) and (12, 2): step(x ⊕ d, u + w) ⊖ step(x, u) = F d + G w + O(2), the
        exact derivative of one step of `method` as implemented.  Batches: x (B, 35), u (B, 2)
        or None give (B, 12, 12), (B, 12, 2).  All three in C (sr_step_jacobian, batches by
        sr_step_jacobian_batch; c/sr_jacobians.c, c/sr_step_jacobians.c); `casadi_step_jacobian`
        is CasADi's AD of the exported steps, the independent check."""
        choice(method, "method", STEPS, "integrator")
        x, u = self._state_and_input(x, u)
        dt = self._dt(dt)
        return self._c_step_jacobian(x, u, dt, method)

    def _c_step_jacobian(self, x, u, dt, method):
        from bindings._sr import ffi, lib
        from bindings.buffers import pointer
        code = {"lie-euler": lib.SR_LIE_EULER, "rkmk4": lib.SR_RKMK4, "cf4": lib.SR_CF4}[method]
        lead = x.shape[:-1]
        F, G = np.empty(lead + (NE, NE)), np.empty(lead + (NE, NU))
        if x.ndim == 1:
            self._check("x", lib.sr_step_jacobian(self._model, code, pointer(x), pointer(u), dt, pointer(F), pointer(G)))
            return F, G
        failed = ffi.new("long *")
        status = lib.sr_step_jacobian_batch(self._model, code, x.shape[0], pointer(x), pointer(u), dt, pointer(F), pointer(G), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 else "x", status)
        return F, G

    def casadi_step_jacobian(self, x, u, dt, method):
        """(F, G) by CasADi's AD of the exported step of `method` (any of the three; arguments as
        step_jacobian's, already checked)."""
        p = self.params.as_array()
        f = jacobian_function(method)
        if x.ndim == 1:
            F, G = f(x, u, dt, p)
            return np.array(F), np.array(G)
        n = x.shape[0]
        F, G = f.map(n)(x.T, u.T, dt, p)
        return (np.asarray(F).reshape(NE, n, NE).transpose(1, 0, 2),
                np.asarray(G).reshape(NE, n, NU).transpose(1, 0, 2))
