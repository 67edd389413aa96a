"""runtime/stability.py: equilibria, steady rolling, Floquet exponents (the physics of these is
checked in tests/runtime/verification/test_linearizations.py)."""
import numpy as np
import pytest

from runtime import Model, Params
from runtime import stability


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def test_the_equilibria_are_at_rest_with_zero_acceleration(model):
    for pendulum in ("down", "up"):
        assert np.abs(model.accel(stability.equilibrium(model.params, pendulum))).max() < 1e-12


def test_pendulum_down_is_stable_and_pendulum_up_is_not(model):
    down = stability.nontrivial(stability.eigenvalues(model, stability.equilibrium(model.params, "down")))
    up = stability.nontrivial(stability.eigenvalues(model, stability.equilibrium(model.params, "up")))
    assert down.real.max() < 0 < up.real.max()


def test_rolling_has_four_zero_floquet_exponents_from_its_symmetries(model):
    ex = stability.floquet_exponents(model, 0.5)
    assert np.sum(np.abs(ex) < 1e-6) == 4 and ex.size == 12


def test_floquet_exponents_refuse_a_speed_without_a_period(model):
    with pytest.raises(ValueError, match="speed"):
        stability.floquet_exponents(model, 0.0)


def test_steady_rolling_refuses_a_speed_the_pendulum_cannot_hold(model):
    with pytest.raises(ValueError, match="no steady rolling"):
        stability.steady_rolling(model, 2.5)


def test_equilibrium_refuses_an_unknown_pendulum_position(model):
    with pytest.raises(ValueError, match="pendulum"):
        stability.equilibrium(model.params, "sideways")
