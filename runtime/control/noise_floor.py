"""How far the LQR loop wanders under a sensor set's white torque disturbance, from its linearisation.

The closed loops on sensors (docs/control.md, "Closed on the estimator") are driven by the set's
process noise: a white torque of density q [N·m/√Hz] on the shell's three axes and on both joints.
About one operating point (steady rolling at v on a path of curvature κ, runtime/control/lqr_design.py)
the loop is z⁺ = (A_d − B_d K) z + w, with w the torque noise put through the inverse inertia
onto the rates and integrated over one period (covariance Q_d = ∫₀ᵀ e^{Aτ} G W Gᵀ e^{Aᵀτ} dτ), so its
steady covariance S solves the discrete Lyapunov equation S = A_cl S A_clᵀ + Q_d.  From S: the
standard deviations of the cross-track error, of the heading (E_z, the yoke's attitude error about
the vertical) and of the torques, and, by a Monte Carlo of the same linear loop, how often the
heading stays inside a band for a given time: the chance that a noisy heading step "settles".

Why this exists: it separates what gains can change from what they cannot.  The heading wanders
from the shell's torque about the vertical, which the motors reach only through the pendulum's
lean: a heading weight that weighs the lean alike (`attitude_rad`, E_y and E_z together) holds back
the lean it steers with and stops at a floor near 1°, however free the torque; the heading's own
weight (`heading_rad`, the lean left at its size) goes far below it, at the cost of pendulum
torque (`main` prints both).
"""
import argparse
import dataclasses
import math

import numpy as np

# The model and the LQR's design are imported where used: the command refuses bad options at once.

#: The heading error's coordinate in lqr_design's z: E_z, the yoke's attitude error about the vertical.
Z_HEADING = 2
#: The lean's coordinate: E_y.
Z_LEAN = 1
#: Quadrature points over one period of the noise's integral (its integrand is smooth: e^{Aτ}).
NOISE_QUADRATURE = 20


@dataclasses.dataclass(frozen=True)
class Wander:
    """The loop's steady spread about one operating point: standard deviations of the cross-track
    error [m], heading and lean [rad], torques (2,) [N·m]; S the steady covariance of the loop's
    coordinates `keep` (A_cl, Q_d its closed-loop matrix and noise, one controller period)."""
    cross_track_m: float
    heading_rad: float
    lean_rad: float
    torque_n_m: np.ndarray
    keep: np.ndarray
    S: np.ndarray
    A_cl: np.ndarray
    Q_d: np.ndarray


def noise_covariance(model, z_star, v, A, densities, period):
    """Q_d (NZ×NZ): the white generalized torque of densities (5,) [N·m/√Hz] on ν = (ω_S, ω_Y, ω_P),
    put onto the rates z[4:9] by M⁻¹ at the operating point z* of speed v and integrated over one
    period through e^{Aτ} (midpoint rule in NOISE_QUADRATURE pieces)."""
    from scipy.linalg import expm
    from . import lqr_design as design
    x = design.lift(z_star, v, model.params.r)
    G = np.zeros((design.NZ, 5))
    G[design.Z_OM.start:design.Z_WP + 1] = np.linalg.inv(model.inertia(x))
    W = G @ np.diag(np.square(densities)) @ G.T
    h = period / NOISE_QUADRATURE
    out = np.zeros_like(W)
    for i in range(NOISE_QUADRATURE):
        E = expm(A * (i + 0.5) * h)
        out += E @ W @ E.T * h
    return out


def wander(params, densities, v, kappa=0.0, path=True, rate=50.0, u_max=0.5, gains=None, tight=False):
    """The Wander of the LQR designed with `gains` (an LqrGains; None: the shipped ones) at the torque
    bound u_max [N·m] at (v, κ) under the white torque of densities (5,) [N·m/√Hz] (a sensor set's
    `process.generalized()`); `tight`: with the tight path gain fully scheduled in, as the law applies
    it (runtime/control/lqr.py, `tight_gain`: the integrators keep the path gain's columns)."""
    from scipy.linalg import solve_discrete_lyapunov
    from ..model import Model
    from . import lqr_design as design
    from .lqr import LqrGains, tight_gain
    gains = LqrGains() if gains is None else gains
    densities = np.asarray(densities, dtype=float)
    if densities.shape != (5,) or not np.all(np.isfinite(densities)) or np.any(densities < 0):
        raise ValueError(f"densities: expected 5 finite values >= 0 [N m/sqrt(Hz)], got {densities!r}")
    model = Model(params)
    z, u = design.operating_point(model, v, kappa)
    A, B = design.linearization(model, z, u, v, kappa)
    K = design.gains(A, B, 1.0 / rate, gains.weights(u_max), path=path)
    if tight and path:
        K = tight_gain(K, design.gains(A, B, 1.0 / rate, gains.tight_weights(u_max)))
    Ad, Bd = design.discretize(A, B, 1.0 / rate)
    Qd = noise_covariance(model, z, v, A, densities, 1.0 / rate)
    keep = np.arange(design.NZ) if path else np.array([i for i in range(design.NZ)
                                                       if i not in (design.Z_EY, design.Z_IY)])
    A_cl = (Ad - Bd @ K)[np.ix_(keep, keep)]
    S = solve_discrete_lyapunov(A_cl, Qd[np.ix_(keep, keep)])
    full = np.zeros((design.NZ, design.NZ))
    full[np.ix_(keep, keep)] = S
    return Wander(cross_track_m=math.sqrt(full[design.Z_EY, design.Z_EY]),
                  heading_rad=math.sqrt(full[Z_HEADING, Z_HEADING]), lean_rad=math.sqrt(full[Z_LEAN, Z_LEAN]),
                  torque_n_m=np.sqrt(np.diag(K @ full @ K.T)), keep=keep, S=S, A_cl=A_cl,
                  Q_d=Qd[np.ix_(keep, keep)])


