"""The model as CasADi Functions: accel and one step of each method on the group.

For CasADi and acados users: the same derivation as the C kernels (M and f of
derive/dynamics.py, converted expression by expression to CasADi SX, ν̇ = M⁻¹ f), and
the steppers of c/src/sr_steppers.c written in SX (Lie–Euler, RKMK4, CF4 on
SO(3) × SO(2) × SO(2) × ℝ³ × ℝ⁵, with the same Rodrigues coefficients, one-axis
rotations, dexp⁻¹ and tableaux).  Every Function takes the parameters as an input
vector p in SR_P_* order (derive.parameters.PARAMETERS), so one file serves any robot:

    sr_accel(x[35], u[2], p) -> nu_dot[5]
    sr_step_lie_euler / sr_step_rkmk4 / sr_step_cf4 (x[35], u[2], dt, p) -> x_next[35]

`derive.codegen.emit.write` serializes them into generated/casadi/ (casadi.Function.load
reads them; runtime.casadi_model.load is the helper).  They are smooth in x, u and p, so
CasADi's AD gives their Jacobians; the branches of the small-angle series are taken with
`if_else` on a guarded argument, so that neither branch produces NaN or ∞ in value or
derivative.
"""
import casadi as ca
import sympy as sp

from . import dynamics
from . import parameters as P
from . import robot as R
from . import state as S

# The series thresholds of c/src/sr_so3.h (SR_SERIES_T2) and of sr_internal_dexpinv.
SERIES_T2 = 0.0625


def sympy_to_casadi(exprs, values):
    """The SymPy expressions `exprs` as CasADi SX, with `values` = {symbol: SX}.

    Polynomials and rational functions only (what M and f are); common subexpressions are
    taken out first (sympy.cse), so the SX graph has the size of the C kernel."""
    replacements, reduced = sp.cse(list(exprs), optimizations="basic")
    env = dict(values)

    def convert(e):
        if e in env:
            return env[e]
        if e.is_Integer or e.is_Rational or e.is_Float:
            return ca.SX(float(e))
        args = [convert(a) for a in e.args]
        if e.is_Add:
            out = args[0]
            for a in args[1:]:
                out = out + a
            return out
        if e.is_Mul:
            out = args[0]
            for a in args[1:]:
                out = out * a
            return out
        if e.is_Pow and e.exp.is_Integer:
            n = int(e.exp)
            return args[0] ** n if n > 0 else 1 / args[0] ** (-n)
        if e.func in (sp.sin, sp.cos):
            return {sp.sin: ca.sin, sp.cos: ca.cos}[e.func](args[0])
        raise ValueError(f"sympy_to_casadi: cannot convert {e.func.__name__} ({e})")

    for symbol, expr in replacements:
        env[symbol] = convert(expr)
    return [convert(e) for e in reduced]


def symbol_values(x, u, p):
    """Every symbol of the general robot's derivation as an SX entry of x, u, p (the layouts of
    derive/state.py and derive/parameters.py), its constants (derive.robot.general_constants) as
    their expressions in p."""
    values = {s: x[i] for s, i in S.STATE_LAYOUT.items()}
    values.update({s: u[i] for s, i in S.INPUT_LAYOUT.items()})
    params = {s: p[i] for i, s in enumerate(P.PARAMETERS)}
    constants = R.general_constants()
    converted = sympy_to_casadi([expr for _, expr in constants], params)
    values.update({c: value for (c, _), value in zip(constants, converted)})
    return values


def accel_function():
    """sr_accel(x, u, p) = M⁻¹ f, M and f as derived for the general robot (derive.dynamics.inertia, rhs)."""
    x, u, p = ca.SX.sym("x", S.NX), ca.SX.sym("u", S.NU), ca.SX.sym("p", len(P.PARAMETERS))
    M, f = dynamics.inertia(R.GENERAL), dynamics.rhs(R.GENERAL)
    n = S.NV
    converted = sympy_to_casadi(list(M) + list(f), symbol_values(x, u, p))
    M_sx = ca.reshape(ca.vertcat(*converted[:n * n]), n, n).T
    f_sx = ca.vertcat(*converted[n * n:])
    return ca.Function("sr_accel", [x, u, p], [cholesky_solve(M_sx, f_sx)], ["x", "u", "p"], ["nu_dot"])


