"""The robustness sweep: closed loops on the estimator over drawn plants, judged by the success rule."""
import math
import os
import subprocess
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest

from runtime.__main__ import main
from runtime.control.reference import circle_path, line_path
from runtime.sweep.robustness import DRAWN, GROUPS, judge, with_nominal
from runtime.sweep.spec import load_sweep

SMALL = """
description = "a handful of plants, cut short"
samples = 3
seed = 7
samples_per_task = 2

[control]
tasks = ["line"]
controllers = ["lqr"]
sensors = "default"
duration = 1.0
"""

SPEED = 0.3


def _sweep(tmp_path, text=SMALL):
    path = tmp_path / "small.toml"
    path.write_text(text)
    return path


def test_a_handful_of_plants_run_through_the_sweep_command_into_a_table_a_summary_and_a_figure(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sweep", str(_sweep(tmp_path)), "--out", str(out), "--scheduler", "serial", "--no-progress"]) == 0
    rows = pq.read_table(out / "results.parquet").to_pydict()
    assert rows["sample"] == [0, 1, 2] and rows["plant"] == [0, 1, 2]
    assert rows["status"] == [0, 0, 0] and all(n == 200 for n in rows["steps_done"])
    assert len(set(rows["m_P"])) == 3 and len(set(rows["cross_track_rms_m"])) == 3
    summary = (out / "summary.md").read_text()
    assert "| line | lqr | 3 | 0 | 0 |" in summary
    assert (out / "summary.png").stat().st_size > 0
    # a row is what rerunning its sample alone gives
    capsys.readouterr()
    assert main(["sweep", str(_sweep(tmp_path)), "--out", str(out), "--rerun", "2"]) == 0
    printed = capsys.readouterr().out
    assert f"cross_track_rms_m = {rows['cross_track_rms_m'][2]!r}" in printed


FIGURE8_SHORT = SMALL.replace("samples = 3", "samples = 1").replace('tasks = ["line"]', 'tasks = ["figure8"]') \
    .replace("duration = 1.0", "duration = 2.0")


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="OpenBLAS runs one thread on one core")
def test_a_row_a_dask_worker_wrote_equals_its_rerun_in_a_process_with_two_blas_threads(tmp_path):
    # Dask's nannies start their workers on one BLAS thread; a shell's `--rerun` gets one per core.
    # The LQR's path gains differ by up to 2e-9 between one and two OpenBLAS threads (the 14 x 14
    # expm of its discretisation), and so does the run (runtime/blas.py).  The rerun runs in a
    # fresh process: this one's designs, cached by earlier tests, do not enter.
    path, out = _sweep(tmp_path, FIGURE8_SHORT), tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    row = pq.read_table(out / "results.parquet").to_pydict()
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    env.update(OPENBLAS_NUM_THREADS="2", OMP_NUM_THREADS="2")
    printed = subprocess.run([sys.executable, "-m", "runtime", "sweep", str(path), "--out", str(out), "--rerun", "0"],
                             env=env, capture_output=True, text=True, check=True).stdout
    for name in ("cross_track_rms_m", "cross_track_max_m", "progress", "saturated_fraction",
                 "estimate_position_rms_m"):
        assert f"{name} = {row[name][0]!r}" in printed


def test_every_run_of_a_plant_sees_the_same_robot_and_the_runs_cycle_through_tasks_and_controllers(tmp_path):
    spec = load_sweep("control-robustness")
    draws = spec.draw(0, 12)
    assert list(draws["plant"]) == [0] * 6 + [1] * 6
    assert list(draws["task"]) == [0, 0, 1, 1, 2, 2] * 2 and list(draws["controller"]) == [0, 1] * 6
    for name in DRAWN:
        assert len(set(draws[name][:6])) == 1 and draws[name][0] != draws[name][6]


