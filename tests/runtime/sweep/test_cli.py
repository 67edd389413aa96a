"""`python -m runtime sweep` (runtime/sweep/cli.py): files, exit statuses, messages."""
import pyarrow.parquet as pq

from runtime.sweep import cli

from .conftest import SWEEP, write_sweep


def test_cli_writes_results_figure_and_percentiles_and_exits_1_when_samples_failed(sweep_file, tmp_path):
    out = tmp_path / "out"
    assert cli.main([str(sweep_file), "--out", str(out), "--scheduler", "serial", "--no-progress"]) == 1
    assert pq.read_table(out / "results.parquet").num_rows == 24
    assert (out / "summary.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "samples ran to the end" in (out / "percentiles.md").read_text()


def test_cli_exits_0_when_every_sample_ran_and_takes_the_sample_count(tmp_path):
    path = write_sweep(tmp_path, SWEEP.replace("normal = [1.0, 0.6]", "uniform = [0.9, 1.1]"))
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out), "--samples", "6", "--scheduler", "serial", "--no-progress"]) == 0
    assert pq.read_table(out / "results.parquet").column("sample").to_pylist() == list(range(6))


def test_cli_reports_a_bad_sweep_file_with_exit_2(tmp_path, capsys):
    path = write_sweep(tmp_path, SWEEP.replace("seed = 7", "seed = 'x'"))
    assert cli.main([str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 2
    assert "seed: expected a non-negative integer" in capsys.readouterr().err


def test_cli_refuses_a_non_positive_worker_count(sweep_file, tmp_path, capsys):
    assert cli.main([str(sweep_file), "--out", str(tmp_path / "out"), "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err
