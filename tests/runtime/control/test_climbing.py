"""The climbing limit (power balance, runtime/control/climbing.py) against simulations by the kernels."""
import math

import pytest

from runtime import Params
from runtime.control.climbing import climbing_limit, holding_limit, simulate_climb, steady_climb_speed
from runtime.scenario import load_scenario

U_Y = 0.5


def battery_robot():
    return load_scenario("battery-geared").params


@pytest.mark.parametrize("robot", [Params.paper_simulation, battery_robot], ids=["paper", "battery-geared"])
@pytest.mark.parametrize("side", [0.8, 1.2], ids=["below the limit", "above the limit"])
def test_the_robot_climbs_below_the_limit_and_rolls_back_above_it_at_the_predicted_speed(robot, side):
    base = robot()
    slope = side * climbing_limit(base, U_Y)
    params = base.replace(slope=slope)
    predicted, simulated = steady_climb_speed(params, U_Y, slope), simulate_climb(params, U_Y)
    assert (simulated > 0) == (side < 1)
    assert simulated == pytest.approx(predicted, rel=0.01)


def test_the_check_sees_a_slope_off_by_five_percent():
    """The prediction for a slope 5 % steeper differs from the simulation by more than the tolerance."""
    base = Params.paper_simulation()
    slope = 0.8 * climbing_limit(base, U_Y)
    simulated = simulate_climb(base.replace(slope=slope), U_Y)
    assert simulated != pytest.approx(steady_climb_speed(base, U_Y, 1.05 * slope), rel=0.01)


def test_the_papers_limits():
    p = Params.paper_simulation()
    assert climbing_limit(p, U_Y) == pytest.approx(math.asin(0.5 / (17 * 9.81 * 0.3)), rel=1e-14)
    assert holding_limit(p) == pytest.approx(1.0 * 9.81 * 0.1, rel=1e-12)       # m_P g l / 2


@pytest.mark.parametrize("name, climbs", [("ramp-climb", True), ("ramp-too-steep", False)])
def test_the_shipped_ramps_climb_or_roll_back_as_the_limit_predicts(name, climbs):
    from runtime.scenario import run_scenario
    scenario = load_scenario(name)
    params, u_Y = scenario.params, scenario.torque_at_step_starts()[0][0]
    assert (params.slope < climbing_limit(params, u_Y)) == climbs
    q_x = run_scenario(scenario).trajectory[:, 27]
    speed = (q_x[-1] - q_x[-501]) / (500 * scenario.dt)
    assert (speed > 0) == climbs
    assert speed == pytest.approx(steady_climb_speed(params, u_Y, params.slope), rel=0.01)


def test_the_battery_robot_is_general_and_runs_its_scenario():
    from runtime import Model
    from runtime.scenario import run_scenario
    scenario = load_scenario("battery-geared").with_overrides(steps=500)
    assert Model(scenario.params)._model.general == 1 and scenario.params.paper_params is None
    assert run_scenario(scenario).trajectory.shape == (501, 35)
