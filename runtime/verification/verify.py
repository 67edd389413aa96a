"""Verification of the generated kernels: an independent model, and the physics itself.

`python -m runtime verify [--states N] [--seed S]` runs every check below,
prints a table (check, worst absolute and relative error, tolerance, pass or
fail) and exits non-zero on any failure.  The tests in tests/runtime/verification/test_verify.py
call the same functions.

Checks
  cross-check   accel, inertia and energy against `runtime.verification.reference` (CasADi AD,
                Lagrange–d'Alembert in coordinates) at random states and parameters
  energy        conservation without friction and torques over 20 s (solve_ivp, rtol 1e-12)
  power         dE/dt = u·(ω_Y, ω_P) − k_S|ω_S|² − k_Y ω_Y² − k_P ω_P² at random states
  rolling       along motions of the C steppers: the contact force the motion implies against the
                reference's multiplier, and the angular momentum balance about the contact point
  contact force the contact-force kernel (Model.contact_force) against the reference's multiplier at
                random states, torques and robots on slopes
  equilibria    accel = 0 at eq. (108); linearization stable below, unstable above
  symmetry      planar motions stay planar
  jacobians     accel_jacobian against CasADi AD of the reference and Richardson-extrapolated
                central differences through retract (runtime.verification.jacobians); step_jacobian
                of each method against Richardson differences of the C step through retract/local,
                and its derivative in dt at 0 against linearize
  parameters    param_jacobian against CasADi AD in the parameters of the reference and Richardson
                differences in p; step_param_jacobian (Lie–Euler, RKMK4) against AD in p of the exported
                steps and Richardson differences of the C step (runtime.verification.param_jacobians)
  sensors       the IMU, encoders, position fix and heading (c/include/sr_sensors.h) and their Jacobians against
                the independent CasADi reference (runtime.verification.sensor_reference) and Richardson
                differences of the C readings through retract (runtime.verification.sensor_checks)
  linearizations eigenvalues at rest against the reference's AD Jacobian, steady rolling against
                power balance and statics, the Floquet exponent of rolling against a perturbed
                simulation (runtime.verification.linearizations)
"""
import argparse
import dataclasses
import sys
import time

import numpy as np

from ..model import Model
from ..params import Params
from ..so3 import exp, rot_x, rot_y, rot_z
from ..state import IDX_NU, IDX_Q, IDX_QZ, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, initial_state, rotations
from ..validation import project_state
from .flow import state_derivative
from .sampling import random_general_params, random_inputs, random_params, random_state


@dataclasses.dataclass
class CheckResult:
    """One row of the verification table: a check's worst errors, its tolerance, and what it would catch."""
    name: str
    abs_error: float
    rel_error: float
    tolerance: float
    detail: str = ""
    at_least: bool = False      # a lower bound on abs_error instead of an upper bound on rel_error
    catches: str = ""           # what a kernel error this row would show (each has a test that it fails)

    @property
    def passed(self):
        """True when the error is within the tolerance (or above the bound, for a lower-bound row)."""
        if self.at_least:
            return bool(self.abs_error >= self.tolerance)
        return bool(self.rel_error <= self.tolerance)


def integrate(model, x0, t_end, u=None, rtol=1e-12, atol=1e-12, dense=False):
    """solve_ivp (DOP853) on the 35 entries with `state_derivative`: the independent tight-tolerance solution."""
    from scipy.integrate import solve_ivp
    return solve_ivp(lambda t, x: state_derivative(model, x, u), (0.0, t_end), x0, method="DOP853",
                     rtol=rtol, atol=atol, first_step=1e-4, dense_output=dense)


# -- cross-check against the independent reference --------------------------------------
def parameter_sets(rng, n_random=5):
    """The paper's simulation parameters and `n_random` random ones."""
    return [Params.paper_simulation()] + [random_params(rng) for _ in range(n_random)]