def test_the_drawn_plants_stay_within_the_files_ranges(tmp_path):
    spec = load_sweep(str(_sweep(tmp_path))).with_samples(400)
    draws = spec.draw(0, 400)
    for name in ("m_S", "m_b", "m_h", "m_P"):
        assert np.all(np.abs(draws[name] - 1) <= 0.2)
    for name in ("k_S", "k_Y", "k_P"):
        assert np.all(np.abs(draws[name] - 1) <= 0.3) and np.abs(draws[name] - 1).max() > 0.25
    shift = np.linalg.norm([draws["c_P_dx_m"], draws["c_P_dy_m"], draws["c_P_dz_m"]], axis=0)
    assert shift.max() <= 0.01 and shift.max() > 0.009
    assert np.all(np.abs(draws["slope_fraction"]) <= 0.25)
    assert np.all(np.abs(draws["dx0_m"]) <= 0.05) and np.all(np.abs(draws["dpsi0_rad"]) <= math.radians(5))
    assert set(DRAWN) <= set(draws)


@pytest.fixture
def line():
    return line_path(np.zeros(2), 0.0, 0.0, 12.0 + 2.0, SPEED)


def _along(t, offset=0.0, stall_after=None):
    x = SPEED * (t if stall_after is None else np.minimum(t, stall_after))
    return np.stack([x, np.full_like(t, offset)], axis=1)


def test_a_run_on_the_path_at_the_reference_speed_succeeds(line):
    t = np.linspace(0.0, 40.0, 401)
    rms, _, progress, ok = judge(line, t, _along(t, offset=0.01), 0.03, 0.9)
    assert rms == pytest.approx(0.01) and progress == pytest.approx(1.0, abs=0.01) and ok


def test_a_run_that_stalls_on_the_path_fails(line):
    t = np.linspace(0.0, 40.0, 401)
    rms, _, progress, ok = judge(line, t, _along(t, stall_after=20.0), 0.03, 0.9)
    assert rms == pytest.approx(0.0, abs=1e-9) and progress == pytest.approx(0.5, abs=0.01)
    assert not ok


def test_a_run_that_goes_far_off_the_path_fails(line):
    t = np.linspace(0.0, 40.0, 401)
    rms, _, progress, ok = judge(line, t, _along(t, offset=0.2), 0.03, 0.9)
    assert rms == pytest.approx(0.2) and progress == pytest.approx(1.0, abs=0.01) and not ok


def test_laps_of_a_circle_count_as_progress():
    circle = circle_path(np.zeros(2), 0.0, 2.0, 20.0, SPEED)
    t = np.linspace(0.0, 60.0, 3001)
    angle = SPEED * t / 2.0 - math.pi / 2
    positions = np.stack([2.0 * np.cos(angle), 2.0 + 2.0 * np.sin(angle)], axis=1)
    _, _, progress, ok = judge(circle, t, positions, 0.03, 0.9)
    assert progress == pytest.approx(1.0, abs=0.01) and ok


def test_a_rerun_can_leave_out_one_perturbation_at_a_time(tmp_path):
    spec = load_sweep(str(_sweep(tmp_path)))
    drawn = {k: v[0].item() for k, v in spec.draw(0, 1).items()}
    for group, values in GROUPS.items():
        changed = with_nominal(drawn, [group])
        assert all(changed[k] == v for k, v in values.items())
        assert all(changed[k] == drawn[k] for k in drawn if k not in values)
    with pytest.raises(ValueError, match="--nominal: 'mass' is not one of masses"):
        with_nominal(drawn, ["mass"])


def _no_operating_point(*args, **kwargs):
    raise ValueError("operating_point: no steady rolling found")


def _designed(spec):
    """`spec` with its controller's LQR schedule designed (and cached) on the real operating points,
    so that a test which then replaces `operating_point` fails only the plant's steady torque,
    whatever ran before it."""
    spec.run_chunk(0, 1)
    return spec


