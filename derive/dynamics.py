"""Equations of motion M(γ, R_Y, R_P) ν̇ = f(γ, R_Y, R_P, ν, u), derived from ℓ and ℓ_c.

ν = (ω_S, ω_Y, ω_P) stacks the axial vector of Ω_S and the coordinates of
Ω_Y = ω_Y Σ_Y and Ω_P = ω_P Σ_P.  Everything below is obtained by
differentiating the Lagrangians of `derive.lagrangian`; nothing is copied
from the printed formulas of Section 4.

Shell (eq. 85, first line, with γ̇ and not γ in the last term; eq. 71 has γ):
    d/dt ∂ℓ_c/∂ω_S = ∂ℓ_c/∂ω_S × ω_S + ∂ℓ/∂γ × γ + r γ̇ × ∂ℓ/∂v − k_S ω_S
                     [+ ∂ℓ/∂χ × χ + r γ × m_R R_Sᵀg⃗   on a slope]
  the vector form of  d/dt ∂ℓ_c/∂Ω_S − ad*_{Ω_S} ∂ℓ_c/∂Ω_S = −γ◇∂ℓ/∂γ + r γ̇◇∂ℓ/∂v − k_S Ω_S.
Yoke and pendulum (eqs. 78, 84):
    d/dt ∂ℓ_c/∂ω_Y = ⟨∂ℓ_c/∂R_Y, R_Y Σ_Y⟩ + u_Y − k_Y ω_Y
    d/dt ∂ℓ_c/∂ω_P = ⟨∂ℓ_c/∂R_P, R_P Σ_P⟩ + u_P − k_P ω_P
The generalized forces are physical torques (pairing by the dot product of
axial vectors, see README, "Conventions").  With ∂ℓ_c/∂ν = M ν (eq. 97):
    M ν̇ = f := [gyroscopic, gravity, non-holonomic and applied terms] − Ṁ ν.

Each function takes the `robot` of derive/robot.py (the paper's by default).
On a slope the potential depends on χ = R_Sᵀ e_x, which is advected like γ
(χ̇ = −Ω_S χ) and so contributes ∂ℓ/∂χ × χ exactly as γ does; and it depends
on q, −m_R g⃗·q, whose variation along the rolling constraint
δq = r R_S Ξ γ is the torque r γ × m_R R_Sᵀg⃗ (gravity on the whole mass,
about the contact point).
"""
import functools

import sympy as sp

from . import lagrangian as L
from . import parameters as P
from . import robot as R
from . import state as S


def cross(a, b):
    return a.cross(b)


#: Generators ordered so that reduction replaces cos² by 1 − sin² and γ_x² by 1 − γ_y² − γ_z².
_MANIFOLD_GENERATORS = (S.RY_c, S.RP_c, S.gamma[0], S.RY_s, S.RP_s, S.gamma[1], S.gamma[2])
#: With χ as well (the general robot on a slope): χ_x² by 1 − χ_y² − χ_z², γ·χ = 0.
_SLOPE_GENERATORS = _MANIFOLD_GENERATORS + (S.chi[0], S.chi[1], S.chi[2])


@functools.lru_cache(maxsize=None)
def _unit_norm_basis(with_chi):
    """Gröbner basis of the identities every valid state satisfies: R_Y, R_P and R_S orthonormal."""
    identities = [S.RY_c**2 + S.RY_s**2 - 1, S.RP_c**2 + S.RP_s**2 - 1, (S.gamma.T * S.gamma)[0] - 1]
    if with_chi:
        identities += [(S.chi.T * S.chi)[0] - 1, (S.chi.T * S.gamma)[0]]
    return sp.groebner(identities, *(_SLOPE_GENERATORS if with_chi else _MANIFOLD_GENERATORS), order="grevlex")


def on_manifold(expr):
    """The canonical remainder of expr modulo cos² + sin² = 1, |γ| = 1 and, where χ appears, |χ| = 1 and
    γ·χ = 0 (fewer terms, same values on valid states).  Expressions free of χ are reduced without its
    identities, so the paper's forms do not depend on them."""
    expr = sp.expand(expr)
    with_chi = bool(expr.free_symbols & set(S.chi))
    generators = _SLOPE_GENERATORS if with_chi else _MANIFOLD_GENERATORS
    _, remainder = sp.reduced(expr, list(_unit_norm_basis(with_chi)), *generators, order="grevlex")
    return sp.expand(remainder)


@functools.lru_cache(maxsize=None)
def inertia(robot=R.PAPER):
    """Generalized inertia M = ∂²k_c/∂ν² (5×5, symmetric; the matrix form of 𝕁, eqs. 97-99)."""
    k_c = sp.expand(L.constrained_kinetic_energy(robot))
    return sp.hessian(k_c, list(S.nu)).applyfunc(on_manifold)


@functools.lru_cache(maxsize=None)
def momenta(robot=R.PAPER):
    """∂ℓ_c/∂ν = M ν: the generalized momenta Λ of eq. (96)."""
    return inertia(robot) * S.nu


def linear_momentum(robot=R.PAPER):
    """∂ℓ/∂v on the constraint (eq. 90)."""
    ell = L.reduced_lagrangian(robot)
    return L.constrain(sp.Matrix([sp.diff(ell, vi) for vi in S.v]), robot)


