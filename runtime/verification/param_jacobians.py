"""Checks of the parameter Jacobians (runtime/param_derivatives.py) against independent sources.

* ∂ν̇/∂p against CasADi AD in the parameters of the independent reference
  (`ReferenceModel.parametric`: the reference's Lagrangian built on a parameter symbol).
* ∂ν̇/∂p and a step's ∂/∂p against central differences of the kernels in the parameters
  (models of the perturbed robots), Richardson-extrapolated.
* A step's ∂/∂p against CasADi AD in p of the exported steps (generated/casadi/, which take the
  parameter vector as an input).

Each check takes the Jacobian under test as a function, so that a test can hand it a perturbed one
and see the check fail.  Central differences need every perturbed robot to be valid: they are
taken on a general robot of `sampling.random_general_params`, whose tensors and dampings are
clear of their bounds (the paper's pendulum, a rod with J_zz = 0, is not).
"""
import functools

import casadi as ca
import numpy as np

from ..model import Model
from ..param_derivatives import NPARAM, PARAMETER_NAMES
from ..params import Params
from ..state import IDX_Q, NE, NV
from .reference import FLAT_PARAM_NAMES, ReferenceModel
from .sampling import random_general_params, random_inputs, random_state

#: The central differences' step per parameter, relative to its value (FLOOR where it is 0): the
#: parameters span seven decades (a rotor's 1e-5 kg m² beside a gear ratio of 50), and the
#: accelerations are far from linear in some (n² j_m dominates a joint's inertia).
DIFFERENCE_STEP, DIFFERENCE_FLOOR = 1e-3, 1e-6


@functools.lru_cache(maxsize=None)
def reference_param_jacobian():
    """CasADi Function (x, u, p) -> ∂ν̇/∂p (5 × 31) by AD of the parametric reference."""
    if FLAT_PARAM_NAMES != PARAMETER_NAMES:
        raise ValueError(f"the reference's parameter layout {FLAT_PARAM_NAMES} is not the C library's {PARAMETER_NAMES}")
    x, u, p, accel = ReferenceModel.parametric().parametric_accel()
    return ca.Function("reference_param_jacobian", [x, u, p], [ca.jacobian(accel, p)])


def _on(x, params):
    """x with q_z = r of params (a state check of a robot of another radius asks for it; q_z enters
    no dynamics)."""
    x = np.array(x, dtype=float)
    x[IDX_Q.start + 2] = params.r
    return x


def _relative(ours, theirs):
    err = float(np.abs(ours - theirs).max())
    return err, err / max(float(np.abs(theirs).max()), 1e-300)


def richardson_in_parameters(value, params, n_out):
    """Columns d value(params)/dp_k by central differences of `value(Params)` (an array of n_out),
    steps h_k = DIFFERENCE_STEP |p_k| (DIFFERENCE_FLOOR if p_k = 0) and h_k/2, Richardson-extrapolated."""
    p0 = params.as_array()
    J = np.empty((n_out, NPARAM))
    for k in range(NPARAM):
        h = DIFFERENCE_STEP * abs(p0[k]) if p0[k] != 0 else DIFFERENCE_FLOOR

        def central(step):
            up, down = p0.copy(), p0.copy()
            up[k] += step
            down[k] -= step
            return (value(Params.from_array(up)) - value(Params.from_array(down))).ravel() / (2 * step)
        J[:, k] = (4 * central(h / 2) - central(h)) / 3
    return J