def cross_check(n_states=1000, seed=0, n_param_sets=6):
    """Kernel vs reference; n_states per parameter set."""
    from .reference import ReferenceModel
    rng = np.random.default_rng(seed)
    worst = {k: [0.0, 0.0, ""] for k in ("accel", "inertia", "energy")}
    for params in parameter_sets(rng, n_param_sets - 1):
        model, ref = Model(params), ReferenceModel(params.as_dict())
        constant_potential = (params.m_S + params.m_Y) * params.g * np.cos(params.slope)
        for _ in range(n_states):
            x, u = random_state(rng, params), random_inputs(rng, 1)[0]
            pairs = {
                "accel": (model.accel(x, u), ref.accel(x, u)),
                "inertia": (model.inertia(x), ref.inertia(x)),
                # The reference counts the shell's and yoke's constant potential (m_S + m_Y) g q_z.
                "energy": (model.energy(x), ref.energy(x) - constant_potential * x[IDX_QZ]),
            }
            for key, (ours, theirs) in pairs.items():
                err = float(np.abs(np.asarray(ours) - theirs).max())
                rel = err / max(float(np.abs(theirs).max()), 1e-300)
                if rel > worst[key][1]:
                    worst[key] = [err, rel, f"worst at a state with |ν| = {np.linalg.norm(x[IDX_NU]):.3g}"]
    total = n_states * n_param_sets
    catches = {"accel": "any error in ν̇ above 1e-10 relative (a term, a sign, a parameter)",
               "inertia": "an error in the mass matrix M",
               "energy": "an error in the kinetic or potential energy"}
    return [CheckResult(f"cross-check {k} ({total} states, {n_param_sets} param sets)", *v[:2], 1e-10, v[2],
                        catches=catches[k]) for k, v in worst.items()]


def general_cross_check(n_states=200, seed=6, n_robots=5):
    """The general kernels on random general robots against both independent models:
    the CasADi reference (accel, inertia, energy) and the Kane model (accel)."""
    from .alternatives.kane import KaneModel
    from .reference import ReferenceModel
    rng = np.random.default_rng(seed)
    worst = {k: [0.0, 0.0, ""] for k in ("accel vs reference", "accel vs Kane", "inertia", "energy")}
    for _ in range(n_robots):
        params = random_general_params(rng)
        model, ref, kane = Model(params), ReferenceModel(params.as_dict()), KaneModel(params)
        constant_potential = (params.m_S + params.m_Y) * params.g * np.cos(params.slope)
        for _ in range(n_states):
            x, u = random_state(rng, params), random_inputs(rng, 1)[0]
            a = model.accel(x, u)
            pairs = {"accel vs reference": (a, ref.accel(x, u)), "accel vs Kane": (a, kane.accel(x, u)),
                     "inertia": (model.inertia(x), ref.inertia(x)),
                     "energy": (model.energy(x), ref.energy(x) - constant_potential * x[IDX_QZ])}
            for key, (ours, theirs) in pairs.items():
                err = float(np.abs(np.asarray(ours) - theirs).max())
                rel = err / max(float(np.abs(theirs).max()), 1e-300)
                if rel > worst[key][1]:
                    worst[key] = [err, rel, f"slope {params.slope:.2f} rad, gears {params.n_Y:.0f}/{params.n_P:.0f}"]
    catches = {"accel vs reference": "an error in the general robot's ν̇: a centre, a tensor entry, a rotor, the slope",
               "accel vs Kane": "the same, against a third derivation (KanesMethod, Euler angles)",
               "inertia": "an error in the general robot's M (rotors, products of inertia)",
               "energy": "an error in the general robot's energy (the slope's potential)"}
    total = n_states * n_robots
    return [CheckResult(f"general robots: {k} ({total} states, {n_robots} robots)", *v[:2], 1e-12, v[2],
                        catches=catches[k]) for k, v in worst.items()]


# -- physics invariants ------------------------------------------------------------------
def energy_conservation(n_runs=3, seed=1, t_end=20.0, general=False):
    """Energy along motions without damping or torque: the paper's robot, or (general=True) random
    general robots on their slopes (the climb's potential m_R g_x q_x included)."""
    rng = np.random.default_rng(seed)
    worst = (0.0, 0.0)
    for _ in range(n_runs):
        params = random_general_params(rng) if general else Params()
        model = Model(params.replace(k_S=0.0, k_Y=0.0, k_P=0.0))
        x0 = random_state(rng, model.params, max_speed=3.0)
        sol = integrate(model, x0, t_end)
        E0 = model.energy(x0)
        at_rest = x0.copy()
        at_rest[IDX_NU] = 0.0
        scale = abs(E0) + abs(E0 - model.energy(at_rest)) + model.params.potential_range()
        drift = max(abs(model.energy(project_state(x, model.params.r)) - E0) for x in sol.y.T)
        if drift / scale > worst[1]:
            worst = (drift, drift / scale)
    robots = "random general robots on slopes" if general else "the paper's robot"
    return CheckResult(f"energy conserved without friction ({n_runs} runs, {t_end:g} s, {robots})", *worst, 1e-9,
                       "relative to |E| + the kinetic energy + the shape potential's range",
                       catches="accel and energy that do not belong to one Lagrangian")