def test_a_plant_without_a_steady_operating_point_is_run_and_counted_apart_under_its_reason(tmp_path, monkeypatch):
    import runtime.control.lqr_design as lqr_design
    from runtime.sweep.robustness import APART_NO_OPERATING_POINT, APART_REASONS
    from runtime.sweep.robustness_summary import group_stats, summary_text
    spec = _designed(load_sweep(str(_sweep(tmp_path))))
    monkeypatch.setattr(lqr_design, "operating_point", _no_operating_point)
    row = spec.run_chunk(0, 1)
    assert row["counted_apart"][0] == APART_NO_OPERATING_POINT and math.isnan(row["steady_torque_nm"][0])
    assert row["status"][0] == 0 and row["steps_done"][0] == 200
    group = group_stats(row, spec)[0]
    assert group["apart"] == 1 and group["n"] == 0
    assert group["apart_reasons"] == {code: int(code == APART_NO_OPERATING_POINT) for code in APART_REASONS}
    assert "| line | lqr | 0 | 1 | 0 | 0 | 0 | 0 |" in summary_text(row, spec, "cmd")


def test_a_plant_whose_steady_torque_exceeds_the_limit_is_counted_apart_under_its_reason(tmp_path, monkeypatch):
    import runtime.control.lqr_design as lqr_design
    from runtime.sweep.robustness import APART_TORQUE
    spec = _designed(load_sweep(str(_sweep(tmp_path))))
    monkeypatch.setattr(lqr_design, "operating_point", lambda *a, **k: (None, np.array([9.0, 0.0])))
    row = spec.run_chunk(0, 1)
    assert row["counted_apart"][0] == APART_TORQUE and row["steady_torque_nm"][0] >= 9.0


def test_each_failed_run_is_counted_under_its_first_cause():
    from types import SimpleNamespace
    from runtime.sweep.robustness_summary import failure_causes
    cols = {"success": np.array([1, 0, 0, 0, 0, 0]), "status": np.array([0, 7, 0, 0, 0, 7]),
            "estimate_position_rms_m": np.array([0.0, 0.0, 0.5, 0.5, 0.0, 0.0]),
            "progress": np.array([1.0, 1.0, 1.0, 0.1, 0.1, 1.0]),}
    rows = np.array([True, True, True, True, True, False])
    assert failure_causes(cols, rows, SimpleNamespace(coverage=0.9)) == \
        {"stopped": 1, "estimate lost": 2, "stall": 1, "offset": 0}
    cols["progress"][4] = 1.0
    assert failure_causes(cols, rows, SimpleNamespace(coverage=0.9))["offset"] == 1


def test_a_lines_slope_pull_is_read_along_the_line_as_turned_by_the_slopes_direction():
    from runtime.sweep.robustness import _task, steady_torque, turned
    task = _task("line", "lqr", "default")
    plant = task.scenario.params.replace(slope=0.001)
    flat = steady_torque(task, task.scenario.params)
    pull = plant.m_R * plant.g * plant.r * math.sin(0.001)
    # The task turned by ψ runs at ψ to the slope (along x): across it at π/2, up it at π.
    assert steady_torque(turned(task, math.pi / 2), plant) == pytest.approx(flat, abs=1e-9)
    assert steady_torque(turned(task, math.pi), plant) == pytest.approx(flat + pull, rel=1e-9)


CIRCLE_PLANTS = """
description = "the shipped study's plants on the circle with the LQR"
samples = 20
seed = 20261126
samples_per_task = 1

[control]
tasks = ["circle"]
controllers = ["lqr"]
sensors = "default"
"""


def test_the_circle_lqr_holds_a_plant_on_which_tighter_attitude_gains_chatter_at_the_torque_limits_and_stall(tmp_path):
    # Plant 16 of the shipped study (masses and dampings up to 24 % off, c_P 7 mm low): with the
    # yoke's attitude sized 0.1 rad the torques clip on about 90 % of the samples and it stalls.
    spec = load_sweep(str(_sweep(tmp_path, CIRCLE_PLANTS)))
    row = spec.run_chunk(16, 17)
    assert row["counted_apart"][0] == 0 and row["steady_torque_nm"][0] < 0.3
    assert row["success"][0] == 1 and row["saturated_fraction"][0] < 0.3


