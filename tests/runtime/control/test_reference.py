"""The curvature a path feeds forward (runtime/control/reference.py): a sampled arc's own, and a
polyline's turns spread over its legs."""
import math

import numpy as np
import pytest

from runtime.control.reference import circle_path, waypoints_path

RADIUS = 4.0
STEP_RAD = 0.05


def _polyline_arc(radius=RADIUS, step=STEP_RAD, sweep=math.pi / 2):
    """Waypoints on a left turn of `radius` every `step` rad, after a 1 m straight, then 1 m on."""
    a = np.arange(0.0, sweep + step / 2, step)
    arc = np.stack([1.0 + radius * np.sin(a), radius * (1 - np.cos(a))], axis=1)
    on = arc[-1] + np.array([math.cos(sweep), math.sin(sweep)])
    return waypoints_path([0.0, 0.0], np.vstack([arc, on]), 0.2)


def test_a_polyline_turn_feeds_forward_the_curvature_of_the_arc_through_its_waypoints():
    path = _polyline_arc()
    legs = RADIUS * 2 * math.sin(STEP_RAD / 2)
    inside = (path.s > 1.0 + legs) & (path.s < 1.0 + RADIUS * math.pi / 2 - legs)
    # Every sample inside the turn, not only those at a waypoint: what a controller sampling the
    # path ahead at any spacing reads.
    np.testing.assert_allclose(path.curvature[inside], 1 / RADIUS, rtol=0.02)


def test_a_polyline_turn_keeps_its_whole_turn():
    path = _polyline_arc()
    total = np.trapezoid(path.curvature, path.s)
    assert total == pytest.approx(math.pi / 2, rel=2e-3)


def test_a_straight_leg_far_from_a_turn_has_no_curvature():
    path = _polyline_arc()
    assert np.all(path.curvature[path.s < 0.8] == 0.0)


def test_a_sampled_arc_keeps_its_curvature():
    path = circle_path([0.0, 0.0], 0.3, 2.0, 20.0, 0.5)
    np.testing.assert_allclose(path.curvature[1:-1], 0.5, rtol=1e-6)


def test_a_corner_is_not_curvature():
    path = waypoints_path([0.0, 0.0], [[1.0, 0.0], [1.0, 1.0]], 0.2)
    assert np.all(path.curvature == 0.0)