def cholesky_solve(M, f):
    """M⁻¹ f for the symmetric positive definite M by Cholesky, M = L Lᵀ: the factorisation the C
    uses (c/src/sr_jacobians.c), better conditioned here than the symbolic QR of ca.solve."""
    n = M.shape[0]
    L = [[None] * n for _ in range(n)]
    for j in range(n):
        d = M[j, j] - sum((L[j][k] ** 2 for k in range(j)), ca.SX(0))
        L[j][j] = ca.sqrt(d)
        for i in range(j + 1, n):
            L[i][j] = (M[i, j] - sum((L[i][k] * L[j][k] for k in range(j)), ca.SX(0))) / L[j][j]
    y = []
    for i in range(n):
        y.append((f[i] - sum((L[i][k] * y[k] for k in range(i)), ca.SX(0))) / L[i][i])
    z = [None] * n
    for i in reversed(range(n)):
        z[i] = (y[i] - sum((L[k][i] * z[k] for k in range(i + 1, n)), ca.SX(0))) / L[i][i]
    return ca.vertcat(*z)


# ---- the group and its steppers (c/src/sr_steppers.c, same names) ----------------------------------

def _hat(w):
    return ca.vertcat(ca.horzcat(0, -w[2], w[1]), ca.horzcat(w[2], 0, -w[0]), ca.horzcat(-w[1], w[0], 0))


def _series(t2, ratios, lead):
    """lead (1 - t2/ratios[0] (1 - t2/ratios[1] (...))): the Horner form of c/src/sr_so3.h."""
    out = 1
    for d in reversed(ratios):
        out = 1 - t2 * (1.0 / d) * out
    return lead * out


def so3_exp(w):
    """Exp([[w]]) = I + A [[w]] + B [[w]]², A = sin t/t and B = (1 - cos t)/t² (series below t² = 1/16)."""
    t2 = ca.dot(w, w)
    small = t2 < SERIES_T2
    safe = ca.if_else(small, 1.0, t2)          # the closed form never sees t = 0
    t = ca.sqrt(safe)
    A = ca.if_else(small, _series(t2, (6, 20, 42, 72, 110), 1.0), ca.sin(t) / t)
    B = ca.if_else(small, _series(t2, (12, 30, 56, 90, 132), 0.5), 2 * ca.sin(t / 2) ** 2 / safe)
    W = _hat(w)
    return ca.SX.eye(3) + A * W + B * ca.mtimes(W, W)


def _rows(v):
    return ca.reshape(v, 3, 3).T                # x stores matrices row-major


def _flat(M):
    return ca.reshape(M.T, 9, 1)


def act(x, th):
    """x . exp(th): R_S Exp([[th_S]]), the one-axis rotations by their angles, q + th_q, nu + th_nu."""
    R_S = ca.mtimes(_rows(x[0:9]), so3_exp(th[0:3]))
    cy, sy = x[S.OFFSET_RY + 4], x[S.OFFSET_RY + 7]
    cy, sy = cy * ca.cos(th[3]) - sy * ca.sin(th[3]), sy * ca.cos(th[3]) + cy * ca.sin(th[3])
    cp, sp_ = x[S.OFFSET_RP + 0], x[S.OFFSET_RP + 2]
    cp, sp_ = cp * ca.cos(th[4]) - sp_ * ca.sin(th[4]), sp_ * ca.cos(th[4]) + cp * ca.sin(th[4])
    R_Y = ca.vertcat(1, 0, 0, 0, cy, -sy, 0, sy, cy)
    R_P = ca.vertcat(cp, 0, sp_, 0, 1, 0, -sp_, 0, cp)
    return ca.vertcat(_flat(R_S), R_Y, R_P, x[S.OFFSET_Q:S.OFFSET_W] + th[5:8], x[S.OFFSET_W:] + th[8:13])


