"""Physical parameters of the robot (Fiori 2024, Section 2.3 and Section 5.2).

Glossary (paper symbol -> Python name):

    r      shell radius [m]                      m_S   shell mass [kg]
    k_S    shell damping [N m s/rad]             b     yoke width (rods of length b lie along y) [m]
    h      yoke length (rods of length h lie along x) [m]
    m_b    mass of each b-rod [kg]               m_h   mass of each h-rod [kg]
    k_Y    yoke damping [N m s/rad]              l     pendulum length [m]
    m_P    pendulum mass [kg]                    k_P   pendulum damping [N m s/rad]
    g      gravitational acceleration [m/s^2]

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

#: The twelve parameters in the order used by every generated function.
PARAMETERS = (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g)

# Derived constants appear in the model as symbols of their own, so that the
# generated kernels read like the paper and the constants are computed once
# per parameter set (by the generated `sr_gen_constants`).
j_S, j_xx, j_yy, j_P, m_Y, m_R = sp.symbols("j_S j_xx j_yy j_P m_Y m_R", positive=True)


def derived_constants():
    """Section 2.3 and eq. (35): derived constant -> expression in the parameters."""
    return {
        j_S: sp.Rational(2, 3) * m_S * r**2,
        j_xx: (m_b / 6 + m_h / 2) * b**2,
        j_yy: (m_b / 2 + m_h / 6) * h**2,
        j_P: m_P * l**2 / 3,
        m_Y: 2 * (m_b + m_h),
        m_R: m_S + 2 * (m_b + m_h) + m_P,
    }


#: Constants the kernels read, in the order of the generated constants array.
CONSTANTS = (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P)


def constant_expressions():
    """Each entry of CONSTANTS as an expression in PARAMETERS."""
    derived = derived_constants()
    return [derived.get(c, c) for c in CONSTANTS]


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
