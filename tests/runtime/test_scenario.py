"""Scenario files (runtime/scenario.py) and the paper's Section 5.3 statements on our data.

The `results` fixture (the three shipped runs) is in conftest.py next to this file.  The physics checks read the raw trajectory and compute what they need from
the rotation matrices themselves (inclinations, rolling angle), so they do not
lean on runtime/scenarios/report.py.  The t-shape torque program is rebuilt here from
the windows of Section 5.3.3 and compared with what the file produces.
"""
import math
import tomllib

import numpy as np
import pytest

from conftest import ROOT
from runtime import Model, Params, initial_state
from runtime.scenario import load_scenario, parse_scenario, run_scenario, shipped_scenarios

R = 0.3   # shell radius of the paper (Section 5.2)


# -- helpers computed from first principles -----------------------------------------------------
def world_axis(x, blocks, column):
    """Column `column` of the product of the rotation blocks of x (rows: samples)."""
    product = np.broadcast_to(np.eye(3), (len(x), 3, 3))
    for start in blocks:
        product = product @ x[:, start:start + 9].reshape(-1, 3, 3)
    return product[:, :, column]


def angle_to_vertical(v):
    return np.degrees(np.arccos(np.clip(v[:, 2], -1.0, 1.0)))


def rotation_angle(Rm):
    """Angle of a rotation matrix, from its trace."""
    return math.acos(max(-1.0, min(1.0, (np.trace(Rm) - 1.0) / 2.0)))


def paper_t_shape_torques(steps, per_step=1):
    """Section 5.3.3 as this project reads it (README, "Conventions"): 0.1 N m on steps 1-800 (yoke),
    1600-1900 (pendulum, negative), 2500-3000 (yoke, negative), 3400-4500 (pendulum); step n is row n-1.
    `per_step` > 1 splits every step of 0.01 s into that many shorter steps."""
    u = np.zeros((10_000, 2))
    u[0:800, 0] = 0.1
    u[1599:1900, 1] = -0.1
    u[2499:3000, 0] = -0.1
    u[3399:4500, 1] = 0.1
    return np.repeat(u, per_step, axis=0)[:steps]


# -- the shipped files -------------------------------------------------------------------------
def test_shipped_scenarios_are_the_papers_three_with_its_settings():
    assert shipped_scenarios()[:3] == ["tilted-pendulum", "tilted-yoke", "t-shape"]
    expected = {"tilted-pendulum": (10_000, 0.0, math.pi / 4), "tilted-yoke": (5_000, math.pi / 4, 0.0),
                "t-shape": (10_000, 0.0, 0.0)}
    for name, (steps, theta_Y, theta_P) in expected.items():
        s = load_scenario(name)
        assert (s.steps, s.dt, s.method) == (steps, 0.01, "lie-euler")
        assert s.params == Params.paper_simulation()
        np.testing.assert_array_equal(s.x0, initial_state(theta_Y=theta_Y, theta_P=theta_P))


def test_t_shape_torque_program_is_section_5_3_3(results):
    s = load_scenario("t-shape")
    np.testing.assert_array_equal(s.torque_at_step_starts(), paper_t_shape_torques(10_000))
    # The scenario runner (chunked) gives exactly what one call of Model.simulate gives.
    direct = Model(Params.paper_simulation()).simulate(initial_state(), 0.01, 10_000, paper_t_shape_torques(10_000))
    np.testing.assert_array_equal(results["t-shape"].trajectory, direct)


def test_time_windows_select_the_same_steps_as_step_windows(tmp_path):
    """Windows by time: a step is in [from, to) when its start time (n-1)·dt is; 15.99/0.01 must count as 1599."""
    text = """dt = 0.01
duration = 100.0
[params]
preset = "paper_simulation"
[[torque]]
from_time = 0.0
to_time = 8.0
u_Y = 0.1
[[torque]]
from_time = 15.99
to_time = 19.0
u_P = -0.1
[[torque]]
from_time = 24.99
to_time = 30.0
u_Y = -0.1
[[torque]]
from_time = 33.99
to_time = 45.0
u_P = 0.1
"""
    path = tmp_path / "by-time.toml"
    path.write_text(text)
    s = load_scenario(path)
    assert s.steps == 10_000 and s.name == "by-time"
    np.testing.assert_array_equal(s.torque_at_step_starts(), paper_t_shape_torques(10_000))


def test_time_windows_tolerate_rounding_of_start_times():
    """0.07 / 0.01 = 7.000000000000001 in floating point: the step starting at t = 0.07 s must still count."""
    assert 0.07 / 0.01 > 7 and 0.14 / 0.01 > 14
    data = {"dt": 0.01, "steps": 20, "torque": [{"from_time": 0.07, "to_time": 0.14, "u_Y": 1.0}]}
    u = parse_scenario(data, "inline").torque_at_step_starts()
    assert np.flatnonzero(u[:, 0]).tolist() == list(range(7, 14))


