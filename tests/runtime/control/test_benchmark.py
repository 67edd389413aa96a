"""`python -m runtime control`: one table for every task, a summary.json with `tracking` per run."""
import csv
import json

from runtime.__main__ import main
from runtime.control.benchmark import COLUMNS


def test_the_benchmark_writes_one_table_row_and_one_summary_per_task_and_controller(tmp_path):
    assert main(["control", "--out", str(tmp_path), "--tasks", "speed-step,circle", "--duration", "1"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "table.csv")))
    assert [(r["task"], r["controller"]) for r in rows] == [
        ("speed-step", "pid"), ("speed-step", "lqr"), ("speed-step", "nmpc"),
        ("circle", "pid"), ("circle", "lqr"), ("circle", "nmpc")]
    table = (tmp_path / "table.md").read_text()
    assert "smoke run" in table and "CPU:" in table
    for run in ("speed-step-pid", "speed-step-lqr", "speed-step-nmpc", "circle-pid", "circle-lqr", "circle-nmpc"):
        summary = json.loads((tmp_path / run / "summary.json").read_text())
        assert set(summary["tracking"]) == set(COLUMNS)
        assert (tmp_path / run / "tracking.png").stat().st_size > 0
