"""The robot written the way a PyDy user would: sympy.physics.mechanics + lambdify.

A baseline for the benchmark.  Nothing here is
shared with ``derive/``, ``generated/``, ``c/`` or ``runtime/verification/reference.py``:
the model is rebuilt from the bodies of Section 2.3 with
``sympy.physics.mechanics.KanesMethod`` and turned into NumPy code with
``sympy.lambdify`` (``cse=True``, NumPy functions: what PyDy's
``generate_ode_function`` does).  ``KaneModel(..., module="math")`` is a
hand-tuned variant for single states (Python's math functions on Python
floats, about twice as fast per call), so that the benchmark also shows how
far a careful user of these tools can get.

Model
-----
* Frames: inertial ``N``; shell ``S`` oriented by body-fixed z-y-x Euler
  angles ``(psi, theta, phi)`` (``S.orient_body_fixed(N, ..., 'zyx')``, i.e.
  ``R_S = Rz(psi) Ry(theta) Rx(phi)``); yoke ``Y`` rotated by ``th_Y`` about
  ``S.x``; pendulum ``P`` rotated by ``th_P`` about ``Y.y``.
* Coordinates ``(psi, theta, phi, th_Y, th_P, x, y)``; the centre is at
  ``x N.x + y N.y + r N.z``.
* Speeds: independent ``(w1, w2, w3, w_Y, w_P)`` with ``omega_S = w1 S.x +
  w2 S.y + w3 S.z`` (set directly with ``set_ang_vel``: the shell body rates
  are the speeds, as in our state), ``w_Y = th_Y'``, ``w_P = th_P'``;
  dependent ``(u_x, u_y) = (x', y')``.
* Rolling without slipping: ``v_O + omega_S x (-r N.z) = 0`` (N.x and N.y
  components) as velocity constraints; the acceleration constraints are its
  time derivative written as ``a_O + alpha_S x (-r N.z)`` and passed to
  ``KanesMethod`` explicitly, so that no Euler-angle rate enters them (see
  "Gimbal lock").
* Bodies as in ``runtime/verification/reference.py``: shell (2/3) m_S r^2 I; four yoke rods
  (two of length b / mass m_b along Y.y at x = +-h/2, two of length h / mass
  m_h along Y.x at y = +-b/2), each its own ``RigidBody`` in frame ``Y``;
  pendulum rod of length l / mass m_P from the centre along -P.z.  Gravity
  ``-g N.z`` on every mass centre.
* Loads: ``(u_Y - k_Y w_Y) Y.x`` on the yoke and its reaction ``-(...) S.x`` on
  the shell; ``(u_P - k_P w_P) Y.y`` on the pendulum and ``-(...) Y.y`` on the
  yoke; ``-k_S omega_S`` on the shell.

``KanesMethod.kanes_equations`` gives ``kane.mass_matrix`` (7x7: the five
dynamic equations of the independent speeds, written in all seven speed
derivatives, stacked on the two acceleration constraints) and
``kane.forcing`` (7); these are lambdified once per process, with the
coordinates, speeds, inputs and the 12 parameters as arguments.  ``accel``
computes the dependent speeds from the (lambdified) velocity constraint,
evaluates M and F and returns the first five entries of ``solve(M, F)``.

Gimbal lock
-----------
The z-y-x angles are singular at ``cos(theta) = 0``, i.e. when the shell's x
axis is vertical (``R_S[2,0] = -+1``).  The conversion from our ``R_S`` reads
``theta = atan2(-R20, hypot(R00, R10))`` (well conditioned everywhere),
``psi = atan2(R10, R00)``, ``phi = atan2(R21, R22)``; where
``hypot(R00, R10) < 1e-12`` it sets ``psi = 0`` and ``phi = atan2(-R12, R11)``,
which reproduces R_S exactly at the lock.  Near the lock psi and phi are
individually ill-determined (errors ~ eps / cos(theta)), but the dynamics is
invariant under yaw and depends on the attitude only through the gravity
direction in the shell frame ``R_S^T e_z = (-sin theta, cos theta sin phi,
cos theta cos phi)``, in which the error of phi is multiplied by
``cos(theta)``.  The lambdified M and F contain no Euler-angle rates (the
shell's angular velocity is set from the speeds, and the acceleration
constraints are given explicitly), so ``accel`` stays accurate at and near
the lock: about 1e-15 relative to the reference at cos(theta) = 6e-17 (this
is checked by the tests, and ``_derive`` asserts that no negative power of
an expression in theta appears in M or F).  With KanesMethod's default
acceleration constraints (the time derivative of the velocity constraints,
which differentiates the direction cosines of S and substitutes the Euler
rates ``q' = W(q)^-1 u``) the ``1/cos(theta)`` terms cancel only analytically:
measured, the error grows roughly like eps / cos(theta) (1e-7 at 1e-10 rad
from the lock, 1e-3 at 1e-14 rad) and is O(1) at the lock.  The kinematic differential
equations themselves (``kane.kindiffdict()``, not used here) do have the
``1/cos(theta)`` singularity: integrating the Euler angles through the lock
would fail, which is why our product uses rotation matrices.
"""
from __future__ import annotations