def configuration_flow(x, t, r=0.0):
    """The state moved for time t along the exact kinematics with the speeds frozen, rolling on a
    shell of radius r (q moves at the constant r (R_S ω_S) × e_z, since R_S Exp(tω_S) ω_S = R_S ω_S)."""
    y = x.copy()
    R_S, R_Y, R_P = rotations(x)
    y[IDX_RS] = (R_S @ exp(t * x[IDX_WS])).ravel()
    y[IDX_RY] = (R_Y @ rot_x(t * x[IDX_WY])).ravel()
    y[IDX_RP] = (R_P @ rot_y(t * x[IDX_WP])).ravel()
    y[IDX_Q] = x[IDX_Q] + t * r * np.cross(R_S @ x[IDX_WS], [0.0, 0.0, 1.0])
    return y


def energy_rate(model, x, u):
    """dE/dt = νᵀ M ν̇ (kernel inertia and accel) + ∂E/∂(configuration)·(kinematics).

    The configuration part is an 8th-order central difference of E along the
    exact configuration flow (q rolling with the shell: on a slope E depends on
    q_x), accurate to rounding.
    """
    nu = x[IDX_NU]
    kinetic_part = nu @ model.inertia(x) @ model.accel(x, u)
    h = 1e-3
    weights = {1: 4 / 5, 2: -1 / 5, 3: 4 / 105, 4: -1 / 280}
    params = getattr(model, "params", None)     # a model without params (the paper's formulas): no slope
    r = params.r if params is not None else 0.0
    config_part = sum(w * (model.energy(configuration_flow(x, k * h, r)) - model.energy(configuration_flow(x, -k * h, r)))
                      for k, w in weights.items()) / h
    return kinetic_part + config_part


def power_balance(n_states=200, seed=2):
    """Check row: the rate of change of the energy equals the power of the torques minus the damping's."""
    rng = np.random.default_rng(seed)
    worst = (0.0, 0.0)
    for params in parameter_sets(rng, 2) + [random_general_params(rng) for _ in range(2)]:
        model = Model(params)
        for _ in range(n_states):
            x, u = random_state(rng, params), random_inputs(rng, 1)[0]
            w_S, w_Y, w_P, w = x[IDX_WS], x[IDX_WY], x[IDX_WP], x[IDX_NU]
            supplied = u @ (w_Y, w_P)
            dissipated = params.k_S * w_S @ w_S + params.k_Y * w_Y ** 2 + params.k_P * w_P ** 2
            err = abs(energy_rate(model, x, u) - (supplied - dissipated))
            scale = abs(supplied) + dissipated + abs(w @ model.inertia(x) @ model.accel(x, u))
            if err / scale > worst[1]:
                worst = (err, err / scale)
    return CheckResult(f"power balance dE/dt = u·ω − Σ k ω² ({5 * n_states} states, 2 general robots on slopes)",
                       *worst, 1e-9,
                       "relative to |u·ω| + Σ k ω² + |νᵀMν̇|",
                       catches="wrong or missing torque or damping terms (the non-conservative forces)")


