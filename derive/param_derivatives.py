"""Derivatives of the dynamics in the parameters, and the regressor form of the equations of motion.

The accelerations solve M(x; p) ν̇ = f(x, u; p) (`derive.dynamics`, the general robot).  Along a
change of the parameters p, differentiating M ν̇ = f with the state and the torques held gives

    ∂ν̇/∂p = −M⁻¹ ∂(M ν̇ − f)/∂p |_(ν̇ held),

so the one generated kernel needed is the derivative of the residual M ν̇ − f with ν̇ an input
(`residual_param_jacobian`); the solve reuses the general robot's factorisation of M in C
(c/src/sr_param_jacobians.c).  The residual is linear in the inertial parameters π below, so its
derivative is taken through the regressor: Y ∂π/∂p plus the derivatives of Y in the few
parameters it depends on.

The regressor.  The Lagrangian is linear in each body's mass, first moment m·c and tensor about
O, in the rotors' axial inertias and, through the Rayleigh forces, in the dampings, and the
equations of motion inherit that linearity.  With the inertial parameters π
(`INERTIAL_PARAMETERS`: per body m, m·c and the standard tensor about the hinge at O, J_O =
J + m(|c|² I − c cᵀ); j_mY, j_mP; k_S, k_Y, k_P) and the known constants r, g, slope, n_Y, n_P,

    M(x; π) ν̇ − f(x, ν, u = 0; π) = Y(x, ν, ν̇) π,

and along any motion M ν̇ − f(u) = 0 gives Y π = (0, 0, 0, u_Y, u_P).  `regressor` derives Y as
the Jacobian of the residual in π and `check_regressor` proves that Y is free of π and that Y π
is the residual, identically.
"""
import functools

import sympy as sp

from . import dynamics as D
from . import parameters as P
from . import robot as R
from . import sensors as SE
from . import state as S


def residual(robot=R.GENERAL):
    """M ν̇ − f at u = 0 (5-vector in the robot's symbols, ν̇ the symbols of `sensors.nu_dot`)."""
    at_rest = {s: 0 for s in S.u}
    return D.inertia(robot) * SE.nu_dot - D.rhs(robot).xreplace(at_rest)


# ---- the regressor ---------------------------------------------------------------------------

def _tensor_symbols(name):
    return tuple(sp.Symbol(f"{name}_{k}", real=True) for k in ("xx", "yy", "zz", "xy", "xz", "yz"))


def _moment_symbols(name):
    return tuple(sp.Symbol(f"{name}_{k}", real=True) for k in ("x", "y", "z"))


#: The parameters the equations of motion are linear in, in the order of the regressor's columns:
#: per body its mass, first moment m·c (body frame, about O) and standard inertia tensor about O
#: (entries xx, yy, zz, xy, xz, yz), its damping; then the rotors' axial inertias.
INERTIAL_PARAMETERS = (
    P.m_S, P.j_S, P.k_S,
    P.m_Y, *_moment_symbols("mc_Y"), *_tensor_symbols("JO_Y"), P.k_Y,
    P.m_P, *_moment_symbols("mc_P"), *_tensor_symbols("JO_P"), P.k_P,
    P.j_mY, P.j_mP)

#: The parameters the regressor itself depends on (known geometry and gravity).
KNOWN_PARAMETERS = (P.r, P.n_Y, P.n_P, P.g, P.slope)


