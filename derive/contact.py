"""The force of the floor on the shell at the contact point, from the balance of the total momentum.

Rolling without slipping (eq. 37) is kept by a force of the floor on the shell; the reduced
equations never form it, but the motion they give determines it.  Its normal component says
whether the shell stays on the floor, and |F_t|/F_n how much friction the rolling needs.
"""
import sympy as sp

from . import sensors as SE
from . import state as S


def contact_force(robot):
    """F = (F_x, F_y, F_z): the floor's force on the shell, in the plane's frame (x up the slope,
    z the floor's normal) [N], given ν̇ (derive.sensors.nu_dot, from the accel kernel).

    The total linear momentum of shell, yoke and pendulum (the rotors sit at O and carry no
    mass of their own) changes only by gravity and the contact force:

        F = Σ_B m_B p̈_B − m_R g⃗,    p_B = q + R_S Q_B c̄_B   (eqs. 22, 26; m_R of eq. 35),

    with Q_Y = R_Y, Q_P = R_Y R_P.  With h_B = m_B c̄_B (eqs. 24, 28: the robot's first moments
    about O, zero for the shell) and R_Bᵀ d²/dt²(R_B h) = (⟦ω̇_B⟧ + ⟦ω_B⟧²) h, in the shell frame

        R_Sᵀ F = m_R (R_Sᵀ q̈ − R_Sᵀ g⃗) + Σ_{B = Y, P} Q_B (⟦ω̇_B⟧ + ⟦ω_B⟧²) h_B,

    R_Sᵀ q̈ from the rolling constraint v = r Ω_S γ (eq. 38) and the advection γ̇ = −Ω_S γ
    (eq. 39); then F = R_S (R_Sᵀ F), whose rows are χ, η, γ.
    """
    shell = robot.m_R * (SE.centre_acceleration() - (-(robot.g_x * S.chi + robot.g_z * S.gamma)))
    swing = sp.zeros(3, 1)
    for body, h in (("yoke", robot.h_Y), ("pendulum", robot.h_P)):
        w, dw = SE.angular_velocity(body), SE.angular_acceleration(body)
        swing += SE.from_body(body, S.hat(dw) * sp.Matrix(h) + S.hat(w) * (S.hat(w) * sp.Matrix(h)))
    F_shell = shell + swing
    return sp.Matrix([S.chi.dot(F_shell), SE.eta.dot(F_shell), S.gamma.dot(F_shell)])
