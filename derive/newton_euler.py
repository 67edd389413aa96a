"""The right-hand side f evaluated body by body: a cheaper form of `dynamics.rhs`, proven equal to it.

`dynamics.rhs` is the truth: f obtained from ℓ and ℓ_c through the
non-holonomic Euler–Poincaré equations (eqs. 78, 84, 85).  Expanded into
monomials it costs about 345 flops.  The same vector, written as d'Alembert's
principle for the three bodies about the shell centre O (Newton–Euler about a
moving point), costs 169 (104 in the yoke frame, see `derive.yoke_frame`),
because the angular velocities and accelerations of the bodies are kept as
named intermediates (`Program`).  `check_equal_to_rhs` proves the two forms
equal modulo the unit-norm identities; `make generate` runs that proof
before it emits this form.

Body quantities about O, in the frame where the yoke's attitude is R_Y:

    shell      mass at O (all of m_R, the rolling mass), inertia j_S I, angular velocity ω_S
    yoke       inertia I_Y = R_Y J_Y R_Yᵀ with J_Y = tr(Ĵ_Y) I − Ĵ_Y, angular velocity ω_y = ω_S + ω_Y e_x
    pendulum   first moment h = m_P ξ (ξ = R_Y R_P c̄_P), inertia about O
               I_O = j_P (I − a aᵀ) (the standard tensor of Ĵ_P) with a = R_Y R_P e_z,
               angular velocity ω_p = ω_y + ω_P e, e = R_Y e_y (eq. 29)

The acceleration of O is r ω̇_S × γ (no velocity-dependent part: q̈ = r R_S ω̇_S × e_z
since Ω_S ω_S = 0), and gravity enters as an upward acceleration g γ of O.
With ν̇ = 0 the inertial forces and torques about O reduce to their bias
parts, and f = (applied generalized forces) − (projections of the bias onto
the partial velocities ∂v_O/∂ν = r(· × γ), ∂ω_y/∂ν = (I, e_x, 0),
∂ω_p/∂ν = (I, e_x, e)).
"""
import sympy as sp

from . import dynamics as D
from . import parameters as P
from . import robot as R
from . import state as S

_e_x = sp.Matrix([1, 0, 0])


class Program:
    """A straight-line program: named intermediate quantities in order of definition.

    Kept as symbols, the body quantities (ω_y, α_P, τ_Y, ...) are computed
    once and shared, which CSE alone does not recover once SymPy has
    distributed the constants into nested vector expressions (120 flops for
    f in the yoke frame instead of 104).  `inline` substitutes them back.
    """

    def __init__(self):
        self.definitions = []      # (symbol, expression), each using only earlier symbols

    def let(self, name, value):
        """A symbol (or a vector of symbols) standing for value; atoms and zeros are used as they are."""
        if isinstance(value, sp.MatrixBase):
            return sp.Matrix([self.let(f"{name}_{'xyz'[i]}", v) for i, v in enumerate(value)])
        value = sp.sympify(value)
        if value.is_Atom:
            return value
        symbol = sp.Symbol(name, real=True)
        self.definitions.append((symbol, value))
        return symbol

    def inline(self, exprs):
        """exprs with every defined symbol replaced by its definition."""
        exprs = sp.Matrix(exprs)
        for symbol, value in reversed(self.definitions):
            exprs = exprs.xreplace({symbol: value})
        return exprs


def joint_axis(R_Y):
    """e = R_Y e_y: the pendulum's rotation axis."""
    return R_Y * sp.Matrix([0, 1, 0])


def shaft(R_Y):
    """a = R_Y R_P e_z: the pendulum's shaft direction; its centre of mass is ξ = c̄_P,z a = −(l/2) a."""
    return R_Y * S.R_P * P.e_z()


def yoke_inertia(R_Y, x):
    """I_Y x = R_Y J_Y R_Yᵀ x, with J_Y = tr(Ĵ_Y) I − Ĵ_Y the standard tensor of Ĵ_Y (Section 2.3)."""
    J_Y = P.Jhat_Y().trace() * sp.eye(3) - P.Jhat_Y()
    return R_Y * (J_Y * (R_Y.T * x))


def program(R_Y=S.R_Y):
    """f body by body as a straight-line program; returns (program, f).

    Vectors are in the frame in which the yoke's attitude is R_Y: the shell
    frame (the default), or the yoke frame with R_Y = I (`derive.yoke_frame`).
    """
    p = Program()
    w, e, a = S.w_S, joint_axis(R_Y), p.let("a", shaft(R_Y))
    w_y = p.let("w_y", w + S.w_Y * _e_x)                                   # yoke angular velocity
    w_p = p.let("w_p", w_y + S.w_P * e)                                    # pendulum angular velocity (eq. 29)
    # Bias angular accelerations (ν̇ = 0): α_Y = ω_Y ω × e_x, α_P = ω × (ω_Y e_x + ω_P e) + ω_Y ω_P e_x × e.
    alpha_P = p.let("alpha_P", w.cross(S.w_Y * _e_x + S.w_P * e) + S.w_Y * S.w_P * _e_x.cross(e))
    # Yoke: I_Y α_Y + ω_y × I_Y ω_y.
    tau_Y = p.let("tau_Y", yoke_inertia(R_Y, S.w_Y * w.cross(_e_x)) + w_y.cross(yoke_inertia(R_Y, w_y)))
    # Pendulum about O, I_O = j_P (I − a aᵀ), first moment h = m_P ξ = κ a:
    # I_O α_P + ω_p × I_O ω_p + h × g γ, with ω_p × I_O ω_p = −j_P (a·ω_p) ω_p × a.
    kappa = P.m_P * P.cbar_P()[2]
    a_alpha, a_w = p.let("a_alpha", a.dot(alpha_P)), p.let("a_w", a.dot(w_p))
    w_x_a = p.let("w_x_a", w_p.cross(a))
    tau_P = p.let("tau_P", P.j_P * (alpha_P - a_alpha * a) - P.j_P * a_w * w_x_a + P.g * kappa * a.cross(S.gamma))
    # Pendulum bias force α_P × h + ω_p × (ω_p × h) = κ b, with b = α_P × a + ω_p × (ω_p × a) the bias
    # acceleration of the shaft point a (κ stays outside, where it joins r in one per-model constant);
    # the rolling mass's m_R g γ is parallel to γ and drops.
    b = p.let("b", alpha_P.cross(a) + w_p.cross(w_x_a))
    T = p.let("T", tau_Y + tau_P)
    shell = -P.k_S * w - (P.r * kappa * S.gamma.cross(b) + T)
    yoke = S.u_Y - P.k_Y * S.w_Y - _e_x.dot(T)
    pendulum = S.u_P - P.k_P * S.w_P - e.dot(tau_P)
    return p, sp.Matrix([*shell, yoke, pendulum])


