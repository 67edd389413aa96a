"""Sensor models in matrix form: what an IMU, the joint encoders, a position fix and a heading sensor read.

Frames.  The inertial frame lies in the floor's plane, x up the slope and z along its normal
(docs/robots.md); gravity there is g⃗ = −(g_x e_x + g_z e_z) with g_x = g sin(slope),
g_z = g cos(slope) (derive/robot.py).  A sensor is mounted on a body B, whose attitude is

    R_B = R_S Q_B,   Q_shell = I,  Q_yoke = R_Y,  Q_pendulum = R_Y R_P,

at a lever arm ρ (B frame, from the shell centre O = q, where both hinges sit) with the mounting
rotation R_m (the sensor's axes in B's frame).  The shell attitude enters through its rows
χ = R_Sᵀ e_x, η = R_Sᵀ e_y and γ = R_Sᵀ e_z, so every quantity below is an expression in the
symbols the kernels read from x.

    gyroscope       y_g = R_mᵀ ω_B + b_g,                 Ω_B = R_Bᵀ Ṙ_B
    accelerometer   y_a = R_mᵀ R_Bᵀ (p̈ − g⃗) + b_a,       p = q + R_B ρ   (specific force)
    encoders        (θ_Y, θ_P): the angles of R_Y about x and of R_P about y
    position fix    (q_x, q_y)
    heading         ψ = atan2(h_y, h_x) of h = R_B R_m e_x, the sensor's x axis in the inertial
                    frame, projected on the floor

The magnetometer is modelled as the heading it yields, not as the field vector in the sensor
frame: the field's dip and the disturbances of a robot's motors would make the vector's tilt
information wrong indoors, while the heading is what the estimator lacks (the IMU gives tilt).
Its derivative grows as 1/|h_xy| where the sensor's x axis nears the floor's normal; the C
wrapper refuses such states.

p̈ needs ν̇: the derivatives are taken with ν̇ held and along ν̇ separately, so that the caller
composes ∂h/∂δ = ∂h/∂δ|_ν̇ + ∂h/∂ν̇ Ja with the accel Jacobian Ja it already has.  The error
coordinates are those of derive/state.py ERROR_BLOCKS (x ⊕ d: R_S Exp(⟦δξ⟧), R_Y Exp(δθ_Y Σ_Y),
R_P Exp(δθ_P Σ_P), q + (δq, 0), ν + δν), followed by the biases b_g, b_a (ESTIMATOR_BLOCKS).
"""
import functools

import sympy as sp

from . import parameters as P
from . import robot as R
from . import state as S
from .dynamics import on_manifold

#: The bodies a sensor can be mounted on, in their code order (emitted as SR_BODY_<name>).
BODIES = ("shell", "yoke", "pendulum")

#: η = R_Sᵀ e_y, the second row of R_S (the heading needs all three rows), and q_y.
eta = sp.Matrix(sp.symbols("eta_x eta_y eta_z", real=True))
q_y = sp.Symbol("q_y", real=True)
#: Extra entries of x read by the sensor kernels (the rest are derive/state.py's STATE_LAYOUT).
STATE_LAYOUT = {eta[0]: S.OFFSET_RS + 3, eta[1]: S.OFFSET_RS + 4, eta[2]: S.OFFSET_RS + 5, q_y: S.OFFSET_Q + 1}

#: ν̇ = (ω̇_S, ω̇_Y, ω̇_P), the accelerations of derive/dynamics.py (an input: the kernels take it).
nu_dot = sp.Matrix(sp.symbols("a_Sx a_Sy a_Sz a_Y a_P", real=True))

#: The mount, a run-time array: the lever arm ρ (B frame) [m], then R_m row-major (sensor axes in B).
lever = sp.Matrix(sp.symbols("rho_x rho_y rho_z", real=True))
R_m = sp.Matrix(3, 3, sp.symbols("Rm_0:9", real=True))
MOUNT_BLOCKS = (("lever", 0, 3), ("R_m", 3, 9))
NMOUNT = 12
MOUNT_LAYOUT = {**{s: i for i, s in enumerate(lever)}, **{s: 3 + i for i, s in enumerate(R_m)}}

#: The IMU's biases (sensor frame): gyroscope [rad/s], then accelerometer [m/s²].
b_g = sp.Matrix(sp.symbols("b_gx b_gy b_gz", real=True))
b_a = sp.Matrix(sp.symbols("b_ax b_ay b_az", real=True))
BIAS_BLOCKS = (("b_g", 0, 3), ("b_a", 3, 3))
NBIAS = 6
BIAS_LAYOUT = {s: i for i, s in enumerate(list(b_g) + list(b_a))}

#: The IMU's measurement vector: gyroscope [rad/s], then accelerometer [m/s²], sensor frame.
IMU_BLOCKS = (("gyro", 0, 3), ("accel", 3, 3))
NIMU = 6

