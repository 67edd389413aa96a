"""`python -m runtime control`: one table for every task, a summary.json with `tracking` and `contact` per run."""
import csv
import dataclasses
import json

import pytest

from bindings._sr import lib
from runtime.__main__ import main
from runtime.control.benchmark import COLUMNS, controller_runs, estimator_table, sensors_target
from runtime.control.offsets import offset_cases
from runtime.control.task import load_task


def test_the_benchmark_writes_one_table_row_and_one_summary_per_task_and_controller(tmp_path):
    assert main(["control", "--out", str(tmp_path), "--tasks", "speed-step,circle", "--duration", "1"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "table.csv")))
    assert [(r["task"], r["controller"]) for r in rows] == [
        ("speed-step", "pid"), ("speed-step", "lqr"), ("speed-step", "nmpc"), ("speed-step", "nmpc-c"),
        ("circle", "pid"), ("circle", "lqr"), ("circle", "nmpc"), ("circle", "nmpc-c")]
    table = (tmp_path / "table.md").read_text()
    assert "smoke run" in table and "CPU:" in table
    for run in ("speed-step-pid", "speed-step-lqr", "speed-step-nmpc", "speed-step-nmpc-c", "circle-pid", "circle-lqr",
                "circle-nmpc", "circle-nmpc-c"):
        summary = json.loads((tmp_path / run / "summary.json").read_text())
        assert set(summary["tracking"]) == set(COLUMNS)
        assert summary["contact"]["least_normal_force_N"] > 0 and summary["contact"]["largest_friction_ratio"] > 0
        assert (tmp_path / run / "tracking.png").stat().st_size > 0


def test_a_task_on_sensors_adds_its_estimate_errors_and_target_below_the_table(tmp_path):
    assert main(["control", "--out", str(tmp_path), "--tasks", "circle-sensors", "--duration", "0.5"]) == 0
    table = (tmp_path / "table.md").read_text()
    assert "On the estimator" in table
    for kind in ("lqr", "nmpc-c"):
        e = json.loads((tmp_path / f"circle-sensors-{kind}" / "summary.json").read_text())["estimate"]
        assert f"| circle-sensors | {kind} | {1e3 * e['position_rms_m']:.1f} / {1e3 * e['position_max_m']:.1f} | " \
            f"{e['heading_rms_deg']:.2f} / {e['heading_max_deg']:.2f} | RMS ≤ 0.03 m |" in table


def _row(task, controller, settle=None, rms=None, estimate=None):
    return {"task": task, "controller": controller, "heading_settle_s": settle, "cross_track_rms_m": rms,
            "estimate": estimate}


def test_the_heading_step_on_sensors_is_held_to_its_own_controllers_nominal_settle_time_plus_two_seconds():
    nominal = [_row("heading-step", "lqr", settle=7.6), _row("heading-step", "nmpc-c", settle=5.0)]
    assert sensors_target(_row("heading-step-sensors", "lqr", settle=9.6), nominal) == ("settle ≤ 9.6 s", True)
    assert sensors_target(_row("heading-step-sensors", "lqr", settle=9.61), nominal)[1] is False
    assert sensors_target(_row("heading-step-sensors", "lqr", settle=None), nominal)[1] is False
    assert sensors_target(_row("heading-step-sensors", "nmpc-c", settle=7.1), nominal)[1] is False


def test_a_path_task_on_sensors_is_held_to_three_centimetres_and_other_tasks_to_no_target():
    assert sensors_target(_row("line-sensors", "lqr", rms=0.03), [])[1] is True
    assert sensors_target(_row("line-sensors", "lqr", rms=0.0301), [])[1] is False
    assert sensors_target(_row("circle-mismatch-ekf", "lqr", rms=0.0301), []) == ("—", None)
    assert sensors_target(_row("heading-step-sensors", "lqr", settle=9.0), []) == ("—", None)


def test_the_estimator_table_lists_only_the_runs_that_read_an_estimate():
    e = {"position_rms_m": 0.004, "position_max_m": 0.012, "heading_rms_deg": 0.2, "heading_max_deg": 0.8}
    table = estimator_table([_row("circle", "lqr", rms=0.001), _row("circle-sensors", "lqr", rms=0.02, estimate=e)])
    assert "| circle-sensors | lqr | 4.0 / 12.0 | 0.20 / 0.80 | RMS ≤ 0.03 m | yes |" in table
    assert "| circle | lqr |" not in table
    assert estimator_table([_row("circle", "lqr", rms=0.001)]) == ""


