"""`python -m runtime bench-table`: the quoted tables compare like with like, and the command
refuses a file that is not a run of `make bench`."""
import copy
import json

import pytest

from runtime.bench import headline


@pytest.fixture(scope="module")
def run():
    return json.loads(headline.REFERENCE.read_text())


def row(markdown, start):
    lines = [line for line in markdown.splitlines() if line.startswith(f"| {start}")]
    assert len(lines) == 1, (start, lines)
    return [cell.strip() for cell in lines[0].strip("|").split("|")]


def test_the_c_baseline_is_the_fastest_kane_model_build(run):
    faster = copy.deepcopy(run)
    faster["c_loop"]["kane_pydy_c_accel"]["ns"] = 100.0
    cells = row(headline.headline(faster), "strongest C baseline")
    assert "PyDy" in cells[0] and cells[1] == "100 ns"


def test_the_verification_models_are_never_the_strongest_baseline(run):
    fast_reference = copy.deepcopy(run)
    fast_reference["c_loop"]["casadi_generated_reference_accel"]["ns"] = 1.0
    fast_reference["python"]["casadi_python_accel_ns"] = 1.0
    table = headline.headline(fast_reference)
    assert "KKT" not in row(table, "strongest C baseline")[0]
    assert "KKT" not in row(table, "strongest Python-call baseline")[0]


def test_the_python_baseline_is_divided_by_a_python_call(run):
    slower_call = copy.deepcopy(run)
    slower_call["python"]["python_model_accel_ns"] *= 2
    before = float(row(headline.headline(run), "strongest Python-call baseline")[2].split("×")[0].replace(",", ""))
    after = float(row(headline.headline(slower_call), "strongest Python-call baseline")[2].split("×")[0].replace(",", ""))
    assert after == pytest.approx(before / 2, rel=0.02)


def test_the_caption_names_the_file_and_the_cpu(run):
    first = headline.headline(run, "bench/results/some-run.json").splitlines()[0]
    assert "`bench/results/some-run.json`" in first and f"CPU {run['cpu']}" in first


def test_write_replaces_only_the_marked_block():
    text = "before\n<!-- bench-table:headline -->\nold\n<!-- /bench-table -->\nafter\n"
    assert headline.replace_block(text, "headline", "new") == (
        "before\n<!-- bench-table:headline -->\nnew\n<!-- /bench-table -->\nafter\n")
    with pytest.raises(ValueError, match="no <!-- bench-table:performance -->"):
        headline.replace_block(text, "performance", "new")


def test_a_file_that_is_not_a_bench_run_is_refused_by_name(tmp_path, capsys):
    other = tmp_path / "other.json"
    other.write_text('{"date": "x"}')
    with pytest.raises(SystemExit) as exit_:
        headline.main(["--reference", str(other)])
    assert exit_.value.code == 2
    assert "--reference" in capsys.readouterr().err


def test_a_missing_reference_is_refused_by_name(tmp_path, capsys):
    with pytest.raises(SystemExit):
        headline.main(["--reference", str(tmp_path / "missing.json")])
    assert "--reference: cannot read" in capsys.readouterr().err