def vector_field(accel, x, u, p):
    """f(x) in the Lie algebra: (w_S, w_Y, w_P, q' = r R_S (w_S × γ) with q'_z = 0, ν̇)."""
    R = _rows(x[0:9])
    w, gam = x[S.OFFSET_W:S.OFFSET_W + 3], x[6:9]
    qdot = p[P.PARAMETERS.index(P.r)] * ca.mtimes(R, ca.cross(w, gam))
    return ca.vertcat(w, x[S.OFFSET_W + 3], x[S.OFFSET_W + 4], qdot[0], qdot[1], 0, accel(x, u, p))


def dexpinv(th, k):
    """dexp⁻¹_{-θ}(k) on the so(3) block: k + ½ θ×k + c(|θ|) θ×(θ×k); the other blocks copied."""
    t, w = th[0:3], k[0:3]
    t2 = ca.dot(t, t)
    small = t2 < SERIES_T2
    safe = ca.if_else(small, 1.0, t2)
    half = 0.5 * ca.sqrt(safe)
    t4 = t2 * t2
    series = ((1.0 / 12 + t2 * (1.0 / 720)) + t4 * (1.0 / 30240 + t2 * (1.0 / 1209600))
              + (t4 * t4) * (1.0 / 47900160 + t2 * (691.0 / 1307674368000.0)))   # dexpinv_series of c/src/sr_so3.h
    c = ca.if_else(small, series, (1 - half * ca.cos(half) / ca.sin(half)) / safe)
    a = ca.cross(t, w)
    return ca.vertcat(w + 0.5 * a + c * ca.cross(t, a), k[3:])


def lie_euler(accel, x, u, h, p):
    return act(x, h * vector_field(accel, x, u, p))


def rkmk4(accel, x, u, h, p):
    K = [vector_field(accel, x, u, p)]
    for a in (0.5, 0.5, 1.0):
        th = a * h * K[-1]
        K.append(dexpinv(th, vector_field(accel, act(x, th), u, p)))
    return act(x, h * (K[0] + 2 * K[1] + 2 * K[2] + K[3]) / 6)


def cf4(accel, x, u, h, p):
    F1 = vector_field(accel, x, u, p)
    Y2 = act(x, 0.5 * h * F1)
    F2 = vector_field(accel, Y2, u, p)
    F3 = vector_field(accel, act(x, 0.5 * h * F2), u, p)
    F4 = vector_field(accel, act(Y2, h * (F3 - 0.5 * F1)), u, p)
    first = act(x, h / 12 * (3 * F1 + 2 * F2 + 2 * F3 - F4))
    return act(first, h / 12 * (-F1 + 2 * F2 + 2 * F3 + 3 * F4))


STEPPERS = {"lie_euler": lie_euler, "rkmk4": rkmk4, "cf4": cf4}


def step_function(accel, method):
    """sr_step_<method>(x, u, dt, p) -> x_next, one step of c/src/sr_steppers.c's method."""
    x, u, p = ca.SX.sym("x", S.NX), ca.SX.sym("u", S.NU), ca.SX.sym("p", len(P.PARAMETERS))
    dt = ca.SX.sym("dt")
    return ca.Function(f"sr_step_{method}", [x, u, dt, p], [STEPPERS[method](accel, x, u, dt, p)],
                       ["x", "u", "dt", "p"], ["x_next"])


def functions():
    """Every exported Function, by the file name it is written to (generated/casadi/<name>.casadi)."""
    accel = accel_function()
    out = {"sr_accel": accel}
    for method in STEPPERS:
        out[f"sr_step_{method}"] = step_function(accel, method)
    return out