def test_a_new_dt_keeps_duration_and_window_time_spans():
    s = load_scenario("t-shape").with_overrides(dt=0.005)
    assert s.steps == 20_000
    np.testing.assert_array_equal(s.torque_at_step_starts(), paper_t_shape_torques(20_000, per_step=2))
    assert load_scenario("t-shape").with_overrides(dt=0.005, steps=7).steps == 7


# -- Section 5.3.1: tilted pendulum --------------------------------------------------------------
def test_5_3_1_tilted_pendulum_rolls_a_few_centimetres_along_x(results):
    x = results["tilted-pendulum"].trajectory
    assert np.max(np.abs(x[:, 28])) < 1e-12                     # "no motion along the y axis"
    assert 0.01 < abs(x[-1, 27]) < 0.2                          # "a few centimeters along the x axis"
    # Pure rolling on a line: distance travelled = r × angle turned by the shell.
    assert abs(abs(x[-1, 27]) - R * rotation_angle(x[-1, 0:9].reshape(3, 3))) < 1e-9


def test_5_3_1_yoke_stays_and_pendulum_comes_to_rest_hanging_vertically(results):
    x = results["tilted-pendulum"].trajectory
    assert np.max(np.abs(x[:, 9:18] - np.eye(3).ravel())) < 1e-12  # R_Y = I throughout ("the yoke stays still")
    assert np.max(np.abs(x[:, 33])) < 1e-12
    shaft = angle_to_vertical(world_axis(x, (0, 9, 18), 2))        # R_S R_Y R_P e_z against e_z, degrees
    assert shaft[0] == pytest.approx(45.0)
    assert shaft[-1] < 0.01                                     # vertical at t = 100 s (measured 1e-5 deg)
    assert np.max(np.abs(x[-1, 30:35])) < 1e-5                  # and at rest (measured 1.5e-7 rad/s)


# -- Section 5.3.2: tilted yoke --------------------------------------------------------------------
def test_5_3_2_tilted_yoke_rolls_a_few_centimetres_along_y(results):
    x = results["tilted-yoke"].trajectory
    assert np.max(np.abs(x[:, 27])) < 1e-12                     # "no motion along the x axis"
    assert 0.01 < abs(x[-1, 28]) < 0.2                          # "a few centimeters along the y axis"
    assert abs(abs(x[-1, 28]) - R * rotation_angle(x[-1, 0:9].reshape(3, 3))) < 1e-9


def test_5_3_2_yoke_returns_to_horizontal_and_pendulum_stays_in_its_frame(results):
    x = results["tilted-yoke"].trajectory
    assert np.max(np.abs(x[:, 18:27] - np.eye(3).ravel())) < 1e-12  # R_P = I throughout
    assert np.max(np.abs(x[:, 34])) < 1e-12
    normal = angle_to_vertical(world_axis(x, (0, 9), 2))       # yoke plane normal R_S R_Y e_z, degrees
    assert normal[0] == pytest.approx(45.0)
    assert np.max(normal[:500]) == pytest.approx(45.0)
    # Over the last 5 s of 50 s the yoke is within 0.6 deg of horizontal (measured 0.25 deg, still swinging).
    assert np.max(normal[-500:]) < 0.6


# -- Section 5.3.3: t-shape --------------------------------------------------------------------------
def test_5_3_3_first_leg_runs_along_y_then_the_path_turns_away(results):
    q = results["t-shape"].trajectory[:, 27:29]
    first_leg = q[:1600]                                        # before the pendulum motor first acts
    assert np.max(np.abs(first_leg[:, 0])) < 1e-12
    assert first_leg[-1, 1] > 0.5                               # measured 0.91 m
    turn = q[3000] - q[1600]                                    # after the pendulum window: sideways motion
    assert turn[0] > 0.1                                        # measured +0.27 m
    back = q[-1] - q[3400]                                      # after the reversed yoke torque: heads back down y
    assert back[1] < -1.0                                       # measured -1.56 m
    assert abs(q[-1, 0]) > 0.1                                  # off the first leg's line (measured 0.19 m)


