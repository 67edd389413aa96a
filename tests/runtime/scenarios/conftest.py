"""Fixtures shared by the scenario tests."""
import pytest

from runtime.scenarios.scenario import load_scenario, run_scenario


@pytest.fixture(scope="module")
def results():
    return {name: run_scenario(load_scenario(name)) for name in ("tilted-pendulum", "tilted-yoke", "t-shape")}
