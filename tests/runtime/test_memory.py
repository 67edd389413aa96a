"""runtime/memory.py: a run's memory is estimated from its inputs before it allocates anything, and a
run that cannot fit the budget (SR_MEMORY_FRACTION of the available memory) is refused by name."""
import pytest

from runtime import memory, scenario
from runtime.scenario import load_scenario, run_scenario, shipped_scenarios
from runtime.scenarios import cli as scenario_cli


def test_parts_within_the_budget_give_their_total():
    assert memory.check("f.toml", {"a": 100, "b": 50}, budget=150) == 150


def test_parts_beyond_the_budget_are_refused_naming_the_file_total_and_largest_parts():
    with pytest.raises(memory.MemoryBudgetExceeded,
                       match=r"^f.toml: the run needs about 3 GiB \(trajectory 2 GiB, path table 1 GiB\), more than "
                             r"the memory budget of 1 GiB;") as caught:
        memory.check("f.toml", {"trajectory": 2 * 2**30, "path table": 2**30}, budget=2**30)
    assert isinstance(caught.value, ValueError) and caught.value.needed == 3 * 2**30


def test_the_budget_is_the_configured_fraction_of_the_available_memory(monkeypatch):
    monkeypatch.setattr(memory, "available_bytes", lambda: 8 * 2**30)
    assert memory.budget_bytes() == 4 * 2**30
    monkeypatch.setenv("SR_MEMORY_FRACTION", "0.25")
    assert memory.budget_bytes() == 2 * 2**30


@pytest.mark.parametrize("text", ["0", "1.5", "half", "nan"])
def test_a_bad_fraction_is_a_named_error(monkeypatch, text):
    monkeypatch.setenv("SR_MEMORY_FRACTION", text)
    with pytest.raises(ValueError, match=rf"SR_MEMORY_FRACTION: expected a number in \(0, 1\], got '{text}'"):
        memory.budget_bytes()


def test_the_available_memory_is_read_from_the_machine():
    assert memory.available_bytes() > 2**20


def test_a_trajectory_is_steps_plus_one_rows_of_35_states_torques_and_energy():
    assert memory.trajectory_bytes(9) == 10 * (35 * 8 + 2 * 2 * 8 + 8)


@pytest.mark.parametrize("name", shipped_scenarios())
def test_every_shipped_scenario_fits_the_budget(name):
    assert scenario.check_memory(load_scenario(name)) < 8 * 2**20


def test_the_longest_scenario_is_refused_on_a_small_machine_before_the_run(monkeypatch):
    longest = load_scenario("t-shape").with_overrides(steps=scenario.MAX_STEPS)
    monkeypatch.setattr(memory, "available_bytes", lambda: 4 * 2**30)
    monkeypatch.setattr(scenario, "Model", lambda *a: pytest.fail("the run started"))
    with pytest.raises(memory.MemoryBudgetExceeded, match=r"t-shape.toml: the run needs about 3.2 GiB \(trajectory 2.98 GiB, contact force 229 MiB\)"):
        run_scenario(longest)


def test_the_run_cli_prints_one_line_and_exits_2_for_a_run_that_cannot_fit(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SR_MEMORY_FRACTION", "1e-9")
    assert scenario_cli.main(["t-shape", "--out", str(tmp_path), "--no-gif", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "memory budget" in err
    assert not (tmp_path / "t-shape" / "trajectory.csv").exists()


def test_the_run_cli_prints_one_line_and_exits_2_for_a_value_beyond_its_range(tmp_path, capsys):
    path = tmp_path / "fast.toml"
    path.write_text("dt = 0.01\nsteps = 10\n[initial]\nw_Y = 1e9\n")
    assert scenario_cli.main([str(path), "--out", str(tmp_path / "out"), "--no-gif", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "initial.w_Y: expected a number in [-1000, 1000] rad/s" in err
