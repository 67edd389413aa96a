"""The tracking metrics on synthetic signals whose values are known by construction."""
import math

import numpy as np
import pytest

from runtime.control.metrics import motor_energy, second_half_stats, settle_time, step_overshoot
from runtime.control.reference import line_path


def test_settle_time_is_the_first_time_after_which_the_error_stays_in_the_band():
    t = np.arange(0, 10.0, 0.1)
    error = np.exp(-t)                       # below 0.05 from t = ln 20 = 2.996 on
    assert settle_time(t, error, 0.05) == pytest.approx(3.0)


def test_settle_time_is_none_when_the_run_ends_outside_the_band():
    t = np.arange(0, 10.0, 0.1)
    assert settle_time(t, np.where(t > 9.5, 1.0, 0.0), 0.05) is None


def test_settle_time_counts_a_late_excursion():
    t = np.arange(0, 10.0, 0.1)
    error = np.where((t > 6.0) & (t < 6.5), 0.2, 0.0)
    assert settle_time(t, error, 0.05) == pytest.approx(6.5)


def test_overshoot_of_a_second_order_step_response_is_its_known_peak():
    zeta = 0.3
    t = np.linspace(0, 20, 20001)
    wd = math.sqrt(1 - zeta ** 2)
    y = 1 - np.exp(-zeta * t) * (np.cos(wd * t) + zeta / wd * np.sin(wd * t))
    expected = math.exp(-zeta * math.pi / wd)
    assert step_overshoot(2 + 3 * y, 2.0, 5.0) == pytest.approx(expected, rel=1e-6)
    assert step_overshoot(2 - 3 * y, 2.0, -1.0) == pytest.approx(expected, rel=1e-6)


def test_overshoot_is_zero_for_a_monotone_response():
    t = np.linspace(0, 5, 100)
    assert step_overshoot(1 - np.exp(-t), 0.0, 1.0) == 0.0


def test_second_half_stats_ignore_the_first_half():
    t = np.linspace(0, 10, 1001)
    error = np.where(t < 5, 100.0, 0.3 * np.sin(2 * np.pi * t))
    rms, peak = second_half_stats(t, error)
    assert rms == pytest.approx(0.3 / math.sqrt(2), rel=1e-2)
    assert peak == pytest.approx(0.3, rel=1e-3)


def test_motor_energy_of_constant_torques_and_speeds():
    t = np.linspace(0, 4, 401)
    torques = np.tile([0.5, -0.2], (401, 1))
    assert motor_energy(t, torques, np.full(401, -2.0), np.full(401, 3.0)) == pytest.approx(4 * (1.0 + 0.6))


def test_cross_track_of_a_line_is_the_signed_distance_to_it():
    path = line_path(np.zeros(2), 0.0, 0.5, 10.0, 0.3)    # the line y = 0.5, left of the start
    points = np.array([[0.0, 0.0], [1.0, 0.7], [2.0, 0.5], [3.0, -1.0]])
    assert path.cross_track(points) == pytest.approx([-0.5, 0.2, 0.0, -1.5], abs=1e-12)
