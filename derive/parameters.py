"""Physical parameters of the robot (Fiori 2024, Section 2.3 and Section 5.2).

Glossary (paper symbol -> Python name):

    r      shell radius [m]                      m_S   shell mass [kg]
    k_S    shell damping [N m s/rad]             b     yoke width (rods of length b lie along y) [m]
    h      yoke length (rods of length h lie along x) [m]
    m_b    mass of each b-rod [kg]               m_h   mass of each h-rod [kg]
    k_Y    yoke damping [N m s/rad]              l     pendulum length [m]
    m_P    pendulum mass [kg]                    k_P   pendulum damping [N m s/rad]
    g      gravitational acceleration [m/s^2]

The general robot (the C API's parameter vector, PARAMETERS):

    j_S    shell's isotropic inertia about its centre [kg m^2]
    m_Y, c_Y, J_Y   yoke mass, centre of mass (yoke frame, from the shell centre), inertia about it
    m_P, c_P, J_P   pendulum mass, centre of mass (pendulum frame, from the hinge at the centre), inertia
    j_mY, n_Y       yoke motor: rotor inertia about its axis, gear ratio (rotor on the shell)
    j_mP, n_P       pendulum motor: rotor inertia, gear ratio (rotor on the yoke)
    slope           inclination of the floor [rad]; the inertial frame lies in the plane, x up the slope

Derived constants (Section 2.3, eq. 35):

    j_S  = 2/3 m_S r^2            thin spherical shell, J_S = j_S I
    j_xx = (m_b/6 + m_h/2) b^2    yoke, about its x axis
    j_yy = (m_b/2 + m_h/6) h^2    yoke, about its y axis
    j_P  = 1/3 m_P l^2            pendulum rod about its pivot
    m_Y  = 2 (m_b + m_h)          yoke mass
    m_R  = m_S + m_Y + m_P        total mass (eq. 35)
    Ĵ_S  = j_S/2 I,  Ĵ_Y = diag(j_yy, j_xx, 0),  Ĵ_P = diag(0, 0, j_P)   (eq. 13)
    c̄_P  = -l/2 e_z               pendulum centre of mass in the pendulum frame

All damping coefficients here are *physical*: a coefficient k produces the
torque -k·ω.  (The paper pairs its forces with tr(AᵀB), which doubles them;
``runtime.Params.paper_simulation()`` carries that factor, not this module.)
"""
import sympy as sp

r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g = sp.symbols(
    "r m_S k_S b h m_b m_h k_Y l m_P k_P g", positive=True)

#: The paper's twelve parameters (Section 5.2), in the order of the SR_PAPER_* indices.
PAPER_PARAMETERS = (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g)

# Derived constants appear in the model as symbols of their own, so that the
# generated kernels read like the paper and the constants are computed once
# per parameter set (by the generated `sr_gen_constants`).
j_S, j_xx, j_yy, j_P, m_Y, m_R = sp.symbols("j_S j_xx j_yy j_P m_Y m_R", positive=True)

# The general robot (derive/robot.py): every body by its mass, centre of mass and
# standard inertia tensor about that centre, plus the motors' rotors and the slope.
j_mY, n_Y, j_mP, n_P, slope = sp.symbols("j_mY n_Y j_mP n_P slope", real=True)
_TENSOR_ENTRIES = ("xx", "yy", "zz", "xy", "xz", "yz")


def vector(name):
    """The parameters name_x, name_y, name_z (a centre of mass, in its body's frame) as a column."""
    return sp.Matrix(sp.symbols(f"{name}_x {name}_y {name}_z", real=True))


def tensor(name):
    """The symmetric 3×3 standard inertia tensor of parameters name_xx .. name_yz (about the centre of mass)."""
    s = {k: sp.Symbol(f"{name}_{k}", real=True) for k in _TENSOR_ENTRIES}
    return sp.Matrix([[s["xx"], s["xy"], s["xz"]], [s["xy"], s["yy"], s["yz"]], [s["xz"], s["yz"], s["zz"]]])


