"""Sweep files: every number in a fixed range, checked at load; a sweep is sized before it runs; the
CLI prints one line and exits 2 for either."""
import dataclasses
import re

import pytest

from runtime import memory
from runtime.__main__ import main
from runtime.scenario import ROBOT_RANGES, SCENARIO_RANGES
from runtime.sweep import runner
from runtime.sweep.spec import FACTOR, SWEEP_RANGES, load_sweep, quantity_range, shipped_sweeps

from .conftest import SWEEP, write_sweep


@pytest.mark.parametrize("change, key, rng", [
    (("samples = 24", "samples = 1000000001"), "samples", SWEEP_RANGES[""]["samples"]),
    (("samples_per_task = 5", "samples_per_task = 0"), "samples_per_task", SWEEP_RANGES[""]["samples_per_task"]),
    (("normal = [1.0, 0.6]", "normal = [2e6, 0.6]"), "params.m_P.normal[0]", ROBOT_RANGES["m_P"]),
    (("uniform = [0.9, 1.1]", "uniform = [0.9, 1000.5]"), "params.k_S.uniform[1]", FACTOR),
    (("values = [0.0, 0.3]", "values = [0.0, 1000.5]"), "initial.theta_P.values[1]", SCENARIO_RANGES["initial"]["theta_P"]),
    (("uniform = [0.5, 1.5]", "uniform = [0.5, 1e9]"), "torque.u_Y_scale.uniform[1]", SWEEP_RANGES["torque"]["u_Y_scale"]),
])
def test_a_sweep_number_beyond_its_range_is_refused_at_load_naming_the_key_and_range(tmp_path, change, key, rng):
    path = write_sweep(tmp_path, SWEEP.replace(*change))
    with pytest.raises(ValueError, match=rf"small.toml: {re.escape(key)}: expected {re.escape(str(rng))}, got"):
        load_sweep(path)


def test_a_normal_spread_wider_than_its_range_is_refused(tmp_path):
    path = write_sweep(tmp_path, SWEEP.replace("normal = [1.0, 0.6]", "normal = [1.0, 1000001]"))
    with pytest.raises(ValueError, match=r"params.m_P.normal\[1\]: expected a number in \[0, 1000000\] kg"):
        load_sweep(path)


def test_a_sweep_at_the_ends_of_its_ranges_loads(tmp_path):
    path = write_sweep(tmp_path, SWEEP.replace("uniform = [0.9, 1.1]", "uniform = [-1000, 1000]")
                       .replace("samples = 24", "samples = 1000000000"))
    assert load_sweep(path).samples == 10**9


@pytest.mark.parametrize("name, relative, expected", [
    ("params.J_Y_xy", False, ROBOT_RANGES["J_Y"]), ("params.c_P_z", False, ROBOT_RANGES["c_P"]),
    ("params.m_Y", False, ROBOT_RANGES["m_Y"]), ("params.m_Y", True, FACTOR),
    ("initial.w_Y", False, SCENARIO_RANGES["initial"]["w_Y"])])
def test_a_quantity_takes_the_range_of_what_it_varies(name, relative, expected):
    assert quantity_range(name, relative) == expected


@pytest.mark.parametrize("name", shipped_sweeps())
def test_every_shipped_sweep_fits_the_budget(name):
    spec = load_sweep(name)
    assert runner.check_memory(spec, spec.samples_per_task or 1000, at_once=4) < 4 * 32 * 2**20


def test_the_estimate_holds_a_torque_program_per_sample_when_a_torque_factor_varies(spec):
    no_factor = dataclasses.replace(spec, quantities=tuple(q for q in spec.quantities
                                                           if not q.name.startswith("torque.")))
    extra = runner.memory_estimate(spec, 10)["tasks"] - runner.memory_estimate(no_factor, 10)["tasks"]
    program = 10 * spec.scenario.steps * 2 * 8
    assert program <= extra < program + 1000          # (and the column of the factor)


def test_the_result_table_grows_with_the_samples(spec):
    assert runner.memory_estimate(spec.with_samples(10**9), 10)["result table"] > 10**9 * 8 * 3 * 10


def test_a_sweep_that_cannot_fit_is_refused_before_anything_is_written(spec, tmp_path, monkeypatch):
    monkeypatch.setattr(memory, "budget_bytes", lambda: 1000)
    with pytest.raises(memory.MemoryBudgetExceeded, match=r"small.toml: the run needs about .*result table"):
        runner.run_sweep(spec, tmp_path / "out", scheduler=runner.SERIAL, progress=False)
    assert not (tmp_path / "out").exists()


def test_the_sweep_cli_prints_one_line_and_exits_2_for_a_value_beyond_its_range(tmp_path, capsys):
    path = write_sweep(tmp_path, SWEEP.replace("samples_per_task = 5", "samples_per_task = 0"))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--scheduler", "serial"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "samples_per_task: expected a whole number in [1, 1000000000]" in err


def test_the_sweep_cli_prints_one_line_and_exits_2_for_a_sweep_that_cannot_fit(sweep_file, tmp_path, capsys,
                                                                               monkeypatch):
    monkeypatch.setenv("SR_MEMORY_FRACTION", "1e-12")
    assert main(["sweep", str(sweep_file), "--out", str(tmp_path / "out"), "--scheduler", "serial",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "memory budget" in err
