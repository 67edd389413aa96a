"""Linearisations: eigenvalues at the equilibria, from `Model.linearize`,
and the Floquet exponents of steady straight rolling, from `Model.step_jacobian` (the error
coordinates of runtime.group).

    python -m runtime stability [FIGURE]    # prints the tables, writes docs/figures/rolling-stability.png

Steady straight rolling at speed v: the shell spins at ω = v/r about its x axis (the yoke's
hinge, kept horizontal), the yoke turns back at ω_Y = −ω so that it keeps its attitude in the
world, tilted by α about x, and the pendulum hangs at θ_P = 0.  The damping of the shell and the
yoke joint brakes that motion; the yoke motor's torque u_Y holds it, and the tilt α is where the
pendulum's weight balances that torque.  (α, u_Y) solve ω̇_S,x = ω̇_Y = 0 (the other three
accelerations vanish by symmetry, checked), by Newton's method with the exact derivatives of
`accel_jacobian`.  Power balance gives u_Y = −(k_S + k_Y) ω (the motor turns the yoke at −ω
relative to the shell against both dampings); the yoke feels u_Y and its joint's damping
k_Y ω, net −k_S ω, which the pendulum's weight balances: sin α = −k_S ω / (m_P g l/2).  Beyond
k_S ω = m_P g l/2 the pendulum cannot hold the yoke, which flips (docs/control.md); for
Params.paper_simulation() that is ω = 6.1 rad/s, v = 1.84 m/s.

Steady rolling is periodic in the state (γ and R_Y turn with the shell), so the eigenvalues of
`linearize` at one instant of it are not its stability: they are the same at every instant but
miss the turning of the error coordinates (at 1 m/s they give a growth rate of 0.14/s where a
perturbed simulation grows at 0.37/s).  The Floquet exponents are: log(eig(Φ))/T of the
monodromy Φ, the product of the step Jacobians (RKMK4) over one period T = 2π r/v; they match
the simulation (runtime.verification.jacobians.rolling_stability_checks).

Zero eigenvalues come from symmetries, not from marginal stability: the position on the plane (2),
the heading (rotation about the vertical), and, at rest, turning the shell about the yoke's or the
pendulum's hinge with the joint angle compensating (2 more; while rolling, 1: the phase along the
motion).  `nontrivial` drops the eigenvalues within 1e-9 of zero.
"""

import argparse

import numpy as np

from .atomic import output_file
from .model import Model
from .params import Params
from .state import IDX_E_TH_Y, IDX_RY, NE, initial_state

SIN_ALPHA = IDX_RY.start + 7      # sin of the yoke's tilt, R_Y[2, 1]
SPEEDS = np.linspace(0.0, 1.8, 37)   # m/s; above 1.84 m/s the paper's robot cannot hold steady rolling


def equilibrium(params, pendulum="down"):
    """The state at rest with the pendulum hanging down (θ_P = 0) or standing up (θ_P = π)."""
    if pendulum not in ("down", "up"):
        raise ValueError(f"pendulum: expected 'down' or 'up', got {pendulum!r}")
    return initial_state(theta_P=0.0 if pendulum == "down" else np.pi, r=params.r)


def rolling_state(params, speed, alpha):
    """The state of steady rolling at `speed` [m/s], the shell spinning about its x axis, the yoke at angle
    `alpha` [rad]."""
    w = speed / params.r
    return initial_state(theta_Y=alpha, w_S=(w, 0.0, 0.0), w_Y=-w, r=params.r)


def steady_rolling(model, speed, tol=1e-13, iterations=30):
    """(x, u) of steady straight rolling at `speed` [m/s] (see the module's docstring)."""
    alpha, u_Y = 0.0, 0.0
    rows = [0, 3]                      # ω̇_S,x and ω̇_Y in ν̇ = (ω̇_S, ω̇_Y, ω̇_P)
    for _ in range(iterations):
        x, u = rolling_state(model.params, speed, alpha), np.array([u_Y, 0.0])
        a = model.accel(x, u)
        if np.abs(a).max() <= tol * max(1.0, speed / model.params.r):
            return x, u
        Ja, Jb = model.accel_jacobian(x, u)
        J = np.array([[Ja[i, IDX_E_TH_Y], Jb[i, 0]] for i in rows])
        d_alpha, d_u = np.linalg.solve(J, -a[rows])
        alpha, u_Y = alpha + d_alpha, u_Y + d_u
    raise ValueError(f"steady_rolling: no steady rolling found at speed {speed} m/s (accelerations {a})")


