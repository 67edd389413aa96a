"""The bodies of the robot as the Lagrangian sees them: the paper's robot and the general one.

Both hinges sit at the shell centre O, so every body enters the kinetic and
potential energies through its mass, its first moment about O and its
non-standard inertia tensor about O (Section 2.3):

    h   = m c                    first moment, c the centre of mass in the body frame
    Ĵ_O = Ĵ_c + m c cᵀ           Ĵ = ∫ρρᵀ dm = ½ tr(J) I − J for the standard tensor J

so ½ tr(W R Ĵ_O Rᵀ Wᵀ) is the body's rotational energy about O and m vᵀ W R c
its coupling with the translation of O (eqs. 10, 25, 31).  A `Robot` holds
these quantities as SymPy expressions in the symbols of the kernels that
evaluate them: `PAPER` in the paper's derived constants (j_xx, j_P, l, ...),
`GENERAL` in the per-model constants that `general_constants` computes from
the parameters of `derive.parameters.PARAMETERS`.

Glossary of the general robot (`derive.parameters` for the symbols):

    j_S          shell's isotropic inertia about O          g_x, g_z   g sin(slope), g cos(slope)
    h_Y, Ĵ_Y     yoke's first moment and tensor about O     j_mY, n_Y  yoke motor rotor (on the shell)
    h_P, Ĵ_P     pendulum's first moment and tensor about O j_mP, n_P  pendulum motor rotor (on the yoke)
"""
import dataclasses

import sympy as sp

from . import parameters as P


@dataclasses.dataclass(frozen=True)
class Robot:
    """One robot of the yoke–pendulum architecture, as the Lagrangian needs it (all SymPy)."""
    name: str
    r: sp.Expr
    m_R: sp.Expr               # total (rolling) mass m_S + m_Y + m_P, eq. (35)
    m_P: sp.Expr               # the pendulum's mass (the energy's m_P g_z q_z, see lagrangian.total_energy)
    Jhat_S: sp.ImmutableMatrix  # shell, about O
    h_Y: sp.ImmutableMatrix     # yoke: first moment about O, yoke frame
    Jhat_Y: sp.ImmutableMatrix  # yoke: non-standard tensor about O, yoke frame
    h_P: sp.ImmutableMatrix     # pendulum: first moment about O, pendulum frame
    Jhat_P: sp.ImmutableMatrix  # pendulum: non-standard tensor about O, pendulum frame
    j_mY: sp.Expr
    n_Y: sp.Expr
    j_mP: sp.Expr
    n_P: sp.Expr
    g_x: sp.Expr               # gravity is −(g_x e_x + g_z e_z) in the plane's frame
    g_z: sp.Expr
    k_S: sp.Expr
    k_Y: sp.Expr
    k_P: sp.Expr


def _symmetric(name):
    """A symmetric 3×3 matrix of symbols name_xx, name_yy, name_zz, name_xy, name_xz, name_yz."""
    s = {k: sp.Symbol(f"{name}_{k}", real=True) for k in ("xx", "yy", "zz", "xy", "xz", "yz")}
    return sp.ImmutableMatrix([[s["xx"], s["xy"], s["xz"]], [s["xy"], s["yy"], s["yz"]], [s["xz"], s["yz"], s["zz"]]])


def _vector(name):
    return sp.ImmutableMatrix(sp.symbols(f"{name}_x {name}_y {name}_z", real=True))


def pivot_tensor(m, c, J):
    """Ĵ_O = ½ tr(J) I − J + m c cᵀ: the non-standard tensor about O of a body with mass m, centre c,
    standard tensor J about its centre (Section 2.3's Ĵ, moved by the parallel-axis theorem)."""
    J = sp.Matrix(J)
    return sp.ImmutableMatrix(J.trace() / 2 * sp.eye(3) - J + m * sp.Matrix(c) * sp.Matrix(c).T)


PAPER = Robot(
    name="paper", r=P.r, m_R=P.m_R, m_P=P.m_P,
    Jhat_S=sp.ImmutableMatrix(P.Jhat_S()),
    h_Y=sp.ImmutableMatrix([0, 0, 0]), Jhat_Y=sp.ImmutableMatrix(P.Jhat_Y()),
    h_P=sp.ImmutableMatrix(P.m_P * P.cbar_P()), Jhat_P=sp.ImmutableMatrix(P.Jhat_P()),
    j_mY=sp.Integer(0), n_Y=sp.Integer(1), j_mP=sp.Integer(0), n_P=sp.Integer(1),
    g_x=sp.Integer(0), g_z=P.g, k_S=P.k_S, k_Y=P.k_Y, k_P=P.k_P)

#: The per-model constants of the general kernels, computed from the parameters by the generated
#: sr_gen_general_constants: first moments and tensors about O, the total mass, gravity's components.
m_R_general, g_x, g_z = sp.symbols("m_R g_x g_z", real=True)
h_Y, h_P = _vector("h_Y"), _vector("h_P")
Jhat_Y, Jhat_P = _symmetric("Jh_Y"), _symmetric("Jh_P")

GENERAL = Robot(
    name="general", r=P.r, m_R=m_R_general, m_P=P.m_P,
    Jhat_S=sp.ImmutableMatrix(P.j_S / 2 * sp.eye(3)),
    h_Y=h_Y, Jhat_Y=Jhat_Y, h_P=h_P, Jhat_P=Jhat_P,
    j_mY=P.j_mY, n_Y=P.n_Y, j_mP=P.j_mP, n_P=P.n_P,
    g_x=g_x, g_z=g_z, k_S=P.k_S, k_Y=P.k_Y, k_P=P.k_P)


def _upper(M):
    return [M[0, 0], M[1, 1], M[2, 2], M[0, 1], M[0, 2], M[1, 2]]


def general_constants():
    """(symbol, expression in the parameters) of the general kernels' named constants, in array order."""
    J_Y, J_P = P.tensor("J_Y"), P.tensor("J_P")
    c_Y, c_P = P.vector("c_Y"), P.vector("c_P")
    pairs = [(P.r, P.r), (m_R_general, P.m_S + P.m_Y + P.m_P), (P.m_P, P.m_P), (P.j_S, P.j_S),
             (P.k_S, P.k_S), (P.k_Y, P.k_Y), (P.k_P, P.k_P)]
    pairs += list(zip(h_Y, P.m_Y * c_Y)) + list(zip(h_P, P.m_P * c_P))
    pairs += list(zip(_upper(Jhat_Y), _upper(pivot_tensor(P.m_Y, c_Y, J_Y))))
    pairs += list(zip(_upper(Jhat_P), _upper(pivot_tensor(P.m_P, c_P, J_P))))
    pairs += [(P.j_mY, P.j_mY), (P.n_Y, P.n_Y), (P.j_mP, P.j_mP), (P.n_P, P.n_P),
              (g_x, P.g * sp.sin(P.slope)), (g_z, P.g * sp.cos(P.slope))]
    return tuple(pairs)


def robot(name):
    return {"paper": PAPER, "general": GENERAL}[name]
