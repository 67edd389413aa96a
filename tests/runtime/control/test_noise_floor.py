"""The LQR loop's steady wander under a white torque disturbance: its covariance is the linear loop's,
it scales with the noise, the heading's share comes from the shell's torque about the vertical, and
the band-holding fraction counts runs that stay inside."""
import math

import numpy as np
import pytest

from runtime.control import noise_floor
from runtime.control.lqr import LqrGains
from runtime.params import Params

PARAMS = Params.paper_simulation()
#: The default sensor set's process noise: 0.01 N m/sqrt(Hz) on the shell's axes and both joints.
DENSITIES = np.full(5, 0.01)


@pytest.fixture(scope="module")
def heading_loop():
    return noise_floor.wander(PARAMS, DENSITIES, 0.3, path=False)


def test_the_covariance_is_the_linear_loops_steady_spread(heading_loop):
    w = heading_loop
    rng = np.random.default_rng(3)
    n, runs = len(w.keep), 4000
    step = np.linalg.cholesky(w.Q_d + 1e-18 * np.eye(n))
    X = np.zeros((runs, n))
    for _ in range(1500):                     # 30 s at 50 Hz: many times the loop's slowest time constant
        X = X @ w.A_cl.T + rng.normal(size=(runs, n)) @ step.T
    i = int(np.nonzero(w.keep == noise_floor.Z_HEADING)[0][0])
    assert X[:, i].std() == pytest.approx(w.heading_rad, rel=0.05)


def test_the_wander_scales_with_the_noise_density(heading_loop):
    twice = noise_floor.wander(PARAMS, 2 * DENSITIES, 0.3, path=False)
    assert twice.heading_rad == pytest.approx(2 * heading_loop.heading_rad, rel=1e-6)
    assert np.allclose(twice.torque_n_m, 2 * heading_loop.torque_n_m, rtol=1e-6)


def test_the_heading_wanders_from_the_shells_torque_about_the_vertical(heading_loop):
    yaw_only = noise_floor.wander(PARAMS, [0.0, 0.0, 0.01, 0.0, 0.0], 0.3, path=False)
    assert yaw_only.heading_rad ** 2 > 0.9 * heading_loop.heading_rad ** 2


def test_a_tighter_heading_weight_narrows_the_heading_but_not_below_the_floor(heading_loop):
    tight = noise_floor.wander(PARAMS, DENSITIES, 0.3, path=False, gains=LqrGains(attitude_rad=0.03))
    assert tight.heading_rad < 0.9 * heading_loop.heading_rad
    assert tight.heading_rad > math.radians(1.0)


def test_the_headings_own_weight_goes_below_the_floor_of_the_lean_weighed_alike(heading_loop):
    # attitude_rad weighs the lean (the steering) as the heading: with the torque nearly free it stops
    # above 1 degree; heading_rad leaves the lean at its size and goes below it within the 0.5 N m limit.
    coupled = noise_floor.wander(PARAMS, DENSITIES, 0.3, path=False, u_max=50.0, gains=LqrGains(attitude_rad=0.001))
    own = noise_floor.wander(PARAMS, DENSITIES, 0.3, path=False, gains=LqrGains(heading_rad=0.02))
    assert coupled.heading_rad > math.radians(1.0)
    assert own.heading_rad < 0.8 * coupled.heading_rad
    assert own.torque_n_m.max() < 0.5 / 3


def test_a_path_loop_reports_its_cross_track_wander():
    w = noise_floor.wander(PARAMS, DENSITIES, 0.3, kappa=0.0, path=True)
    assert 0.005 < w.cross_track_m < 0.1


def test_the_band_fraction_counts_runs_that_stay_inside(heading_loop):
    sigma = heading_loop.heading_rad
    assert noise_floor.band_hold_fraction(heading_loop, 10 * sigma, 5.0, runs=200) == 1.0
    assert noise_floor.band_hold_fraction(heading_loop, 0.1 * sigma, 5.0, runs=200) == 0.0
    middle = noise_floor.band_hold_fraction(heading_loop, 2 * sigma, 5.0, runs=400)
    assert 0.05 < middle < 0.95


@pytest.mark.parametrize("densities", [[0.01] * 4, [0.01, 0.01, -0.01, 0.01, 0.01], [math.nan] * 5])
def test_bad_densities_are_refused_by_name(densities):
    with pytest.raises(ValueError, match="densities"):
        noise_floor.wander(PARAMS, densities, 0.3, path=False)


def test_the_command_refuses_a_hold_time_of_zero():
    with pytest.raises(SystemExit):
        noise_floor.main(["--hold", "0"])


def test_the_heading_and_lean_coordinates_are_the_designs():
    from runtime.control import lqr_design
    assert (noise_floor.Z_LEAN, noise_floor.Z_HEADING) == (lqr_design.Z_E.start + 1, lqr_design.Z_E.start + 2)
