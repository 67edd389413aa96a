"""The slope estimate (runtime/control/slope.py) against a pendulum unlike the model's: the pendulum's
mass, centre of mass and joint damping are estimated with the slope, so what they pull is not read
as a slope, and a real slope still is."""
import math

import numpy as np
import pytest

from runtime import so3
from runtime.control import lqr
from runtime.control.climbing import climbing_limit
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.reference import SpeedHeading, circle_path
from runtime.control.slope import SlopeEstimator
from runtime.params import Params
from runtime.state import IDX_Q, initial_state

PARAMS = Params.paper_simulation()
SPEED, RADIUS, RATE = 0.3, 2.0, 20.0
#: A quarter of the climbing limit under 0.5 N m (the offset table's slope).
SLOPE = 0.25 * climbing_limit(PARAMS, 0.5)
# The closed loop these runs were specified on (the integral and the tight gains of the law then
# shipped): what the estimate recovers depends on the motion, not on later tuning of the defaults.
GAINS = lqr.LqrGains(v_min=SPEED, n_speeds=1, kappa_max=0.5, n_curvatures=3, cross_track_integral_m_s=2.0,
                     steady_rate_m_s=0.002, tight_cross_track_m=0.05, tight_band_m=0.05)
#: How soon [s] a slope is read rolling straight up it.
READ_WITHIN_S = 0.5


def _estimates_on_the_circle(plant, duration=20.0):
    """The estimator's (slope (n, 2), pendulum (n, 5)) at every sample of the LQR (flat model, no
    estimate of its own) on the circle, reading the run's states and torques as the NMPC's would."""
    x0 = initial_state(R_S=so3.rot_z(-math.pi / 2), q=(0.0, 0.0, PARAMS.r), w_S=(-SPEED / PARAMS.r, 0.0, 0.0),
                       w_Y=SPEED / PARAMS.r, r=PARAMS.r)
    reference = circle_path(x0[IDX_Q][:2], 0.0, RADIUS, 10.0, SPEED)
    result = simulate_closed_loop(plant, lqr.Lqr(PARAMS, rate=RATE, gains=GAINS), reference, x0, duration, 0.005,
                                  method="rkmk4")
    per = round(1 / (RATE * 0.005))
    estimator, slopes, pendulums = SlopeEstimator(PARAMS, 1 / RATE, 5.0), [], []
    for k in range(0, len(result.time) - 1, per):
        slopes.append(estimator.update(result.trajectory[k], result.torques[k - 1] if k else np.zeros(2)).copy())
        pendulums.append(np.append(estimator.pendulum, estimator.pendulum_damping))
    return np.array(slopes), np.array(pendulums)


def test_a_lighter_pendulum_is_not_read_as_a_slope():
    # Fitted with the slope and a torque offset alone, the start's transient read as slopes of up to
    # 8 times this one (and the feedforward acting on it diverged on the circle).
    slopes, pendulums = _estimates_on_the_circle(PARAMS.with_changes(m_P=0.8 * PARAMS.paper_params.m_P))
    assert np.max(np.linalg.norm(slopes[int(2 * RATE):], axis=1)) < 0.5 * SLOPE
    assert pendulums[-1][0] == pytest.approx(-0.2 * PARAMS.m_P, rel=0.2)


def test_a_centre_of_mass_moved_is_read_as_the_pendulum_not_a_slope():
    moved = PARAMS.with_changes(c_P=tuple(np.array(PARAMS.c_P) + (-0.01, 0.0, 0.0)))
    slopes, pendulums = _estimates_on_the_circle(moved)
    assert np.max(np.linalg.norm(slopes[int(2 * RATE):], axis=1)) < 0.1 * SLOPE
    assert pendulums[-1][1] == pytest.approx(-0.01, rel=0.05)


@pytest.mark.parametrize("factor", [0.8, 1.2])
def test_a_pendulum_joint_damped_unlike_the_model_is_read_as_the_pendulum_not_a_slope(factor):
    # Without the damping's column: slopes of 5 (k_P -20 %) and 7 (+20 %) times this one after 2 s,
    # which the NMPC's feedforward acted on (the circle's start 13 cm off the path).
    slopes, pendulums = _estimates_on_the_circle(PARAMS.with_changes(k_P=factor * PARAMS.paper_params.k_P))
    assert np.max(np.linalg.norm(slopes[int(2 * RATE):], axis=1)) < 0.1 * SLOPE
    assert pendulums[-1][4] == pytest.approx((factor - 1) * PARAMS.k_P, rel=0.1)


def test_a_slope_is_still_read_as_the_slope():
    slopes, pendulums = _estimates_on_the_circle(PARAMS.replace(slope=SLOPE))
    assert np.linalg.norm(slopes[-1] - (SLOPE, 0.0)) < 0.02 * SLOPE
    assert np.all(np.abs(pendulums[-1]) < 1e-3 * np.array([PARAMS.m_P, 1, 1, 1, PARAMS.k_P]))


def test_rolling_straight_the_slope_is_read_before_the_pendulum_can_be():
    # Up a slope at one heading the pendulum's columns are not yet told from the slope's and d's;
    # the estimate then holds the pendulum and reads the slope as it would without it.
    plant = PARAMS.replace(slope=SLOPE)
    x0 = initial_state(R_S=so3.rot_z(-math.pi / 2), q=(0.0, 0.0, PARAMS.r), w_S=(-SPEED / PARAMS.r, 0.0, 0.0),
                       w_Y=SPEED / PARAMS.r, r=PARAMS.r)
    result = simulate_closed_loop(plant, lqr.Lqr(PARAMS, rate=RATE, gains=GAINS), SpeedHeading(SPEED, 0.0), x0,
                                  READ_WITHIN_S, 0.005, method="rkmk4")
    estimator, per = SlopeEstimator(PARAMS, 1 / RATE, 5.0), round(1 / (RATE * 0.005))
    for k in range(0, len(result.time) - 1, per):
        estimator.update(result.trajectory[k], result.torques[k - 1] if k else np.zeros(2))
    assert np.linalg.norm(estimator.slope - (SLOPE, 0.0)) < 0.02 * SLOPE