def rolling_contact(n_runs=3, seed=3, t_end=1.0, dt=2.5e-4, samples=20):
    """The rolling contact along motions computed by the C steppers (RKMK4, CF4), two balances.

    Contact force: the force the kernel's motion implies (dP/dt − m_tot g_vec, the bodies' momenta
    from rigid-body kinematics, differentiated in time) against the force of the independent
    reference's Lagrange multiplier at the same state.  Angular momentum about the contact point:
    dH_c/dt + q̇ × P against the moments of gravity and shell damping (runtime.verification.contact).
    A constant torque per run keeps the motion smooth for the time differences; dt = 2.5e-4 s keeps
    the steppers' O(dt⁴) error (about 1e-11 relative) well below the tolerance 1e-9.
    """
    from .contact import DIFF_HALF_WIDTH, ReferenceContact, momentum_residuals
    rng = np.random.default_rng(seed)
    steps = int(round(t_end / dt))
    worst_force, worst_moment = (0.0, 0.0), (0.0, 0.0)
    for run, params in enumerate(parameter_sets(rng, n_runs - 1)):
        model, reference = Model(params), ReferenceContact(params.as_dict())
        x0 = random_state(rng, params, max_speed=3.0)
        u = np.tile(random_inputs(rng, 1)[0], (steps, 1))
        X = model.simulate(x0, dt, steps, u=u, method=("rkmk4", "cf4")[run % 2])
        implied, moment_residual = momentum_residuals(X, dt, params.as_dict())
        rows = np.linspace(0, len(implied) - 1, samples).round().astype(int)
        expected = np.array([reference.force(X[i + DIFF_HALF_WIDTH], u[0]) for i in rows])
        err = float(np.abs(implied[rows] - expected).max())
        if err / np.abs(expected).max() > worst_force[1]:
            worst_force = (err, err / float(np.abs(expected).max()))
        weight_moment = params.m_R * params.g * params.r
        err = float(np.abs(moment_residual).max())
        if err / weight_moment > worst_moment[1]:
            worst_moment = (err, err / weight_moment)
    return [CheckResult(f"rolling: contact force of the C-stepped motion vs reference multiplier ({n_runs} runs)",
                        *worst_force, 1e-9, "dP/dt - m g against λ; relative to max |λ|",
                        catches="C-stepped motion whose forces are wrong (a parameter off by 1e-6)"),
            CheckResult(f"rolling: angular momentum balance about the contact point ({n_runs} runs)",
                        *worst_moment, 1e-9, "relative to m_tot g r",
                        catches="C-stepped motion violating Euler's law about the contact point")]


def contact_force(n_states=200, seed=10, n_robots=2):
    """The contact-force kernel (Model.contact_force: the total momentum balance at the kernel's ν̇)
    against the independent reference's Lagrange multiplier (runtime.verification.contact) at random
    states and torques, on the paper's robot and on random general robots on slopes."""
    from .contact import ReferenceContact
    rng = np.random.default_rng(seed)
    robots = [Params.paper_simulation()] + [random_general_params(rng) for _ in range(n_robots)]
    worst = (0.0, 0.0)
    for params in robots:
        model, reference = Model(params), ReferenceContact(params.as_dict())
        for _ in range(n_states):
            x, u = random_state(rng, params, max_speed=5.0), random_inputs(rng, 1)[0]
            expected = reference.force(x, u)
            err = float(np.abs(model.contact_force(x, u) - expected).max())
            if err / float(np.abs(expected).max()) > worst[1]:
                worst = (err, err / float(np.abs(expected).max()))
    return CheckResult(f"contact force vs reference multiplier ({n_states * len(robots)} states, "
                       f"{len(robots)} robots, slopes)", *worst, 1e-12, "relative to max |λ|",
                       catches="a force off by 1e-9 relative; a mass or the slope off by 1e-6 in the kernel")


def equilibrium_state(theta_Y, theta_P, up, alpha=0.0):
    """The rest state with joint angles theta_Y, theta_P and the pendulum below (or above, `up`) the
    centre."""
    R_YP = rot_x(theta_Y) @ rot_y(theta_P)
    flip = rot_x(np.pi) if up else np.eye(3)
    return initial_state(theta_Y, theta_P, R_S=rot_z(alpha) @ flip @ R_YP.T)


def linearization(model, x):
    """Jacobian of (configuration, ν) ↦ (ν, ν̇) at x; configuration = (φ on R_S, θ_Y, θ_P)."""
    def field(z):
        y = x.copy()
        R_S, R_Y, R_P = rotations(x)
        y[IDX_RS] = (R_S @ exp(z[0:3])).ravel()
        y[IDX_RY] = (R_Y @ rot_x(z[3])).ravel()
        y[IDX_RP] = (R_P @ rot_y(z[4])).ravel()
        y[IDX_NU] = z[5:10]
        # d/dt of the chart coordinates equals ν to first order at z = 0.
        return np.concatenate([z[5:10], model.accel(y)])
    h = 1e-6
    return np.column_stack([(field(h * e) - field(-h * e)) / (2 * h) for e in np.eye(10)])