def test_the_circle_lqr_holds_a_plant_whose_slow_offset_the_former_integral_bound_left_above_the_rule(tmp_path):
    # Plant 3 of the shipped study (a slope at -0.21 of the limit, k_Y +10 %): with the circle's
    # former settings (∫e_y held while |ė_y| > 10 mm/s, e_y sized 0.15 m, tight gains at 3 cm) its
    # second-half RMS is about 40 mm; the circle task's 30 mm/s bound, 0.2 m and 2.5 cm hold it to
    # about 24 mm (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, CIRCLE_PLANTS)))
    row = spec.run_chunk(3, 4)
    assert row["plant"][0] == 3 and row["progress"][0] > 0.9
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.028


def test_the_circle_lqr_holds_a_plant_that_left_the_path_with_the_steering_torque_clipped(tmp_path):
    # Plant 84 of the shipped study: with the heading sized as the lean (0.2 rad) and the curvature
    # previewed 0.3 m ahead, the pendulum's torque clips on about 88 % of the samples and the robot
    # leaves the circle (about 0.8 m RMS, 0.75 of the path); the circle task's heading at 0.4 rad
    # and 0.6 m preview hold it to about 17 mm (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, CIRCLE_PLANTS.replace("samples = 20", "samples = 100"))))
    row = spec.run_chunk(84, 85)
    assert row["plant"][0] == 84 and row["progress"][0] > 0.9 and row["saturated_fraction"][0] < 0.4
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.025



def test_the_circle_lqr_holds_a_plant_that_swung_its_pendulum_past_the_horizontal_chasing_a_growing_error(tmp_path):
    # Plant 398 of the shipped study: without the recovery the law's lean demand grows with the
    # cross-track and heading errors, the pendulum's torque clips on about 77 % of the samples and the
    # robot leaves the circle (about 1.5 m RMS, 0.57 of the path); the circle task's recovery (errors
    # clipped to 0.15 m and 0.15 rad) holds it to about 18 mm (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, CIRCLE_PLANTS.replace("samples = 20", "samples = 400"))))
    row = spec.run_chunk(398, 399)
    assert row["plant"][0] == 398 and row["progress"][0] > 0.9 and row["saturated_fraction"][0] < 0.3
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.025


LINE_PLANTS = CIRCLE_PLANTS.replace("on the circle", "on the line").replace('tasks = ["circle"]', 'tasks = ["line"]')


def test_the_line_lqr_holds_a_plant_whose_wander_the_3_cm_tight_gains_leave_above_the_rule(tmp_path):
    # Plant 31 of the shipped study (its sensors' seed, the filter's mismatch allowance): with the
    # tight path gains designed at 3 cm the second-half wander is 32 mm, over the 3 cm rule; the
    # line task's 2 cm gains hold it to about 27 mm (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, LINE_PLANTS.replace("samples = 20", "samples = 40"))))
    row = spec.run_chunk(31, 32)
    assert row["plant"][0] == 31 and row["progress"][0] > 0.9
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.029


def test_the_line_lqr_holds_a_plant_whose_wander_the_2_cm_tight_gains_within_10_cm_leave_far_above_the_rule(tmp_path):
    # Plant 104 of the shipped study (a slope at 0.18 of the limit across the line, c_P 5 mm off
    # in x and y): with the tight path gains at 2 cm within 10 cm of the line it wanders 74 mm RMS
    # in the second half, at 7 mm within 10 cm 60 mm, at 2 cm within 20 cm 35 mm; the line task's
    # 7 mm within 20 cm hold it to about 22 mm (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, LINE_PLANTS.replace("samples = 20", "samples = 120"))))
    row = spec.run_chunk(104, 105)
    assert row["plant"][0] == 104 and row["progress"][0] > 0.9
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.026


def test_the_line_lqr_holds_a_plant_near_its_torque_limits_by_dropping_the_tight_gains_within_2_s_of_a_clip(tmp_path):
    # Plant 84 of the shipped study (a slope at 0.22 of the limit, nearly along the line): with the
    # 7 mm tight gains falling over 10 s after a clipped torque it clips on 45 % of the samples and
    # wanders 44 mm RMS; the line task's 2 s fall holds it to about 25 mm (27 % clipped).
    spec = load_sweep(str(_sweep(tmp_path, LINE_PLANTS.replace("samples = 20", "samples = 120"))))
    row = spec.run_chunk(84, 85)
    assert row["plant"][0] == 84 and row["progress"][0] > 0.9
    assert row["success"][0] == 1 and row["cross_track_rms_m"][0] < 0.028


