"""Derivatives of the dynamics in the error coordinates (derive/state.py ERROR_BLOCKS).

The accelerations solve M ν̇ = f (`derive.dynamics`: M of eqs. 97-99, f from eqs. 71/85, 78, 84).
Along x ⊕ d the configuration moves on its group, right-trivialised:
    γ = R_Sᵀ e_z  →  Exp(−⟦δξ⟧) γ,   so  ∂γ/∂δξ_k = −e_k × γ       (eq. 85's advection, with δξ for Ω_S dt)
    χ = R_Sᵀ e_x  likewise (the general robot on a slope)
    R_Y → R_Y Exp(δθ_Y Σ_Y),  R_P → R_P Exp(δθ_P Σ_P)              (eqs. 39)
q enters neither M nor f, and ν, u enter additively.  Differentiating M ν̇ = f gives
    ∂ν̇ = M⁻¹ (∂f − (∂M) ν̇),
so one factorisation of M serves ν̇ and every column (c/src/sr_jacobians.c does the solves).
`derive.dynamics` reduced M and f modulo |γ| = 1 and cos² + sin² = 1; those forms agree with
the derivation on the manifold, so their derivatives along its tangent directions (the only ones
taken here) agree too.
"""
import functools

import sympy as sp

from . import dynamics as D
from . import robot as R
from . import state as S
from . import yoke_frame as YF


def configuration_directions():
    """The rates of the configuration symbols along δξ_x, δξ_y, δξ_z, δθ_Y, δθ_P (unit steps)."""
    none, still = sp.zeros(3, 3), sp.zeros(3, 1)
    units = [S.hat([int(i == k) for i in range(3)]) for k in range(3)]
    directions = [S.configuration_rates(none, none, -E * S.gamma, -E * S.chi) for E in units]
    directions.append(S.configuration_rates(S.R_Y * S.Sigma_Y, none, still))
    directions.append(S.configuration_rates(none, S.R_P * S.Sigma_P, still))
    return directions


def _column(expr_matrix, block, k):
    """∂/∂d of a matrix of expressions along error coordinate k of `block` (the full chain rule)."""
    names = {name: (offset, length) for name, offset, length in S.ERROR_BLOCKS}
    if block == "nu":
        return expr_matrix.diff(S.nu[k])
    if block == "q":                      # the dynamics does not depend on where the shell is
        return sp.zeros(*expr_matrix.shape)
    index = k if block == "xi_S" else {"th_Y": 3, "th_P": 4}[block]
    assert names[block][1] > k
    rates = configuration_directions()[index]
    return expr_matrix.applyfunc(lambda e: S.directional_derivative(e, rates))


def error_columns():
    """(block, k) for the NE error coordinates, in the order of ERROR_BLOCKS."""
    return [(name, k) for name, _, length in S.ERROR_BLOCKS for k in range(length)]


@functools.lru_cache(maxsize=None)
def rhs_jacobian(robot=R.PAPER):
    """∂f/∂d (5×NE): f along x ⊕ d, at d = 0."""
    f = D.rhs(robot)
    return sp.Matrix.hstack(*[_column(f, block, k) for block, k in error_columns()])


@functools.lru_cache(maxsize=None)
def rhs_input_jacobian(robot=R.PAPER):
    """∂f/∂u (5×2): the motor torques enter the joint equations (eqs. 78, 84)."""
    return D.rhs(robot).jacobian(S.u)


@functools.lru_cache(maxsize=None)
def inertia_derivatives(robot=R.PAPER):
    """∂M/∂d along the five configuration coordinates δξ_S (3), δθ_Y, δθ_P: five 5×5 matrices
    (M depends on γ, R_Y, R_P only: its derivatives along q and ν are zero)."""
    M = D.inertia(robot)
    return tuple(M.applyfunc(lambda e: S.directional_derivative(e, rates)) for rates in configuration_directions())


def accel_jacobian(M=None, f=None):
    """Ja = M⁻¹(∂f/∂d − Σ_k ∂M/∂d_k ν̇ e_kᵀ) symbolically (for the proofs and the tests; slow)."""
    M = D.inertia() if M is None else M
    f = D.rhs() if f is None else f
    a = M.LUsolve(f)
    dM_a = sp.zeros(5, S.NE)
    for k, dM in enumerate(inertia_derivatives()):
        dM_a[:, k] = dM * a
    return M.LUsolve(rhs_jacobian() - dM_a)


# ---- The paper's robot in the yoke frame (derive.yoke_frame): what c/src/sr_jacobians.c evaluates ----
# ν̇ = Tᵀ g with T = diag(R_Yᵀ, 1, 1) and g = M'⁻¹ f'(γ', R_P, ν'), γ' = R_Yᵀ γ, ν' = T ν, where M'
# and f' are M and f at R_Y = I (a third of the operations of the shell-frame forms, and none of
# their dependence on R_Y).  The shell frame's error coordinates move the yoke frame's variables as
#     δξ_S:  γ' → Exp(−⟦δξ'⟧) γ' with δξ' = R_Yᵀ δξ_S,
#     δθ_Y:  γ' and ω' turn by −δθ_Y about e_x (δξ' = δθ_Y e_x, δω' = ω' × e_x δθ_Y),
#            and the output ν̇_S = R_Y g_S turns with R_Y (+ R_Y (e_x × g_S) δθ_Y),
#     δθ_P:  R_P → R_P Exp(δθ_P Σ_P),     δν: δν' = T δν,
# so the derivatives below are taken along δξ' (3), δθ_P and δν' (5) only: the chain rule through T
# is a few rotations by R_Y, done in C.  Like M and f, M' and f' agree with the derivation on the
# manifold (yoke_frame.check_equivalence), so their tangent derivatives agree too.

def yoke_configuration_directions():
    """The rates of γ' and R_P along δξ'_x, δξ'_y, δξ'_z and δθ_P (unit steps; γ' stands as γ): the
    shell frame's directions but δθ_Y, which the yoke-frame forms do not have (their χ rates meet
    no χ there)."""
    xi_x, xi_y, xi_z, _, th_P = configuration_directions()
    return [xi_x, xi_y, xi_z, th_P]


@functools.lru_cache(maxsize=None)
def yoke_rhs_jacobian():
    """∂f'/∂(δξ', δθ_P, δν') (5×9) in the yoke frame."""
    f = YF.rhs()
    columns = [f.applyfunc(lambda e: S.directional_derivative(e, rates)) for rates in yoke_configuration_directions()]
    return sp.Matrix.hstack(*columns, f.jacobian(S.nu))


@functools.lru_cache(maxsize=None)
def yoke_inertia_derivatives():
    """∂M'/∂(δξ', δθ_P): four 5×5 matrices (M' depends on γ' and R_P only)."""
    M = YF.inertia()
    return tuple(M.applyfunc(lambda e: S.directional_derivative(e, rates)) for rates in yoke_configuration_directions())
