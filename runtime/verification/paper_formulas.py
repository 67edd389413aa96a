"""The paper's matrix formulas of Sections 2-4, transcribed in NumPy.

A third path to the same dynamics, independent of both `derive/` (SymPy) and
`runtime.verification.reference` (CasADi, coordinates): the printed matrix equations
(41), (85), (87)-(95), (97)-(99), (102)-(105) and Appendix C, evaluated in the
Lie algebra with the paper's trace pairing ⟨A, B⟩ = tr(AᵀB).  Each printed
erratum is a switch (`Errata`), so `docs/errata.md` can show the error with
the printed form and with the corrected one.  It also serves the benchmark as
"what a user would write in NumPy from the paper".

Units: the non-conservative terms are transcribed literally from eq. (42),
⟨−k_S Ω_S, δΩ_S⟩ + ⟨τ_Y − k_Y Ω_Y, δΩ_Y⟩ + ⟨τ_P − k_P Ω_P, δΩ_P⟩ with
⟨A, B⟩ = tr(AᵀB), in the paper's own coefficients (`accel_paper_units`).
`accel(x, u)` takes physical u and k and finds the paper's coefficients by
equal virtual work (`paper_coefficient`): the factor 1/2 comes out of the
pairing, ⟨Σ, Σ⟩ = 2, and is written nowhere by hand (docs/errata.md,
"The factor 2").
"""
import dataclasses

import numpy as np

from ..params import Params
from ..so3 import hat
from ..state import IDX_NU, IDX_Q, IDX_WP, IDX_WS, IDX_WY, rotations

E_X, E_Y, E_Z = np.eye(3)


SIGMA_Y, SIGMA_P, SIGMA_C = hat(E_X), hat(E_Y), hat(E_Z)


def pairing(A, B):
    """⟨A, B⟩ = tr(AᵀB), the inner product of so(3) with which eq. (42) pairs forces and variations."""
    return float(np.trace(A.T @ B))


def paper_coefficient(physical, axis):
    """The paper's coefficient (τ or k of eq. 42) of a physical torque or damping coefficient about `axis`.

    `axis` is the unit generator Σ of the rotation (Σ_Y for the yoke, Σ_P for the pendulum, any
    unit ⟦e⟧ for the shell).  A physical torque u about the axis does the virtual work u·ε on a
    virtual rotation by the angle ε about it, δΩ = ε Σ; in eq. (42) the paper's term τ Σ does
    ⟨τ Σ, ε Σ⟩ = τ ε ⟨Σ, Σ⟩.  Equal for every ε: τ = u / ⟨Σ, Σ⟩.  A damping torque −k ω does
    −k ω ε, the paper's −k' Ω = −k' ω Σ does −k' ω ε ⟨Σ, Σ⟩: k' = k / ⟨Σ, Σ⟩ likewise.
    """
    return physical / pairing(axis, axis)


def sigma(M):
    """Skew part, σ(M) = ½(M − Mᵀ) (Section 3.3)."""
    return (M - M.T) / 2


def sigma_axis(M, S):
    """Projection on span{S}, ½ tr(Mᵀ S) S (eqs. 76, 82, 131)."""
    return np.trace(M.T @ S) / 2 * S


def diamond(a, b):
    """a ◇ b = σ(b aᵀ) (eq. 54)."""
    return sigma(np.outer(b, a))


def ad_star(Omega, Lam):
    """ad*_Ω Λ = [Λ, Ω] under the trace pairing."""
    return Lam @ Omega - Omega @ Lam


@dataclasses.dataclass(frozen=True)
class Errata:
    """Which printed forms to use (True) instead of the corrected ones (False)."""
    eq31_mass: bool = False        # ½ m_Y |q̇|² in K_P instead of ½ m_P |q̇|²
    eq71_gamma: bool = False       # r γ ◇ ∂ℓ/∂v instead of r γ̇ ◇ ∂ℓ/∂v in the shell equation
    eq102_Jdot: bool = False       # d/dt Λ = 𝕁 Ω̇ + 𝕁 Ω instead of 𝕁 Ω̇ + 𝕁̇ Ω
    eq105_minus_J: bool = False    # ν̇ = 𝕁⁻¹{…} − 𝕁 Ω instead of 𝕁⁻¹({…} − 𝕁̇ Ω)


