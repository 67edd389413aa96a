"""Fixes that arrive late (a sensor set's `latency`): the estimate over a log marks each fix at the
instant it measures and applies it on arrival as a delayed fix, so the position still meets its
target and its σ still holds the truth.  Short runs only."""
import dataclasses

import pytest

from runtime.estimation.estimate import errors, estimate_log
from runtime.estimation.sense import load_run, simulate_log
from runtime.sensor_set import FixSpec, SensorSet

SECONDS = 12.0          # scored over the second half
LATENCY = 0.2           # s: a camera's or a motion-capture link's delay


@pytest.fixture(scope="module")
def late_fixes():
    task = load_run("circle")
    scenario = task.scenario.with_overrides(steps=round(SECONDS / task.scenario.dt))
    default = SensorSet.default()
    sensors = dataclasses.replace(default, fixes=dataclasses.replace(default.fixes, latency=LATENCY))
    log = simulate_log(dataclasses.replace(task, scenario=scenario), sensors, seed=3)
    return log, estimate_log(log)


def test_every_late_fix_is_applied(late_fixes):
    log, result = late_fixes
    assert (log.fixes.t - log.fixes["t_measured"]).min() == pytest.approx(LATENCY)
    assert result.counters["position"]["accepted"] == len(log.fixes) and result.counters["position"]["gated"] == 0


def test_with_late_fixes_the_position_meets_its_target_within_its_sigma(late_fixes):
    metrics = errors(*late_fixes)
    assert metrics["position_rms_m"] <= 0.01
    assert min(metrics["within_3_sigma"]["q_x"], metrics["within_3_sigma"]["q_y"]) >= 0.9