def equilibria(seed=4):
    """Check rows: no acceleration at the equilibria; the pendulum down is stable, up unstable."""
    rng = np.random.default_rng(seed)
    model = Model(Params.paper_simulation())
    worst_accel = 0.0
    down_max, up_max = -np.inf, np.inf
    for _ in range(10):
        theta_Y, theta_P, alpha = rng.uniform(-np.pi, np.pi, size=3)
        for up in (False, True):
            x = equilibrium_state(theta_Y, theta_P, up, alpha)
            worst_accel = max(worst_accel, float(np.abs(model.accel(x)).max()))
            growth = np.linalg.eigvals(linearization(model, x)).real.max()
            if up:
                up_max = min(up_max, growth)
            else:
                down_max = max(down_max, growth)
    return [
        CheckResult("equilibria of eq. (108): accel = 0", worst_accel, worst_accel, 1e-12,
                    catches="a spurious force at rest (a bias of 1e-10 in ν̇)"),
        CheckResult("pendulum down: max Re(eigenvalue) <= 1e-6", max(down_max, 0.0), max(down_max, 0.0), 1e-6,
                    catches="a sign error in ν̇ (restoring forces that repel)"),
        CheckResult("pendulum up: max Re(eigenvalue) >= 0.1 1/s", up_max, float("nan"), 0.1,
                    "smallest growth rate over the cases", at_least=True,
                    catches="gravity too weak or of the wrong sign"),
    ]


def planar_symmetry(steps=2000):
    """R_Y = I, yoke at rest: motion in the x–z plane; R_P = I, pendulum at rest: the y–z plane."""
    model = Model(Params.paper_simulation())
    a = model.simulate(initial_state(theta_P=0.7), 0.01, steps, u=np.tile([0.0, 0.05], (steps, 1)))
    b = model.simulate(initial_state(theta_Y=0.7), 0.01, steps, u=np.tile([0.05, 0.0], (steps, 1)))
    q_x, q_y = IDX_Q.start, IDX_Q.start + 1
    w_Sx, w_Sy, w_Sz = range(IDX_WS.start, IDX_WS.stop)
    off_a = np.abs(a[:, [q_y, w_Sx, w_Sz, IDX_WY]]).max()
    off_b = np.abs(b[:, [q_x, w_Sy, w_Sz, IDX_WP]]).max()
    scale_a, scale_b = np.abs(a[:, q_x]).max(), np.abs(b[:, q_y]).max()
    return [CheckResult("symmetry: R_Y = I, yoke at rest -> x-z plane", off_a, off_a / scale_a, 1e-12,
                        "q_y, ω_Sx, ω_Sz, ω_Y", catches="a coupling that breaks the symmetry (1e-9)"),
            CheckResult("symmetry: R_P = I, pendulum at rest -> y-z plane", off_b, off_b / scale_b, 1e-12,
                        "q_x, ω_Sy, ω_Sz, ω_P", catches="a coupling that breaks the symmetry (1e-9)")]


