"""The right-hand side f evaluated body by body: a cheaper form of `dynamics.rhs`, proven equal to it.

`dynamics.rhs` is the truth: f obtained from ℓ and ℓ_c through the
non-holonomic Euler–Poincaré equations (eqs. 78, 84, 85).  Expanded into
monomials it costs about 345 flops.  The same vector, written as d'Alembert's
principle for the three bodies about the shell centre O (Newton–Euler about a
moving point), costs about 200, because it keeps the angular velocities and
accelerations of the bodies as intermediate vectors.  `check_equal_to_rhs`
proves the two forms equal modulo the unit-norm identities; `make generate`
runs that proof before it emits this form.

All vectors are in the shell frame.  Body quantities about O:

    shell      mass at O (all of m_R, the rolling mass), inertia j_S I, angular velocity ω_S
    yoke       inertia I_Y = R_Y J_Y R_Yᵀ with J_Y = tr(Ĵ_Y) I − Ĵ_Y, angular velocity ω_S + ω_Y e_x
    pendulum   first moment h = m_P ξ (ξ = R_Y R_P c̄_P), inertia about O
               I_O = j_P (I − a aᵀ) (the standard tensor of Ĵ_P) with a = R_Y R_P e_z,
               angular velocity ω_p = ω_S + ω_Y e_x + ω_P e, e = R_Y e_y (eq. 29)

The acceleration of O is r ω̇_S × γ (no velocity-dependent part: q̈ = r R_S ω̇_S × e_z
since Ω_S ω_S = 0), and gravity enters as an upward acceleration g γ of O.
With ν̇ = 0 the inertial forces and torques about O reduce to their bias
parts, and f = (applied generalized forces) − (projections of the bias onto
the partial velocities ∂v_O/∂ν = r(· × γ), ∂ω_Y/∂ν = (I, e_x, 0),
∂ω_p/∂ν = (I, e_x, e)).
"""
import sympy as sp

from . import dynamics as D
from . import lagrangian as L
from . import parameters as P
from . import state as S

_e_x = sp.Matrix([1, 0, 0])


def joint_axis():
    """e = R_Y e_y: the pendulum's rotation axis in the shell frame."""
    return S.R_Y * sp.Matrix([0, 1, 0])


def shaft():
    """a = R_Y R_P e_z: the pendulum's shaft direction; ξ = −(l/2) a."""
    return S.R_Y * S.R_P * P.e_z()


def joint_velocity():
    """ω_Y e_x + ω_P e: the pendulum's angular velocity relative to the shell."""
    return S.w_Y * _e_x + S.w_P * joint_axis()


def yoke_inertia(x):
    """I_Y x = R_Y J_Y R_Yᵀ x, with J_Y = tr(Ĵ_Y) I − Ĵ_Y the standard tensor of Ĵ_Y (Section 2.3)."""
    J_Y = P.Jhat_Y().trace() * sp.eye(3) - P.Jhat_Y()
    return S.R_Y * (J_Y * (S.R_Y.T * x))


def yoke_bias_torque():
    """I_Y α_Y + ω_y × I_Y ω_y at ν̇ = 0, where α_Y = ω_Y ω_S × e_x."""
    w_y = S.w_S + S.w_Y * _e_x
    return yoke_inertia(S.w_Y * S.w_S.cross(_e_x)) + w_y.cross(yoke_inertia(w_y))


def pendulum_bias_acceleration():
    """α_P at ν̇ = 0: ω_S × (ω_Y e_x + ω_P e) + ω_Y ω_P e_x × e."""
    return S.w_S.cross(joint_velocity()) + S.w_Y * S.w_P * _e_x.cross(joint_axis())


def pendulum_bias_torque():
    """I_O α_P + ω_p × I_O ω_p + h × g γ at ν̇ = 0, with I_O = j_P(I − a aᵀ).

    ω_p × I_O ω_p = −j_P (a·ω_p) ω_p × a, since ω_p × ω_p = 0.
    """
    a, alpha = shaft(), pendulum_bias_acceleration()
    w_p = S.w_S + joint_velocity()
    h = P.m_P * L.pendulum_centre()
    return P.j_P * (alpha - a * a.dot(alpha)) - P.j_P * a.dot(w_p) * w_p.cross(a) + P.g * h.cross(S.gamma)


def pendulum_bias_force():
    """α_P × h + ω_p × (ω_p × h): the pendulum's bias force (the rolling mass's m_R g γ is parallel to γ and drops)."""
    alpha = pendulum_bias_acceleration()
    w_p = S.w_S + joint_velocity()
    h = P.m_P * L.pendulum_centre()
    return alpha.cross(h) + w_p.cross(w_p.cross(h))


def rhs():
    """f of M ν̇ = f, body by body (equal to `dynamics.rhs()` on valid states)."""
    tau_Y, tau_P = yoke_bias_torque(), pendulum_bias_torque()
    shell = -P.k_S * S.w_S - (P.r * S.gamma.cross(pendulum_bias_force()) + tau_Y + tau_P)
    yoke = S.u_Y - P.k_Y * S.w_Y - _e_x.dot(tau_Y + tau_P)
    pendulum = S.u_P - P.k_P * S.w_P - joint_axis().dot(tau_P)
    return sp.Matrix([*shell, yoke, pendulum])


def check_equal_to_rhs():
    """Residuals rhs() − dynamics.rhs() reduced modulo the unit-norm identities: all zero."""
    return [D.on_manifold(sp.expand(x - y)) for x, y in zip(rhs(), D.rhs())]
