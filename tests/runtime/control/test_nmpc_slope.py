"""The NMPC's (Python and C) feedforward of a slope in its model, in any direction: it holds a line
across a quarter-limit slope that the flat prediction leaves centimetres off."""
import math

import numpy as np
import pytest

from runtime import so3
from runtime.control import nmpc
from runtime.control.climbing import climbing_limit
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.reference import line_path
from runtime.params import Params
from runtime.state import IDX_Q, initial_state

PARAMS = Params.paper_simulation()
SPEED = 0.2
#: A quarter of the climbing limit under 0.5 N m (the offset table's slope).
SLOPE = 0.25 * climbing_limit(PARAMS, 0.5)
#: One operating point (straight, 0.2 m/s) and a short horizon keep the design and the run cheap.
GAINS = nmpc.NmpcGains(v_min=SPEED, n_speeds=1, kappa_max=0.0, n_curvatures=1, horizon=10)


def _rolling(psi):
    return initial_state(R_S=so3.rot_z(psi - math.pi / 2), q=(0.0, 0.0, PARAMS.r), w_S=(-SPEED / PARAMS.r, 0.0, 0.0),
                         w_Y=SPEED / PARAMS.r, r=PARAMS.r)


@pytest.mark.parametrize("cls", [nmpc.Nmpc, nmpc.NmpcC])
def test_the_feedforward_of_a_known_slope_holds_a_line_across_it(cls):
    # Heading +y, the slope rising towards +x (on the right): the model knows the slope.
    plant = PARAMS.replace(slope=SLOPE)
    controller = cls(plant, rate=20.0, gains=GAINS)
    x0 = _rolling(math.pi / 2)
    reference = line_path(x0[IDX_Q][:2], math.pi / 2, 0.0, 10.0, SPEED)
    result = simulate_closed_loop(plant, controller, reference, x0, 12.0, 0.005, method="rkmk4")
    e = reference.cross_track(result.trajectory[len(result.trajectory) // 2:, IDX_Q])
    assert np.sqrt(np.mean(e ** 2)) < 0.005