def jacobian_rows(n_states=1000, seed=5):
    """Check rows of the accel and step Jacobians against finite differences and the variational equations."""
    from .jacobians import accel_jacobian_checks, step_jacobian_checks, variational_checks
    general = random_general_params(np.random.default_rng(seed + 2))
    general_rows = [(f"{name} on a general robot", *rest)
                    for name, *rest in accel_jacobian_checks(max(n_states // 5, 20), seed + 3, params=general,
                                                             n_difference=10)]
    return ([CheckResult(*row, catches="a Jacobian entry off by 1e-6")
             for row in accel_jacobian_checks(n_states, seed) + general_rows]
            + [CheckResult(*row, catches="an entry of F or G off by 1e-6 of the largest")
               for row in step_jacobian_checks(min(n_states, 20), seed + 1)]
            + [CheckResult(*row, detail="worst rel = how far the measured order falls short of the expected",
                           catches="a step Jacobian of the wrong order (another method's, a missing stage); "
                                   "for RKMK4 and CF4 an entry off by 1e-3")
               for row in variational_checks(seed=seed + 4)])


def param_jacobian_rows(n_states=1000, seed=0):
    """Check rows of the parameter Jacobians against AD and differences in the parameters."""
    from .param_jacobians import param_jacobian_checks, step_param_jacobian_checks
    return ([CheckResult(*row, catches="a column of dν̇/dp off by 1e-6 of the largest entry")
             for row in param_jacobian_checks(max(n_states // 5, 20), seed)]
            + [CheckResult(*row, catches="a row of the step's dx/dp off by 1e-6 of the largest entry")
               for row in step_param_jacobian_checks(min(n_states, 10), seed + 1)])


#: What each sensor row would show (tests/runtime/verification/test_sensor_checks.py fails each).
SENSOR_CATCHES = ("a lever arm off by 1e-6 m; the slope left out", "a heading off by 1e-9 rad",
                  "an encoder angle off by 1e-9 rad", "a Jacobian entry off by 1e-7 (also along nu_dot)",
                  "a Jacobian entry off by 1e-7", "a Jacobian entry off by 1e-7",
                  "nu_dot held where it moves with the state; an entry off by 1e-7",
                  "an entry along nu_dot off by 1e-7", "a Jacobian entry off by 1e-7", "a lever arm off by 1e-6 m")


def sensor_rows(n_states=1000, seed=0):
    """The sensor models (c/include/sr_sensors.h) against the independent CasADi reference
    (runtime.verification.sensor_reference) and Richardson differences of the C readings, on the
    paper's robot and on a general robot on a slope (runtime.verification.sensor_checks)."""
    from .sensor_checks import ad_checks, difference_checks, measured_accel_check, value_checks
    general = random_general_params(np.random.default_rng(seed + 1))
    n = max(n_states // 5, 30)
    rows = []
    for k, (label, params) in enumerate((("paper's robot", None), ("a general robot on a slope", general))):
        s = seed + 10 * k
        found = (value_checks(n, s + 2, params) + ad_checks(n, s + 3, params)
                 + difference_checks(max(n // 10, 6), s + 4, params) + measured_accel_check(max(n // 4, 10), s + 5, params))
        rows += [CheckResult(f"{name}, {label}", err, rel, tol, catches=catches)
                 for (name, err, rel, tol), catches in zip(found, SENSOR_CATCHES)]
    return rows


def linearization_rows():
    """Check rows of the linearisations (equilibria, steady rolling, its stability)."""
    from .linearizations import equilibrium_checks, rolling_stability_checks, steady_rolling_checks
    return ([CheckResult(*row, catches="the pendulum's stiffness in A off by 1e-6") for row in equilibrium_checks()]
            + [CheckResult(*row, catches="an acceleration off by 1e-6 rad/s²") for row in steady_rolling_checks()]
            + [CheckResult(*row, catches="snapshot eigenvalues of a periodic motion; step Jacobians of a 2 % longer step")
               for row in rolling_stability_checks()])


def run_all(n_states=1000, seed=0, progress=None):
    """Runs every check and returns the CheckResult rows."""
    steps = [
        ("cross-check", lambda: cross_check(n_states, seed)),
        ("general robots", lambda: general_cross_check(max(n_states // 5, 20), seed + 6)),
        ("energy", lambda: [energy_conservation(seed=seed + 1), energy_conservation(seed=seed + 7, t_end=5.0, general=True)]),
        ("power", lambda: [power_balance(max(n_states // 5, 20), seed=seed + 2)]),
        ("rolling", lambda: rolling_contact(seed=seed + 3)),
        ("contact force", lambda: [contact_force(max(n_states // 5, 20), seed + 10)]),
        ("equilibria", lambda: equilibria(seed=seed + 4)),
        ("symmetry", planar_symmetry),
        ("jacobians", lambda: jacobian_rows(n_states, seed + 5)),
        ("linearizations", linearization_rows),
        ("parameters", lambda: param_jacobian_rows(n_states, seed + 11)),
        ("sensors", lambda: sensor_rows(n_states, seed + 9)),
    ]
    results = []
    for i, (name, fn) in enumerate(steps):
        if progress:
            progress(f"[{i + 1}/{len(steps)}] {name} ...")
        results.extend(fn())
    return results


def format_table(results):
    """The CheckResult rows as the printed table."""
    rows = [("check", "worst abs", "worst rel", "tolerance", "result", "would catch")]
    rows += [(r.name, f"{r.abs_error:.2e}", "-" if np.isnan(r.rel_error) else f"{r.rel_error:.2e}",
              (">= " if r.at_least else "") + f"{r.tolerance:.0e}",
              "pass" if r.passed else "FAIL", r.catches) for r in results]
    widths = [max(len(row[i]) for row in rows) for i in range(6)]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)) for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def main(argv=None):
    """`python -m runtime verify`: run every check and print the table; returns 1 when one fails, else 0."""
    parser = argparse.ArgumentParser(prog="python -m runtime verify", description="Verify the generated kernels.")
    parser.add_argument("--states", type=int, default=1000, help="random states per parameter set (default 1000)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.states < 1:
        parser.error("--states: must be at least 1")
    start = time.perf_counter()
    results = run_all(args.states, args.seed, progress=lambda m: print(m, file=sys.stderr, flush=True))
    print(format_table(results))
    failed = [r for r in results if not r.passed]
    print(f"\n{len(results) - len(failed)} passed, {len(failed)} failed ({time.perf_counter() - start:.1f} s)")
    return 1 if failed else 0
