"""The EKF over a log (runtime/estimation/estimate.py, `python -m runtime estimate`): on a simulated
circle with the default sensor set it meets the accuracy targets of docs/estimation.md, without
fixes its tilt and speeds still hold, and (nothing seeing the heading) the filter is
observability-constrained, with fixes it is not; the metrics see a planted error; the command writes the
estimate in trajectory.csv's columns and refuses a bad log in one line.  Short runs only."""
import dataclasses
import json

import numpy as np
import pytest

from runtime.estimation.estimate import ERROR_NAMES, errors, estimate_log, main, moving_at_start, table
from runtime.estimation.logs import write_log
from runtime.estimation.sense import load_run, simulate_log
from runtime.sensor_set import load_sensor_set
from runtime.so3 import rot_x
from runtime.state import IDX_Q, IDX_RS, STATE_COLUMNS

SECONDS = 12.0          # scored over the second half


def circle(sensors=None, seed=3):
    task = load_run("circle")
    scenario = task.scenario.with_overrides(steps=round(SECONDS / task.scenario.dt))
    return simulate_log(dataclasses.replace(task, scenario=scenario), sensors, seed=seed)


@pytest.fixture(scope="module")
def with_fixes():
    log = circle()
    return log, estimate_log(log)


@pytest.fixture(scope="module")
def without_fixes():
    log = circle(load_sensor_set("imu-encoders"))
    return log, estimate_log(log)


def test_with_fixes_position_heading_tilt_and_speed_meet_their_targets(with_fixes):
    metrics = errors(*with_fixes)
    assert metrics["position_rms_m"] <= 0.01
    assert metrics["heading_rms_deg"] <= 1.0
    assert metrics["tilt_rms_deg"] <= 0.3
    assert metrics["forward_speed_rms_m_s"] <= 0.01


def test_with_fixes_the_truth_stays_within_three_sigma(with_fixes):
    assert min(errors(*with_fixes)["within_3_sigma"].values()) >= 0.9


def test_without_fixes_tilt_and_forward_speed_still_meet_their_targets(without_fixes):
    metrics = errors(*without_fixes)
    assert metrics["tilt_rms_deg"] <= 0.5
    assert metrics["forward_speed_rms_m_s"] <= 0.02


def test_without_fixes_the_position_sigma_grows_as_its_error_can(without_fixes):
    _, result = without_fixes
    sigma = result.sigma[:, ERROR_NAMES.index("q_x")]
    assert sigma[-1] > 5 * sigma[len(sigma) // 10]


def test_the_metrics_see_a_position_off_by_two_centimetres(with_fixes):
    log, result = with_fixes
    x = result.x.copy()
    x[:, IDX_Q.start] += 0.02
    assert errors(log, dataclasses.replace(result, x=x))["position_rms_m"] > 0.015


def test_the_tilt_metric_sees_the_shell_tilted_by_one_degree(with_fixes):
    log, result = with_fixes
    x = result.x.copy()
    R_S = x[:, IDX_RS].reshape(-1, 3, 3)
    x[:, IDX_RS] = (rot_x(np.radians(1.0)) @ R_S).reshape(-1, 9)     # about the floor's x axis
    assert errors(log, dataclasses.replace(result, x=x))["tilt_rms_deg"] == pytest.approx(1.0, abs=0.05)


def test_a_log_without_truth_has_no_metrics(with_fixes):
    log, result = with_fixes
    assert errors(dataclasses.replace(log, truth=None), result) is None


def test_the_circle_starts_moving_so_the_start_rule_widens_the_speeds(with_fixes):
    assert moving_at_start(with_fixes[0])


def test_the_estimate_table_has_the_trajectory_columns_then_the_sigmas(with_fixes):
    header, rows = table(with_fixes[1])
    assert header[1:1 + len(STATE_COLUMNS)] == STATE_COLUMNS
    assert header[1 + len(STATE_COLUMNS)] == f"sigma_{ERROR_NAMES[0]}"
    assert rows.shape == (len(with_fixes[1].t), len(header)) and np.isfinite(rows).all()


def test_the_command_writes_the_estimate_its_figure_and_summary(with_fixes, tmp_path):
    write_log(with_fixes[0], tmp_path / "log")
    assert main([str(tmp_path / "log"), "--out", str(tmp_path / "est"), "--quiet"]) == 0
    assert {p.name for p in (tmp_path / "est").iterdir()} == {"estimate.csv", "estimate.png", "summary.json"}
    summary = json.loads((tmp_path / "est" / "summary.json").read_text())
    assert summary["errors"]["position_rms_m"] <= 0.01


def test_the_command_refuses_a_folder_that_is_not_a_log_in_one_line(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main([str(tmp_path / "empty"), "--out", str(tmp_path / "est")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1
    assert not (tmp_path / "est").exists()


def test_the_filter_predicts_with_the_truths_method_when_the_log_says_which():
    from types import SimpleNamespace
    from runtime.estimation.estimate import prediction_method
    assert prediction_method(SimpleNamespace(meta={"method": "lie-euler"})) == "lie-euler"
    assert prediction_method(SimpleNamespace(meta={"method": "cf4"})) == "cf4"


def test_a_log_without_a_method_is_predicted_with_rkmk4():
    from types import SimpleNamespace
    from runtime.estimation.estimate import prediction_method
    assert prediction_method(SimpleNamespace(meta={})) == "rkmk4"


def test_a_log_naming_an_unknown_method_is_refused_naming_the_field():
    from types import SimpleNamespace
    from runtime.estimation.estimate import prediction_method
    with pytest.raises(ValueError, match="method"):
        prediction_method(SimpleNamespace(meta={"method": "euler"}))


def test_without_fixes_and_heading_the_filter_is_observability_constrained(without_fixes):
    log, result = without_fixes
    heading = ERROR_NAMES.index("xi_S_z")
    on, off = (estimate_log(log, constrained=c).sigma[-1, heading] for c in (True, False))
    assert result.sigma[-1, heading] == on and on > 1.15 * off


def test_with_fixes_the_filter_is_not_observability_constrained(with_fixes):
    log, result = with_fixes
    assert (result.sigma == estimate_log(log, constrained=False).sigma).all()
    assert not (result.sigma == estimate_log(log, constrained=True).sigma).all()


def test_a_constrained_that_is_not_a_bool_or_none_is_a_value_error_naming_it(with_fixes):
    with pytest.raises(ValueError, match="constrained"):
        estimate_log(with_fixes[0], constrained="auto")
