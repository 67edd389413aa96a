"""The rolling contact's two sides: the reference's multiplier force and the momentum balances of a motion."""
import numpy as np

from runtime import Params
from runtime.state import initial_state
from runtime.verification.contact import DIFF_HALF_WIDTH, ReferenceContact, momentum_residuals
from runtime.verification.sampling import random_state

PARAMS = Params.paper_simulation()
TOTAL_MASS = PARAMS.m_S + 2 * (PARAMS.paper_params.m_b + PARAMS.paper_params.m_h) + PARAMS.m_P


def test_reference_contact_force_at_rest_carries_the_weight_and_nothing_sideways():
    force = ReferenceContact(PARAMS.as_dict()).force(initial_state(r=PARAMS.r), np.zeros(2))
    assert np.allclose(force, [0.0, 0.0, TOTAL_MASS * PARAMS.g], rtol=1e-13, atol=1e-12)


def test_reference_contact_force_of_a_moving_robot_differs_from_its_weight(rng):
    """Away from rest the contact force also accelerates the bodies: its vertical part is not m_tot g."""
    x = random_state(rng, PARAMS, max_speed=5.0)
    force = ReferenceContact(PARAMS.as_dict()).force(x, np.zeros(2))
    assert np.all(np.isfinite(force)) and abs(force[2] - TOTAL_MASS * PARAMS.g) > 1e-3


def test_a_robot_at_rest_implies_the_weight_as_contact_force_and_balanced_moments():
    X = np.tile(initial_state(r=PARAMS.r), (2 * DIFF_HALF_WIDTH + 3, 1))
    force, moment = momentum_residuals(X, 0.01, PARAMS.as_dict())
    assert force.shape == moment.shape == (3, 3)
    assert np.allclose(force, [0.0, 0.0, TOTAL_MASS * PARAMS.g], rtol=1e-14)
    assert np.abs(moment).max() < 1e-13


def test_a_tilted_pendulum_at_rest_shows_an_unbalanced_moment():
    X = np.tile(initial_state(theta_P=0.3, r=PARAMS.r), (2 * DIFF_HALF_WIDTH + 1, 1))
    moment = momentum_residuals(X, 0.01, PARAMS.as_dict())[1]
    expected = PARAMS.m_P * PARAMS.g * PARAMS.paper_params.l / 2 * np.sin(0.3)
    assert np.isclose(np.abs(moment).max(), expected, rtol=1e-12)
