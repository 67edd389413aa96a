"""The equations of motion in the yoke frame: the form the `accel` kernel evaluates, proven equal.

The kinetic and potential energies are scalars, so they are unchanged when
every shell-frame vector is expressed in the yoke frame instead: γ' = R_Yᵀ γ,
ω' = R_Yᵀ ω_S.  In that frame the yoke's inertia is the constant J_Y, its
axis is still e_x and the pendulum's joint axis is e_y, so M and f are the
shell-frame expressions with R_Y = I:

    M(γ, R_Y, R_P)    = Tᵀ M(γ', I, R_P) T,
    f(γ, R_Y, R_P, ν) = Tᵀ f(γ', I, R_P, T ν),     T = diag(R_Yᵀ, 1, 1),

and ν̇ = Tᵀ ν̇' with M(γ', I, R_P) ν̇' = f(γ', I, R_P, T ν).  That costs two
rotations in and one out (18 flops) and saves about a hundred.
`check_equivalence` proves both identities modulo the unit-norm identities;
`make generate` runs it before emitting the `accel` kernel.
"""
import sympy as sp

from . import dynamics as D
from . import newton_euler as NE
from . import state as S

#: R_Y = I: the yoke frame seen from itself.
_IDENTITY = {S.RY_c: 1, S.RY_s: 0}


def transform():
    """T = diag(R_Yᵀ, 1, 1): shell-frame ν to yoke-frame ν'."""
    return sp.diag(S.R_Y.T, 1, 1)


def inertia():
    """M(γ', I, R_P): the generalized inertia in the yoke frame, γ standing for γ'."""
    return D.inertia().xreplace(_IDENTITY)


def program():
    """f(γ', I, R_P, ν') body by body, as a straight-line program (γ and ω_S standing for γ', ω')."""
    return NE.program(sp.eye(3))


def rhs():
    """f(γ', I, R_P, ν'): the body-by-body right-hand side in the yoke frame, as one expression."""
    p, f = program()
    return p.inline(f)


def from_shell_frame():
    """The substitution γ -> R_Yᵀ γ, ω_S -> R_Yᵀ ω_S that evaluates the yoke-frame forms at a shell-frame state."""
    return dict(zip(list(S.gamma) + list(S.w_S), list(S.R_Y.T * S.gamma) + list(S.R_Y.T * S.w_S)))


def check_equivalence():
    """Residuals of M = Tᵀ M' T and f = Tᵀ f' at a shell-frame state, reduced: all zero."""
    T, sub = transform(), from_shell_frame()
    M = T.T * inertia().xreplace(sub) * T
    f = T.T * D.rhs().xreplace(_IDENTITY).xreplace(sub)
    return ([D.on_manifold(sp.expand(x - y)) for x, y in zip(M, D.inertia())]
            + [D.on_manifold(sp.expand(x - y)) for x, y in zip(f, D.rhs())])
