"""The benchmark runs end to end and checks every kernel's numbers before timing (no time is asserted)."""
import json

import numpy as np

from runtime.bench import baselines, checks, cli, harness, report
from runtime.model import Model
from runtime.params import Params
from runtime.state import initial_state
from runtime.verification.sampling import random_inputs, random_states


def test_bench_runs_and_checks_numbers_on_a_tiny_problem(tmp_path):
    # The step anatomy has its own tests below; built here again it would double this test's time.
    args = ["--states", "16", "--repeats", "1", "--batch", "2000", "--no-kane", "--loop-steps", "20",
            "--skip", "step-anatomy"]
    assert cli.main([*args, "--out", str(tmp_path)]) == 0
    [written] = tmp_path.glob("*.json")
    result = json.loads(written.read_text())
    assert written.name == report.result_file_name(result["date"])
    assert result["c_loop"]["accel_flops"] > 0
    assert "casadi_generated_reference_accel" in result["c_loop"]
    assert result["skipped"] == ["step-anatomy"] and "step_anatomy" not in result and "ekf_sample" in result
    assert set(result["python"]["lie_euler_loop_ms"]) == {
        "ours: Model.accel", "NumPy paper formulas", "CasADi reference from Python"}


def test_python_lie_euler_loop_reproduces_the_c_lie_euler_trajectory():
    model = Model(Params.paper_simulation())
    u, x0 = baselines.t_shape_program()[:300], initial_state()
    expected = model.simulate(x0, 0.01, 300, u, method="lie-euler")[-1]
    final = baselines.lie_euler_loop(model.accel, x0, 0.01, u, model.params.r)
    assert np.abs(final - expected).max() < 1e-13
    assert np.abs(final - model.simulate(x0, 0.01, 300, u, method="rkmk4")[-1]).max() > 1e-6


def test_check_close_rejects_wrong_numbers():
    try:
        checks.check_close("x", [1.0, 2.0], [1.0, 2.0 + 1e-6], 1e-10)
    except checks.WrongNumbers:
        return
    raise AssertionError("a relative difference of 5e-7 passed a 1e-10 check")


def test_every_run_is_kept_in_its_own_file_and_none_is_overwritten(tmp_path):
    run = {"date": "2026-11-23T22:10:05", "cpu": "test"}
    first = report.write_results(run, tmp_path)
    second = report.write_results({**run, "cpu": "other"}, tmp_path)
    assert first.name == "2026-11-23T22-10-05.json" and second.name == "2026-11-23T22-10-05-2.json"
    assert json.loads(first.read_text())["cpu"] == "test"
    assert {p.name for p in tmp_path.iterdir()} == {first.name, second.name}   # no temporary left


def test_call_overhead_timings_check_the_raw_calls_and_time_both_sides():
    model = Model(Params.paper_simulation())
    rng = np.random.default_rng(3)
    X, U = random_states(rng, 4, model.params), random_inputs(rng, 4)
    out = baselines.call_overhead_timings(model, list(zip(X, U)), min_seconds=1e-4, rounds=1)
    assert set(out) == {"python_model_accel_ns", "raw_cffi_accel_ns", "python_model_step_lie-euler_ns",
                        "raw_cffi_step_lie-euler_ns", "python_model_step_rkmk4_ns", "raw_cffi_step_rkmk4_ns"}
    assert all(v > 0 for v in out.values())


def test_a_stored_run_renders_as_the_readmes_markdown_tables(capsys):
    stored = sorted((cli.RESULTS).glob("2026-11-23T22-24-32.json"))[0]
    assert cli.main(["--markdown", str(stored)]) == 0
    text = capsys.readouterr().out
    for title in ("**C against C", "**Python call against Python call", "**Batches"):
        assert title in text
    assert "| Kane model, CasADi C: M, F and ca.solve (what a CasADi user ships) |" in text
    assert text.rstrip().splitlines()[-1].startswith("targets: accel <= 150 ns: met")


def test_step_anatomy_stubs_the_dynamics_in_its_glue_only_build_and_nowhere_else(tmp_path):
    params = Params.paper_simulation()
    rng = np.random.default_rng(5)
    X, U = random_states(rng, 8, params), random_inputs(rng, 8)
    out = harness.step_anatomy(tmp_path, harness.write_input(tmp_path / "input.bin", params, X, U), 1)
    full, glue = out["full"], out["glue_only"]
    for key in ("accel", "accels_chained_through_nu", "accels_chained_through_state"):
        assert full[f"{key}_sink"] == glue[f"{key}_sink"]      # the real kernel in both builds
    for key in ("step_rkmk4", "step_cf4"):
        assert full[f"{key}_sink"] != glue[f"{key}_sink"]      # the steps' dynamics stubbed
        assert full[key] > 0 and glue[key] > 0


def test_step_anatomy_section_reports_what_six_times_one_accel_leaves_besides_the_accelerations():
    anatomy = {"full": {"accel": 40.0, "accels_chained_through_nu": 180.0, "accels_chained_through_state": 200.0,
                        "step_rkmk4": 340.0, "step_cf4": 350.0},
               "glue_only": {"step_rkmk4": 220.0, "step_cf4": 230.0}}
    title, rows = report.anatomy_section(anatomy)
    assert title.startswith("Anatomy of a fourth-order step")
    assert rows[-1][1:] == ("60.0 ns", "1.50x")                 # 6 x 40 - 180
    assert ("rkmk4 step with the dynamics stubbed: check, group action, kinematics, tableau", "220.0 ns",
            "5.50x") in rows
