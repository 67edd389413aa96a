"""The rolling contact, both sides: the reference's contact force, and the momentum balances of a motion.

Reference side (`ReferenceContact`): the reference's Lagrangian (runtime.verification.reference,
CasADi, same bodies and chart) with the centre height q_z made a coordinate too, so that all three
components of the contact-point velocity are constraints.  The Lagrange–d'Alembert equations with
multipliers,

    [ M   -Aᵀ ] [ s̈ ]   [ Q + ∂L/∂s − (∂/∂s ∂L/∂ṡ) ṡ ]
    [ A    0  ] [ λ ] = [ −(∂/∂s (A ṡ)) ṡ             ],      A ṡ = v_contact,

give λ, the force the ground exerts on the shell at the contact point (its virtual power is
λ·v_contact).  Like the reference, this imports neither derive/ nor the kernels.

Motion side (`momentum_residuals`): from a sampled motion (states at equal time steps, e.g. computed
by the C steppers), the bodies' momenta and angular momenta by rigid-body kinematics, differentiated
in time by an 8th-order central difference:

* total momentum:  dP/dt − m_tot g_vec   is the contact force the motion implies;
* angular momentum about the contact point c = q − r e_z (which moves with q̇):
  dH_c/dt + q̇ × P = Σ (p_i − c) × m_i g_vec − k_S R_S ω_S
  (the motor torques and the yoke and pendulum damping are internal; the shell's damping acts
  on it from outside; the contact force has no moment about c).
"""
import casadi as ca
import numpy as np

from .reference import (checked_params, STATE_DIM, ReferenceModel, _NU, _Q, _RP, _RS, _RY, _WP, _WS, _WY,
                        _expm_series, _mat_rowmajor, _rot_x, _rot_y, _time_derivative, _vee_skew)

#: 8th-order central first-derivative weights w_k for (f(t + k h) − f(t − k h)) / h.
_CENTRAL_8 = {1: 4 / 5, 2: -1 / 5, 3: 4 / 105, 4: -1 / 280}
DIFF_HALF_WIDTH = max(_CENTRAL_8)


class ReferenceContact:
    """Contact force of the independent reference at a state and input."""

    def __init__(self, params: dict):
        self._ref = ReferenceModel(params)        # checks the names; gives the bodies
        self.params = self._ref.params
        self._build()

    def _build(self):
        p = self.params
        r, k_S, k_Y, k_P = p["r"], p["k_S"], p["k_Y"], p["k_P"]
        ez = ca.DM([0, 0, 1])
        x0, u = ca.SX.sym("x", STATE_DIM), ca.SX.sym("u", 2)
        RS0, RY0, RP0 = _mat_rowmajor(x0[_RS]), _mat_rowmajor(x0[_RY]), _mat_rowmajor(x0[_RP])
        s, sd = ca.SX.sym("s", 8), ca.SX.sym("sd", 8)      # (φ, dθ_Y, dθ_P, dx, dy, dz)
        RS = RS0 @ _expm_series(s[0:3])
        frames = {"S": RS, "Y": RS @ RY0 @ _rot_x(s[3]), "mY": RS @ _rot_x(p["n_Y"] * s[3])}
        frames["P"] = frames["Y"] @ RP0 @ _rot_y(s[4])
        frames["mP"] = frames["Y"] @ _rot_y(p["n_P"] * s[4])
        gravity = ca.DM(gravity_vector(p))
        q = x0[_Q] + s[5:8]
        lagr = 0
        for body in self._ref._bodies():
            Rb = frames[body.frame]
            pos = q + Rb @ ca.DM(body.c_local)
            vel = ca.jtimes(pos, s, sd)
            w_body = _vee_skew(Rb.T @ _time_derivative(Rb, s, sd))
            lagr += 0.5 * body.mass * ca.dot(vel, vel) + 0.5 * ca.dot(w_body, ca.DM(body.inertia) @ w_body)
            lagr += body.mass * ca.dot(gravity, pos)
        wS = _vee_skew(RS.T @ _time_derivative(RS, s, sd))
        con = sd[5:8] + ca.cross(RS @ wS, -r * ez)         # the contact point's velocity, all of it
        A = ca.jacobian(con, sd)
        M, dL_dsd = ca.hessian(lagr, sd)
        Q = ca.jacobian(wS, sd).T @ (-k_S * wS)
        Q += ca.vertcat(0, 0, 0, u[0] - k_Y * sd[3], u[1] - k_P * sd[4], 0, 0, 0)
        kkt = ca.blockcat([[M, -A.T], [A, ca.SX.zeros(3, 3)]])
        rhs = ca.vertcat(Q + ca.gradient(lagr, s) - ca.jtimes(dL_dsd, s, sd), -ca.jtimes(con, s, sd))
        # At the base point s = 0 with ṡ = (ν, q̇) and q̇ from the constraint itself.
        zero_s, nu = ca.DM.zeros(8), x0[_NU]
        qdot = -ca.substitute(con, ca.vertcat(s, sd), ca.vertcat(zero_s, nu, 0, 0, 0))
        at_state = lambda e: ca.substitute(e, ca.vertcat(s, sd), ca.vertcat(zero_s, nu, qdot))  # noqa: E731
        self._f_kkt = ca.Function("contact_kkt", [x0, u], [at_state(kkt), at_state(rhs)])

    def force(self, x, u) -> np.ndarray:
        """Force (3,) of the ground on the shell at the contact point, inertial frame [N]."""
        K, rhs = self._f_kkt(np.asarray(x, dtype=float).reshape(STATE_DIM), np.asarray(u, dtype=float).reshape(2))
        return np.linalg.solve(np.asarray(K), np.asarray(rhs).reshape(-1))[8:11]


