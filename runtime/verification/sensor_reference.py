"""Independent reference of the sensor models: CasADi, from the bodies' motion in time.

The kernels (derive/sensors.py) write each reading in closed form: the bodies' angular velocities
joint by joint, the rolling acceleration r ω̇_S × γ, the tangential and centripetal terms.  This
module writes none of those.  It follows the state along a short motion in time t,

    R_S(t) = R_S Exp(ω_S t + ½ ω̇_S t²),  R_Y(t) = R_Y rot_x(ω_Y t + ½ ω̇_Y t²),  R_P(t) likewise,

(whose body rates at t = 0 are ν and their derivatives ν̇: the right-trivialised chart of
reference.py), and reads by CasADi's AD in t:

* the body's angular velocity, the skew part of R_Bᵀ dR_B/dt;
* the point's acceleration, d/dt of q̇(t) + d/dt (R_B(t) ρ), with q̇(t) = r (R_S(t) ω_S(t)) × e_z,
  rolling without slipping as reference.py states it;
* gravity −g (sin(slope), 0, cos(slope)) in the floor's frame (x up the slope).

Its Jacobians are CasADi's AD of those readings at x ⊕ d, ⊕ written here again (R_S Exp(⟦δξ⟧),
R_Y rot_x(δθ_Y), R_P rot_y(δθ_P), q + (δq, 0), ν + δν), and of the biases added.  It imports
only numpy, casadi and reference.py's CasADi helpers, never derive/ nor the kernels
(tests/runtime/test_imports.py); it reads the state by reference.py's layout, and its mount, bias
and body tables are its own (tests/runtime/verification/test_tables.py checks them against the
generated SR_* macros).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .reference import (_NU, _Q, _RP, _RS, _RY, _WP, _WS, _WY, STATE_DIM, _expm_series, _mat_rowmajor, _rot_x,
                        _rot_y, _vee_skew, checked_params)

#: The bodies a sensor can sit on, in their code order.
BODIES = ("shell", "yoke", "pendulum")
#: The mount array: lever arm ρ (body frame, 3), then the mounting rotation R_m row-major (9).
MOUNT_LEVER, MOUNT_ROTATION, MOUNT_DIM = slice(0, 3), slice(3, 12), 12
#: The IMU's biases (gyroscope, accelerometer) and its reading (gyroscope, accelerometer).
BIAS_DIM, IMU_DIM = 6, 6
#: The error state of the Jacobians: 12 coordinates of x ⊕ d, then the 6 biases.
ERROR_DIM = 12


def _rowmajor(R):
    return ca.reshape(R.T, 9, 1)


def retract(x, d):
    """x ⊕ d (CasADi): R_S Exp(⟦δξ⟧) (a series exact to fourth order, enough for first
    derivatives at 0), R_Y rot_x(δθ_Y), R_P rot_y(δθ_P), q + (δq_x, δq_y, 0), ν + δν."""
    return ca.vertcat(_rowmajor(_mat_rowmajor(x[_RS]) @ _expm_series(d[0:3])),
                      _rowmajor(_mat_rowmajor(x[_RY]) @ _rot_x(d[3])),
                      _rowmajor(_mat_rowmajor(x[_RP]) @ _rot_y(d[4])),
                      x[_Q] + ca.vertcat(d[5], d[6], 0), x[_NU] + d[7:12])


class SensorReference:
    """The sensor readings of a robot (its r, g and slope) as CasADi Functions; numpy in and out."""

    def __init__(self, params: dict):
        p = checked_params(params)
        self.r, self.g, self.slope = p["r"], p["g"], p["slope"]
        x, a = ca.SX.sym("x", STATE_DIM), ca.SX.sym("nu_dot", 5)
        mount, bias = ca.SX.sym("mount", MOUNT_DIM), ca.SX.sym("bias", BIAS_DIM)
        d, db = ca.SX.sym("d", ERROR_DIM), ca.SX.sym("db", BIAS_DIM)
        zero = ca.DM.zeros(ERROR_DIM + BIAS_DIM)
        self._imu, self._imu_jac, self._heading, self._heading_jac = {}, {}, {}, {}
        for body in BODIES:
            y = self._imu_expr(x, a, mount, bias, body)
            y_moved = ca.substitute(y, ca.vertcat(x, bias), ca.vertcat(retract(x, d), bias + db))
            H = ca.substitute(ca.jacobian(y_moved, ca.vertcat(d, db)), ca.vertcat(d, db), zero)
            self._imu[body] = ca.Function(f"imu_{body}", [x, a, mount, bias], [y])
            self._imu_jac[body] = ca.Function(f"imu_{body}_jacobian", [x, a, mount, bias], [H, ca.jacobian(y, a)])
            psi = self._heading_expr(x, mount, body)
            dpsi = ca.substitute(ca.jacobian(ca.substitute(psi, x, retract(x, d)), d), d, ca.DM.zeros(ERROR_DIM))
            self._heading[body] = ca.Function(f"heading_{body}", [x, mount], [psi])
            self._heading_jac[body] = ca.Function(f"heading_{body}_jacobian", [x, mount],
                                                  [ca.horzcat(dpsi, ca.DM.zeros(1, BIAS_DIM))])
        for name, expr in (("encoders", self._encoders_expr(x)), ("position", x[_Q][0:2])):
            moved = ca.substitute(expr, x, retract(x, d))
            H = ca.horzcat(ca.substitute(ca.jacobian(moved, d), d, ca.DM.zeros(ERROR_DIM)), ca.DM.zeros(2, BIAS_DIM))
            setattr(self, f"_{name}", ca.Function(name, [x], [expr]))
            setattr(self, f"_{name}_jac", ca.Function(f"{name}_jacobian", [x], [H]))

    # ------------------------------------------------------------------ build
    def _motion(self, x, a, t):
        """R_S(t), R_Y(t), R_P(t) along the motion through x with rates ν and accelerations a."""
        R_S = _mat_rowmajor(x[_RS]) @ _expm_series(x[_WS] * t + a[0:3] * t**2 / 2)
        R_Y = _mat_rowmajor(x[_RY]) @ _rot_x(x[_WY] * t + a[3] * t**2 / 2)
        R_P = _mat_rowmajor(x[_RP]) @ _rot_y(x[_WP] * t + a[4] * t**2 / 2)
        return R_S, R_Y, R_P

    @staticmethod
    def _attitude(body, R_S, R_Y, R_P):
        return {"shell": R_S, "yoke": R_S @ R_Y, "pendulum": R_S @ R_Y @ R_P}[body]

    def _imu_expr(self, x, a, mount, bias, body):
        t = ca.SX.sym("t")
        R_S, R_Y, R_P = self._motion(x, a, t)
        R_B = self._attitude(body, R_S, R_Y, R_P)

        def rate(expr):
            return ca.reshape(ca.jacobian(ca.vec(expr), t), expr.shape[0], expr.shape[1])

        w_B = _vee_skew(R_B.T @ rate(R_B))
        w_S = _vee_skew(R_S.T @ rate(R_S))
        q_dot = self.r * ca.cross(R_S @ w_S, ca.DM([0, 0, 1]))
        lever, R_m = mount[MOUNT_LEVER], _mat_rowmajor(mount[MOUNT_ROTATION])
        p_ddot = ca.jacobian(q_dot, t) + rate(rate(R_B @ lever))
        gravity = -self.g * ca.DM([np.sin(self.slope), 0.0, np.cos(self.slope)])
        y = ca.vertcat(R_m.T @ w_B + bias[0:3], R_m.T @ R_B.T @ (p_ddot - gravity) + bias[3:6])
        return ca.substitute(y, t, 0)

    def _heading_expr(self, x, mount, body):
        R_B = self._attitude(body, _mat_rowmajor(x[_RS]), _mat_rowmajor(x[_RY]), _mat_rowmajor(x[_RP]))
        h = R_B @ _mat_rowmajor(mount[MOUNT_ROTATION])[:, 0]
        return ca.atan2(h[1], h[0])

    @staticmethod
    def _encoders_expr(x):
        R_Y, R_P = _mat_rowmajor(x[_RY]), _mat_rowmajor(x[_RP])
        return ca.vertcat(ca.atan2(R_Y[2, 1], R_Y[1, 1]), ca.atan2(R_P[0, 2], R_P[0, 0]))

    # ---------------------------------------------------------------- public
    @staticmethod
    def _body(body):
        if body not in BODIES:
            raise ValueError(f"body: expected one of {BODIES}, got {body!r}")
        return body

    def imu(self, x, nu_dot, body, mount, bias=None):
        """(gyroscope, accelerometer) (6,) in the sensor frame."""
        bias = np.zeros(BIAS_DIM) if bias is None else bias
        return np.asarray(self._imu[self._body(body)](x, nu_dot, mount, bias)).reshape(-1)

    def imu_jacobians(self, x, nu_dot, body, mount, bias=None):
        """(H (6, 18) = ∂y/∂(d, b) with ν̇ held, Hn (6, 5) = ∂y/∂ν̇) by AD through retract."""
        bias = np.zeros(BIAS_DIM) if bias is None else bias
        H, Hn = self._imu_jac[self._body(body)](x, nu_dot, mount, bias)
        return np.asarray(H), np.asarray(Hn)

    def heading(self, x, body, mount):
        """The heading of the sensor's x axis on the floor [rad], in (-π, π]."""
        return float(self._heading[self._body(body)](x, mount))

    def heading_jacobian(self, x, body, mount):
        """H (18,) of the heading by AD through retract (the bias columns zero)."""
        return np.asarray(self._heading_jac[self._body(body)](x, mount)).reshape(-1)

    def encoders(self, x):
        """(θ_Y, θ_P) [rad], each in (-π, π]."""
        return np.asarray(self._encoders(x)).reshape(-1)

    def encoders_jacobian(self, x):
        """H (2, 18) of the encoders by AD through retract."""
        return np.asarray(self._encoders_jac(x))

    def position(self, x):
        """(q_x, q_y) [m], the shell centre on the floor."""
        return np.asarray(self._position(x)).reshape(-1)

    def position_jacobian(self, x):
        """H (2, 18) of the position fix by AD through retract."""
        return np.asarray(self._position_jac(x))