def rhs():
    """f of M ν̇ = f, body by body, as one expression (equal to `dynamics.rhs()` on valid states)."""
    p, f = program()
    return p.inline(f)


def check_equal_to_rhs():
    """Residuals rhs() − dynamics.rhs() reduced modulo the unit-norm identities: all zero."""
    return [D.on_manifold(sp.expand(x - y)) for x, y in zip(rhs(), D.rhs())]


def general_program():
    """f of the general robot (derive.robot.GENERAL) body by body, in the shell frame:
    (program, f).  The same d'Alembert principle about O as `program`, with what the general robot
    adds: first moments h = R c m and tensors about O of any shape (I = R J_O Rᵀ with
    J_O = tr(Ĵ_O) I − Ĵ_O), gravity G = R_Sᵀg⃗ = −(g_x χ + g_z γ) on a slope (as an acceleration −G
    of O: moments −h × G, and the whole mass's −m_R G through the rolling constraint), and the two
    rotors (axial inertia j e eᵀ about their axes e_x on the shell and e = R_Y e_y on the yoke,
    angular velocities ω + n_Y ω_Y e_x and ω_y + n_P ω_P e, partial velocities n_Y e_x, n_P e)."""
    rb = R.GENERAL
    p = Program()
    w, e = S.w_S, joint_axis(S.R_Y)
    G = p.let("G", -(rb.g_x * S.chi + rb.g_z * S.gamma))
    w_y = p.let("w_y", w + S.w_Y * _e_x)
    w_p = p.let("w_p", w_y + S.w_P * e)
    alpha_Y = p.let("alpha_Y", S.w_Y * w.cross(_e_x))
    alpha_P = p.let("alpha_P", alpha_Y + S.w_P * w_y.cross(e))

    def about_O(rotation, Jhat):
        """R J_O Rᵀ: the standard tensor about O of a non-standard one, in the shell frame."""
        Jhat = sp.Matrix(Jhat)
        return rotation * (Jhat.trace() * sp.eye(3) - Jhat) * rotation.T

    R_YP = S.R_Y * S.R_P
    I_Y, I_P = about_O(S.R_Y, rb.Jhat_Y), about_O(R_YP, rb.Jhat_P)
    h_Y, h_P = p.let("hY", S.R_Y * sp.Matrix(rb.h_Y)), p.let("hP", R_YP * sp.Matrix(rb.h_P))
    tau_Y = p.let("tau_Y", I_Y * alpha_Y + w_y.cross(I_Y * w_y) - h_Y.cross(G))
    tau_P = p.let("tau_P", I_P * alpha_P + w_p.cross(I_P * w_p) - h_P.cross(G))
    w_rY, w_rP = w + rb.n_Y * S.w_Y * _e_x, w_y + rb.n_P * S.w_P * e
    a_rY, a_rP = rb.n_Y * S.w_Y * w.cross(_e_x), alpha_Y + rb.n_P * S.w_P * w_y.cross(e)
    s_rY = p.let("s_rY", rb.j_mY * (_e_x.dot(a_rY) * _e_x + _e_x.dot(w_rY) * w_rY.cross(_e_x)))
    s_rP = p.let("s_rP", rb.j_mP * (e.dot(a_rP) * e + e.dot(w_rP) * w_rP.cross(e)))
    F = p.let("F", alpha_Y.cross(h_Y) + w_y.cross(w_y.cross(h_Y)) + alpha_P.cross(h_P)
              + w_p.cross(w_p.cross(h_P)) - rb.m_R * G)
    T = p.let("T", tau_Y + tau_P + s_rY + s_rP)
    shell = -rb.k_S * w - (T + rb.r * S.gamma.cross(F))
    yoke = S.u_Y - rb.k_Y * S.w_Y - _e_x.dot(tau_Y + tau_P + s_rP) - rb.n_Y * _e_x.dot(s_rY)
    pendulum = S.u_P - rb.k_P * S.w_P - e.dot(tau_P) - rb.n_P * e.dot(s_rP)
    return p, sp.Matrix([*shell, yoke, pendulum])


def check_general_equal_to_rhs():
    """Residuals of `general_program` − dynamics.rhs(GENERAL), reduced modulo the unit-norm
    identities (|γ| = |χ| = 1, γ·χ = 0, cos² + sin² = 1): all zero."""
    p, f = general_program()
    return [D.on_manifold(sp.expand(x - y)) for x, y in zip(p.inline(f), D.rhs(R.GENERAL))]
