"""The state in matrix form (Sections 2.1, 2.6, 2.7) and its layout in memory.

No rotation angles, no quaternions: the shell attitude enters the reduced
Lagrangian only through the advected vector γ = R_Sᵀ e_z (Section 2.6); the
yoke and pendulum attitudes are the rotation matrices R_Y (about x) and R_P
(about y), whose entries are symbols read straight from the state vector.

Memory layout of the state x ∈ ℝ³⁵ (row-major matrices):

    x[0:9]   R_S      x[9:18]  R_Y      x[18:27] R_P
    x[27:30] q        x[30:33] ω_S      x[33] ω_Y      x[34] ω_P

Input u ∈ ℝ²: (yoke motor torque, pendulum motor torque) [N m].
"""
import sympy as sp

NX, NU, NV = 35, 2, 5
OFFSET_RS, OFFSET_RY, OFFSET_RP, OFFSET_Q, OFFSET_W = 0, 9, 18, 27, 30

#: The blocks of x: (name, offset, length).  The one source of the state layout: the generator
#: emits it as the SR_X_<name> offsets of generated/sr_generated.h, which the hand-written C
#: uses and the Python runtime reads from the compiled module.
STATE_BLOCKS = (
    ("R_S", OFFSET_RS, 9), ("R_Y", OFFSET_RY, 9), ("R_P", OFFSET_RP, 9), ("q", OFFSET_Q, 3),
    ("w_S", OFFSET_W, 3), ("w_Y", OFFSET_W + 3, 1), ("w_P", OFFSET_W + 4, 1),
)
#: The entries of u: (name, index), emitted as SR_U_<name>.
INPUT_NAMES = (("u_Y", 0), ("u_P", 1))

#: The error (tangent) state d, right-trivialised: x ⊕ d is R_S Exp(⟦d_xi_S⟧),
#: R_Y Exp(d_th_Y Σ_Y), R_P Exp(d_th_P Σ_P), q + (d_q, 0), ν + d_nu.  (name, offset, length),
#: emitted as SR_E_<name> and SR_GEN_NE; the Jacobians of the dynamics and the steps use it.
ERROR_BLOCKS = (("xi_S", 0, 3), ("th_Y", 3, 1), ("th_P", 4, 1), ("q", 5, 2), ("nu", 7, 5))
NE = 12


def hat(w):
    """⟦w⟧ of eq. (2): the skew-symmetric matrix with ⟦w⟧ z = w × z."""
    return sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def vee(W):
    """Inverse of hat: the axial vector of a skew-symmetric matrix."""
    return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


# Basis of so(3), eq. (3).
Sigma_Y = hat([1, 0, 0])
Sigma_P = hat([0, 1, 0])
Sigma_C = hat([0, 0, 1])

# γ = R_Sᵀ e_z is the third row of R_S.
gamma = sp.Matrix(sp.symbols("gamma_x gamma_y gamma_z", real=True))
# χ = R_Sᵀ e_x, the first row of R_S: the up-slope direction in the shell frame.  On a slope
# gravity has a component along e_x, so the potential depends on χ as well as γ.
chi = sp.Matrix(sp.symbols("chi_x chi_y chi_z", real=True))
# Entries of R_Y (rotation about x) and R_P (rotation about y).
RY_c, RY_s = sp.symbols("RY_11 RY_21", real=True)
RP_c, RP_s = sp.symbols("RP_00 RP_02", real=True)
R_Y = sp.Matrix([[1, 0, 0], [0, RY_c, -RY_s], [0, RY_s, RY_c]])
R_P = sp.Matrix([[RP_c, 0, RP_s], [0, 1, 0], [-RP_s, 0, RP_c]])
q_x, q_z = sp.symbols("q_x q_z", real=True)

w_S = sp.Matrix(sp.symbols("w_Sx w_Sy w_Sz", real=True))
w_Y, w_P = sp.symbols("w_Y w_P", real=True)
nu = sp.Matrix([w_S[0], w_S[1], w_S[2], w_Y, w_P])  # ν = (ω_S, ω_Y, ω_P)

Omega_S = hat(w_S)
Omega_Y = w_Y * Sigma_Y
Omega_P = w_P * Sigma_P

u_Y, u_P = sp.symbols("u_Y u_P", real=True)
u = sp.Matrix([u_Y, u_P])

v = sp.Matrix(sp.symbols("v_x v_y v_z", real=True))  # v = R_Sᵀ q̇ (Section 2.6)

#: The configuration symbols that the reduced dynamics depends on.
CONFIGURATION = (gamma[0], gamma[1], gamma[2], RY_c, RY_s, RP_c, RP_s, chi[0], chi[1], chi[2])

#: Where each symbol lives in x (or u); the code generator reads this table.
STATE_LAYOUT = {
    gamma[0]: OFFSET_RS + 6, gamma[1]: OFFSET_RS + 7, gamma[2]: OFFSET_RS + 8,
    RY_c: OFFSET_RY + 4, RY_s: OFFSET_RY + 7,
    RP_c: OFFSET_RP + 0, RP_s: OFFSET_RP + 2,
    chi[0]: OFFSET_RS + 0, chi[1]: OFFSET_RS + 1, chi[2]: OFFSET_RS + 2,
    q_x: OFFSET_Q, q_z: OFFSET_Q + 2,
    w_S[0]: OFFSET_W, w_S[1]: OFFSET_W + 1, w_S[2]: OFFSET_W + 2,
    w_Y: OFFSET_W + 3, w_P: OFFSET_W + 4,
}
INPUT_LAYOUT = {u_Y: 0, u_P: 1}


def configuration_rates(dR_Y, dR_P, dgamma, dchi=None):
    """Rates of the configuration symbols given matrix rates Ṙ_Y, Ṙ_P, γ̇ (and χ̇, zero if None).

    The entries are read off the matrix rates at the positions the symbols
    occupy, so any tangent vector (a time derivative or a virtual
    displacement) is expressed in matrix form first.
    """
    return {
        gamma[0]: dgamma[0], gamma[1]: dgamma[1], gamma[2]: dgamma[2],
        RY_c: dR_Y[1, 1], RY_s: dR_Y[2, 1],
        RP_c: dR_P[0, 0], RP_s: dR_P[0, 2],
        **{c: (0 if dchi is None else dchi[i]) for i, c in enumerate(chi)},
    }


def time_rates():
    """Reconstruction and advection equations: Ṙ_Y = R_Y Ω_Y, Ṙ_P = R_P Ω_P, γ̇ = -Ω_S γ (eqs. 39, 85),
    and χ̇ = -Ω_S χ (χ is advected like γ)."""
    return configuration_rates(R_Y * Omega_Y, R_P * Omega_P, -Omega_S * gamma, -Omega_S * chi)


def directional_derivative(expr, rates):
    """⟨∂expr/∂(configuration), rate⟩: the chain rule through the matrix entries."""
    return sum((sp.diff(expr, s) * rate for s, rate in rates.items()), sp.Integer(0))
