"""Climbing a slope under a constant yoke torque: the limit, and the speed either side of it.

In steady climbing the yoke and the pendulum hang still in the world while the shell rolls up the
slope at ω, so the yoke motor turns at ω relative to the shell and the rotors at constant speeds
(their energy does not change).  The power balance of that motion,

    u_Y ω = m_R g sin(slope) r ω + (k_S + k_Y) ω²,

gives the steady rate ω = (|u_Y| − m_R g r sin(slope)) / (k_S + k_Y): the robot climbs if and only if
|u_Y| > m_R g r sin(slope), the climbing limit sin(slope_max) = |u_Y| / (m_R g r).  The torque
itself is bounded by what holds the yoke: gravity's largest moment about the yoke's axis on the
yoke and the pendulum (m_P g l/2 for the paper's robot); a larger torque flips the yoke over.
Both follow from the physics alone, not from the kernels; `simulate_climb` runs the kernels, and
tests/runtime/control/test_climbing.py holds one against the other on both sides of the limit.

    python -m runtime climbing      # prints the limit, writes docs/figures/climbing-limit.png
"""
import argparse
import math

import numpy as np

from ..atomic import output_file
from ..model import Model
from ..params import Params
from ..so3 import rot_y, rot_z
from ..state import IDX_Q, initial_state

DT = 0.01
#: Yoke axis across the slope (shell x along the world's −y): a positive yoke torque rolls the robot up (+x).
ACROSS_THE_SLOPE = rot_z(-np.pi / 2)


def climbing_limit(params, u_Y):
    """The steepest slope [rad] a constant yoke torque u_Y [N m] climbs: asin(|u_Y| / (m_R g r))."""
    return math.asin(min(1.0, abs(u_Y) / (params.m_R * params.g * params.r)))


def steady_climb_speed(params, u_Y, slope):
    """The steady speed up the slope [m/s] from the power balance (negative: it rolls back down)."""
    return params.r * (abs(u_Y) - params.m_R * params.g * params.r * math.sin(slope)) / (params.k_S + params.k_Y)


def holding_limit(params, samples=721):
    """The largest yoke torque [N m] that gravity on the yoke and pendulum can hold: g times the
    largest first moment about the yoke's axis, over the pendulum's angles."""
    h_Y, h_P = params.m_Y * np.asarray(params.c_Y), params.m_P * np.asarray(params.c_P)
    moments = [np.hypot(*(h_Y + rot_y(t) @ h_P)[1:]) for t in np.linspace(-np.pi, np.pi, samples)]
    return params.g * max(moments)


def simulate_climb(params, u_Y, duration=60.0, window=5.0):
    """The simulated speed up the slope [m/s]: the mean over the last `window` s of a run from rest
    with the yoke's axis across the slope and u_Y held (RKMK4, dt = 0.01 s)."""
    steps = round(duration / DT)
    x0 = initial_state(R_S=ACROSS_THE_SLOPE, r=params.r)
    traj = Model(params).simulate(x0, DT, steps, np.tile([u_Y, 0.0], (steps, 1)), method="rkmk4")
    back = round(window / DT)
    return float((traj[-1, IDX_Q][0] - traj[-1 - back, IDX_Q][0]) / window)


def main(argv=()):
    """Prints the limit and both sides for the paper's robot; writes the figure (FIGURE, default
    docs/figures/climbing-limit.png): simulated against predicted speed over slopes for the paper's
    robot and the battery robot of runtime/scenarios/robots/battery-geared.toml."""
    parser = argparse.ArgumentParser(prog="python -m runtime climbing")
    parser.add_argument("figure", nargs="?", type=output_file, default="docs/figures/climbing-limit.png", help="where to write the figure")
    args = parser.parse_args(list(argv))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..scenario import load_scenario
    base = Params.paper_simulation()
    u_Y = 0.5
    limit = climbing_limit(base, u_Y)
    print(f"Params.paper_simulation(), u_Y = {u_Y} N m: climbing limit {limit:.5f} rad "
          f"({math.degrees(limit):.3f} deg); holding limit {holding_limit(base):.3f} N m")
    for slope in (0.8 * limit, 1.2 * limit):
        p = base.replace(slope=slope)
        print(f"  slope {slope:.5f} rad: predicted {steady_climb_speed(p, u_Y, slope):+.4f} m/s, "
              f"simulated {simulate_climb(p, u_Y):+.4f} m/s")
    fig, ax = plt.subplots(figsize=(6.5, 4))
    robots = {"the paper's robot": base, "battery-geared robot": load_scenario("battery-geared").params}
    for label, robot in robots.items():
        lim = climbing_limit(robot, u_Y)
        slopes = np.linspace(0.0, 1.6 * lim, 9)
        line, = ax.plot(np.degrees(slopes), [steady_climb_speed(robot, u_Y, s) for s in slopes], "-",
                        label=f"{label}: power balance (limit {math.degrees(lim):.2f}°)")
        ax.plot(np.degrees(slopes), [simulate_climb(robot.replace(slope=s), u_Y) for s in slopes], "o",
                color=line.get_color(), label=f"{label}: simulated (kernels, RKMK4)")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("slope [deg]"), ax.set_ylabel("steady speed up the slope [m/s]")
    ax.set_title(f"climbing under a held yoke torque of {u_Y} N m"), ax.legend(fontsize=7)
    fig.tight_layout()
    out = args.figure
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")
    return 0
