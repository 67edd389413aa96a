"""Whether no-slip holds along a motion (runtime/contact.py): the extremes of the contact force and the flags."""
import dataclasses

import numpy as np
import pytest

from runtime.contact import contact_flags, contact_summary, friction_ratio
from runtime.scenario import load_scenario, run_scenario
from runtime.scenarios.report import summary


@pytest.fixture(scope="module")
def climb():
    """The first 3 s of the shipped ramp climb (a yoke torque on a slope: friction is needed)."""
    scenario = load_scenario("ramp-climb")
    return run_scenario(dataclasses.replace(scenario, steps=300))


def flagged(result, friction):
    return summary(dataclasses.replace(result, scenario=dataclasses.replace(result.scenario, friction=friction)))["contact"]


def test_a_run_summary_reports_the_least_normal_force_and_the_largest_friction_ratio(climb):
    contact = summary(climb)["contact"]
    F = climb.contact_force
    assert contact["least_normal_force_N"] == F[:, 2].min() > 0
    assert climb.time[np.argmin(F[:, 2])] == contact["least_normal_force_time_s"]
    ratio = np.hypot(F[:, 0], F[:, 1]) / F[:, 2]
    assert contact["largest_friction_ratio"] == ratio.max() > 0
    assert climb.time[np.argmax(ratio)] == contact["largest_friction_ratio_time_s"]
    assert contact["friction"] is None and contact["flags"] == []


def test_the_slide_flag_fires_for_a_friction_just_below_the_runs_largest_ratio(climb):
    largest = summary(climb)["contact"]["largest_friction_ratio"]
    contact = flagged(climb, largest * (1 - 1e-9))
    [flag] = contact["flags"]
    assert flag["kind"] == "slide"
    assert flag["worst_time_s"] == contact["largest_friction_ratio_time_s"]
    assert flag["margin"] == pytest.approx(-1e-9 * largest, rel=1e-3)


def test_the_slide_flag_stays_off_for_a_friction_just_above_the_runs_largest_ratio(climb):
    largest = summary(climb)["contact"]["largest_friction_ratio"]
    assert flagged(climb, largest * (1 + 1e-9))["flags"] == []


def test_the_lift_off_flag_names_where_the_normal_force_first_reaches_zero_and_its_least_value():
    t = np.linspace(0.0, 1.0, 11)
    F = np.column_stack([np.zeros(11), np.zeros(11), 5.0 - 20.0 * np.sin(np.pi * t)])
    [flag] = contact_flags(t, F)
    assert flag.kind == "lift-off"
    assert flag.time_s == pytest.approx(0.1) and flag.worst_time_s == pytest.approx(0.5)
    assert flag.margin == pytest.approx(-15.0)
    assert "leave the floor" in flag.message()


def test_a_normal_force_that_stays_positive_raises_no_lift_off_flag():
    t = np.linspace(0.0, 1.0, 11)
    F = np.column_stack([np.zeros(11), np.zeros(11), 1e-9 + t])
    assert contact_flags(t, F) == []


def test_the_friction_ratio_is_undefined_where_the_floor_does_not_push():
    ratio = friction_ratio([[3.0, 4.0, 10.0], [1.0, 0.0, 0.0], [1.0, 0.0, -1.0]])
    assert ratio[0] == 0.5 and np.isnan(ratio[1:]).all()
    contact = contact_summary([0.0, 1.0], [[1.0, 0.0, -1.0], [1.0, 0.0, -2.0]], friction=0.5)
    assert contact["largest_friction_ratio"] is None
    assert [flag["kind"] for flag in contact["flags"]] == ["lift-off"]
