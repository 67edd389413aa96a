"""The benchmark runs end to end and checks every kernel's numbers before timing (no time is asserted)."""
import json

from runtime import bench


def test_bench_runs_and_checks_numbers_on_a_tiny_problem(tmp_path):
    assert bench.main(["--states", "16", "--repeats", "1", "--batch", "2000", "--no-kane", "--out", str(tmp_path)]) == 0
    result = json.loads((tmp_path / "latest.json").read_text())
    assert result["c_loop"]["accel_flops"] > 0
    assert "casadi_generated_reference_accel" in result["c_loop"]


def test_check_close_rejects_wrong_numbers():
    try:
        bench.check_close("x", [1.0, 2.0], [1.0, 2.0 + 1e-6], 1e-10)
    except bench.WrongNumbers:
        return
    raise AssertionError("a relative difference of 5e-7 passed a 1e-10 check")