import math
import threading
import time

import numpy as np

# The parameter order and the state layout, written here on purpose (this model shares nothing
# with derive/ or the kernels); tests/runtime/verification/test_tables.py checks them against
# the generated SR_P_* and SR_X_* macros.
PARAM_NAMES = ("r", "m_S", "k_S", "b", "h", "m_b", "m_h", "k_Y", "l", "m_P", "k_P", "g")
#: The general robot, flattened (centres x, y, z; tensors xx, yy, zz, xy, xz, yz).
_TENSOR = ("xx", "yy", "zz", "xy", "xz", "yz")
GENERAL_PARAM_NAMES = ("r", "m_S", "j_S", "k_S", "m_Y", "c_Y_x", "c_Y_y", "c_Y_z", *(f"J_Y_{k}" for k in _TENSOR),
                       "k_Y", "m_P", "c_P_x", "c_P_y", "c_P_z", *(f"J_P_{k}" for k in _TENSOR), "k_P",
                       "j_mY", "n_Y", "j_mP", "n_P", "g", "slope")
STATE_DIM = 35
#: Offsets of the blocks of the state: R_S, R_Y, R_P row-major (9 each), q (3), nu = (w_S, w_Y, w_P).
X_R_S, X_R_Y, X_R_P, X_Q, X_NU = 0, 9, 18, 27, 30

_LOCK = threading.Lock()
_DERIVED = {}  # "symbolic" and (cse, module) -> derived functions, filled once per process


