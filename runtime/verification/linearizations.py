"""Rows of `make verify` for the linearisations of runtime/stability.py.

* Eigenvalues at the equilibria (pendulum down and up): `linearize` against the same error
  dynamics with the accel Jacobian replaced by CasADi AD of the independent reference.
* Steady rolling: the holding torque and the yoke's tilt against power balance and statics
  (u_Y = −(k_S + k_Y) ω, sin α = −k_S ω / (m_P g l/2), derived by hand in stability.py).
* Rolling stability: the largest Floquet exponent at 1 m/s against the growth rate of a
  perturbed nonlinear simulation (C RKMK4, 12 s, fitted over the last 8 s).

Each check takes the function under test as an argument, so a test can perturb it.
"""
import numpy as np

from .. import stability
from ..model import Model
from ..params import Params
from ..state import IDX_E_NU
from .jacobians import reference_accel_jacobian
from .reference import ReferenceModel


def _spectrum_distance(ours, theirs):
    """max over ours of the distance to the nearest of theirs, relative to the largest |λ|."""
    return float(max(np.min(np.abs(theirs - ev)) for ev in ours) / np.abs(theirs).max())


def equilibrium_checks(params=None, linearize=None):
    """Check rows: the eigenvalues of the linearisation at the two equilibria against those of the
    independent reference's Jacobian."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    linearize = linearize or (lambda m, x, u: m.linearize(x, u))
    ref = reference_accel_jacobian(ReferenceModel(params.as_dict()))
    rows = []
    for pendulum in ("down", "up"):
        x, u = stability.equilibrium(params, pendulum), np.zeros(2)
        A, _ = linearize(model, x, u)
        A_ref, _ = model.linearize(x, u)
        A_ref = A_ref.copy()
        A_ref[IDX_E_NU, :] = np.asarray(ref(x, u)[0])
        rel = _spectrum_distance(np.linalg.eigvals(A), np.linalg.eigvals(A_ref))
        rows.append((f"eigenvalues at rest, pendulum {pendulum}: linearize vs the reference's AD Jacobian",
                     rel, rel, 1e-8))
    return rows


def steady_rolling_checks(params=None, speeds=(0.3, 1.0, 1.5)):
    """Check rows: steady rolling at each speed holds with the predicted torque and accelerations."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    worst = 0.0
    for v in speeds:
        x, u = stability.steady_rolling(model, v)
        w = v / params.r
        worst = max(worst, abs(u[0] + (params.k_S + params.k_Y) * w) / abs(u[0]),
                    abs(x[stability.SIN_ALPHA] + params.k_S * w / (params.m_P * params.g * -params.c_P[2])))
    return [(f"steady rolling ({len(speeds)} speeds): holding torque and tilt vs power balance and statics",
             worst, worst, 1e-10)]


def rolling_growth_rate(model, speed, duration=12.0, dt=0.001, seed=0):
    """Growth rate [1/s] of a 1e-7 perturbation of steady rolling in the nonlinear C simulation: the
    slope of log |x ⊖ x_ref| (attitude of the shell and position left out: they drift with the
    symmetries) over the last two thirds of `duration`."""
    x, u = stability.steady_rolling(model, speed)
    n = int(round(duration / dt))
    torques = np.tile(u, (n, 1))
    ref = model.simulate(x, dt, n, u=torques, method="rkmk4")
    d = np.random.default_rng(seed).normal(size=12)
    pert = model.simulate(model.retract(x, 1e-7 * d / np.linalg.norm(d)), dt, n, u=torques, method="rkmk4")
    keep = [3, 4, 7, 8, 9, 10, 11]
    t = np.arange(0, n + 1, 100) * dt
    err = np.array([np.linalg.norm(model.local(ref[k], pert[k])[keep]) for k in range(0, n + 1, 100)])
    late = t >= duration / 3
    return float(np.polyfit(t[late], np.log(err[late]), 1)[0])


def rolling_stability_checks(params=None, speed=1.0, floquet=None):
    """Check rows: the largest Floquet exponent of steady rolling against the growth rate of a perturbed
    simulation."""
    params = Params.paper_simulation() if params is None else params
    model = Model(params)
    floquet = floquet or stability.floquet_exponents
    predicted = float(floquet(model, speed)[0].real)
    simulated = rolling_growth_rate(model, speed)
    rel = abs(predicted - simulated) / abs(simulated)
    return [(f"rolling at {speed} m/s: largest Floquet exponent ({predicted:.4f}/s) vs a perturbed simulation "
             f"({simulated:.4f}/s)", abs(predicted - simulated), rel, 0.01)]