def gravity_gradient(robot=R.PAPER, advected=S.gamma):
    """∂ℓ/∂γ on the constraint (eq. 88: −m_P g R_Y R_P c̄_P); with advected=S.chi, ∂ℓ/∂χ."""
    ell = L.reduced_lagrangian(robot)
    return L.constrain(sp.Matrix([sp.diff(ell, gi) for gi in advected]), robot)


def slope_torque(robot=R.PAPER):
    """r γ × m_R R_Sᵀg⃗: the virtual work of −m_R g⃗·q along δq = r R_S Ξ γ (zero on a level floor)."""
    return robot.r * robot.m_R * cross(S.gamma, L.gravity_in_shell_frame(robot))


def shell_forces(robot=R.PAPER):
    """Right-hand side of the shell equation, before −Ṁν:
    K×ω + ∂ℓ/∂γ×γ + ∂ℓ/∂χ×χ + r γ̇×∂ℓ/∂v + r γ × m_R R_Sᵀg⃗ − k_S ω_S."""
    K_S = momenta(robot)[0:3, 0]
    gamma_dot = -S.Omega_S * S.gamma
    return (cross(K_S, S.w_S) + cross(gravity_gradient(robot), S.gamma)
            + cross(gravity_gradient(robot, S.chi), S.chi)
            + robot.r * cross(gamma_dot, linear_momentum(robot)) + slope_torque(robot) - robot.k_S * S.w_S)


def joint_force(virtual_rates, torque, damping, speed, robot=R.PAPER):
    """⟨∂ℓ_c/∂R, R Σ⟩ + τ − k ω for a one-axis joint (eqs. 76-78, 82-84)."""
    ell_c = L.reduced_constrained_lagrangian(robot)
    return S.directional_derivative(ell_c, virtual_rates) + torque - damping * speed


def yoke_force(robot=R.PAPER):
    zero = sp.zeros(3, 3)
    rates = S.configuration_rates(S.R_Y * S.Sigma_Y, zero, sp.zeros(3, 1))
    return joint_force(rates, S.u_Y, robot.k_Y, S.w_Y, robot)


def pendulum_force(robot=R.PAPER):
    zero = sp.zeros(3, 3)
    rates = S.configuration_rates(zero, S.R_P * S.Sigma_P, sp.zeros(3, 1))
    return joint_force(rates, S.u_P, robot.k_P, S.w_P, robot)


def inertia_rate_times_nu(robot=R.PAPER):
    """Ṁ ν along the reconstruction and advection equations."""
    M_dot = inertia(robot).applyfunc(lambda m: S.directional_derivative(m, S.time_rates()))
    return M_dot * S.nu


@functools.lru_cache(maxsize=None)
def rhs(robot=R.PAPER):
    """f with M ν̇ = f (5-vector)."""
    forces = sp.Matrix.vstack(shell_forces(robot), sp.Matrix([yoke_force(robot), pendulum_force(robot)]))
    return (forces - inertia_rate_times_nu(robot)).applyfunc(on_manifold)


@functools.lru_cache(maxsize=None)
def equilibrium_residual(robot=R.PAPER):
    """f at ν = 0, u = 0: the conditions of eq. (106); zero exactly at the equilibria."""
    at_rest = {s: 0 for s in list(S.nu) + list(S.u)}
    return rhs(robot).subs(at_rest).applyfunc(sp.simplify)


def energy(robot=R.PAPER):
    """Total energy, ½νᵀMν + height and shape potentials (lagrangian.total_energy)."""
    return on_manifold(L.total_energy(robot))


def pendulum_axis():
    """R_Y R_P e_z: the pendulum shaft direction (opposite to the rod) in the shell frame."""
    return S.R_Y * S.R_P * sp.Matrix([0, 0, 1])


def check_equilibrium_set():
    """Prove symbolically that the paper robot's equilibrium residual vanishes exactly on eq. (108).

    With a = R_Y R_P e_z, a unit vector, the shell residual is
    (m_P g l / 2) a × γ and the joint residuals are its components along the
    joint axes, so the residual is zero iff a ∥ γ, i.e. R_S R_Y R_P e_z = ±e_z.
    Returns the list of identities checked (each simplified to 0).
    """
    res = equilibrium_residual()
    a = pendulum_axis()
    shell_torque = P.m_P * P.g * P.l / 2 * cross(a, S.gamma)
    unit = {S.RY_c**2: 1 - S.RY_s**2, S.RP_c**2: 1 - S.RP_s**2}
    identities = list(res[0:3, 0] - shell_torque)
    identities.append(res[3] - shell_torque[0])                       # along the yoke axis e_x
    identities.append(res[4] - (S.R_Y * sp.Matrix([0, 1, 0])).dot(shell_torque))  # along R_Y e_y
    # |a × γ|² = |a|²|γ|² − (a·γ)² (eq. 1): zero iff a·γ = ±1 for unit a, γ.
    identities.append(sp.expand(cross(a, S.gamma).dot(cross(a, S.gamma)) - (a.dot(a) * S.gamma.dot(S.gamma) - a.dot(S.gamma) ** 2)))
    identities.append(sp.expand(a.dot(a) - 1).subs(unit))
    return [sp.simplify(sp.expand(e).subs(unit)) for e in identities]