def _derive(general=False):
    """Symbolic derivation with sympy.physics.mechanics; returns a dict of the expressions to lambdify.

    general=False: the paper's robot by its twelve parameters (rods); True: the general robot of
    the general robot (bodies by mass, centre and tensor, motor rotors, a slope)."""
    import sympy as sm
    import sympy.physics.mechanics as me

    t0 = time.perf_counter()
    par = sm.symbols(" ".join(GENERAL_PARAM_NAMES if general else PARAM_NAMES), real=True)
    named = dict(zip(GENERAL_PARAM_NAMES if general else PARAM_NAMES, par))
    r, m_S, k_S, k_Y, m_P, k_P, g = (named[k] for k in ("r", "m_S", "k_S", "k_Y", "m_P", "k_P", "g"))
    u_Y, u_P = sm.symbols("u_Y u_P", real=True)

    psi, theta, phi, thY, thP, xq, yq = me.dynamicsymbols("psi theta phi th_Y th_P x y")
    w1, w2, w3, wY, wP, ux, uy = me.dynamicsymbols("w1 w2 w3 w_Y w_P u_x u_y")
    q = [psi, theta, phi, thY, thP, xq, yq]
    u_ind = [w1, w2, w3, wY, wP]
    u_dep = [ux, uy]

    N = me.ReferenceFrame("N")
    S = me.ReferenceFrame("S")
    Y = me.ReferenceFrame("Y")
    P = me.ReferenceFrame("P")
    S.orient_body_fixed(N, (psi, theta, phi), "zyx")
    Y.orient_axis(S, S.x, thY)
    P.orient_axis(Y, Y.y, thP)
    # The Euler-angle kinematics, then the speeds as the body rates.
    w_S_qdot = S.ang_vel_in(N)
    kd = [w_S_qdot.dot(S.x) - w1, w_S_qdot.dot(S.y) - w2, w_S_qdot.dot(S.z) - w3,
          thY.diff() - wY, thP.diff() - wP, xq.diff() - ux, yq.diff() - uy]
    S.set_ang_vel(N, w1 * S.x + w2 * S.y + w3 * S.z)
    Y.set_ang_vel(S, wY * S.x)
    P.set_ang_vel(Y, wP * Y.y)

    O = me.Point("O")                      # shell centre
    O.set_vel(N, ux * N.x + uy * N.y)

    # Rolling: velocity of the shell's material point at O - r N.z is zero.
    v_contact = O.vel(N) + S.ang_vel_in(N).cross(-r * N.z)
    vel_con = [v_contact.dot(N.x), v_contact.dot(N.y)]
    # Its time derivative, written as a_O + alpha_S x (-r N.z) (N.z is fixed in N).
    # Differentiating vel_con itself (KanesMethod's default) would differentiate
    # the direction cosines of S in time and bring in, through the kinematic
    # differential equations, terms in 1/cos(theta) that cancel only analytically.
    a_contact = O.acc(N) + S.ang_acc_in(N).cross(-r * N.z)
    acc_con = [a_contact.dot(N.x), a_contact.dot(N.y)]

    def rod(name, frame, mass, length, axis, centre):
        pt = O.locatenew(name + "_cm", centre)
        pt.v2pt_theory(O, N, frame)
        ixx, iyy, izz = [mass * length**2 / 12 * (1 - a) for a in axis]
        return me.RigidBody(name, pt, frame, mass, (me.inertia(frame, ixx, iyy, izz), pt))

    def body(name, frame, mass, c, J):
        pt = O.locatenew(name + "_cm", c[0] * frame.x + c[1] * frame.y + c[2] * frame.z)
        pt.v2pt_theory(O, N, frame)
        return me.RigidBody(name, pt, frame, mass, (me.inertia(frame, *J), pt))

    if general:
        def centre(prefix):
            return [named[f"{prefix}_{a}"] for a in "xyz"]

        def tensor(prefix):
            """me.inertia's argument order: ixx, iyy, izz, ixy, iyz, izx."""
            return [named[f"{prefix}_{k}"] for k in ("xx", "yy", "zz", "xy", "yz", "xz")]

        shell = me.RigidBody("shell", O, S, m_S, (me.inertia(S, *(3 * [named["j_S"]])), O))
        # The motors' rotors: only their axial inertias count; each turns n times its joint
        # relative to its carrier (the yoke motor's on the shell, the pendulum motor's on the yoke).
        RmY, RmP = me.ReferenceFrame("RmY"), me.ReferenceFrame("RmP")
        RmY.orient_axis(S, S.x, named["n_Y"] * thY)
        RmY.set_ang_vel(S, named["n_Y"] * wY * S.x)
        RmP.orient_axis(Y, Y.y, named["n_P"] * thP)
        RmP.set_ang_vel(Y, named["n_P"] * wP * Y.y)
        bodies = [shell, body("yoke", Y, named["m_Y"], centre("c_Y"), tensor("J_Y")),
                  body("pendulum", P, m_P, centre("c_P"), tensor("J_P")),
                  me.RigidBody("rotor_Y", O, RmY, 0, (me.inertia(RmY, named["j_mY"], 0, 0), O)),
                  me.RigidBody("rotor_P", O, RmP, 0, (me.inertia(RmP, 0, named["j_mP"], 0), O))]
        gravity = -g * (sm.sin(named["slope"]) * N.x + sm.cos(named["slope"]) * N.z)
    else:
        b, h, m_b, m_h, l = (named[k] for k in ("b", "h", "m_b", "m_h", "l"))
        shell = me.RigidBody("shell", O, S, m_S, (me.inertia(S, *(3 * [sm.Rational(2, 3) * m_S * r**2])), O))
        bodies = [
            shell,
            rod("b_plus", Y, m_b, b, (0, 1, 0), +h / 2 * Y.x),
            rod("b_minus", Y, m_b, b, (0, 1, 0), -h / 2 * Y.x),
            rod("h_plus", Y, m_h, h, (1, 0, 0), +b / 2 * Y.y),
            rod("h_minus", Y, m_h, h, (1, 0, 0), -b / 2 * Y.y),
            rod("pendulum", P, m_P, l, (0, 0, 1), -l / 2 * P.z),
        ]
        gravity = -g * N.z
    tau_Y = u_Y - k_Y * wY
    tau_P = u_P - k_P * wP
    loads = [(body.masscenter, body.mass * gravity) for body in bodies if body.mass != 0]
    loads += [
        (Y, tau_Y * Y.x), (S, -tau_Y * S.x),
        (P, tau_P * Y.y), (Y, -tau_P * Y.y),
        (S, -k_S * (w1 * S.x + w2 * S.y + w3 * S.z)),
    ]

    kane = me.KanesMethod(N, q_ind=q, u_ind=u_ind, kd_eqs=kd, u_dependent=u_dep,
                          velocity_constraints=vel_con, acceleration_constraints=acc_con)
    kane.kanes_equations(bodies, loads)
    M = kane.mass_matrix                   # 7x7, in (w1', w2', w3', w_Y', w_P', u_x', u_y')
    F = kane.forcing                       # 7
    t_kane = time.perf_counter() - t0

    # Dependent speeds from the velocity constraints (linear in the speeds).
    A_dep, rhs_dep = sm.linear_eq_to_matrix(vel_con, u_dep)
    udep_expr = A_dep.LUsolve(rhs_dep)

    # Plain symbols for the dynamic symbols, then lambdify (numpy, cse).
    qs = sm.symbols("q0:7", real=True)
    us = sm.symbols("s0:7", real=True)
    sub = dict(zip(q + u_ind + u_dep, list(qs) + list(us)))
    leftover = me.find_dynamicsymbols(sm.Matrix([*M, *F])) - set(q) - set(u_ind) - set(u_dep)
    if leftover:                           # no Euler rates (or any other rate) may remain
        raise RuntimeError(f"unexpected dynamic symbols in M, F: {leftover}")
    for node in sm.preorder_traversal(sm.Matrix([*M, *F])):
        if isinstance(node, sm.Pow) and node.exp.is_negative and node.base.has(theta):
            raise RuntimeError(f"M or F is singular at the gimbal lock: {node}")
    M_s, F_s = M.xreplace(sub), F.xreplace(sub)
    udep_s = udep_expr.xreplace(sub)
    args = (qs, us, (u_Y, u_P), par)
    # The kinematic differential equations q' = f(q, u) (with the 1/cos(theta) of the Euler
    # angles): not used by `accel`, but part of the ODE function a PyDy user generates
    # (runtime/bench/kane_compiled.py).
    kdd = kane.kindiffdict()
    qdot_s = sm.Matrix([kdd[qi.diff()] for qi in q]).xreplace(sub)
    return {"MF": (args, (M_s, F_s)), "udep": ((qs, us[:5], par), udep_s), "qdot": ((qs, us, par), qdot_s),
            "seconds": time.perf_counter() - t0, "kane_seconds": t_kane,
            "n_ops": int(sm.count_ops(M_s) + sm.count_ops(F_s))}