def eigenvalues(model, x, u=None):
    """Eigenvalues of A of `linearize(x, u)`, sorted by real part, then imaginary part."""
    A, _ = model.linearize(x, u)
    ev = np.linalg.eigvals(A)
    return ev[np.lexsort((ev.imag, ev.real))]


def nontrivial(ev, tol=1e-9):
    """The eigenvalues `ev` larger in modulus than `tol` (drops the zeros of the symmetries)."""
    return ev[np.abs(ev) > tol]


def floquet_exponents(model, speed, steps_per_second=250, min_steps=400):
    """Floquet exponents [1/s] of steady rolling at `speed` > 0: log(eig(Φ))/T, Φ the product of
    RKMK4 step Jacobians over one period T = 2π r / speed; sorted by real part, largest first."""
    if not speed > 0:
        raise ValueError(f"speed: steady rolling needs a positive speed for its period, got {speed!r}")
    x, u = steady_rolling(model, speed)
    period = 2 * np.pi * model.params.r / speed
    n = max(min_steps, int(np.ceil(period * steps_per_second)))
    dt = period / n
    monodromy = np.eye(NE)
    for _ in range(n):
        F, _ = model.step_jacobian(x, u, dt, "rkmk4")
        monodromy = F @ monodromy
        x = model.step(x, u, dt, "rkmk4")
    ex = np.log(np.linalg.eigvals(monodromy).astype(complex)) / period
    return ex[np.argsort(-ex.real, kind="stable")]


def rolling_table(model, speeds=SPEEDS):
    """Per speed > 0: (speed, holding torque u_Y [N m], the non-trivial Floquet exponents)."""
    rows = []
    for v in speeds:
        if v > 0:
            _, u = steady_rolling(model, v)
            rows.append((float(v), float(u[0]), nontrivial(floquet_exponents(model, v), 1e-6)))
    return rows


def figure(model, out, speeds=SPEEDS):
    """Draws the Floquet exponents of steady rolling against speed and saves the figure to `out`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_re, ax_im) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for v, _, ev in rolling_table(model, speeds):
        ax_re.plot(np.full(ev.size, v), ev.real, "k.", ms=4)
        ax_im.plot(np.full(ev.size, v), np.abs(ev.imag) / (2 * np.pi), "k.", ms=4)
    ax_re.axhline(0.0, color="r", lw=0.8)
    ax_re.set(xlabel="rolling speed v [m/s]", ylabel="Re λ [1/s]  (> 0: grows)",
              title="Growth (> 0) or decay rate of each mode")
    ax_im.set(xlabel="rolling speed v [m/s]", ylabel="|Im λ| / 2π [Hz] (modulo the rolling frequency)",
              title="Oscillation frequency")
    fig.suptitle("Steady straight rolling, Params.paper_simulation(): Floquet exponents from step_jacobian")
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv=()):
    """Prints the eigenvalues of the equilibria and the Floquet exponents of steady rolling."""
    parser = argparse.ArgumentParser(prog="python -m runtime stability")
    parser.add_argument("figure", nargs="?", type=output_file, default="docs/figures/rolling-stability.png", help="where to write the figure")
    args = parser.parse_args(list(argv))
    model = Model(Params.paper_simulation())
    np.set_printoptions(precision=4, suppress=True, linewidth=120)
    for pendulum in ("down", "up"):
        print(f"equilibrium, pendulum {pendulum}: {nontrivial(eigenvalues(model, equilibrium(model.params, pendulum)))}")
    print("steady rolling: speed [m/s], holding torque u_Y [N m], largest Floquet exponent: Re [1/s], |Im| [rad/s]")
    for v, u_Y, ev in rolling_table(model, SPEEDS[::5]):
        top = ev[np.argmax(ev.real)]
        print(f"  {v:4.2f}  {u_Y:8.5f}  {top.real:8.4f}  {abs(top.imag):8.4f}")
    out = args.figure
    figure(model, out)
    print(f"written: {out}")
    return 0
