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


@pytest.mark.parametrize("name", [n for n in est.SETTING_NAMES if n != "rate"])
def test_a_setting_that_is_not_positive_is_named(name):
    with pytest.raises(ValueError, match=name):
        est.EkfSettings(**{name: 0.0})


def test_a_negative_rate_is_named_and_zero_means_the_controllers():
    with pytest.raises(ValueError, match=r"^rate: "):
        est.EkfSettings(rate=-1.0)
    assert est.EkfSettings(rate=0.0).rate == 0.0


class HeldController:
    """Zero torques at 10 Hz, for the closed loop's bookkeeping."""
    rate, period, saturated_fraction, solve_s = 10.0, 0.1, 0.0, ()

    def reset(self, y):
        pass

    def update(self, t, y, target):
        return np.zeros(2)


class CountingEstimator:
    """Records the period of every update; passes the measurement through."""
    def __init__(self, rate):
        self.rate, self.periods = rate, []

    def reset(self, y):
        return y

    def update(self, y, u, period):
        self.periods.append(period)
        return y


def closed_loop_with(estimator, seconds=1.0):
    task = load_task("speed-step")
    return simulate_closed_loop(task.plant_params, HeldController(), task.reference(), task.scenario.x0,
                                seconds, 0.005, "lie-euler", estimator=estimator)


def test_an_estimator_with_a_rate_reads_the_sensors_between_the_controllers_samples():
    counting = CountingEstimator(rate=40.0)     # 4 per controller sample
    closed_loop_with(counting)
    assert counting.periods == [0.025] * (10 * 4 - 1)   # 10 samples, the first one a reset


def test_an_estimator_without_a_rate_runs_once_per_controller_sample():
    counting = CountingEstimator(rate=0.0)
    closed_loop_with(counting)
    assert counting.periods == [0.1] * 9


@pytest.mark.parametrize("rate, why", [(25.0, "not a whole multiple"), (30.0, "not a whole number of plant steps")])
def test_an_estimator_rate_the_loop_cannot_keep_is_named(rate, why):
    # 25 Hz: 2.5 per controller sample; 30 Hz: 3 per sample, but 1/30 s is no whole number of 5 ms steps.
    with pytest.raises(ValueError, match=rf"^estimator.rate: .*{why}"):
        closed_loop_with(CountingEstimator(rate=rate))


def test_a_task_file_names_a_bad_estimator():
    data = {"duration": 1.0, "dt": 0.01, "reference": {"kind": "speed", "speed": 0.3},
            "controller": {"kind": "pid"}, "estimator": {"kind": "ukf"}}
    with pytest.raises(ValueError, match=r"t.toml: estimator.kind"):
        parse_task(data, source="t.toml")
    data["estimator"] = {"kind": "ekf", "rate_rad_s": -1.0}
    with pytest.raises(ValueError, match=r"t.toml: estimator.rate_rad_s: expected a number in "):
        parse_task(data, source="t.toml")
    data["estimator"] = {"kind": "ekf", "rate_rad_s": 0.05, "rate": 100}
    assert parse_task(data, source="t.toml").estimator.rate_rad_s == 0.05
    assert parse_task(data, source="t.toml").estimator.rate == 100
    data["estimator"] = {"kind": "ekf", "rate": -10}
    with pytest.raises(ValueError, match=r"t.toml: estimator.rate: expected a number in "):
        parse_task(data, source="t.toml")