#: lambdify's modules for each `module` of KaneModel: PyDy's choice (NumPy, with the
#: matrices as arrays), or Python's math module for scalars (with the matrices as arrays).
MODULES = {"numpy": "numpy",
           "math": [{"ImmutableDenseMatrix": np.array, "MutableDenseMatrix": np.array}, "math"]}


def _lambdify(d, cse, module):
    """The expressions of `_derive` (d) lambdified: M, F and the dependent speeds, and (NumPy
    only) their batch forms; a dict."""
    import sympy as sm
    t0 = time.perf_counter()
    out = {"f_MF": sm.lambdify(*d["MF"], modules=MODULES[module], cse=cse),
           "f_udep": sm.lambdify(*d["udep"], modules=MODULES[module], cse=cse)}
    if module == "numpy":
        # The same expressions for arrays of states (accel_batch): entries that do not
        # depend on the state (the zeros of M and F) are broadcast to the batch.
        batch = [{"array": _broadcast_array}, "numpy"]
        out["f_MF_batch"] = sm.lambdify(*d["MF"], modules=batch, cse=cse)
        out["f_udep_batch"] = sm.lambdify(*d["udep"], modules=batch, cse=cse)
    out["seconds"] = time.perf_counter() - t0
    return out


def _broadcast_array(rows):
    """numpy.array of a nested list whose entries are arrays of one batch shape or scalars."""
    entries = [e for row in rows for e in row]
    shape = np.broadcast_shapes(*(np.shape(e) for e in entries))
    return np.array([[np.broadcast_to(e, shape) for e in row] for row in rows])