# -- time-step convergence ------------------------------------------------------------------------------
# Final positions (x, y) at dt = 0.01 and dt = 0.005 (same duration, same torque time spans) differ by
# (measured) 1.24e-4 m (tilted-pendulum), 7.7e-6 m (tilted-yoke), 2.3e-3 m (t-shape); halving again
# shrinks the difference by a factor 3.4-4.5.  Against a converged 4th-order run (cf4, dt = 0.0025 s,
# itself stable to 4e-10 m) the dt = 0.01 errors are 1.6e-4, 1.1e-5 and 3.5e-3 m, so the difference
# is about 3/4 of the actual error.  The bounds below are about 4x the measured differences.
HALVING_BOUNDS_M = {"tilted-pendulum": 5e-4, "tilted-yoke": 3e-5, "t-shape": 1e-2}


@pytest.mark.parametrize("name", sorted(HALVING_BOUNDS_M))
def test_halving_dt_moves_the_final_position_by_less_than_the_bound(name):
    """dt = 0.01 s against dt = 0.005 s: the final position moves by less than HALVING_BOUNDS_M.

    Lie-Euler is first order, but the final (rest) position converges faster
    here (the difference shrinks about 4x per halving), so the dt / dt/2
    difference is close to the error of the dt run itself.  The bound is about
    four times the measured difference: a change of integrator or of
    torque-window timing that made the run less accurate fails here.  A second
    halving must shrink the difference by at least 1.5 (convergence, not a
    coincidence).
    """
    base = load_scenario(name)
    finals = [run_scenario(base.with_overrides(dt=base.dt / k)).trajectory[-1, 27:29] for k in (1, 2, 4)]
    first, second = np.linalg.norm(finals[0] - finals[1]), np.linalg.norm(finals[1] - finals[2])
    assert first < HALVING_BOUNDS_M[name]
    assert second < first / 1.5


# -- validation ----------------------------------------------------------------------------------------
VALID = """dt = 0.01
steps = 10
[params]
preset = "paper"
[initial]
theta_P = 0.5
"""


@pytest.mark.parametrize("text, key, what", [
    (VALID + "stepz = 3\n", "stepz", "unknown key"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nk_Q = 1.0'), "k_Q", "unknown key"),
    (VALID.replace('preset = "paper"', 'preset = "moon"'), "params.preset", "unknown preset"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nk_S = "0.1"'), "params.k_S", "expected a number"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nh = 2.0'), "Params.b, Params.h", "does not fit"),
    (VALID.replace("dt = 0.01", 'dt = "0.01"'), "dt", "expected a number"),
    (VALID.replace("dt = 0.01", "dt = -0.01"), "dt", "must be > 0"),
    (VALID.replace("dt = 0.01", "dt = 0.01\nduration = 1.0"), "steps, duration", "exactly one"),
    (VALID.replace("steps = 10", "duration = 0.015"), "duration", "whole number of steps"),
    (VALID.replace("steps = 10", "steps = 10.5"), "steps", "expected a whole number"),
    (VALID.replace("steps = 10", 'steps = 10\nmethod = "rk99"'), "method", "unknown integrator"),
    (VALID + "theta_Y = 0.1\nR_Y = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n", "theta_Y, R_Y", "not both"),
    (VALID + "R_S = [[1, 0, 0], [0, 1, 0], [0, 0, 2]]\n", "initial.R_S", "not a rotation"),
    (VALID + "R_S = [[1, 0], [0, 1]]\n", "initial.R_S", "3×3"),
    (VALID + "R_Y = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n", "initial.R_Y", "rotation about the x axis"),
    (VALID + "q = [0.0, 0.0, 0.5]\n", "initial.q", "q_z = r"),
    (VALID + "w_S = [0.0, 1.0]\n", "initial.w_S", "list of 3 numbers"),
    (VALID + "[[torque]]\nfrom_step = 1\nto_step = 2\nu_Y = 0.1\nspeed = 3\n", "torque[1]", "'speed'"),
    (VALID + "[[torque]]\nfrom_step = 5\nto_step = 2\nu_Y = 0.1\n", "torque[1].from_step, to_step", "1 <= from_step"),
    (VALID + "[[torque]]\nfrom_step = 5\nto_step = 11\nu_Y = 0.1\n", "torque[1].to_step", "past the end"),
    (VALID + "[[torque]]\nfrom_step = 1\nto_step = 2\n", "torque[1]", "give u_Y"),
    (VALID + "[[torque]]\nfrom_step = 1\nto_step = 2\nu_P = true\n", "torque[1].u_P", "expected a number"),
    (VALID + "[[torque]]\nfrom_step = 1\nto_time = 2.0\nu_P = 1.0\n", "torque[1]", "not both"),
    (VALID + "[[torque]]\nfrom_time = 1.0\nu_P = 1.0\n", "torque[1]: to_time", "missing"),
    ("dt = 0.01\nsteps = \n", "", "not valid TOML"),
    # the kernels' rules, resource limits, windows that select nothing
    (VALID + "R_Y = [[1, 0, 1e-9], [0, 1, 0], [0, 0, 1]]\n", "initial.R_Y[0][2]", "must be exactly 0"),
    (VALID + "R_S = [[1, 0, 0], [0, 1, 0], [0, 0, 1.00001]]\n", "initial.R_S", "max |RᵀR − I| = 2e-05"),
    (VALID.replace("steps = 10", "steps = 100000000"), "steps", "MAX_STEPS"),
    (VALID.replace("steps = 10", "duration = 1e9"), "duration", "MAX_STEPS"),
    (VALID + "[[torque]]\nfrom_time = 0.1\nto_time = 0.2\nu_P = 1.0\n", "torque[1].from_time", "past the end"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nr = 1e-200\nb = 1e-200\nh = 1e-200\nl = 1e-200'),
     "params", "Params.j_S: must be > 0"),
    # the general robot's values
    (VALID.replace('preset = "paper"', 'preset = "paper"\nJ_P = [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.3]]'),
     "Params.J_P", "not a physical inertia tensor"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nJ_Y = [[0.2, 0.18, 0], [0.18, 0.2, 0], [0, 0, 0.3]]'),
     "Params.J_Y", "not a physical inertia tensor"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nc_Y = [0.0, 0.0, 0.31]'), "Params.c_Y", "inside the shell"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nslope = 1.6'), "Params.slope", "pi/2"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nc_P = [0.0, -0.1]'), "Params.c_P", "shape (3,)"),
    (VALID.replace('preset = "paper"', 'preset = "paper"\nslope = 0.1\nb = 0.3'), "Params.b", "paper's robot"),
    (VALID.replace('preset = "paper"', 'robot = "no-such-robot.toml"'), "robot", "cannot read"),
    # the floor's friction coefficient
    (VALID.replace("dt = 0.01", "dt = 0.01\nfriction = 0.0"), "friction", "must be > 0"),
    (VALID.replace("dt = 0.01", 'dt = 0.01\nfriction = "0.5"'), "friction", "expected a number"),
    (VALID.replace("dt = 0.01", "dt = 0.01\nfriction = 20.0"), "friction", "(0, 10]"),
])
def test_invalid_files_name_the_file_the_key_and_the_problem(tmp_path, text, key, what):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ValueError) as info:
        load_scenario(path)
    message = str(info.value)
    assert str(path) in message and key in message and what in message, message