def param_jacobian_checks(n_states=200, seed=11, jacobian=None, params=None, n_difference=5):
    """Rows of `make verify` for Model.param_jacobian: against AD of the parametric reference
    (n_states random states and torques, ≤ 1e-10 relative) and Richardson central differences in
    the parameters (n_difference states, ≤ 1e-7 relative).  `jacobian(model, x, u)` is the function
    under test; params default to a random general robot."""
    rng = np.random.default_rng(seed)
    params = random_general_params(rng) if params is None else params
    model = Model(params)
    jacobian = jacobian or (lambda m, x, u: m.param_jacobian(x, u))
    X = np.array([random_state(rng, params) for _ in range(n_states)])
    U = random_inputs(rng, n_states)
    ref = reference_param_jacobian().map(n_states)(X.T, U.T, params.as_array())
    ref = np.asarray(ref).reshape(NV, n_states, NPARAM).transpose(1, 0, 2)
    worst_ad, worst_fd = (0.0, 0.0), (0.0, 0.0)
    for i in range(n_states):
        J = jacobian(model, X[i], U[i])
        worst_ad = max(worst_ad, _relative(J, ref[i]), key=lambda e: e[1])
        if i < n_difference:
            fd = richardson_in_parameters(lambda p: Model(p).accel(_on(X[i], p), U[i]), params, NV)
            worst_fd = max(worst_fd, _relative(J, fd), key=lambda e: e[1])
    return [(f"param_jacobian vs CasADi AD of the parametric reference ({n_states} states)", *worst_ad, 1e-10),
            (f"param_jacobian vs Richardson central differences in p ({min(n_difference, n_states)} states)",
             *worst_fd, 1e-7)]


STEPS = {"lie-euler": "sr_step_lie_euler", "rkmk4": "sr_step_rkmk4"}


@functools.lru_cache(maxsize=None)
def casadi_step_param_jacobian(method):
    """CasADi Function (x, u, dt, p) -> ∂(step ⊖ step₀)/∂p (12 × 31) by AD of the exported step."""
    from ..casadi_model import load
    from ..step_jacobian import _local_first_order
    step = load(STEPS[method])
    x, u, dt = ca.SX.sym("x", 35), ca.SX.sym("u", 2), ca.SX.sym("dt")
    p0, dp = ca.SX.sym("p", NPARAM), ca.SX.sym("dp", NPARAM)
    e = _local_first_order(ca, step(x, u, dt, p0), step(x, u, dt, p0 + dp))
    J = ca.substitute(ca.jacobian(e, dp), dp, ca.DM.zeros(NPARAM))
    return ca.Function(f"{STEPS[method]}_param_jacobian", [x, u, dt, p0], [J])


def step_param_jacobian_checks(n_states=10, seed=12, jacobian=None, params=None, dt=0.01, n_difference=2):
    """Rows of `make verify` for Model.step_param_jacobian, per method (Lie–Euler, RKMK4): against
    CasADi AD in p of the exported step (≤ 1e-10 relative) and Richardson central differences of
    the C step in p through `local` (≤ 1e-7 relative).  `jacobian(model, x, u, dt, method)` is the
    function under test."""
    rng = np.random.default_rng(seed)
    params = random_general_params(rng) if params is None else params
    model = Model(params)
    jacobian = jacobian or (lambda m, x, u, h, method: m.step_param_jacobian(x, u, h, method))
    X = np.array([random_state(rng, params, max_speed=3.0) for _ in range(n_states)])
    U = random_inputs(rng, n_states)
    rows = []
    for method in STEPS:
        ad = casadi_step_param_jacobian(method)
        worst_ad, worst_fd = (0.0, 0.0), (0.0, 0.0)
        for i, (x, u) in enumerate(zip(X, U)):
            J = jacobian(model, x, u, dt, method)
            worst_ad = max(worst_ad, _relative(J, np.asarray(ad(x, u, dt, params.as_array()))), key=lambda e: e[1])
            if i < n_difference:
                y0 = model.step(x, u, dt, method)
                fd = richardson_in_parameters(lambda p: model.local(y0, _on(Model(p).step(_on(x, p), u, dt, method), params)), params, NE)
                worst_fd = max(worst_fd, _relative(J, fd), key=lambda e: e[1])
        rows.append((f"step_param_jacobian {method} vs CasADi AD in p of the exported step ({n_states} states)",
                     *worst_ad, 1e-10))
        rows.append((f"step_param_jacobian {method} vs Richardson central differences in p "
                     f"({min(n_difference, n_states)} states)", *worst_fd, 1e-7))
    return rows