def _derivation(general=False):
    """The symbolic derivation, once per process (per variant)."""
    with _LOCK:
        if ("symbolic", general) not in _DERIVED:
            _DERIVED[("symbolic", general)] = _derive(general)
        return _DERIVED[("symbolic", general)]


def _lambdified(cse, module, general=False):
    """The lambdified functions for (cse, module), once per process (per variant)."""
    d = _derivation(general)
    with _LOCK:
        if (cse, module, general) not in _DERIVED:
            _DERIVED[(cse, module, general)] = _lambdify(d, cse, module)
        return _DERIVED[(cse, module, general)]


def euler_zyx(R_S):
    """(psi, theta, phi) with R_S = Rz(psi) Ry(theta) Rx(phi); psi = 0 at the lock (see module doc)."""
    R = np.asarray(R_S, dtype=float).reshape(3, 3)
    c = math.hypot(R[0, 0], R[1, 0])
    theta = math.atan2(-R[2, 0], c)
    if c < 1e-12:                          # gimbal lock: only phi -+ psi is defined
        return 0.0, theta, math.atan2(-R[1, 2], R[1, 1])
    return math.atan2(R[1, 0], R[0, 0]), theta, math.atan2(R[2, 1], R[2, 2])


def flat_general(params):
    """A general parameter dict with c_* (3,) and J_* (3, 3) arrays, flattened to GENERAL_PARAM_NAMES."""
    out = {}
    for k, v in params.items():
        v = np.asarray(v, dtype=float)
        if v.shape == (3,):
            out.update({f"{k}_{a}": float(v[i]) for i, a in enumerate("xyz")})
        elif v.shape == (3, 3):
            out.update({f"{k}_{t}": float(v["xyz".index(t[0]), "xyz".index(t[1])]) for t in _TENSOR})
        else:
            out[k] = float(v)
    return out