def test_valid_base_file_loads(tmp_path):
    """The base of the invalid cases above is itself valid (so each case fails for its own reason)."""
    path = tmp_path / "ok.toml"
    path.write_text(VALID)
    s = load_scenario(path)
    np.testing.assert_array_equal(s.x0, initial_state(theta_P=0.5))
    assert s.params == Params() and s.torques == ()


def test_the_friction_coefficient_is_optional_and_carried_into_the_scenario():
    assert parse_scenario(tomllib.loads(VALID)).friction is None
    assert parse_scenario(tomllib.loads("friction = 0.6\n" + VALID)).friction == 0.6


def test_the_documented_example_is_a_valid_scenario(tmp_path):
    """The full example of docs/scenarios.md loads (so the documentation cannot drift from the parser)."""
    doc = (ROOT / "docs" / "scenarios.md").read_text()
    example = doc.split("```toml\n", 1)[1].split("```", 1)[0]
    path = tmp_path / "example.toml"
    path.write_text(example)
    s = load_scenario(path)
    assert s.steps == 10_000 and s.params.k_S == 0.16 and len(s.torques) == 2
    np.testing.assert_array_equal(s.x0, initial_state(theta_P=math.pi / 4))


def test_missing_file_is_named(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(ValueError, match="nowhere.toml: no such scenario file"):
        load_scenario(missing)
    with pytest.raises(ValueError, match="no such scenario file"):
        load_scenario("no-such-shipped-scenario")


def test_parse_scenario_accepts_full_matrices():
    c, s = math.cos(0.3), math.sin(0.3)
    data = {"dt": 0.02, "steps": 5, "initial": {"R_Y": [[1, 0, 0], [0, c, -s], [0, s, c]],
                                                 "R_S": [[c, -s, 0], [s, c, 0], [0, 0, 1]], "w_Y": 0.5}}
    x0 = parse_scenario(data, "inline").x0
    np.testing.assert_allclose(x0, initial_state(theta_Y=0.3, R_S=[[c, -s, 0], [s, c, 0], [0, 0, 1]], w_Y=0.5),
                               atol=1e-15)


def test_a_file_that_is_not_utf8_is_named(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(b"description = 'caf\xe9'\ndt = 0.01\nsteps = 10\n")
    with pytest.raises(ValueError, match=r"latin1.toml: not valid TOML \(not UTF-8 text"):
        load_scenario(path)
