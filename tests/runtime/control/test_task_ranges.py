"""Task files: values that are finite and positive but absurd are named errors at load (they would
hang or exhaust the memory at run time), a run is sized before it starts, and `python -m runtime
control` prints one line and exits 2 for either."""
import copy
import re
import tomllib

import pytest

from runtime import memory
from runtime.__main__ import main
from runtime.control import benchmark
from runtime.control.task import PATH_ROW_BYTES, TASK_RANGES, load_task, parse_task, shipped_tasks, task_dir

CIRCLE = tomllib.loads((task_dir() / "circle.toml").read_text())     # controllers: pid, lqr, nmpc


def circle_with(change):
    data = copy.deepcopy(CIRCLE)
    change(data)
    return data


ABSURD = {
    "figure eight of 1e-12 m": (lambda d: d["reference"].update(kind="figure8", size=1e-12), "reference.size"),
    "1e9 NMPC iterations": (lambda d: d["controller"][2].update(iterations=1e9), "controller[2].iterations"),
    "circle of 1e7 m": (lambda d: d["reference"].update(radius=1e7), "reference.radius"),
    "waypoint at 1e9 m": (lambda d: d["reference"].update(kind="waypoints", points=[[1e9, 0.0]]),
                          r"reference.points[0][0]"),
    "1e12 LQR speeds": (lambda d: d["controller"][1].update(n_speeds=1e12), "controller[1].n_speeds"),
    "NMPC horizon 1e12": (lambda d: d["controller"][2].update(horizon=1e12), "controller[2].horizon"),
    "NMPC node_periods 1e12": (lambda d: d["controller"][2].update(node_periods=1e12), "controller[2].node_periods"),
    "u_max 1e200": (lambda d: d["controller"][0].update(u_max=1e200), "controller[0].u_max"),
    "NMPC slope estimate over 1e9 s": (lambda d: d["controller"][2].update(slope_estimate_s=1e9),
                                       "controller[2].slope_estimate_s"),
}


@pytest.mark.parametrize("change, key", ABSURD.values(), ids=ABSURD.keys())
def test_an_absurd_value_is_refused_at_load_naming_the_file_key_and_range(change, key):
    with pytest.raises(ValueError, match=rf"^f.toml: {re.escape(key)}: expected a (whole )?number in [\[(]"):
        parse_task(circle_with(change), "f.toml")


SECTIONS = {"reference": lambda d, k, v: d["reference"].update(
                {"kind": {"radius": "circle", "size": "figure8", "points": "waypoints", "offset": "line",
                          "heading": "heading"}.get(k, "circle"), "size": 2.0, "offset": 0.5, "heading": 0.0,
                 "points": [[3.0, 0.0]], k: [[v, 0.0]] if k == "points" else v}),
            "controller": lambda d, k, v: d["controller"][0].update({k: v}),
            "controller.pid": lambda d, k, v: d["controller"][0].update({k: v}),
            "controller.lqr": lambda d, k, v: d["controller"][1].update({k: v}),
            "controller.nmpc": lambda d, k, v: d["controller"][2].update({k: v}),
            "controller.nmpc-c": lambda d, k, v: d["controller"][2].update({"kind": "nmpc-c", k: v}),
            "estimator": lambda d, k, v: d.update(estimator={"kind": "ekf", k: v}),
            "plant": lambda d, k, v: d.update(plant={k: [v, 0.0, 0.0] if k in ("c_Y", "c_P") else
                                                     [[v, 0, 0], [0, 1, 0], [0, 0, 1]] if k in ("J_Y", "J_P")
                                                     else v})}


def _beyond(rng):
    return rng.high + 1 if rng.whole else rng.high * (1 + 1e-9) + 1e-9


@pytest.mark.parametrize("section, key", [(s, k) for s, ranges in TASK_RANGES.items() for k in ranges])
def test_every_task_value_beyond_its_range_is_refused_at_load(section, key):
    rng = TASK_RANGES[section][key]
    data = circle_with(lambda d: SECTIONS[section](d, key, _beyond(rng)))
    with pytest.raises(ValueError, match=rf"^f.toml: .*{re.escape(key)}"):
        parse_task(data, "f.toml")


def test_a_task_at_the_ends_of_the_reference_ranges_loads():
    task = parse_task(circle_with(lambda d: d["reference"].update(kind="figure8", size=0.05, speed=10.0)), "f.toml")
    assert task.reference_spec["size"] == 0.05


@pytest.mark.parametrize("name", shipped_tasks())
def test_every_shipped_task_loads_and_fits_the_memory_budget(name):
    task = load_task(name)
    assert 0 < task.check_memory() < 64 * 2**20


@pytest.mark.parametrize("name", ["circle", "figure8", "line", "square"])
def test_the_path_table_estimate_counts_the_samples_the_path_is_built_with(name):
    task = load_task(name)
    built = len(task.reference().points)
    assert built <= task.memory_estimate()["path table"] / PATH_ROW_BYTES <= 1.01 * built + 2


def test_a_task_that_cannot_fit_is_refused_before_anything_is_built(monkeypatch):
    task = load_task("figure8")
    monkeypatch.setattr(type(task), "reference", lambda self: pytest.fail("the run started"))
    with pytest.raises(memory.MemoryBudgetExceeded, match=r"figure8.toml: the run needs about .* \(trajectory .*, path table .*\), more than the memory budget of 1 MiB;"):
        task.check_memory(budget=2**20)
    monkeypatch.setattr(memory, "budget_bytes", lambda: 2**20)
    with pytest.raises(memory.MemoryBudgetExceeded):
        benchmark.run_task(task)


def test_the_control_cli_prints_one_line_and_exits_2_for_an_absurd_value(tmp_path, capsys):
    path = tmp_path / "tiny.toml"
    path.write_text((task_dir() / "figure8.toml").read_text().replace("size = 2.0", "size = 1e-12"))
    assert main(["control", "--out", str(tmp_path / "out"), "--tasks", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "reference.size" in err and "[0.05, 1000]" in err


def test_the_control_cli_refuses_a_run_that_cannot_fit_before_the_first_run(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(memory, "budget_bytes", lambda: 2**20)
    monkeypatch.setattr(benchmark, "simulate_closed_loop", lambda *a, **k: pytest.fail("a run started"))
    assert main(["control", "--out", str(tmp_path), "--tasks", "speed-step"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "memory budget" in err and "speed-step.toml" in err