class PaperModel:
    """Eqs. (41)-(105) of the paper in NumPy; same API subset as `runtime.Model`."""

    def __init__(self, params=None, errata=Errata()):
        robot = Params() if params is None else params
        if robot.paper_params is None:
            raise ValueError("PaperModel: params must be the paper's robot (Params.paper(...)), "
                             "whose formulas these are")
        p = robot.paper_params
        self.p, self.errata = robot, errata
        j_S = 2 / 3 * p.m_S * p.r**2
        j_xx = (p.m_b / 6 + p.m_h / 2) * p.b**2
        j_yy = (p.m_b / 2 + p.m_h / 6) * p.h**2
        j_P = p.m_P * p.l**2 / 3
        self.m_Y = 2 * (p.m_b + p.m_h)
        self.m_R = p.m_S + self.m_Y + p.m_P
        self.Jh_S = j_S / 2 * np.eye(3)
        self.Jh_Y = np.diag([j_yy, j_xx, 0.0])
        self.Jh_P = np.diag([0.0, 0.0, j_P])
        self.c_P = -p.l / 2 * E_Z

    # -- configuration ---------------------------------------------------------
    @staticmethod
    def unpack(x):
        """The state's rotations, position and the angular-velocity matrices of the paper's formulas."""
        x = np.asarray(x)
        R_S, R_Y, R_P = rotations(x)
        return R_S, R_Y, R_P, x[IDX_Q], hat(x[IDX_WS]), x[IDX_WY] * SIGMA_Y, x[IDX_WP] * SIGMA_P

    def blocks(self, gamma, R_Y, R_P):
        """The state-dependent inertia matrices of eq. (99)."""
        p, c = self.p, self.c_P
        JP = R_Y @ R_P @ self.Jh_P @ R_P.T @ R_Y.T
        JY = R_Y @ self.Jh_Y @ R_Y.T
        xi = R_Y @ R_P @ c
        J = {}
        J["SS"] = (self.m_R * p.r**2 * np.outer(gamma, gamma) + self.Jh_S + JY + JP
                   + p.m_P * p.r * (np.outer(gamma, xi) + np.outer(xi, gamma)))
        J["SY"] = JY + JP + p.m_P * p.r * np.outer(gamma, xi)
        J["SP"] = (R_Y @ R_P @ self.Jh_P + p.m_P * p.r * np.outer(gamma, c)) @ R_P.T
        J["YS"] = J["SY"].T
        J["YY"] = R_Y @ (self.Jh_Y + R_P @ self.Jh_P @ R_P.T) @ R_Y.T
        J["YP"] = R_Y @ R_P @ self.Jh_P @ R_P.T
        J["PS"], J["PY"] = J["SP"].T, J["YP"].T
        J["PP"] = R_P @ self.Jh_P @ R_P.T
        return J

    def momenta(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """(Λ_S, Λ_Y, Λ_P) = 𝕁 (Ω_S, Ω_Y, Ω_P), eqs. (97)-(98)."""
        J = self.blocks(gamma, R_Y, R_P)
        L_S = sigma(J["SS"] @ O_S + J["SY"] @ O_Y + J["SP"] @ O_P @ R_Y.T)
        L_Y = sigma_axis(J["YS"] @ O_S + J["YY"] @ O_Y + J["YP"] @ O_P @ R_Y.T, SIGMA_Y)
        L_P = sigma_axis(J["PS"] @ O_S @ R_Y + J["PY"] @ O_Y @ R_Y + J["PP"] @ O_P, SIGMA_P)
        return L_S, L_Y, L_P

    @staticmethod
    def coefficients(L_S, L_Y, L_P):
        """The five scalars ½tr(Σᵀ·) of Appendix C, times 2 as the paper writes them."""
        return np.array([np.trace(L_S.T @ SIGMA_Y), np.trace(L_S.T @ SIGMA_P), np.trace(L_S.T @ SIGMA_C),
                         np.trace(L_Y.T @ SIGMA_Y), np.trace(L_P.T @ SIGMA_P)])

    def appendix_c_matrix(self, gamma, R_Y, R_P):
        """The 5×5 matrix of Appendix C: column j is 𝕁 applied to the j-th basis velocity."""
        basis = [(SIGMA_Y, 0 * SIGMA_Y, 0 * SIGMA_P), (SIGMA_P, 0 * SIGMA_Y, 0 * SIGMA_P),
                 (SIGMA_C, 0 * SIGMA_Y, 0 * SIGMA_P), (0 * SIGMA_C, SIGMA_Y, 0 * SIGMA_P),
                 (0 * SIGMA_C, 0 * SIGMA_Y, SIGMA_P)]
        return np.column_stack([self.coefficients(*self.momenta(gamma, R_Y, R_P, *b)) for b in basis])

    def inertia(self, x):
        """The generalized inertia matrix of the paper's Appendix C at state x."""
        R_S, R_Y, R_P, *_ = self.unpack(x)
        return self.appendix_c_matrix(R_S[2], R_Y, R_P)

    # -- Lagrangian terms -----------------------------------------------------------
    def dl_dv(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """∂ℓ/∂v on the constraint, eq. (90)."""
        p = self.p
        xi = R_Y @ R_P @ self.c_P
        return (O_S @ (self.m_R * p.r * gamma + p.m_P * xi) + O_Y @ (p.m_P * xi)
                + R_Y @ O_P @ (p.m_P * R_P @ self.c_P))

    def dl_dgamma(self, R_Y, R_P):
        """∂ℓ/∂γ, eq. (88)."""
        return -self.p.m_P * self.p.g * R_Y @ R_P @ self.c_P

    def dlc_dRY(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """∂ℓ_c/∂R_Y as printed in eq. (94)."""
        p, c, JhY, JhP = self.p, self.c_P, self.Jh_Y, self.Jh_P
        W = O_S + O_Y + R_Y @ O_P @ R_Y.T
        S2 = O_S + O_Y
        return (S2.T @ S2 @ R_Y @ JhY
                + W @ R_Y @ R_P @ JhP @ R_P.T @ O_P.T
                + R_Y @ R_P @ JhP @ R_P.T @ R_Y.T @ W @ R_Y @ O_P
                + W.T @ W @ R_Y @ R_P @ JhP @ R_P.T
                + p.m_P * p.r * O_S @ np.outer(gamma, c) @ R_P.T @ O_P.T
                + p.m_P * p.r * R_Y @ R_P @ np.outer(c, gamma) @ O_S.T @ R_Y @ O_P
                + p.m_P * p.r * W.T @ O_S @ np.outer(gamma, c) @ R_P.T
                - p.m_P * p.g * np.outer(gamma, c) @ R_P.T)

    def dlc_dRP(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """∂ℓ_c/∂R_P as printed in eq. (95)."""
        p, c = self.p, self.c_P
        W = O_S + O_Y + R_Y @ O_P @ R_Y.T
        return (R_Y.T @ W.T @ W @ R_Y @ R_P @ self.Jh_P
                + p.m_P * p.r * R_Y.T @ W.T @ O_S @ np.outer(gamma, c)
                - p.m_P * p.g * R_Y.T @ np.outer(gamma, c))

    def lagrangian_c(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """ℓ_c of eq. (41), Ĵ_S in the second term; constant dropped."""
        p = self.p
        W = O_S + O_Y + R_Y @ O_P @ R_Y.T
        xi = R_Y @ R_P @ self.c_P
        JP = R_Y @ R_P @ self.Jh_P @ R_P.T @ R_Y.T
        S2 = O_S + O_Y
        return (self.m_R * p.r**2 / 2 * np.trace(O_S @ np.outer(gamma, gamma) @ O_S.T)
                + np.trace(O_S @ self.Jh_S @ O_S.T) / 2
                + np.trace(S2 @ R_Y @ self.Jh_Y @ R_Y.T @ S2.T) / 2
                + p.m_P * p.r * gamma @ O_S.T @ W @ xi
                + np.trace(W @ JP @ W.T) / 2
                - p.m_P * p.g * gamma @ xi)

    # -- equations of motion ----------------------------------------------------------
    @staticmethod
    def nonconservative(O_S, O_Y, O_P, tau, k):
        """The forces of eq. (42) as printed: (−k_S Ω_S, τ_Y − k_Y Ω_Y, τ_P − k_P Ω_P), τ_Y = τ[0] Σ_Y,
        τ_P = τ[1] Σ_P; tau = (τ_Y, τ_P) and k = (k_S, k_Y, k_P) in the paper's coefficients."""
        return -k[0] * O_S, tau[0] * SIGMA_Y - k[1] * O_Y, tau[1] * SIGMA_P - k[2] * O_P

    def paper_units(self, u):
        """(τ, k) of eq. (42) for physical torques u and the physical damping of the parameters."""
        p = self.p
        tau = (paper_coefficient(u[0], SIGMA_Y), paper_coefficient(u[1], SIGMA_P))
        k = (paper_coefficient(p.k_S, SIGMA_C), paper_coefficient(p.k_Y, SIGMA_Y), paper_coefficient(p.k_P, SIGMA_P))
        return tau, k

    def forces(self, gamma, R_Y, R_P, O_S, O_Y, O_P, tau, k):
        """Right-hand sides of eq. (85) with Λ̇ moved left: the terms in braces of eq. (105); τ, k the paper's."""
        p, e = self.p, self.errata
        L_S, _, _ = self.momenta(gamma, R_Y, R_P, O_S, O_Y, O_P)
        gamma_dot = -O_S @ gamma
        nonholonomic = gamma if e.eq71_gamma else gamma_dot
        N_S, N_Y, N_P = self.nonconservative(O_S, O_Y, O_P, tau, k)
        F_S = (ad_star(O_S, L_S) - diamond(gamma, self.dl_dgamma(R_Y, R_P))
               + p.r * diamond(nonholonomic, self.dl_dv(gamma, R_Y, R_P, O_S, O_Y, O_P)) + N_S)
        F_Y = sigma_axis(R_Y.T @ self.dlc_dRY(gamma, R_Y, R_P, O_S, O_Y, O_P), SIGMA_Y) + N_Y
        F_P = sigma_axis(R_P.T @ self.dlc_dRP(gamma, R_Y, R_P, O_S, O_Y, O_P), SIGMA_P) + N_P
        return F_S, F_Y, F_P

    def momentum_rate_at_fixed_speed(self, gamma, R_Y, R_P, O_S, O_Y, O_P):
        """𝕁̇ Ω (eq. 103): the derivative of 𝕁(γ, R_Y, R_P) Ω along γ̇ = −Ω_Sγ, Ṙ = RΩ.

        𝕁 is polynomial in the configuration, so a complex step gives the
        directional derivative to rounding error.
        """
        h = 1e-30
        g_c = gamma + 1j * h * (-O_S @ gamma)
        RY_c = R_Y + 1j * h * (R_Y @ O_Y)
        RP_c = R_P + 1j * h * (R_P @ O_P)
        return [L.imag / h for L in self.momenta(g_c, RY_c, RP_c, O_S, O_Y, O_P)]

    def accel(self, x, u=None):
        """ν̇ from eq. (105) for physical torques u (2,) and the parameters' physical damping."""
        u = np.zeros(2) if u is None else np.asarray(u, dtype=float)
        return self.accel_paper_units(x, *self.paper_units(u))

    def accel_paper_units(self, x, tau, k):
        """ν̇ from eq. (105) with 𝕁 inverted through the Appendix C system; τ = (τ_Y, τ_P) and
        k = (k_S, k_Y, k_P) are the paper's coefficients of eq. (42), used as printed."""
        R_S, R_Y, R_P, _, O_S, O_Y, O_P = self.unpack(x)
        gamma = R_S[2]
        A = self.appendix_c_matrix(gamma, R_Y, R_P)
        rhs = self.coefficients(*self.forces(gamma, R_Y, R_P, O_S, O_Y, O_P, tau, k))
        if self.errata.eq102_Jdot:
            rate = self.momenta(gamma, R_Y, R_P, O_S, O_Y, O_P)
        else:
            rate = self.momentum_rate_at_fixed_speed(gamma, R_Y, R_P, O_S, O_Y, O_P)
        if self.errata.eq105_minus_J:
            nu = np.asarray(x)[IDX_NU]
            return np.linalg.solve(A, rhs) - A @ nu
        return np.linalg.solve(A, rhs - self.coefficients(*rate))

    def energy(self, x):
        """Kinetic energy from eq. (100) (with eq. 31's mass as selected) plus the potential of eq. (32)."""
        R_S, R_Y, R_P, q, O_S, O_Y, O_P = self.unpack(x)
        gamma = R_S[2]
        p = self.p
        v = p.r * O_S @ gamma
        ell_c = self.lagrangian_c(gamma, R_Y, R_P, O_S, O_Y, O_P)
        potential = p.m_P * p.g * gamma @ R_Y @ R_P @ self.c_P
        kinetic = ell_c + potential
        if self.errata.eq31_mass:
            kinetic += (self.m_Y - p.m_P) / 2 * v @ v
        return float(kinetic + p.m_P * p.g * q[2] + potential)
