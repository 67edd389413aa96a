"""The yoke rotor's inertia j_mY on the battery-geared robot (n_Y = 60): the full-state fit
identifies it alone, next to the yoke's inertia about its axis, and its interval holds the truth."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification.coverage import random_torques
from runtime.identification.fit import identify
from runtime.scenario import load_scenario
from runtime.sensor_set import SensorSet

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params
# the rotor half as heavy again as the robot file says (reflected: 0.0216 against 0.0144 kg m²)
TRUTH = NOMINAL.replace(j_mY=6e-6, J_Y=np.asarray(NOMINAL.J_Y) + np.diag([0.01, 0.0, 0.0]))


@pytest.fixture(scope="module")
def fit():
    duration = 10.0
    run = dataclasses.replace(SCENARIO, params=TRUTH, torques=random_torques(duration, np.random.default_rng(7)),
                              steps=int(round(duration / SCENARIO.dt)))
    return identify(simulate_log(run, SensorSet.default(), seed=7), NOMINAL, "j_mY,J_Y_xx", full_state=True)


def test_the_geared_rotor_is_identified_alone_beside_the_yoke_axis_inertia(fit):
    assert fit.rank == 2 and np.all(fit.identified)
    assert [c["name"] for c in fit.combinations if c["identified"]] == ["JO_Y_xx + JO_P_zz", "j_mY"]


def test_the_rotor_interval_holds_the_truth_and_not_the_robot_files_value(fit):
    truth = np.array([TRUTH.j_mY, np.asarray(TRUTH.J_Y)[0, 0]])
    assert np.all(np.abs(fit.estimate - truth) <= 3 * fit.sigma), (fit.estimate, truth, fit.sigma)
    assert abs(fit.nominal[0] - truth[0]) > 3 * fit.sigma[0]
    assert fit.residual_check["passed"]