class KaneModel:
    """Spherical-robot accelerations from sympy.physics.mechanics (KanesMethod), lambdified.

    ``KaneModel(params)`` with the 12 parameters by the paper's names (a dict, or
    anything with those attributes such as ``runtime.Params``).  The symbolic
    derivation and lambdify run once per process, on the first construction;
    ``derivation_seconds`` reports how long they took.  ``cse=False`` lambdifies
    with sympy's default options (no common-subexpression elimination).
    ``module="numpy"`` is what PyDy's ``generate_ode_function`` does (NumPy
    functions, ``cse=True``); ``module="math"`` is a hand-tuned variant for
    single states: Python's math functions on Python floats, about twice as
    fast per call.
    """

    def __init__(self, params, cse=True, module="numpy"):
        self.cse = bool(cse)
        if module not in MODULES:
            raise ValueError(f"module: expected one of {sorted(MODULES)}, got {module!r}")
        self.module = module
        if not isinstance(params, dict):     # a runtime.Params: the paper's names if it is the paper's robot
            paper = getattr(params, "paper_params", None)
            params = ({k: getattr(paper, k) for k in PARAM_NAMES} if paper is not None
                      else flat_general(params.as_dict()))
        elif "c_Y" in params:
            params = flat_general(params)
        self.general = set(params) != set(PARAM_NAMES)
        names = GENERAL_PARAM_NAMES if self.general else PARAM_NAMES
        missing = [k for k in names if k not in params]
        extra = [k for k in params if k not in names]
        if missing or extra:
            raise ValueError(f"bad parameter set: missing={missing}, unknown={extra}")
        self.params = {k: float(params[k]) for k in names}
        self._p = tuple(self.params[k] for k in names)
        d = _lambdified(self.cse, self.module, self.general)
        self._f_MF, self._f_udep = d["f_MF"], d["f_udep"]

    @property
    def derivation_seconds(self) -> float:
        """Wall time of the symbolic derivation (KanesMethod) plus lambdify, once per process."""
        return _derivation(self.general)["seconds"] + _lambdified(self.cse, self.module, self.general)["seconds"]

    @staticmethod
    def coordinates(x):
        """Our 35-vector -> (q (7): psi, theta, phi, th_Y, th_P, x, y;  independent speeds (5))."""
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.size != STATE_DIM:
            raise ValueError(f"state must have {STATE_DIM} entries, got {x.size}")
        psi, theta, phi = euler_zyx(x[X_R_S:X_R_S + 9])
        th_Y = math.atan2(x[X_R_Y + 7], x[X_R_Y + 4])       # R_Y[2,1], R_Y[1,1]
        th_P = math.atan2(x[X_R_P + 2], x[X_R_P + 0])       # R_P[0,2], R_P[0,0]
        return ((psi, theta, phi, th_Y, th_P, float(x[X_Q]), float(x[X_Q + 1])),
                tuple(x[X_NU:X_NU + 5].tolist()))

    def mass_matrix_forcing(self, x, u):
        """kane.mass_matrix (7x7) and kane.forcing (7) at our state x and input u."""
        qv, w = self.coordinates(x)
        udep = np.asarray(self._f_udep(qv, w, self._p), dtype=float).reshape(-1)
        uu = np.asarray(u, dtype=float).reshape(2)
        M, F = self._f_MF(qv, w + tuple(udep.tolist()), tuple(uu.tolist()), self._p)
        return np.asarray(M, dtype=float), np.asarray(F, dtype=float).reshape(-1)

    def accel(self, x, u) -> np.ndarray:
        """(d omega_S/dt (shell frame, 3), d omega_Y/dt, d omega_P/dt), shape (5,)."""
        M, F = self.mass_matrix_forcing(x, u)
        return np.linalg.solve(M, F)[:5]

    @staticmethod
    def coordinates_batch(X):
        """`coordinates` for states in rows, vectorized: (7 coordinate arrays, 5 speed arrays)."""
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != STATE_DIM:
            raise ValueError(f"states must have shape (n, {STATE_DIM}), got {X.shape}")
        R = X[:, X_R_S:X_R_S + 9].reshape(-1, 3, 3)
        c = np.hypot(R[:, 0, 0], R[:, 1, 0])
        theta = np.arctan2(-R[:, 2, 0], c)
        lock = c < 1e-12
        psi = np.where(lock, 0.0, np.arctan2(R[:, 1, 0], R[:, 0, 0]))
        phi = np.where(lock, np.arctan2(-R[:, 1, 2], R[:, 1, 1]), np.arctan2(R[:, 2, 1], R[:, 2, 2]))
        th_Y = np.arctan2(X[:, X_R_Y + 7], X[:, X_R_Y + 4])
        th_P = np.arctan2(X[:, X_R_P + 2], X[:, X_R_P + 0])
        return ((psi, theta, phi, th_Y, th_P, X[:, X_Q], X[:, X_Q + 1]),
                tuple(X[:, X_NU + i] for i in range(5)))

    def accel_batch(self, X, U) -> np.ndarray:
        """`accel` for states and inputs in rows, shape (n, 5): the lambdified code on arrays
        (what a NumPy user would do with a batch) and one batched solve."""
        if self.module != "numpy":
            raise ValueError(f"accel_batch: needs module='numpy', this model has module={self.module!r}")
        d = _lambdified(self.cse, self.module, self.general)
        qv, w = self.coordinates_batch(X)
        U = np.asarray(U, dtype=float)
        if U.shape != (len(qv[0]), 2):
            raise ValueError(f"inputs must have shape ({len(qv[0])}, 2), got {U.shape}")
        udep = d["f_udep_batch"](qv, w, self._p).reshape(2, -1)
        M, F = d["f_MF_batch"](qv, w + (udep[0], udep[1]), (U[:, 0], U[:, 1]), self._p)
        M = np.moveaxis(M.reshape(7, 7, -1), -1, 0)
        F = np.moveaxis(F.reshape(7, -1), -1, 0)
        return np.linalg.solve(M, F[..., None])[:, :5, 0]
