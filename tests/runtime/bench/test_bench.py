"""The benchmark runs end to end and checks every kernel's numbers before timing (no time is asserted)."""
import json

import numpy as np

from runtime.bench import baselines, checks, cli
from runtime.model import Model
from runtime.params import Params
from runtime.state import initial_state


def test_bench_runs_and_checks_numbers_on_a_tiny_problem(tmp_path):
    args = ["--states", "16", "--repeats", "1", "--batch", "2000", "--no-kane", "--loop-steps", "20"]
    assert cli.main([*args, "--out", str(tmp_path)]) == 0
    result = json.loads((tmp_path / "latest.json").read_text())
    assert result["c_loop"]["accel_flops"] > 0
    assert "casadi_generated_reference_accel" in result["c_loop"]
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