def _symmetric(entries):
    xx, yy, zz, xy, xz, yz = entries
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def general_constants_in_inertial():
    """Each general constant (robot.general_constants) as an expression in INERTIAL_PARAMETERS and
    KNOWN_PARAMETERS: linear in the former.  Ĵ_O = ½ tr(J_O) I − J_O for the standard tensor J_O
    about O (robot.pivot_tensor's Ĵ, the parallel-axis move already in J_O)."""
    JO_Y, JO_P = _symmetric(_tensor_symbols("JO_Y")), _symmetric(_tensor_symbols("JO_P"))
    hat_Y = JO_Y.trace() / 2 * sp.eye(3) - JO_Y
    hat_P = JO_P.trace() / 2 * sp.eye(3) - JO_P
    upper = lambda M: [M[0, 0], M[1, 1], M[2, 2], M[0, 1], M[0, 2], M[1, 2]]   # noqa: E731
    values = {R.m_R_general: P.m_S + P.m_Y + P.m_P, R.g_x: P.g * sp.sin(P.slope), R.g_z: P.g * sp.cos(P.slope)}
    values.update(zip(R.h_Y, _moment_symbols("mc_Y")))
    values.update(zip(R.h_P, _moment_symbols("mc_P")))
    values.update(zip(upper(R.Jhat_Y), upper(hat_Y)))
    values.update(zip(upper(R.Jhat_P), upper(hat_P)))
    return values


@functools.lru_cache(maxsize=None)
def regressor_residual():
    """M ν̇ − f at u = 0 of the general robot with its constants written in the inertial parameters."""
    return residual().xreplace(general_constants_in_inertial()).applyfunc(sp.expand)


@functools.lru_cache(maxsize=None)
def regressor():
    """Y (5 × len(INERTIAL_PARAMETERS)) with M ν̇ − f(u = 0) = Y π."""
    return regressor_residual().jacobian(list(INERTIAL_PARAMETERS))


def check_regressor():
    """The residues of the regressor form, all zero: Y free of π, and Y π − (M ν̇ − f) expanded."""
    Y = regressor()
    pi = sp.Matrix(INERTIAL_PARAMETERS)
    free = [e for e in Y if e.free_symbols & set(INERTIAL_PARAMETERS)]
    return free + [e for e in (Y * pi - regressor_residual()).applyfunc(sp.expand) if e != 0]


@functools.lru_cache(maxsize=None)
def residual_param_jacobian():
    """∂(M ν̇ − f)/∂p (5 × len(PARAMETERS), ν̇ held) through the regressor form: the residual is
    Y(x, ν̇; k) π(p), k the known parameters (r, n_Y, n_P, g, slope), so

        ∂/∂p_j = Y ∂π/∂p_j + Σ_k (∂Y/∂k π) ∂k/∂p_j,

    exact given `check_regressor` and `check_inertial_parameters`; in the parameters alone."""
    Y = regressor()
    pi = sp.Matrix(inertial_parameters_from_general())
    out = Y * pi.jacobian(list(P.PARAMETERS))
    for k in KNOWN_PARAMETERS:
        j = P.PARAMETERS.index(k)
        out[:, j] = out[:, j] + Y.diff(k) * pi
    return out


def check_inertial_parameters():
    """The residues, all zero, of the general kernels' constants written through π: the constants
    of `general_constants_in_inertial` at π = `inertial_parameters_from_general` are those of
    robot.general_constants."""
    pi = dict(zip(INERTIAL_PARAMETERS, inertial_parameters_from_general()))
    through_pi = general_constants_in_inertial()
    residues = [sp.simplify(sp.expand(through_pi.get(s, s).xreplace(pi) - e)) for s, e in R.general_constants()]
    return [r for r in residues if r != 0]


def inertial_parameters_from_general():
    """π as expressions in PARAMETERS (mass, m·c, J + m(|c|² I − c cᵀ)): what a general robot's
    parameters give for INERTIAL_PARAMETERS."""
    def about_O(m, c, J):
        c = sp.Matrix(c)
        return sp.Matrix(J) + m * ((c.T * c)[0] * sp.eye(3) - c * c.T)
    out = []
    for body, m, k in (("Y", P.m_Y, P.k_Y), ("P", P.m_P, P.k_P)):
        c, J = P.vector(f"c_{body}"), P.tensor(f"J_{body}")
        JO = about_O(m, c, J)
        out += [m, *(m * c), JO[0, 0], JO[1, 1], JO[2, 2], JO[0, 1], JO[0, 2], JO[1, 2], k]
    return (P.m_S, P.j_S, P.k_S, *out, P.j_mY, P.j_mP)
