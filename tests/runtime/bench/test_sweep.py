"""`python -m runtime sweep-bench` (runtime/bench/sweep.py) runs end to end on a tiny sweep and keeps
each run in its own file (the numbers themselves belong to `make bench`, not to a test)."""
import json

from runtime.bench import sweep as sweep_bench


def test_sweep_bench_writes_a_result_file_per_run_with_the_cpu_and_the_model(tmp_path, capsys):
    args = ["--samples", "4", "--samples-per-task", "2", "--noop-tasks", "5", "--rounds", "1",
            "--out", str(tmp_path), "--quiet"]
    assert sweep_bench.main(args) == 0
    files = list(tmp_path.iterdir())
    assert len(files) == 1 and files[0].suffix == ".json"
    result = json.loads(files[0].read_text())
    assert result["cpu"] and result["measured"]["tasks"] == 2
    assert result["derived"]["speedup_2_vs_1_workers"] > 0
    assert result["derived"]["model_1e6_on_64"]["tasks"] >= 1
    assert "simulations/s" in capsys.readouterr().out
