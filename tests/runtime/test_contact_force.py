"""Model.contact_force: the floor's force on the shell from the model's own momentum balance."""
import numpy as np
import pytest

from runtime import Model, Params
from runtime.state import IDX_RS, initial_state
from runtime.verification.contact import ReferenceContact
from runtime.verification.sampling import random_general_params, random_inputs, random_state, random_states


@pytest.fixture(scope="module")
def sloped():
    """A general robot (off-centre masses, full tensors, rotors) on a slope."""
    params = random_general_params(np.random.default_rng(5))
    assert params.slope != 0
    return params


@pytest.mark.parametrize("robot", ["paper", "general on a slope"])
def test_contact_force_equals_the_reference_multiplier(robot, sloped, rng):
    params = Params.paper_simulation() if robot == "paper" else sloped
    model, reference = Model(params), ReferenceContact(params.as_dict())
    for _ in range(5):
        x, u = random_state(rng, params, max_speed=5.0), random_inputs(rng, 1)[0]
        expected = reference.force(x, u)
        assert np.abs(model.contact_force(x, u) - expected).max() <= 1e-12 * np.abs(expected).max()


def test_at_rest_on_a_slope_the_floor_carries_the_normal_weight_and_less_than_the_downhill_pull():
    """The robot starts rolling down: friction holds only part of the weight's component along the slope."""
    params = Params.paper_simulation().with_changes(slope=0.1)
    force = Model(params).contact_force(initial_state(r=params.r))
    weight = (params.m_S + params.m_Y + params.m_P) * params.g
    assert force[2] == pytest.approx(weight * np.cos(0.1), rel=1e-14)
    assert force[1] == 0.0
    assert 0.0 < force[0] < 0.5 * weight * np.sin(0.1)


def test_batch_contact_force_equals_row_by_row(sloped, rng):
    model = Model(sloped)
    x, u = random_states(rng, 7, sloped), random_inputs(rng, 7)
    batch = model.contact_force(x, u)
    assert batch.shape == (7, 3)
    assert np.array_equal(batch, np.array([model.contact_force(xi, ui) for xi, ui in zip(x, u)]))
    assert np.array_equal(model.contact_force(x), np.array([model.contact_force(xi) for xi in x]))


def test_contact_force_names_a_state_that_is_not_finite():
    x = initial_state()
    x[3] = np.nan
    with pytest.raises(ValueError, match=r"^x"):
        Model().contact_force(x)


def test_batch_contact_force_names_the_bad_row(rng):
    x = random_states(rng, 3)
    x[2, IDX_RS] *= 1.01
    with pytest.raises(ValueError, match=r"x\[2\]"):
        Model().contact_force(x)


def test_contact_force_refuses_torques_of_the_wrong_shape_or_not_finite():
    with pytest.raises(ValueError, match="^u: shape"):
        Model().contact_force(np.tile(initial_state(), (2, 1)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="^u"):
        Model().contact_force(initial_state(), [0.0, np.inf])
