"""The LQR's tight path gains in the closed loop on sensors: under the default sensor set's process
noise they hold the nominal robot nearer the line than the path gains alone, on the same seeded
disturbance."""
import dataclasses

import pytest

from runtime.control.closed_loop import simulate_on_sensors
from runtime.control.lqr import Lqr
from runtime.control.metrics import tracking_metrics
from runtime.control.task import load_task


def line_rms(seed, tight):
    task = load_task("line-sensors").with_controller("lqr")
    gains = task.gains if tight else dataclasses.replace(task.gains, tight_band_m=0.0)
    shipped = task.controller()
    controller = Lqr(task.scenario.params, task.rate, task.u_max, gains=gains, schedule=shipped.schedule)
    reference = task.reference()
    s = task.scenario
    result = simulate_on_sensors(task.plant_params, controller, reference, s.x0, task.duration, s.dt,
                                 task.make_estimator(), task.sensors, s.method, seed, engine="c", record_samples=False)
    every = round(1 / (task.rate * s.dt))
    return tracking_metrics(result, reference, "line", task.plant_params.r, sample_every=every)["cross_track_rms_m"]


@pytest.mark.parametrize("seed", [2])
def test_the_tight_gains_lower_the_lines_cross_track_rms_under_the_process_noise(seed):
    assert line_rms(seed, tight=True) < 0.9 * line_rms(seed, tight=False)
