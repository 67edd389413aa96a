"""A slope in any direction for the LQR: the feedforward of a known slope holds a line across it, the
online estimate finds the slope's direction and size, and the ramp tasks stand on half the climbing
limit."""
import dataclasses
import math

import numpy as np

from runtime import so3
from runtime.control import lqr
from runtime.control.climbing import climbing_limit
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.reference import SpeedHeading, line_path
from runtime.control.slope import slope_components
from runtime.control.task import load_task
from runtime.params import Params
from runtime.state import IDX_Q, initial_state

PARAMS = Params.paper_simulation()
SPEED = 0.2
#: A quarter of the climbing limit under 0.5 N m (the offset table's slope).
SLOPE = 0.25 * climbing_limit(PARAMS, 0.5)
#: One operating point (straight, 0.2 m/s) keeps the design cheap.
GAINS = lqr.LqrGains(v_min=SPEED, n_speeds=1, kappa_max=0.0, n_curvatures=1)


def _rolling(psi):
    return initial_state(R_S=so3.rot_z(psi - math.pi / 2), q=(0.0, 0.0, PARAMS.r), w_S=(-SPEED / PARAMS.r, 0.0, 0.0),
                         w_Y=SPEED / PARAMS.r, r=PARAMS.r)


def test_slope_components_read_the_slope_along_and_to_the_right_of_the_heading():
    assert np.allclose(slope_components((SLOPE, 0.0), 0.0), (SLOPE, 0.0))
    assert np.allclose(slope_components((SLOPE, 0.0), math.pi / 2), (0.0, SLOPE))
    assert np.allclose(slope_components((0.0, SLOPE), math.pi), (0.0, SLOPE))


def test_the_feedforward_of_a_known_slope_holds_a_line_across_it():
    # Heading +y, the slope rising towards +x (on the right): the integral alone leaves centimetres
    # here (the offset table); the feedforward, the model knowing the slope, holds the line.
    plant = PARAMS.replace(slope=SLOPE)
    controller = lqr.Lqr(plant, rate=50.0, gains=GAINS)
    x0 = _rolling(math.pi / 2)
    reference = line_path(x0[IDX_Q][:2], math.pi / 2, 0.0, 10.0, SPEED)
    result = simulate_closed_loop(plant, controller, reference, x0, 12.0, 0.005, method="rkmk4")
    e = reference.cross_track(result.trajectory[len(result.trajectory) // 2:, IDX_Q])
    assert np.sqrt(np.mean(e ** 2)) < 0.005


def test_the_slope_estimate_finds_the_slope_against_a_flat_model():
    # The robot rolls at heading 2 rad (the slope, rising towards +x, mostly on its right and behind
    # it); the controller's model is flat.  After 15 s the estimate is the slope vector (α, 0).
    plant = PARAMS.replace(slope=SLOPE)
    controller = lqr.Lqr(PARAMS, rate=50.0, gains=dataclasses.replace(GAINS, slope_estimate_s=2.0))
    simulate_closed_loop(plant, controller, SpeedHeading(SPEED, 2.0), _rolling(2.0), 15.0, 0.005, method="rkmk4")
    assert np.linalg.norm(controller.slope - (SLOPE, 0.0)) < 0.1 * SLOPE


def test_the_ramp_tasks_stand_on_half_the_climbing_limit_known_and_estimated():
    known, estimated = load_task("ramp"), load_task("ramp-estimated")
    for task in (known, estimated):
        limit = climbing_limit(task.plant_params, task.u_max)
        assert math.isclose(task.plant_params.slope, limit / 2, rel_tol=1e-12)
        assert task.reference_spec["speed"] == 0.2
    assert known.scenario.params.slope == known.plant_params.slope
    assert all(c.gains.slope_estimate_s == 0.0 for c in known.controllers)
    assert estimated.scenario.params.slope == 0.0
    assert all(c.gains.slope_estimate_s > 0.0 for c in estimated.controllers)