FIGURE8_PLANTS = CIRCLE_PLANTS.replace("on the circle", "on the figure eight").replace('tasks = ["circle"]',
                                                                                         'tasks = ["figure8"]')


def test_the_figure_eight_lqr_stays_on_a_plant_that_left_it_with_the_yokes_attitude_sized_as_elsewhere(tmp_path):
    # Plant 3 of the shipped study: with the yoke's lean and heading sized 0.1 rad the LQR left the
    # figure eight (0.79 m RMS); the figure-eight task's 0.2 rad keeps it within about 50 mm, the
    # lobes' meeting's share (docs/control.md, "Robustness over many robots").
    spec = load_sweep(str(_sweep(tmp_path, FIGURE8_PLANTS)))
    row = spec.run_chunk(3, 4)
    assert row["plant"][0] == 3 and row["progress"][0] > 0.9
    assert row["cross_track_rms_m"][0] < 0.07


WHOLE = SMALL.replace("samples = 3", "samples = 8").replace('tasks = ["line"]', 'tasks = ["line", "circle"]') \
    .replace('controllers = ["lqr"]', 'controllers = ["lqr", "lqr-slope"]')
#: Two one-controller parts of WHOLE: the same plants, its tasks in another order in one of them.
PARTS = (SMALL.replace("samples = 3", "samples = 4").replace('tasks = ["line"]', 'tasks = ["circle", "line"]')
         .replace('controllers = ["lqr"]', 'controllers = ["lqr-slope"]'),
         SMALL.replace("samples = 3", "samples = 4").replace('tasks = ["line"]', 'tasks = ["line", "circle"]'))


def _run(tmp_path, name, text):
    path, out = tmp_path / f"{name}.toml", tmp_path / name
    path.write_text(text)
    assert main(["sweep", str(path), "--out", str(out), "--scheduler", "serial", "--no-progress"]) == 0
    return path, out


@pytest.fixture(scope="module")
def combined(tmp_path_factory):
    """(the whole sweep's folder, the folder its two parts were combined into, the parts' folders)."""
    tmp = tmp_path_factory.mktemp("combine")
    whole_path, whole = _run(tmp, "whole", WHOLE)
    parts = [_run(tmp, f"part{i}", text)[1] for i, text in enumerate(PARTS)]
    out = tmp / "combined"
    assert main(["sweep", str(whole_path), "--out", str(out), "--combine", *map(str, parts)]) == 0
    return whole, out, parts, whole_path


def test_one_controllers_sweeps_combine_into_the_rows_and_summary_of_the_sweep_of_both(combined):
    import pyarrow as pa
    from runtime.sweep.robustness import from_identity
    from runtime.sweep.robustness_summary import summary_text
    whole, out, _, whole_path = combined
    rows = pq.read_table(whole / "results.parquet").to_pydict()
    summary = (whole / "summary.md").read_text()
    assert "Unfinished" not in (out / "summary.md").read_text()
    assert (out / "summary.md").read_text().replace(str(out), str(whole)) == summary   # but the --out of its reruns
    assert (out / "summary.png").stat().st_size > 0
    # the combined table itself: every row of the whole sweep, renumbered into its samples
    spec = load_sweep(str(whole_path))
    assert summary_text(pa.table(rows), spec, f"python -m runtime sweep {whole_path} --out {whole}") + "\n" == summary
    assert rows["sample"] == list(range(8)) and set(rows["controller"]) == {0, 1} and set(rows["task"]) == {0, 1}
    assert from_identity(spec.identity(), spec.name, spec.source).identity() == spec.identity()


def test_a_combination_missing_runs_is_summarised_as_unfinished(combined, tmp_path):
    whole, _, parts, whole_path = combined
    out = tmp_path / "half"
    assert main(["sweep", str(whole_path), "--out", str(out), "--combine", str(parts[1])]) == 0
    summary = (out / "summary.md").read_text()
    assert summary.startswith("Unfinished: 4 of the sweep's 8 runs.")
    assert "| line | lqr | 2 | 0 | 0 |" in summary and "| line | lqr-slope | 0 | 0 | 0 |" in summary


