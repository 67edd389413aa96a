"""`python -m runtime heading-seeds` (runtime/control/heading_seeds.py): a run's class against the
deadline, the summary's interval, refusals by name, and the task files' LQR heading setting meeting
the deadline on seeds the former setting missed."""
import json
import math

import numpy as np
import pytest

from runtime.control import heading_seeds

BAND = math.radians(3.0)
T = np.arange(0.0, 30.0, 0.02)


def approach(t_in, overshoot_deg=0.0, at=0.0, width=1.0):
    """A heading error falling from 90° to 0 at `t_in`, plus a bump of `overshoot_deg` centred at `at`."""
    error = np.radians(90.0) * np.clip(1 - T / t_in, 0, None)
    return error + np.radians(overshoot_deg) * np.exp(-((T - at) / width) ** 2 * 4)


def test_a_run_inside_the_band_from_before_the_deadline_meets_it():
    settle, met, miss = heading_seeds.classify(T, approach(7.0), 9.6)
    assert met and miss is None
    assert settle == pytest.approx(7.0 - 7.0 * 3 / 90, abs=0.03)


def test_a_run_first_inside_after_the_deadline_is_late():
    assert heading_seeds.classify(T, approach(10.0), 9.6)[1:] == (False, "late")


def test_an_overshoot_out_of_the_band_at_the_deadline_misses_it():
    assert heading_seeds.classify(T, approach(7.0, -4.5, at=9.5), 9.6)[1:] == (False, "out at the deadline")


def test_the_same_overshoot_back_before_the_deadline_meets_it():
    assert heading_seeds.classify(T, approach(7.0, -4.5, at=8.5), 9.6)[1:] == (True, None)


def test_an_excursion_of_more_than_twice_the_band_after_the_deadline_is_a_swing():
    assert heading_seeds.classify(T, approach(7.0, 12.0, at=12.0), 9.6)[1:] == (False, "swing")


def test_leaving_the_band_after_the_deadline_by_less_is_the_wander():
    assert heading_seeds.classify(T, approach(7.0, 4.0, at=20.0, width=0.5), 9.6)[1:] == (False, "later out")


def test_the_summary_gives_the_exact_interval_of_160_in_200():
    # 73.8–85.3 %: the interval docs/control.md gave for 160 of 200 before this command existed
    records = [{"met": k < 160, "miss": None if k < 160 else "later out", "saturated": 0.1} for k in range(200)]
    text = heading_seeds.summary(records, 9.6)
    assert "160/200" in text and "95 % CI 73.8-85.3 %" in text and "later out 40" in text


@pytest.mark.parametrize("argv, field", [(["--seeds", "3-1"], "seeds"), (["--seeds", "a-b"], "seeds"),
                                         (["--set", "heading_rad"], "set"), (["--set", "no_such_gain=1"], "no_such_gain"),
                                         (["--set", "heading_rad=3"], "nominal: the heading step does not settle")])
def test_bad_arguments_are_refused_by_name(argv, field, capsys):
    with pytest.raises(SystemExit):
        heading_seeds.main(argv)
    assert field in capsys.readouterr().err


def test_the_command_prints_a_record_per_seed_and_the_summary(capsys):
    assert heading_seeds.main(["--seeds", "0-0", "--details"]) == 0
    lines = capsys.readouterr().out.splitlines()
    record = json.loads(lines[0])
    assert record["seed"] == 0 and record["met"] == (record["settle_s"] is not None)
    assert lines[1].startswith("lqr as the task files, seeds 0-0: ")


#: The LQR's heading setting before the softer approach: heading_rad 0 (attitude_rad's 0.1), band 0.15, tight 0.01.
FORMER = dict(heading_rad=0.0, heading_band_rad=0.15, tight_heading_rad=0.01)


@pytest.mark.parametrize("changes, met", [(None, True), (FORMER, False)])
def test_the_task_files_lqr_meets_the_deadline_on_seeds_its_former_setting_overshot(changes, met):
    nominal, task = heading_seeds.tasks("lqr", changes)
    limit = heading_seeds.deadline(nominal)
    records = [heading_seeds.run_seed(task, seed, limit) for seed in (7, 9)]
    assert all(r["met"] == met for r in records)
    if not met:
        assert {r["miss"] for r in records} == {"out at the deadline"}


@pytest.fixture(scope="module")
def lqr_task_and_deadline():
    nominal, task = heading_seeds.tasks("lqr")
    return task, heading_seeds.deadline(nominal)


def test_a_miss_of_the_law_stays_a_miss_with_the_controller_on_the_true_state(lqr_task_and_deadline):
    # seed 11 leaves the band at 11.7-15.1 s by 3.4° while the estimate is within 0.4° of the truth
    task, limit = lqr_task_and_deadline
    on_estimate, on_truth = (heading_seeds.run_seed(task, 11, limit, truth) for truth in (False, True))
    assert not on_estimate["met"] and not on_truth["met"]
    assert on_estimate["estimate_after_deg"] < 0.4 < 3.0 < on_estimate["worst_after_deg"]


def test_a_miss_by_the_estimate_meets_with_the_controller_on_the_true_state(lqr_task_and_deadline):
    # seed 53 is out at the deadline on the estimate (0.36° off after it), inside on the truth
    task, limit = lqr_task_and_deadline
    assert not heading_seeds.run_seed(task, 53, limit)["met"]
    assert heading_seeds.run_seed(task, 53, limit, truth=True)["met"]


def test_the_summary_gives_the_estimates_largest_error_in_the_misses_only():
    records = [{"met": True, "miss": None, "saturated": 0.1, "estimate_after_deg": 0.9},
               {"met": False, "miss": "later out", "saturated": 0.1, "estimate_after_deg": 0.25},
               {"met": False, "miss": "late", "saturated": 0.1, "estimate_after_deg": 0.125}]
    assert "in the misses ≤ 0.25°" in heading_seeds.summary(records, 9.6)


def test_the_command_says_when_the_controller_read_the_true_state(capsys):
    assert heading_seeds.main(["--seeds", "0-0", "--truth"]) == 0
    assert capsys.readouterr().out.startswith("lqr as the task files, on the true state, seeds 0-0: ")


def test_a_nominal_step_settling_too_late_to_leave_a_deadline_in_the_run_is_refused(monkeypatch):
    nominal, _ = heading_seeds.tasks("lqr")
    monkeypatch.setattr(heading_seeds, "run_task", lambda task: (None, None, {"heading_settle_s": 28.5}))
    with pytest.raises(ValueError, match="nominal: the heading step settles at 28.5 s"):
        heading_seeds.deadline(nominal)
    monkeypatch.setattr(heading_seeds, "run_task", lambda task: (None, None, {"heading_settle_s": 27.5}))
    assert heading_seeds.deadline(nominal) == pytest.approx(29.5)
