"""Fixtures shared by the tests of runtime/scenario.py and of the scenario application."""
import pytest

from runtime.scenario import load_scenario, run_scenario


@pytest.fixture(scope="module")
def results():
    return {name: run_scenario(load_scenario(name)) for name in ("tilted-pendulum", "tilted-yoke", "t-shape")}