def test_combining_a_folder_with_an_altered_chunk_names_the_chunk_instead_of_dropping_its_runs(combined, tmp_path, capsys):
    import shutil
    _, _, parts, whole_path = combined
    copy = tmp_path / "altered"
    shutil.copytree(parts[1], copy)
    chunk = sorted((copy / "chunks").glob("*.parquet"))[0]
    chunk.write_bytes(b"not parquet")
    assert main(["sweep", str(whole_path), "--out", str(tmp_path / "o"), "--combine", str(parts[0]), str(copy)]) == 2
    err = capsys.readouterr().err
    assert chunk.name in err and "not a verified chunk" in err and "not a readable Parquet file" in err
    assert not (tmp_path / "o" / "summary.md").exists()


def test_the_figure_names_each_groups_successes_and_runs_and_an_unfinished_sweep(tmp_path):
    from runtime.sweep.robustness_summary import robustness_figure
    spec = load_sweep(str(_sweep(tmp_path)))
    rows = spec.run_chunk(0, 2)
    rows["success"] = np.array([1, 0], dtype=np.int32)
    fig = robustness_figure(rows, spec)
    assert [t.get_text() for t in fig.axes[2].get_xticklabels()] == ["line\nlqr\n1/2"]
    assert fig.get_suptitle() == "small: 2 runs on 2 plants (unfinished: 3 runs in all)"


def test_combining_a_folder_twice_or_a_sweep_of_other_plants_is_refused(combined, tmp_path, capsys):
    from runtime.sweep.robustness import from_identity, in_sweep
    _, _, parts, whole_path = combined
    assert main(["sweep", str(whole_path), "--out", str(tmp_path / "o"), "--combine", str(parts[0]),
                 str(parts[0])]) == 2
    assert "is in more than one folder" in capsys.readouterr().err
    spec = load_sweep(str(whole_path))
    other = from_identity({"robustness": {**spec.identity()["robustness"], "seed": 8}}, "other", "x")
    with pytest.raises(ValueError, match="there: its sweep's seed is 8, whole's is 7"):
        in_sweep({}, other, spec, "there")
    wider = from_identity({"robustness": {**spec.identity()["robustness"], "controllers": ["nmpc-c"]}}, "o", "x")
    with pytest.raises(ValueError, match=r"there: its controllers \['nmpc-c'\] are not among"):
        in_sweep({}, wider, spec, "there")


def test_finished_summarises_the_runs_on_disk_of_a_sweep_not_yet_merged(combined, tmp_path, capsys):
    import shutil
    _, _, parts, _ = combined
    folder = tmp_path / "part"
    shutil.copytree(parts[1], folder)
    (folder / "results.parquet").unlink()
    next((folder / "chunks").iterdir()).unlink()      # one chunk of two runs not done yet
    path = tmp_path / "part.toml"
    path.write_text(PARTS[1])
    assert main(["sweep", str(path), "--out", str(folder), "--finished"]) == 0
    assert (folder / "summary.md").read_text().startswith("Unfinished: 2 of the sweep's 4 runs.")


def test_the_summary_gives_the_runs_fifth_percentile_of_progress(tmp_path):
    from runtime.sweep.robustness_summary import summary_text
    spec = load_sweep(str(_sweep(tmp_path)))
    rows = spec.run_chunk(0, 1)
    n = 21                         # progress 0.00, 0.05, ..., 1.00: the 5th percentile is 0.05
    many = {name: np.repeat(values, n) for name, values in rows.items()}
    many["progress"] = np.linspace(0.0, 1.0, n)
    many["sample"], many["plant"] = np.arange(n), np.arange(n)
    line = next(l for l in summary_text(many, spec, "cmd").splitlines() if l.startswith("| line | lqr | 21 |"))
    assert line.split(" | ")[-3:-1] == ["0.050", "0.000"]