#: The estimator's error state: the 12 error coordinates of the state, then the biases.
ESTIMATOR_BLOCKS = S.ERROR_BLOCKS + (("b_g", S.NE, 3), ("b_a", S.NE + 3, 3))
NEB = S.NE + NBIAS

#: The shell radius and gravity's components in the floor's frame, the general robot's symbols.  The
#: sensor kernels read them from their own array sc (SR_SC_*), which sr_gen_sensor_constants fills
#: from the parameters: a model of either kind, and a firmware without the general kernels, has them.
radius, g_x, g_z = P.r, R.g_x, R.g_z
CONSTANTS = (radius, g_x, g_z)
NCONST = 3


def constant_expressions():
    """sc = (r, g sin(slope), g cos(slope)) from the parameters (derive/robot.py's general constants)."""
    named = dict(R.general_constants())
    return tuple(named[s] for s in CONSTANTS)


#: The joints from the shell to each body: (its one-axis rotation, the reconstruction rate Q̇ = Q Ω_j).
JOINTS = {"shell": (), "yoke": ((S.R_Y, S.Omega_Y),), "pendulum": ((S.R_Y, S.Omega_Y), (S.R_P, S.Omega_P))}


def to_body(body, v):
    """Q_Bᵀ v, one joint at a time (R_Pᵀ (R_Yᵀ v): the nested form the kernels evaluate)."""
    for R_j, _ in JOINTS[body]:
        v = R_j.T * v
    return v


def from_body(body, v):
    """Q_B v, one joint at a time (R_Y (R_P v))."""
    for R_j, _ in reversed(JOINTS[body]):
        v = R_j * v
    return v


def configuration_rates(dR_Y, dR_P, dgamma, dchi, deta):
    """Rates of the configuration symbols (η as well as state.configuration_rates' γ, χ, R_Y, R_P)."""
    rates = S.configuration_rates(dR_Y, dR_P, dgamma, dchi)
    rates.update({e: deta[i] for i, e in enumerate(eta)})
    return rates


def time_rates():
    """Ṙ_Y = R_Y Ω_Y, Ṙ_P = R_P Ω_P, and every row c of R_S advected as ċ = −Ω_S c."""
    return configuration_rates(S.R_Y * S.Omega_Y, S.R_P * S.Omega_P,
                               -S.Omega_S * S.gamma, -S.Omega_S * S.chi, -S.Omega_S * eta)


def time_derivative(expr):
    """d/dt of an expression of the configuration and ν, along the motion (ν̇ = nu_dot)."""
    rate = S.directional_derivative(expr, time_rates())
    return rate + sum((sp.diff(expr, n) * a for n, a in zip(S.nu, nu_dot)), sp.Integer(0))


_PARENT = sp.Matrix(sp.symbols("W_x W_y W_z", real=True))


@functools.lru_cache(maxsize=None)
def angular_velocity(body):
    """ω_B, the body's angular velocity in its own frame, from Ω_B = R_Bᵀ Ṙ_B joint by joint:
    for R = R' Q with Ṙ' = R' Ω', Q̇ = Q Ω_j,  RᵀṘ = Qᵀ Ω' Q + Qᵀ Q Ω_j, reduced on the manifold
    (QᵀQ = I) with the parent's ω' kept as a symbol, then substituted (a nested form)."""
    w = S.w_S
    for R_j, Omega_j in JOINTS[body]:
        Omega = R_j.T * S.hat(_PARENT) * R_j + R_j.T * R_j * Omega_j
        step = S.vee(Omega.applyfunc(on_manifold))
        w = step.xreplace(dict(zip(_PARENT, w)))
    return w


@functools.lru_cache(maxsize=None)
def angular_acceleration(body):
    """ω̇_B = d/dt ω_B (B frame), through the configuration's rates and ν̇."""
    return angular_velocity(body).applyfunc(time_derivative)


def centre_velocity():
    """R_Sᵀ q̇ = r Ω_S γ: rolling without slipping (the paper's q̇ = r R_S Ω_S γ, Section 2.6)."""
    return radius * S.Omega_S * S.gamma


@functools.lru_cache(maxsize=None)
def centre_acceleration():
    """R_Sᵀ q̈ = Ω_S v + v̇ for q̇ = R_S v (Ṙ_S = R_S Ω_S), expanded (the Ω_S² terms cancel)."""
    v = centre_velocity()
    return (S.Omega_S * v + v.applyfunc(time_derivative)).applyfunc(sp.expand)


def gravity_in_shell_frame():
    """R_Sᵀ g⃗ = −(g_x χ + g_z γ)."""
    return -(g_x * S.chi + g_z * S.gamma)