def _tensor_symbols(name):
    T = tensor(name)
    return (T[0, 0], T[1, 1], T[2, 2], T[0, 1], T[0, 2], T[1, 2])


#: The parameters of the C API (SR_P_*), in order: the general robot.
PARAMETERS = (r, m_S, j_S, k_S, m_Y, *vector("c_Y"), *_tensor_symbols("J_Y"), k_Y,
              m_P, *vector("c_P"), *_tensor_symbols("J_P"), k_P, j_mY, n_Y, j_mP, n_P, g, slope)


def derived_constants():
    """Section 2.3 and eq. (35): derived constant -> expression in the paper's parameters."""
    return {
        j_S: sp.Rational(2, 3) * m_S * r**2,
        j_xx: (m_b / 6 + m_h / 2) * b**2,
        j_yy: (m_b / 2 + m_h / 6) * h**2,
        j_P: m_P * l**2 / 3,
        m_Y: 2 * (m_b + m_h),
        m_R: m_S + 2 * (m_b + m_h) + m_P,
    }


def from_paper():
    """Each of PARAMETERS as an expression in PAPER_PARAMETERS: the paper's robot (Section 2.3) as a
    general one.  The yoke's four rods lie in its x-y plane, so J_Y = diag(j_xx, j_yy, j_xx + j_yy);
    the pendulum is a slender rod of length l hanging from O: c_P = −(l/2) e_z and
    J_P = (m_P l²/12) diag(1, 1, 0); the motors are massless, the floor level."""
    d = derived_constants()
    values = {j_S: d[j_S], m_Y: d[m_Y]}
    values.update(zip(_tensor_symbols("J_Y"), (d[j_xx], d[j_yy], d[j_xx] + d[j_yy], 0, 0, 0)))
    values.update(zip(vector("c_Y"), (0, 0, 0)))
    values.update(zip(vector("c_P"), (0, 0, -l / 2)))
    values.update(zip(_tensor_symbols("J_P"), (m_P * l**2 / 12, m_P * l**2 / 12, 0, 0, 0, 0)))
    values.update({j_mY: 0, n_Y: 1, j_mP: 0, n_P: 1, slope: 0})
    return tuple(sp.sympify(values.get(p, p)) for p in PARAMETERS)


#: Constants the paper-geometry kernels read, in the order of the generated constants array.
CONSTANTS = (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P)


def constant_expressions():
    """Each entry of CONSTANTS as an expression in PARAMETERS, for a robot of the paper's geometry
    (c_Y = 0, J_Y_zz = J_Y_xx + J_Y_yy, c_P and the pendulum's axis along z, no rotors, no slope:
    the conditions under which sr_model_init selects these kernels)."""
    c_Pz = vector("c_P")[2]
    values = {l: -2 * c_Pz, m_R: m_S + m_Y + m_P, j_xx: tensor("J_Y")[0, 0], j_yy: tensor("J_Y")[1, 1],
              j_P: tensor("J_P")[0, 0] + m_P * c_Pz**2}
    return [values.get(c, c) for c in CONSTANTS]


def e_z():
    return sp.Matrix([0, 0, 1])


def Jhat_S():
    """Non-standard inertia tensor of the shell, Ĵ_S = ½ j_S I (Section 2.3)."""
    return j_S / 2 * sp.eye(3)


def Jhat_Y():
    """Non-standard inertia tensor of the yoke, Ĵ_Y = diag(j_yy, j_xx, 0) (Section 2.3)."""
    return sp.diag(j_yy, j_xx, 0)


def Jhat_P():
    """Non-standard inertia tensor of the pendulum about its pivot, Ĵ_P = diag(0, 0, j_P)."""
    return sp.diag(0, 0, j_P)


def cbar_P():
    """Pendulum centre of mass in the pendulum frame, c̄_P = -l/2 e_z (Section 2.3)."""
    return -l / 2 * e_z()
