"""The reduced Lagrangian ℓ (eq. 36), the reduced-constrained Lagrangian ℓ_c (eq. 41) and the energy.

Printed-equation errata corrected here (see docs/errata.md): eq. (31) and
(34) carry ½ m_Y and Ĵ_R where the derivation gives ½ m_P and Ĵ_S, and
eq. (34) writes ‖Ṙ_Sᵀ q̇‖ for ‖R_Sᵀ q̇‖.  The Lagrangian below is the one
that eqs. (19)-(32) define, term by term.

Every function takes the `robot` (derive/robot.py): the paper's (Section 2.3,
the default) or the general one, whose bodies have arbitrary
centres of mass and tensors, whose motors have rotors and whose floor is
inclined.  The paper's robot gives the paper's terms exactly.
"""
import sympy as sp

from . import robot as R
from . import state as S


def trace_quadratic(A, J):
    """½ tr(A J Aᵀ): the rotational kinetic energy of eq. (10)."""
    return (A * J * A.T).trace() / 2


def pendulum_angular_velocity():
    """Ω_S + Ω_Y + R_Y Ω_P R_Yᵀ: the pendulum's angular velocity in the shell frame (eq. 29)."""
    return S.Omega_S + S.Omega_Y + S.R_Y * S.Omega_P * S.R_Y.T


def yoke_moment(robot):
    """R_Y h_Y: the yoke's first moment about O in the shell frame (zero for the paper's yoke)."""
    return S.R_Y * robot.h_Y


def pendulum_moment(robot):
    """R_Y R_P h_P = m_P ξ with ξ = R_Y R_P c̄_P: the pendulum's first moment in the shell frame (Section 2.6)."""
    return S.R_Y * S.R_P * robot.h_P


def rotor_energy(robot):
    """The motors' rotors, axial inertia only: ½ j_mY (e_xᵀω_S + n_Y ω_Y)² for the yoke
    motor's rotor on the shell, ½ j_mP ((R_Y e_y)ᵀω_S + n_P ω_P)² for the pendulum motor's on the yoke."""
    yoke_rotor = S.w_S[0] + robot.n_Y * S.w_Y
    pendulum_rotor = (S.R_Y * sp.Matrix([0, 1, 0])).dot(S.w_S) + robot.n_P * S.w_P
    return robot.j_mY * yoke_rotor**2 / 2 + robot.j_mP * pendulum_rotor**2 / 2


def kinetic_energy(v, robot=R.PAPER):
    """K_S + K_Y + K_P of eqs. (20), (25), (31), written with v = R_Sᵀ q̇, plus the rotors'."""
    W_Y = S.Omega_S + S.Omega_Y
    W_P = pendulum_angular_velocity()
    translational = robot.m_R * (v.T * v)[0] / 2
    shell = trace_quadratic(S.Omega_S, robot.Jhat_S)
    yoke_coupling = (v.T * W_Y * yoke_moment(robot))[0]
    yoke = trace_quadratic(W_Y, S.R_Y * robot.Jhat_Y * S.R_Y.T)
    pendulum_coupling = (v.T * W_P * pendulum_moment(robot))[0]
    pendulum = trace_quadratic(W_P, S.R_Y * S.R_P * robot.Jhat_P * S.R_P.T * S.R_Y.T)
    return translational + shell + yoke_coupling + yoke + pendulum_coupling + pendulum + rotor_energy(robot)


def gravity_in_shell_frame(robot):
    """R_Sᵀ g⃗ = −(g_x χ + g_z γ): gravity seen from the shell (g⃗ = −g e_z on a level floor)."""
    return -(robot.g_x * S.chi + robot.g_z * S.gamma)


def potential_energy(robot=R.PAPER):
    """U_P of eq. (32) without its q-dependent part: −R_Sᵀg⃗ · (R_Y h_Y + R_Y R_P h_P).

    For the paper's robot, m_P g γᵀ R_Y R_P c̄_P."""
    moment = yoke_moment(robot) + pendulum_moment(robot)
    return -(gravity_in_shell_frame(robot).T * moment)[0]


def reduced_lagrangian(robot=R.PAPER):
    """ℓ(γ, χ, R_Y, R_P, Ω_S, Ω_Y, Ω_P, v) of eq. (36), the constant and q-dependent terms dropped."""
    return kinetic_energy(S.v, robot) - potential_energy(robot)


def rolling_velocity(robot=R.PAPER):
    """The non-holonomic constraint in the shell frame, v = r Ω_S γ (eq. 38)."""
    return robot.r * S.Omega_S * S.gamma


def constrain(expr, robot=R.PAPER):
    """Substitute v = r Ω_S γ (eq. 40)."""
    return expr.subs(dict(zip(S.v, rolling_velocity(robot))), simultaneous=True)


def constrained_kinetic_energy(robot=R.PAPER):
    """k_c of eq. (100): the kinetic energy on the constraint distribution."""
    return constrain(kinetic_energy(S.v, robot), robot)


def reduced_constrained_lagrangian(robot=R.PAPER):
    """ℓ_c(γ, χ, R_Y, R_P, Ω_S, Ω_Y, Ω_P) of eq. (41), constant dropped."""
    return constrained_kinetic_energy(robot) - potential_energy(robot)


def total_energy(robot=R.PAPER):
    """Kinetic plus potential: k_c + m_R g_x q_x + m_P g_z q_z + U_P.

    The whole potential is −Σ m_i g⃗·(q + R_S R_i c_i); its part m_R g_z q_z is constant (q_z = r):
    like the paper (Section 2.5) the shell's and yoke's shares (m_S + m_Y) g_z r are left out.
    On a slope m_R g_x q_x is the climb's potential.
    """
    height = robot.m_R * robot.g_x * S.q_x + robot.m_P * robot.g_z * S.q_z
    return constrained_kinetic_energy(robot) + height + potential_energy(robot)
