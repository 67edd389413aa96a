"""The EKF on the group (runtime/control/estimator.py): it filters the sensors' noise, its
covariance stays a covariance, a broken prediction is caught, bad settings are named."""
import dataclasses

import numpy as np
import pytest

from runtime.control import estimator as est
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.task import load_task, parse_task
from runtime.state import IDX_NU, IDX_Q

SIGMA_POSITION, SIGMA_RATE = 0.005, 0.02


def noisy_circle(ekf_class=est.Ekf, seconds=10.0):
    """(estimates, true states at the samples) of the LQR on the circle, nominal plant, sensor noise."""
    task = load_task("circle-mismatch").with_controller("lqr")
    nominal = load_task("circle")
    task = dataclasses.replace(task, plant_params=nominal.plant_params, estimator=est.EkfSettings(),
                               scenario=dataclasses.replace(task.scenario, steps=round(seconds / task.scenario.dt)))
    ekf = ekf_class(task.scenario.params, task.estimator)
    result = simulate_closed_loop(task.plant_params, task.controller(), task.reference(), task.scenario.x0,
                                  task.duration, task.scenario.dt, task.scenario.method, task.noise, estimator=ekf)
    per = round(1 / (task.rate * task.scenario.dt))
    return result.estimates, result.trajectory[:-1:per], ekf


def rms(a):
    return float(np.sqrt(np.mean(np.square(a))))


def test_the_estimate_is_closer_to_the_truth_than_the_sensors():
    estimates, truth, _ = noisy_circle()
    assert rms(estimates[:, IDX_Q][:, :2] - truth[:, IDX_Q][:, :2]) < 0.3 * SIGMA_POSITION
    assert rms(estimates[:, IDX_NU] - truth[:, IDX_NU]) < 0.5 * SIGMA_RATE


def test_the_covariance_stays_symmetric_positive_definite():
    _, _, ekf = noisy_circle(seconds=2.0)
    assert np.allclose(ekf.P, ekf.P.T, rtol=0, atol=1e-15)
    assert np.linalg.eigvalsh(ekf.P).min() > 0


class HoldingEkf(est.Ekf):
    """A broken prediction: the state held over the sample instead of stepped."""
    def update(self, y, u, period):
        model = self.model
        step = model.step
        model.step = lambda x, u, dt, method: x
        try:
            return super().update(y, u, period)
        finally:
            model.step = step


def test_the_filtering_check_fails_for_a_prediction_that_does_not_move():
    estimates, truth, _ = noisy_circle(HoldingEkf)
    assert not rms(estimates[:, IDX_Q][:, :2] - truth[:, IDX_Q][:, :2]) < 0.3 * SIGMA_POSITION


@pytest.mark.parametrize("name", est.SETTING_NAMES)
def test_a_setting_that_is_not_positive_is_named(name):
    with pytest.raises(ValueError, match=name):
        est.EkfSettings(**{name: 0.0})


def test_a_task_file_names_a_bad_estimator():
    data = {"duration": 1.0, "dt": 0.01, "reference": {"kind": "speed", "speed": 0.3},
            "controller": {"kind": "pid"}, "estimator": {"kind": "ukf"}}
    with pytest.raises(ValueError, match=r"t.toml: estimator.kind"):
        parse_task(data, source="t.toml")
    data["estimator"] = {"kind": "ekf", "rate_rad_s": -1.0}
    with pytest.raises(ValueError, match=r"estimator.rate_rad_s: must be > 0"):
        parse_task(data, source="t.toml")
    data["estimator"] = {"kind": "ekf", "rate_rad_s": 0.05}
    assert parse_task(data, source="t.toml").estimator.rate_rad_s == 0.05
