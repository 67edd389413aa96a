"""Independent numerical reference model of the yoke-pendulum spherical robot.

This module is a *cross-check* for the main derivation: it rebuilds the
dynamics of the robot of S. Fiori (2024), Section 2.3, from classical rigid-body
mechanics, using CasADi automatic differentiation instead of hand-derived
(or paper-derived) equations of motion.  It imports only numpy, casadi, math
and the NumPy SO(3) helpers of ``runtime.so3`` (which import nothing else),
and shares no code with ``derive/``, ``generated/``, ``c/`` or ``bindings/``
(tests/runtime/test_imports.py checks this).  Its state layout and parameter
order below are its own, on purpose; tests/runtime/verification/test_tables.py
checks them against the generated SR_X_* and SR_P_* macros.

Conventions (binding contract)
------------------------------
State ``x`` (35 floats)::

    [R_S row-major (9) | R_Y row-major (9) | R_P row-major (9) | q (3) |
     omega_S (3) | omega_Y | omega_P]

* ``R_S`` maps shell-frame coordinates to inertial ones; ``omega_S`` is the
  shell angular velocity in the shell (body) frame, ``R_S^T dR_S/dt = hat(omega_S)``
  with ``hat(a) b = a x b``.
* ``R_Y`` is the yoke attitude relative to the shell, a rotation about x by
  theta_Y; ``omega_Y = d theta_Y/dt``.
* ``R_P`` is the pendulum attitude relative to the yoke, a rotation about y by
  theta_P; ``omega_P = d theta_P/dt``.
* ``q`` is the shell centre (inertial), ``q_z = r``; ground is z = 0, gravity
  is ``-g e_z``.  A yoke point ``p_Y`` sits at ``q + R_S R_Y p_Y``, a pendulum
  point ``p_P`` at ``q + R_S R_Y R_P p_P``.
* Input ``u = (u_Y, u_P)``: motor torques [N m], generalized forces on theta_Y
  and theta_P (the reactions on shell / yoke are internal).
* Damping: generalized force ``-k_S omega_S`` conjugate to the shell's
  body-frame virtual rotation, ``-k_Y omega_Y`` on theta_Y, ``-k_P omega_P`` on
  theta_P.
* Rolling without slipping: the shell's material point at ``q - r e_z`` has
  zero velocity, i.e. ``dq/dt = r (R_S omega_S) x e_z``.

Bodies
------
* Shell: thin spherical shell, mass m_S, radius r, centre q, central inertia
  (2/3) m_S r^2 I.
* Yoke: four thin uniform rods in the yoke x-y plane, each treated as its own
  rigid body: two of length b / mass m_b parallel to y at x = +-h/2, two of
  length h / mass m_h parallel to x at y = +-b/2 (this reproduces the paper's
  j_xx = (m_b/6 + m_h/2) b^2 and j_yy = (m_b/2 + m_h/6) h^2).
* Pendulum: thin uniform rod, length l, mass m_P, from the shell centre along
  the pendulum -z axis (centre of mass at -(l/2) e_z in the pendulum frame).
* A thin rod of mass m, length L along the unit axis a has central inertia
  (m L^2 / 12)(I - a a^T).

Method
------
Generalized coordinates ``s = (phi (3), dth_Y, dth_P, dx, dy)`` form a local
chart around the current state x0::

    R_S(s) = R_S0 expm(hat(phi)),  R_Y(s) = R_Y0 Rx(dth_Y),
    R_P(s) = R_P0 Ry(dth_P),       q(s) = q0 + (dx, dy, 0),

evaluated at s = 0.  The Lagrangian ``L(s, sdot) = sum_bodies [1/2 m |v_cm|^2
+ 1/2 w_b^T I_b w_b - m g z_cm]`` is written from the body kinematics only:
``v_cm = d/dt p_cm(s)`` and ``hat(w_b) = R_b^T dR_b/dt`` (skew part), both by
CasADi forward differentiation along ``sdot``.  The Lagrange-d'Alembert
equations with multipliers for the rolling constraint ``A(s) sdot = 0``
(horizontal components of the contact-point velocity
``v_c = dq/dt + (R_S w_S) x (-r e_z)``) read::

    [ M   -A^T ] [ sddot  ]   [ Q + dL/ds - (d/ds dL/dsdot) sdot ]
    [ A    0   ] [ lambda ] = [ -(d/ds (A sdot)) sdot            ]

with ``M = d^2 L / dsdot^2`` and every derivative obtained by CasADi AD.  The
generalized forces Q come from the virtual work of the torques and damping,
``Q_phi = (d w_S / d phidot)^T (-k_S w_S)``.

At phi = 0 the right-trivialised exponential chart satisfies
``w_S = phidot`` and ``d w_S/dt = phiddot`` (because
``w_S = (I - hat(phi)/2 + O(phi^2)) phidot``, and the correction term
``-(1/2) hat(phidot) phidot`` vanishes).  The code nevertheless applies the
exact conversion ``d w_S/dt = (d w_S/d sdot) sddot + (d w_S/d s) sdot``, whose
identity at phi = 0 is asserted by the tests (see ``chart_check``).

``expm`` is replaced by its Taylor polynomial of degree 4,
``I + H + H^2/2 + H^3/6 + H^4/24``: only derivatives of order <= 2 at phi = 0
enter the equations, and those are exact (the polynomial has no singular
sin(t)/t term, so AD is well defined at phi = 0).

The constraint-acceleration term ``(d/ds (A sdot)) sdot`` is computed by AD
but vanishes at phi = 0 for this chart (it is proportional to
``phidot x phidot``), consistent with ``d(R_S omega_S)/dt = R_S d omega_S/dt``
for the inertial angular velocity of the shell.

The mass matrix in the constrained velocities ``nu = (omega_S, omega_Y,
omega_P)`` (``inertia``) is the Hessian of the kinetic energy after
substituting ``dq/dt`` from the rolling constraint.

Public API
----------
``ReferenceModel(params)`` with ``accel(x, u)``, ``inertia(x)``, ``energy(x)``,
``contact_point_velocity(x, qdot=None)``, plus the conveniences
``centre_velocity(x)``, ``state_derivative(x, u)`` (full 35-element dx/dt for
ODE integrators) and ``chart_check(x)``; module helper ``make_state(...)``.
Each ``ReferenceModel`` builds its CasADi functions once, with the parameters
baked in as constants (about 0.1 s); ``accel`` costs about 0.15 ms.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ..so3 import hat as _hat_np
from ..so3 import rot_x as _rot_x_np
from ..so3 import rot_y as _rot_y_np

#: The general robot: scalars, c_* 3-vectors, J_* 3x3 tensors about the centre of mass.
PARAM_NAMES = ("r", "m_S", "j_S", "k_S", "m_Y", "c_Y", "J_Y", "k_Y", "m_P", "c_P", "J_P", "k_P",
               "j_mY", "n_Y", "j_mP", "n_P", "g", "slope")
#: The flat parameter vector of `ReferenceModel.parametric`: c_* by x, y, z, J_* by xx, yy, zz, xy, xz, yz.
FLAT_PARAM_NAMES = tuple(
    n for name in PARAM_NAMES for n in (
        [f"{name}_{a}" for a in "xyz"] if name in ("c_Y", "c_P") else
        [f"{name}_{k}" for k in ("xx", "yy", "zz", "xy", "xz", "yz")] if name in ("J_Y", "J_P") else [name]))
#: The paper's robot (Section 5.2), built here from its rods (`paper_robot`).
PAPER_PARAM_NAMES = ("r", "m_S", "k_S", "b", "h", "m_b", "m_h", "k_Y", "l", "m_P", "k_P", "g")

STATE_DIM = 35
# Slices of the state vector.
_RS, _RY, _RP = slice(0, 9), slice(9, 18), slice(18, 27)
_Q, _WS, _WY, _WP = slice(27, 30), slice(30, 33), 33, 34
_NU = slice(30, 35)


# --------------------------------------------------------------------------- #
# Small symbolic helpers
# --------------------------------------------------------------------------- #
def _hat(a):
    """Skew matrix with hat(a) b = a x b."""
    return ca.vertcat(
        ca.horzcat(0, -a[2], a[1]),
        ca.horzcat(a[2], 0, -a[0]),
        ca.horzcat(-a[1], a[0], 0),
    )


def _vee_skew(m):
    """Vector of the skew-symmetric part of a 3x3 matrix (inverse of _hat)."""
    return 0.5 * ca.vertcat(m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1])


def _expm_series(phi):
    """exp(hat(phi)) to degree 4 in phi: derivatives up to 4th order exact at 0."""
    h = _hat(phi)
    h2 = h @ h
    return ca.SX.eye(3) + h + h2 / 2 + (h2 @ h) / 6 + (h2 @ h2) / 24


def _rot_x(t):
    c, s = ca.cos(t), ca.sin(t)
    return ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, c, -s), ca.horzcat(0, s, c))


def _rot_y(t):
    c, s = ca.cos(t), ca.sin(t)
    return ca.vertcat(ca.horzcat(c, 0, s), ca.horzcat(0, 1, 0), ca.horzcat(-s, 0, c))


def _mat_rowmajor(v):
    """3x3 SX matrix from a 9-vector stored row-major."""
    return ca.reshape(v, 3, 3).T


def _time_derivative(expr, s, sdot):
    """d/dt expr(s) = (d expr/ds) sdot, for a matrix/vector expression."""
    flat = ca.vec(expr)
    return ca.reshape(ca.jtimes(flat, s, sdot), expr.shape[0], expr.shape[1])


def _casadi(value):
    """A CasADi matrix of value: a number array as DM, a CasADi expression as it is."""
    return value if isinstance(value, (ca.SX, ca.DM)) else ca.DM(value)


class _Body:
    """A rigid body: mass, central inertia in its own frame, and kinematic maps."""

    def __init__(self, mass, inertia_body, c_local, frame):
        self.mass = mass            # float
        self.inertia = inertia_body  # 3x3 numpy, about the centre of mass
        self.c_local = c_local      # centre of mass in `frame` coordinates
        self.frame = frame          # 'S', 'Y', 'P', or a motor rotor's: 'mY', 'mP'


def paper_robot(paper):
    """The paper's robot from its twelve parameters, by composing its rods (Section 2.3) with the
    parallel-axis theorem here, independently of the kernels' conversion (derive/parameters.py):
    a general parameter dict for ReferenceModel."""
    r, mS, b, h, mb, mh, l, mP = (float(paper[k]) for k in ("r", "m_S", "b", "h", "m_b", "m_h", "l", "m_P"))
    ex, ey, ez = np.eye(3)

    def rod(m, length, axis, centre):
        """(mass, first moment, inertia about the yoke's origin) of a thin uniform rod."""
        centre = np.asarray(centre, dtype=float)
        about_centre = m * length**2 / 12.0 * (np.eye(3) - np.outer(axis, axis))
        return m, m * centre, about_centre + m * (centre @ centre * np.eye(3) - np.outer(centre, centre))

    rods = [rod(mb, b, ey, +h / 2 * ex), rod(mb, b, ey, -h / 2 * ex),
            rod(mh, h, ex, +b / 2 * ey), rod(mh, h, ex, -b / 2 * ey)]
    m_Y = sum(m for m, _, _ in rods)
    c_Y = sum(moment for _, moment, _ in rods) / m_Y
    J_Y = sum(J for _, _, J in rods) - m_Y * (c_Y @ c_Y * np.eye(3) - np.outer(c_Y, c_Y))
    return {"r": r, "m_S": mS, "j_S": 2.0 / 3.0 * mS * r**2, "k_S": float(paper["k_S"]),
            "m_Y": m_Y, "c_Y": c_Y, "J_Y": J_Y, "k_Y": float(paper["k_Y"]),
            "m_P": mP, "c_P": -l / 2 * ez, "J_P": mP * l**2 / 12.0 * (np.eye(3) - np.outer(ez, ez)),
            "k_P": float(paper["k_P"]), "j_mY": 0.0, "n_Y": 1.0, "j_mP": 0.0, "n_P": 1.0,
            "g": float(paper["g"]), "slope": 0.0}


def checked_params(params):
    """The general parameter dict (floats, (3,) and (3, 3) arrays) from params: a dict of the
    general names, or of the paper's twelve (then built by `paper_robot`)."""
    if set(params) == set(PAPER_PARAM_NAMES):
        params = paper_robot(params)
    missing = [k for k in PARAM_NAMES if k not in params]
    extra = [k for k in params if k not in PARAM_NAMES]
    if missing or extra:
        raise ValueError(f"bad parameter set: missing={missing}, unknown={extra}")
    shapes = {"c_Y": (3,), "c_P": (3,), "J_Y": (3, 3), "J_P": (3, 3)}
    out = {}
    for k in PARAM_NAMES:
        value = np.asarray(params[k], dtype=float)
        if value.shape != shapes.get(k, ()):
            raise ValueError(f"bad parameter {k}: shape {value.shape}, expected {shapes.get(k, ())}")
        out[k] = value if k in shapes else float(value)
    return out


# --------------------------------------------------------------------------- #
# Reference model
# --------------------------------------------------------------------------- #
class ReferenceModel:
    """Spherical robot dynamics from a CasADi-differentiated Lagrangian.

    Parameters
    ----------
    params : dict
        The general robot's parameters named in ``PARAM_NAMES`` (SI units; c_* of shape (3,),
        J_* of shape (3, 3)), or the paper's twelve of ``PAPER_PARAM_NAMES`` (built from rods
        by ``paper_robot``).

    All public methods take the 35-element state described in the module
    docstring and return numpy arrays.
    """

    def __init__(self, params: dict):
        #: The paper's twelve parameters when the robot was given by them, else None.
        self.paper = {k: float(params[k]) for k in PAPER_PARAM_NAMES} if set(params) == set(PAPER_PARAM_NAMES) else None
        self.params = checked_params(params)
        self._build()

    @classmethod
    def parametric(cls):
        """The model with its parameters as a CasADi symbol p (the flat vector of
        `FLAT_PARAM_NAMES`): only `parametric_accel` is available on it."""
        model = cls.__new__(cls)
        model.paper = None
        p = ca.SX.sym("p", len(FLAT_PARAM_NAMES))
        entries = dict(zip(FLAT_PARAM_NAMES, ca.vertsplit(p)))
        params = {}
        for name in PARAM_NAMES:
            if name in ("c_Y", "c_P"):
                params[name] = ca.vertcat(*(entries[f"{name}_{a}"] for a in "xyz"))
            elif name in ("J_Y", "J_P"):
                e = {k: entries[f"{name}_{k}"] for k in ("xx", "yy", "zz", "xy", "xz", "yz")}
                params[name] = ca.vertcat(ca.horzcat(e["xx"], e["xy"], e["xz"]), ca.horzcat(e["xy"], e["yy"], e["yz"]),
                                          ca.horzcat(e["xz"], e["yz"], e["zz"]))
            else:
                params[name] = entries[name]
        model.params = params
        model._p = p
        model._build(parameters=(p,))
        return model

    def parametric_accel(self):
        """SX (x, u, p, accel): the accelerations of a `parametric` model as an expression in fresh
        symbols x (35), u (2) and its p, for AD in the parameters."""
        x, u = ca.SX.sym("x", STATE_DIM), ca.SX.sym("u", 2)
        K, rhs = self._f_kkt(x, u, self._p)
        sol = ca.solve(K, rhs)
        J, b0 = self._f_conv(x, self._p)
        return x, u, self._p, ca.vertcat(J @ sol[:7] + b0, sol[3:5])

    # ------------------------------------------------------------------ build
    def _bodies(self):
        """Shell, yoke, pendulum and the motors' rotors (axial inertia only; a rotor turns n times
        its joint's angle relative to its carrier: frames 'mY' on the shell, 'mP' on the yoke)."""
        p = self.params
        ex, ey = np.eye(3)[0], np.eye(3)[1]
        return [
            _Body(p["m_S"], p["j_S"] * ca.DM.eye(3), np.zeros(3), "S"),
            _Body(p["m_Y"], p["J_Y"], p["c_Y"], "Y"),
            _Body(p["m_P"], p["J_P"], p["c_P"], "P"),
            _Body(0.0, p["j_mY"] * ca.DM(np.outer(ex, ex)), np.zeros(3), "mY"),
            _Body(0.0, p["j_mP"] * ca.DM(np.outer(ey, ey)), np.zeros(3), "mP"),
        ]

    def _build(self, parameters=()):
        """The CasADi Functions; `parameters`: SX symbols the parameter values are made of
        (`parametric`), appended to the inputs of the accelerations' Functions."""
        p = self.params
        r, g = p["r"], p["g"]
        kS, kY, kP = p["k_S"], p["k_Y"], p["k_P"]
        # Gravity in the plane's frame (x up the slope): -g (sin(slope) e_x + cos(slope) e_z).
        gravity = -g * ca.vertcat(ca.sin(p["slope"]), 0.0, ca.cos(p["slope"]))
        ez = ca.DM([0, 0, 1])

        # Current state (the chart's base point) and inputs.
        x0 = ca.SX.sym("x", STATE_DIM)
        u = ca.SX.sym("u", 2)
        RS0, RY0, RP0 = _mat_rowmajor(x0[_RS]), _mat_rowmajor(x0[_RY]), _mat_rowmajor(x0[_RP])
        q0 = x0[_Q]
        nu = x0[_NU]

        # Chart coordinates s = (phi, dth_Y, dth_P, dx, dy) and their rates.
        s = ca.SX.sym("s", 7)
        sd = ca.SX.sym("sd", 7)
        sdd = ca.SX.sym("sdd", 7)
        RS = RS0 @ _expm_series(s[0:3])
        RY = RY0 @ _rot_x(s[3])
        RP = RP0 @ _rot_y(s[4])
        q = q0 + ca.vertcat(s[5], s[6], 0)
        frames = {"S": RS, "Y": RS @ RY, "P": RS @ RY @ RP,
                  "mY": RS @ _rot_x(p["n_Y"] * s[3]), "mP": RS @ RY @ _rot_y(p["n_P"] * s[4])}

        # Body kinematics and Lagrangian.
        kinetic = 0
        potential = 0
        for body in self._bodies():
            Rb = frames[body.frame]
            pos = q + Rb @ _casadi(body.c_local)
            vel = ca.jtimes(pos, s, sd)
            w_body = _vee_skew(Rb.T @ _time_derivative(Rb, s, sd))
            kinetic += 0.5 * body.mass * ca.dot(vel, vel)
            kinetic += 0.5 * ca.dot(w_body, _casadi(body.inertia) @ w_body)
            potential -= body.mass * ca.dot(gravity, pos)
        lagr = kinetic - potential

        # Shell body angular velocity, contact-point velocity (constraint).
        wS = _vee_skew(RS.T @ _time_derivative(RS, s, sd))
        qdot = ca.vertcat(sd[5], sd[6], 0)
        v_contact = qdot + ca.cross(RS @ wS, -r * ez)
        con = v_contact[0:2]                      # A(s) sd  (z part is identically 0)
        A = ca.jacobian(con, sd)
        Adot_sd = ca.jtimes(con, s, sd)           # (d/ds (A sd)) sd

        # Lagrange-d'Alembert terms.
        M, dL_dsd = ca.hessian(lagr, sd)
        dL_ds = ca.gradient(lagr, s)
        coupling = ca.jtimes(dL_dsd, s, sd)       # (d/ds dL/dsdot) sdot
        dwS_dsd = ca.jacobian(wS, sd)
        Q = dwS_dsd.T @ (-kS * wS)
        Q += ca.vertcat(0, 0, 0, u[0] - kY * sd[3], u[1] - kP * sd[4], 0, 0)

        kkt = ca.blockcat([[M, -A.T], [A, ca.SX.zeros(2, 2)]])
        rhs = ca.vertcat(Q + dL_ds - coupling, -Adot_sd)

        # Exact chart -> body-rate conversion: d wS/dt = J sdd + (d wS/ds) sd.
        wS_dot = dwS_dsd @ sdd + ca.jtimes(wS, s, sd)

        # Evaluate at the base point s = 0 with sd = (nu, qdot_xy(nu)).
        zero_s = ca.DM.zeros(7)
        sd_nu_free = ca.vertcat(nu, 0, 0)
        qdot_xy = -ca.substitute(con, ca.vertcat(s, sd), ca.vertcat(zero_s, sd_nu_free))
        sd_nu = ca.vertcat(nu, qdot_xy)

        def at_state(expr):
            return ca.substitute(expr, ca.vertcat(s, sd), ca.vertcat(zero_s, sd_nu))

        self._f_kkt = ca.Function("kkt", [x0, u, *parameters], [at_state(kkt), at_state(rhs)])
        if parameters:   # the accelerations only: the other Functions need numbers
            self._f_conv = ca.Function("conv", [x0, *parameters], [at_state(ca.jacobian(wS_dot, sdd)),
                                                      at_state(ca.substitute(wS_dot, sdd, ca.DM.zeros(7)))])
            return
        conv_J = at_state(ca.jacobian(wS_dot, sdd))
        conv_b = at_state(ca.substitute(wS_dot, sdd, ca.DM.zeros(7)))
        self._f_conv = ca.Function("conv", [x0], [conv_J, conv_b])

        # Energy and constrained mass matrix in nu.
        nu_sym = ca.SX.sym("nu", 5)
        sd_of_nu = ca.vertcat(nu_sym, ca.substitute(qdot_xy, nu, nu_sym))
        T_nu = ca.substitute(ca.substitute(kinetic, s, zero_s), sd, sd_of_nu)
        M_nu = ca.hessian(T_nu, nu_sym)[0]
        self._f_inertia = ca.Function("inertia", [x0], [ca.substitute(M_nu, nu_sym, ca.DM.zeros(5))])
        self._f_energy = ca.Function("energy", [x0], [at_state(kinetic + potential)])
        self._f_qdot = ca.Function("qdot", [x0], [ca.vertcat(qdot_xy, 0)])

        # Velocity of the shell's material point currently touching the ground,
        # from differentiating its position along the chart (independent of v_contact).
        qdot_in = ca.SX.sym("qdot", 3)
        c_body = RS0.T @ (-r * ez)
        p_mat = RS @ c_body
        v_mat = qdot_in + ca.jtimes(p_mat, s, sd)
        v_mat = ca.substitute(v_mat, ca.vertcat(s, sd), ca.vertcat(zero_s, sd_nu))
        self._f_contact = ca.Function("contact", [x0, qdot_in], [v_mat])

    # ---------------------------------------------------------------- public
    @staticmethod
    def _state(x):
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.size != STATE_DIM:
            raise ValueError(f"state must have {STATE_DIM} entries, got {x.size}")
        return x

    def accel(self, x, u) -> np.ndarray:
        """(d omega_S/dt (3, body frame), d omega_Y/dt, d omega_P/dt)."""
        x = self._state(x)
        u = np.asarray(u, dtype=float).reshape(2)
        K, rhs = self._f_kkt(x, u)
        sol = np.linalg.solve(np.asarray(K), np.asarray(rhs).reshape(-1))
        sdd = sol[:7]
        J, b0 = self._f_conv(x)
        wS_dot = np.asarray(J) @ sdd + np.asarray(b0).reshape(-1)
        return np.concatenate([wS_dot, sdd[3:5]])

    def accel_batch(self, X, U) -> np.ndarray:
        """`accel` for states and inputs in rows, shape (n, 5): the CasADi functions mapped over
        the batch (`Function.map`, what a CasADi user would do) and one batched solve."""
        X, U = np.asarray(X, dtype=float), np.asarray(U, dtype=float)
        if X.ndim != 2 or X.shape[1] != STATE_DIM or U.shape != (len(X), 2):
            raise ValueError(f"states and inputs must have shapes (n, {STATE_DIM}) and (n, 2), "
                             f"got {X.shape} and {U.shape}")
        n = len(X)
        K, rhs = self._f_kkt.map(n)(X.T, U.T)
        J, b0 = self._f_conv.map(n)(X.T)
        m = K.size1()
        K = np.asarray(K).reshape(m, n, m).transpose(1, 0, 2)
        sdd = np.linalg.solve(K, np.asarray(rhs).T[..., None])[:, :7, 0]
        J = np.asarray(J).reshape(3, n, 7).transpose(1, 0, 2)
        wS_dot = np.einsum("nij,nj->ni", J, sdd) + np.asarray(b0).T
        return np.concatenate([wS_dot, sdd[:, 3:5]], axis=1)

    def inertia(self, x) -> np.ndarray:
        """5x5 mass matrix M(x) with kinetic energy = 1/2 nu^T M nu on the constraint."""
        return np.asarray(self._f_inertia(self._state(x)))

    def energy(self, x) -> float:
        """Kinetic + potential energy; potential = sum_bodies m g z_cm (ground z = 0)."""
        return float(self._f_energy(self._state(x)))

    def centre_velocity(self, x) -> np.ndarray:
        """dq/dt imposed by rolling without slipping: r (R_S omega_S) x e_z."""
        return np.asarray(self._f_qdot(self._state(x))).reshape(3)

    def contact_point_velocity(self, x, qdot=None) -> np.ndarray:
        """Inertial velocity of the shell material point at q - r e_z.

        The point's velocity is obtained by differentiating its position
        ``q + R_S c`` (c fixed in the shell) along the exponential chart.  The
        centre velocity is ``qdot`` if given, otherwise the rolling-constraint
        value ``centre_velocity(x)``; in the latter case the result is ~0 and
        checks the internal consistency of the kinematics.
        """
        x = self._state(x)
        qd = self.centre_velocity(x) if qdot is None else np.asarray(qdot, dtype=float).reshape(3)
        return np.asarray(self._f_contact(x, qd)).reshape(3)

    def state_derivative(self, x, u) -> np.ndarray:
        """Full 35-element dx/dt (rotation matrices, rolling q, accelerations)."""
        x = self._state(x)
        RS, RY, RP = (x[sl].reshape(3, 3) for sl in (_RS, _RY, _RP))
        wS, wY, wP = x[_WS], x[_WY], x[_WP]
        hx = np.array([[0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
        hy = np.array([[0, 0, 1.0], [0, 0, 0], [-1.0, 0, 0]])
        return np.concatenate([
            (RS @ _hat_np(wS)).reshape(-1),
            (RY @ hx * wY).reshape(-1),
            (RP @ hy * wP).reshape(-1),
            self.centre_velocity(x),
            self.accel(x, u),
        ])

    def chart_check(self, x):
        """(d omega_S/d sddot, bias) of the chart conversion at the base point.

        For the exponential chart this must be ([I3 | 0], 0): phiddot equals
        d omega_S/dt at phi = 0.
        """
        J, b0 = self._f_conv(self._state(x))
        return np.asarray(J), np.asarray(b0).reshape(-1)


def make_state(R_S=None, theta_Y=0.0, theta_P=0.0, q_xy=(0.0, 0.0), omega_S=(0.0, 0.0, 0.0),
               omega_Y=0.0, omega_P=0.0, r=None) -> np.ndarray:
    """Assemble a 35-element state (q_z = r; r is required)."""
    if r is None:
        raise ValueError("r (shell radius) is required to set q_z")
    R_S = np.eye(3) if R_S is None else np.asarray(R_S, dtype=float)
    R_Y, R_P = _rot_x_np(theta_Y), _rot_y_np(theta_P)
    return np.concatenate([R_S.reshape(-1), R_Y.reshape(-1), R_P.reshape(-1),
                           [q_xy[0], q_xy[1], r], omega_S, [omega_Y, omega_P]])