def band_hold_fraction(w, band_rad, duration_s, rate=50.0, runs=2000, seed=0):
    """The fraction of `runs` runs of the linear loop of `w`, each started from its steady spread,
    whose heading error stays within ±band_rad for duration_s: a heading step settled at the start
    of that time keeps its settle time with this probability (torques unclipped)."""
    rng = np.random.default_rng(seed)
    n = len(w.keep)
    i = int(np.nonzero(w.keep == Z_HEADING)[0][0])
    step_noise = np.linalg.cholesky(w.Q_d + 1e-18 * np.eye(n))
    X = rng.normal(size=(runs, n)) @ np.linalg.cholesky(w.S + 1e-18 * np.eye(n)).T
    inside = np.abs(X[:, i]) <= band_rad
    for _ in range(int(round(duration_s * rate))):
        X = X @ w.A_cl.T + rng.normal(size=(runs, n)) @ step_noise.T
        inside &= np.abs(X[:, i]) <= band_rad
    return float(inside.mean())


def main(argv=()):
    """`python -m runtime noise-floor`: the LQR's steady wander on the shipped tasks' operating points
    under the sensor set's process noise: on the paths at the shipped gains, tighter cross-track
    weights and with the shipped tight gains fully scheduled in, on the heading step at the shipped gains, tighter
    heading weights with the lean weighed alike (`attitude_rad`) and apart (`heading_rad`), and each with the torque
    nearly free (the floor no such gains go below)."""
    parser = argparse.ArgumentParser(prog="python -m runtime noise-floor")
    parser.add_argument("--sensors", default="default", help="a shipped sensor set or a sensors file")
    parser.add_argument("--hold", type=float, default=18.4,
                        help="how long [s] the heading must stay in its ±3° band (a 30 s step settled by 11.6 s)")
    args = parser.parse_args(list(argv))
    if not (math.isfinite(args.hold) and 0 < args.hold <= 3600):
        parser.error(f"--hold: must be a time in (0, 3600] s, got {args.hold:g}")
    from ..sensor_set import load_sensor_set
    from .lqr import LqrGains
    from .metrics import HEADING_BAND_RAD
    from .task import load_task
    try:
        densities = load_sensor_set(args.sensors).process.generalized()
    except ValueError as exc:
        parser.error(f"--sensors: {exc}")
    params = load_task("circle").scenario.params
    shipped = ("shipped", LqrGains(), 0.5)
    floor = ("attitude_rad 0.001, torque weight 50 N·m", LqrGains(attitude_rad=0.001), 50.0)
    own_floor = ("heading_rad 0.001, torque weight 50 N·m", LqrGains(heading_rad=0.001), 50.0)
    on_path = (shipped, ("cross_track_m 0.05", LqrGains(cross_track_m=0.05), 0.5),
               ("cross_track_m 0.02", LqrGains(cross_track_m=0.02), 0.5),
               ("shipped, tight gains scheduled in", LqrGains(), 0.5, True))
    heading = (shipped, ("attitude_rad 0.03", LqrGains(attitude_rad=0.03), 0.5), floor,
               ("heading_rad 0.03", LqrGains(heading_rad=0.03), 0.5), ("heading_rad 0.02", LqrGains(heading_rad=0.02), 0.5),
               own_floor)
    cases = (("circle R = 2 m", 0.5, True, on_path), ("line", 0.0, True, on_path), ("heading step", 0.0, False, heading))
    print("| case | gains | cross-track σ [mm] | heading σ [°] | torque σ (yoke, pendulum) [N·m] "
          f"| heading within ±3° for {args.hold:g} s |")
    print("|---|---|---:|---:|---|---:|")
    for label, kappa, path, settings in cases:
        for name, gains, weight, *tight in settings:
            w = wander(params, densities, 0.3, kappa, path, u_max=weight, gains=gains, tight=bool(tight))
            hold = "" if path else f"{100 * band_hold_fraction(w, HEADING_BAND_RAD, args.hold):.0f} %"
            print(f"| {label} | {name} | {1000 * w.cross_track_m:.1f} | {math.degrees(w.heading_rad):.2f} | "
                  f"{w.torque_n_m[0]:.3f}, {w.torque_n_m[1]:.3f} | {hold} |")
    return 0