def test_the_offset_table_writes_one_row_per_chosen_case_with_its_target(tmp_path):
    assert main(["control", "--offsets", "--controllers", "lqr", "--only", "slope", "--duration", "0.5",
                 "--out", str(tmp_path)]) == 0
    rows = list(csv.DictReader(open(tmp_path / "offsets.csv")))
    assert [r["task"] for r in rows] == ["circle", "line", "line", "line"]
    assert [float(r["target_m"]) for r in rows] == [0.01, 0.005, 0.005, 0.005]
    assert " of 4 runs meet their target" in (tmp_path / "offsets.md").read_text()


def test_the_known_slope_offset_table_runs_only_the_slope_cases_with_the_slope_in_the_model():
    cases = offset_cases(load_task("circle").with_controller("lqr"), load_task("line").with_controller("lqr"),
                         known_slope=True)
    assert [c.change.split(", ")[1] for c in cases] == ["known", "known", "known", "known"]
    assert all(c.task.scenario.params.slope == c.task.plant_params.slope > 0 for c in cases)


def test_the_offset_table_names_an_unknown_controller(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["control", "--offsets", "--controllers", "pid", "--out", str(tmp_path)])
    assert "--controllers" in capsys.readouterr().err
def test_a_task_with_the_nmpc_also_runs_the_c_nmpc_on_its_settings():
    runs = controller_runs(load_task("circle"))
    assert [r.controller_kind for r in runs] == ["pid", "lqr", "nmpc", "nmpc-c"]
    assert runs[3].controllers[0] == dataclasses.replace(runs[2].controllers[0], kind="nmpc-c")


def test_the_c_nmpc_is_left_out_where_the_horizon_exceeds_its_capacity():
    task = load_task("circle").with_controller("nmpc")
    spec = task.controllers[0]
    for horizon, kinds in ((lib.SR_NMPC_MAX_HORIZON, ["nmpc", "nmpc-c"]), (lib.SR_NMPC_MAX_HORIZON + 1, ["nmpc"])):
        gains = dataclasses.replace(spec.gains, horizon=horizon)
        longer = dataclasses.replace(task, controllers=(dataclasses.replace(spec, gains=gains),))
        assert [r.controller_kind for r in controller_runs(longer)] == kinds


PID_ONLY_TASK = """
dt = 0.005
duration = 1.0
[params]
preset = "paper_simulation"
[initial]
R_S = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
[reference]
kind = "speed"
speed = 0.3
[[controller]]
kind = "pid"
rate = 50.0
"""


def test_a_task_given_by_path_runs_under_out_which_is_created_as_needed(tmp_path):
    task = tmp_path / "tasks" / "my-task.toml"
    task.parent.mkdir()
    task.write_text(PID_ONLY_TASK)
    out = tmp_path / "not" / "yet"
    assert main(["control", "--out", str(out), "--tasks", str(task), "--duration", "0.1"]) == 0
    assert [r["task"] for r in csv.DictReader(open(out / "table.csv"))] == ["my-task"]
    assert json.loads((out / "my-task-pid" / "summary.json").read_text())["task"] == "my-task"
    assert sorted(p.name for p in task.parent.iterdir()) == ["my-task.toml"]


def test_a_missing_task_is_a_named_error(tmp_path, capsys):
    assert main(["control", "--out", str(tmp_path), "--tasks", str(tmp_path / "absent.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "absent.toml: no such task file" in err


def test_two_tasks_of_one_name_are_a_named_error(tmp_path, capsys):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "same.toml").write_text(PID_ONLY_TASK)
    with pytest.raises(SystemExit) as stop:
        main(["control", "--out", str(tmp_path / "out"), "--tasks", f"{tmp_path}/a/same.toml,{tmp_path}/b/same.toml"])
    assert stop.value.code == 2
    assert "two tasks named 'same'" in capsys.readouterr().err


def test_an_out_that_cannot_be_created_is_a_named_error(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as stop:
        main(["control", "--out", str(tmp_path / "file" / "out"), "--tasks", "speed-step"])
    assert stop.value.code == 2
    assert "--out: cannot create the folder" in capsys.readouterr().err