def _body_kinematics(X, params):
    """Per body and sample: mass, centre of mass p, its velocity v, and the angular momentum about it.

    X: states (n, 35).  Rigid-body kinematics only: Ω_S = R_S ω_S, Ω_Y = Ω_S + R_S R_Y e_x ω_Y,
    Ω_P = Ω_Y + R_S R_Y R_P e_y ω_P, q̇ = r Ω_S × e_z (rolling).
    """
    n = len(X)
    R_S, R_Y, R_P = (X[:, sl].reshape(n, 3, 3) for sl in (_RS, _RY, _RP))
    frames = {"S": R_S, "Y": R_S @ R_Y}
    frames["P"] = frames["Y"] @ R_P
    omega = {"S": np.einsum("nij,nj->ni", R_S, X[:, _WS])}
    omega["Y"] = omega["S"] + frames["Y"][:, :, 0] * X[:, [_WY]]
    omega["P"] = omega["Y"] + frames["P"][:, :, 1] * X[:, [_WP]]
    # The rotors' inertias are axial (about e_x, e_y of their carriers), so their frames' angles
    # about those axes do not matter: the carriers' frames, with the rotors' angular velocities.
    frames["mY"], frames["mP"] = frames["S"], frames["Y"]
    omega["mY"] = omega["S"] + frames["S"][:, :, 0] * (float(params["n_Y"]) * X[:, [_WY]])
    omega["mP"] = omega["Y"] + frames["Y"][:, :, 1] * (float(params["n_P"]) * X[:, [_WP]])
    q = X[:, _Q]
    qdot = params["r"] * np.cross(omega["S"], [0.0, 0.0, 1.0])
    bodies = []
    for body in ReferenceModel._bodies(_BodyParams(params)):
        F = frames[body.frame]
        arm = np.einsum("nij,j->ni", F, body.c_local)
        spin = np.einsum("nij,jk,nlk,nl->ni", F, body.inertia, F, omega[body.frame])   # F I Fᵀ Ω
        bodies.append((body.mass, q + arm, qdot + np.cross(omega[body.frame], arm), spin))
    return q, qdot, omega["S"], bodies


class _BodyParams:
    """Lets `ReferenceModel._bodies` (pure data: masses, inertias, centres) run without building CasADi."""

    def __init__(self, params):
        self.params = checked_params(params)


def gravity_vector(params):
    """-g (sin(slope), 0, cos(slope)): gravity in the plane's frame (x up the slope)."""
    return -float(params["g"]) * np.array([np.sin(float(params["slope"])), 0.0, np.cos(float(params["slope"]))])


def _derivative(values, dt):
    """d/dt of samples (n, ...) at the interior samples (n − 8, ...), 8th-order central difference."""
    k0 = DIFF_HALF_WIDTH
    n = len(values)
    return sum(w * (values[k0 + k:n - k0 + k] - values[k0 - k:n - k0 - k]) for k, w in _CENTRAL_8.items()) / dt


def momentum_residuals(X, dt, params):
    """For states X (n, 35) sampled every dt: (implied contact force, angular momentum residual), each (n − 8, 3).

    The first is dP/dt − m_tot g_vec, the contact force the motion implies; the second is
    dH_c/dt + q̇ × P − Σ (p_i − c) × m_i g_vec + k_S Ω_S, zero for a motion that obeys the physics.
    """
    X = np.asarray(X, dtype=float)
    params = checked_params(params)
    g_vec = gravity_vector(params)
    q, qdot, omega_S, bodies = _body_kinematics(X, params)
    contact = q - [0.0, 0.0, float(params["r"])]
    P = sum(m * v for m, _, v, _ in bodies)
    H_c = sum(np.cross(p - contact, m * v) + spin for m, p, v, spin in bodies)
    torque_c = sum(np.cross(p - contact, m * g_vec) for m, p, _, _ in bodies) - float(params["k_S"]) * omega_S
    inner = slice(DIFF_HALF_WIDTH, len(X) - DIFF_HALF_WIDTH)
    m_tot = sum(m for m, _, _, _ in bodies)
    force = _derivative(P, dt) - m_tot * g_vec
    angular = _derivative(H_c, dt) + np.cross(qdot[inner], P[inner]) - torque_c[inner]
    return force, angular