def specific_force(body):
    """R_Bᵀ (p̈ − g⃗) for p = q + R_B ρ: what an ideal accelerometer on B at ρ reads in B's axes
    (+g upwards at rest).  R_Bᵀ p̈ is the centre's acceleration plus the tangential (ω̇_B × ρ) and
    centripetal (ω_B × (ω_B × ρ)) terms: R_Bᵀ d²/dt²(R_B ρ) = (⟦ω̇_B⟧ + ⟦ω_B⟧²) ρ."""
    w, dw = angular_velocity(body), angular_acceleration(body)
    centre = to_body(body, centre_acceleration() - gravity_in_shell_frame())
    return centre + S.hat(dw) * lever + S.hat(w) * (S.hat(w) * lever)


@functools.lru_cache(maxsize=None)
def imu(body):
    """(y_g, y_a) stacked (6): R_mᵀ ω_B + b_g and R_mᵀ R_Bᵀ (p̈ − g⃗) + b_a."""
    y_g = R_m.T * angular_velocity(body) + b_g
    y_a = R_m.T * specific_force(body) + b_a
    return sp.Matrix.vstack(y_g, y_a)


def encoders():
    """(θ_Y, θ_P): R_Y = rot_x(θ_Y), R_P = rot_y(θ_P)."""
    return sp.Matrix([sp.atan2(S.RY_s, S.RY_c), sp.atan2(S.RP_s, S.RP_c)])


def position():
    """(q_x, q_y): the shell centre on the floor (inertial frame)."""
    return sp.Matrix([S.q_x, q_y])


def heading_vector(body):
    """(h_x, h_y): the sensor's x axis h = R_B R_m e_x = R_S (Q_B R_m e_x) on the floor's axes
    (h_x = χ · Q_B R_m e_x, h_y = η · Q_B R_m e_x)."""
    a = from_body(body, R_m[:, 0])
    return sp.Matrix([S.chi.dot(a), eta.dot(a)])


def heading(body):
    """ψ = atan2(h_y, h_x): the heading of the sensor's x axis, counter-clockwise from the
    inertial x axis (up the slope) about the floor's normal."""
    h = heading_vector(body)
    return sp.Matrix([sp.atan2(h[1], h[0])])


# ---- Derivatives in the estimator's error coordinates -------------------------------------------

def configuration_directions():
    """Rates of the configuration symbols along δξ_x, δξ_y, δξ_z, δθ_Y, δθ_P (unit steps):
    R_S → R_S Exp(⟦δξ⟧) moves each row c of R_S as c → Exp(−⟦δξ⟧) c."""
    none, still = sp.zeros(3, 3), sp.zeros(3, 1)
    units = [S.hat([int(i == k) for i in range(3)]) for k in range(3)]
    directions = [configuration_rates(none, none, -E * S.gamma, -E * S.chi, -E * eta) for E in units]
    directions.append(configuration_rates(S.R_Y * S.Sigma_Y, none, still, still, still))
    directions.append(configuration_rates(none, S.R_P * S.Sigma_P, still, still, still))
    return directions


def error_jacobian(h):
    """∂h/∂(δ, b_g, b_a) (rows of h × NEB) at d = 0 with ν̇ held: the configuration along its
    group directions, q and ν additively (δq moves q_x, q_y), the biases additively."""
    xi_x, xi_y, xi_z, th_Y, th_P = configuration_directions()
    columns = [h.applyfunc(lambda e, rates=rates: S.directional_derivative(e, rates))
               for rates in (xi_x, xi_y, xi_z, th_Y, th_P)]
    columns += [h.diff(S.q_x), h.diff(q_y)] + [h.diff(n) for n in S.nu] + [h.diff(b) for b in list(b_g) + list(b_a)]
    return sp.Matrix.hstack(*columns)


def nu_dot_jacobian(h):
    """∂h/∂ν̇ (rows of h × 5): for ∂h/∂δ = ∂h/∂δ|_ν̇ + ∂h/∂ν̇ Ja."""
    return h.jacobian(nu_dot)


@functools.lru_cache(maxsize=None)
def imu_jacobians(body):
    """(∂y/∂(δ, b) with ν̇ held (6 × NEB), ∂y/∂ν̇ (6 × 5)) of the IMU on `body`."""
    y = imu(body)
    return error_jacobian(y), nu_dot_jacobian(y)


def heading_jacobian(body):
    """∂ψ/∂(δ, b) (1 × NEB): (h_x ∂h_y − h_y ∂h_x) / (h_x² + h_y²)."""
    h = heading_vector(body)
    dh = error_jacobian(h)
    return ((h[0] * dh[1, :] - h[1] * dh[0, :]) / (h[0] ** 2 + h[1] ** 2))


def encoders_jacobian():
    """∂(θ_Y, θ_P)/∂(δ, b) (2 × NEB); reduced with cos² + sin² = 1, exact on valid states."""
    unit = {S.RY_c ** 2: 1 - S.RY_s ** 2, S.RP_c ** 2: 1 - S.RP_s ** 2}
    return error_jacobian(encoders()).applyfunc(lambda e: sp.simplify(sp.expand(e).subs(unit)))


def position_jacobian():
    """∂(q_x, q_y)/∂(δ, b) (2 × NEB)."""
    return error_jacobian(position())
