"""The reduced Lagrangian ℓ (eq. 36), the reduced-constrained Lagrangian ℓ_c (eq. 41) and the energy.

Printed-equation errata corrected here (see docs/errata.md): eq. (31) and
(34) carry ½ m_Y and Ĵ_R where the derivation gives ½ m_P and Ĵ_S, and
eq. (34) writes ‖Ṙ_Sᵀ q̇‖ for ‖R_Sᵀ q̇‖.  The Lagrangian below is the one
that eqs. (19)-(32) define, term by term.
"""
import sympy as sp

from . import parameters as P
from . import state as S


def trace_quadratic(A, J):
    """½ tr(A J Aᵀ): the rotational kinetic energy of eq. (10)."""
    return (A * J * A.T).trace() / 2


def pendulum_angular_velocity():
    """Ω_S + Ω_Y + R_Y Ω_P R_Yᵀ: the pendulum's angular velocity in the shell frame (eq. 29)."""
    return S.Omega_S + S.Omega_Y + S.R_Y * S.Omega_P * S.R_Y.T


def pendulum_centre():
    """ξ = R_Y R_P c̄_P: the pendulum's centre of mass in the shell frame (Section 2.6)."""
    return S.R_Y * S.R_P * P.cbar_P()


def kinetic_energy(v):
    """K_S + K_Y + K_P of eqs. (20), (25), (31), written with v = R_Sᵀ q̇."""
    W_P = pendulum_angular_velocity()
    translational = P.m_R * (v.T * v)[0] / 2
    shell = trace_quadratic(S.Omega_S, P.Jhat_S())
    yoke = trace_quadratic(S.Omega_S + S.Omega_Y, S.R_Y * P.Jhat_Y() * S.R_Y.T)
    pendulum_coupling = P.m_P * (v.T * W_P * pendulum_centre())[0]
    pendulum = trace_quadratic(W_P, S.R_Y * S.R_P * P.Jhat_P() * S.R_P.T * S.R_Y.T)
    return translational + shell + yoke + pendulum_coupling + pendulum


def potential_energy():
    """U_P of eq. (32) without its constant m_P g r: m_P g γᵀ R_Y R_P c̄_P."""
    return P.m_P * P.g * (S.gamma.T * pendulum_centre())[0]


def reduced_lagrangian():
    """ℓ(γ, R_Y, R_P, Ω_S, Ω_Y, Ω_P, v) of eq. (36), constant dropped."""
    return kinetic_energy(S.v) - potential_energy()


def rolling_velocity():
    """The non-holonomic constraint in the shell frame, v = r Ω_S γ (eq. 38)."""
    return P.r * S.Omega_S * S.gamma


def constrain(expr):
    """Substitute v = r Ω_S γ (eq. 40)."""
    return expr.subs(dict(zip(S.v, rolling_velocity())), simultaneous=True)


def constrained_kinetic_energy():
    """k_c of eq. (100): the kinetic energy on the constraint distribution."""
    return constrain(kinetic_energy(S.v))


def reduced_constrained_lagrangian():
    """ℓ_c(γ, R_Y, R_P, Ω_S, Ω_Y, Ω_P) of eq. (41), constant dropped."""
    return constrained_kinetic_energy() - potential_energy()


def total_energy():
    """Kinetic plus the pendulum's potential m_P g e_zᵀ(q + R_S R_Y R_P c̄_P).

    The shell and yoke potentials are constant (Section 2.5) and left out.
    """
    return constrained_kinetic_energy() + P.m_P * P.g * S.q_z + potential_energy()
