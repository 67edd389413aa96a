"""`python -m runtime sweep` (runtime/sweep/cli.py): files, exit statuses, messages."""
import json
import socket

import pyarrow.parquet as pq
import pytest

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


def one_line_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: "), err
    return err[0]


def test_a_uniform_range_whose_width_overflows_is_refused_before_anything_is_written(tmp_path, capsys):
    path = write_sweep(tmp_path, SWEEP.replace("uniform = [0.9, 1.1]", "uniform = [-1e308, 1e308]"))
    assert cli.main([str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 2
    assert f"{path}: params.k_S.uniform: the width high - low" in one_line_error(capsys)
    assert not (tmp_path / "out").exists()


def test_an_out_folder_below_a_file_is_a_usage_error_naming_the_file(sweep_file, tmp_path, capsys):
    (tmp_path / "FILE").write_text("")
    assert cli.main([str(sweep_file), "--out", str(tmp_path / "FILE" / "sub"), "--scheduler", "serial"]) == 2
    assert f"--out: {tmp_path / 'FILE'} is a file, not a folder" in one_line_error(capsys)


@pytest.mark.parametrize("address, message", [
    ("localhost:notaport", "the port 'notaport' is not a number"),
    ("tcp://localhost:0", "the port '0' is not a number from 1 to 65535"),
    ("localhost:70000", "the port '70000' is not a number from 1 to 65535"),
    ("localhost", "is not a scheduler address"),
    ("htp://localhost:8786", "unknown protocol 'htp'"),
])
def test_a_malformed_scheduler_address_is_a_usage_error(sweep_file, tmp_path, capsys, address, message):
    assert cli.main([str(sweep_file), "--out", str(tmp_path / "out"), "--scheduler", address]) == 2
    line = one_line_error(capsys)
    assert "--scheduler" in line and message in line
    assert not (tmp_path / "out").exists()


def test_an_unreachable_scheduler_is_an_environment_error_after_the_connect_timeout(sweep_file, tmp_path, capsys):
    pytest.importorskip("distributed")
    with socket.socket() as s:          # a port that nothing listens on once the socket closes
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    assert cli.main([str(sweep_file), "--out", str(tmp_path / "out"), "--scheduler", f"127.0.0.1:{port}",
                     "--connect-timeout", "1", "--no-progress"]) == 1
    assert f"--scheduler: no Dask scheduler answered at 127.0.0.1:{port} within 1 s" in one_line_error(capsys)


@pytest.mark.parametrize("argv, option", [
    (["--connect-timeout", "0"], "--connect-timeout"),
    (["--connect-timeout", "nan"], "--connect-timeout"),
    (["--samples", "many"], "--samples"),
    (["--samples-per-task", "0"], "--samples-per-task"),
    (["--workers", "100000"], "--workers"),
])
def test_bad_option_values_are_one_line_usage_errors_naming_the_option(sweep_file, tmp_path, capsys, argv, option):
    assert cli.main([str(sweep_file), "--out", str(tmp_path / "out"), "--scheduler", "serial"] + argv) == 2
    assert f"argument {option}:" in one_line_error(capsys)


def test_a_missing_out_option_is_a_one_line_usage_error(sweep_file, capsys):
    assert cli.main([str(sweep_file)]) == 2
    assert "--out" in one_line_error(capsys)


@pytest.mark.parametrize("edit, message", [
    (lambda m: m | {"samples_per_task": 0}, "sweep.json: samples_per_task: expected a whole number from 1"),
    (lambda m: m | {"samples_per_task": "5"}, "sweep.json: samples_per_task: expected a whole number from 1"),
    (lambda m: {"identity": m["identity"]}, "sweep.json is not a sweep manifest (KeyError"),
    (lambda m: [m], "sweep.json is not a sweep manifest (TypeError"),
])
def test_an_edited_manifest_is_named_with_its_key(sweep_file, tmp_path, capsys, edit, message):
    out = tmp_path / "out"
    command = [str(sweep_file), "--out", str(out), "--scheduler", "serial", "--no-progress"]
    assert cli.main(command) == 1
    manifest = out / "sweep.json"
    manifest.write_text(json.dumps(edit(json.loads(manifest.read_text()))))
    capsys.readouterr()
    assert cli.main(command) == 2
    assert message in one_line_error(capsys)
