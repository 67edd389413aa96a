"""Every number of a scenario, robot, task or sweep file has a fixed range (runtime/schema.py
`Range`), declared once per file kind, checked when the file loads, and listed in
docs/robustness.md: a value that is finite but absurd (a lobe of 1e-12 m, 1e9 iterations) is a
named error at load, never a hang or an exhausted memory at run time."""
import copy
import math
import os
import re

import pytest

from conftest import ROOT
from runtime.control.task import TASK_RANGES, parse_task
from runtime.params import NAMES as PARAM_NAMES
from runtime.params import PAPER_NAMES, SHAPES
from runtime.scenario import ROBOT_RANGES, SCENARIO_RANGES, parse_scenario
from runtime.schema import check_range, ranges_markdown
from runtime.sensor_set import SENSOR_RANGES
from runtime.sweep.spec import FACTOR, SWEEP_RANGES

DOC = ROOT / "docs" / "robustness.md"
BEGIN, END = "<!-- ranges: begin (generated) -->", "<!-- ranges: end -->"


def documented_ranges():
    """The ranges section of docs/robustness.md, generated from the declarative tables."""
    parts = [("Scenario files", {k: v for k, v in SCENARIO_RANGES.items() if k != "params"}),
             ("Robot files, `[params]` of scenario files, `[plant]` of task files", {"": ROBOT_RANGES}),
             ("Task files (beyond their scenario's keys)", TASK_RANGES),
             ("Sensor sets (`[sensors]` of scenario, task and sensors files)",
              {f"sensors.{table}": ranges for table, ranges in SENSOR_RANGES.items()}),
             ("Sweep files (a quantity's numbers: a parameter's as robot files, `relative`: a factor)",
              {**SWEEP_RANGES, "relative = true": {"values, uniform, normal mean": FACTOR}})]
    return "\n\n".join(f"{title}:\n\n{ranges_markdown(sections)}" for title, sections in parts)


def every_range():
    tables = {"scenario": SCENARIO_RANGES, "task": TASK_RANGES, "sweep": SWEEP_RANGES, "sensors": SENSOR_RANGES}
    return [pytest.param(rng, id=f"{kind}:{section}.{key}") for kind, sections in tables.items()
            for section, ranges in sections.items() for key, rng in ranges.items()]


def inside_ends(rng):
    return [math.nextafter(rng.low, math.inf) if rng.open_low else rng.low, rng.high]


def outside_ends(rng):
    if rng.whole:
        return [rng.low - 1, rng.high + 1]
    low = rng.low if rng.open_low else rng.low - max(abs(rng.low), 1.0) * 1e-9
    return [low, rng.high + max(abs(rng.high), 1.0) * 1e-9]


@pytest.mark.parametrize("rng", every_range())
def test_each_range_accepts_its_ends(rng):
    for value in inside_ends(rng):
        assert check_range(value, rng, "f: key") == value


@pytest.mark.parametrize("rng", every_range())
def test_each_range_refuses_just_beyond_its_ends_naming_the_key_and_the_range(rng):
    for value in outside_ends(rng):
        with pytest.raises(ValueError, match=rf"^f: key: expected {re.escape(str(rng))}, got "):
            check_range(value, rng, "f: key")


@pytest.mark.parametrize("rng", [p.values[0] for p in every_range() if p.values[0].whole])
def test_a_whole_range_refuses_a_fraction(rng):
    with pytest.raises(ValueError, match="expected a whole number"):
        check_range(rng.low + 0.5, rng, "f: key")


# -- every numeric key has a range ------------------------------------------------------------
def test_every_parameter_of_a_robot_has_a_range():
    assert set(ROBOT_RANGES) == set(PARAM_NAMES) | set(PAPER_NAMES)


def test_every_numeric_key_of_a_task_file_has_a_range():
    from runtime.control.estimator import SETTING_NAMES
    from runtime.control.task import _NOISE_KEYS, _REFERENCE_KEYS, AVAILABLE_CONTROLLERS
    assert set(TASK_RANGES["reference"]) == _REFERENCE_KEYS - {"kind"}
    for kind, (_, _, names) in AVAILABLE_CONTROLLERS.items():
        assert set(TASK_RANGES[f"controller.{kind}"]) == set(names), kind
    assert set(TASK_RANGES["estimator"]) == set(SETTING_NAMES)
    assert set(TASK_RANGES["plant"]) == set(ROBOT_RANGES) | set(_NOISE_KEYS)


def test_every_numeric_key_of_a_scenario_file_has_a_range():
    from runtime.scenario import _INITIAL_KEYS, _TORQUE_KEYS
    assert set(SCENARIO_RANGES[""]) == {"dt", "steps", "duration", "friction"}
    assert set(SCENARIO_RANGES["initial"]) == _INITIAL_KEYS
    assert set(SCENARIO_RANGES["torque"]) == _TORQUE_KEYS


# -- scenario and robot files: every key checked at load ----------------------------------------
SCENARIO = {"dt": 0.01, "steps": 10, "params": {"preset": "paper_simulation"}, "initial": {},
            "torque": [{"from_step": 1, "to_step": 5, "u_Y": 0.1}, {"from_time": 0.0, "to_time": 0.05, "u_P": 0.1}]}


def _entry(shape, value):
    """`value` as the first entry of a number, vector or matrix of `shape`."""
    if shape == (3,):
        return [value, 0.0, 0.0]
    if shape == (3, 3):
        return [[value, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    return value


SCENARIO_SHAPES = {"q": (3,), "w_S": (3,), "R_S": (3, 3), "R_Y": (3, 3), "R_P": (3, 3), **SHAPES}


def scenario_with(section, key, value):
    data = copy.deepcopy(SCENARIO)
    value = _entry(SCENARIO_SHAPES.get(key, ()), value)
    if section == "":
        data.pop("steps" if key == "duration" else "", None)
        data[key] = value
    elif section == "torque":
        data["torque"][0 if key.endswith("_step") else 1][key] = value
    elif section == "initial" and key == "q":
        data["initial"]["q"] = [value, 0.0, 0.3]
    else:
        data[section][key] = value
    return data


@pytest.mark.parametrize("section, key", [(s, k) for s, ranges in SCENARIO_RANGES.items() for k in ranges])
def test_a_scenario_value_beyond_its_range_is_a_named_error_at_load(section, key):
    rng = SCENARIO_RANGES[section][key]
    for value in outside_ends(rng):
        with pytest.raises(ValueError, match=rf"^f.toml: .*{key}"):
            parse_scenario(scenario_with(section, key, value), "f.toml")


def test_a_scenario_at_the_ends_of_its_ranges_loads():
    data = copy.deepcopy(SCENARIO)
    data["initial"] = {"w_S": [1e3, -1e3, 0.0], "w_Y": 1e3, "w_P": -1e3, "theta_Y": 1e3, "q": [1e6, -1e6, 0.3]}
    data["torque"][0].update(u_Y=1e3, u_P=-1e3)
    data["dt"] = 1.0
    assert parse_scenario(data, "f.toml").dt == 1.0


def test_a_robot_file_value_beyond_its_range_names_the_file_and_key(tmp_path):
    (tmp_path / "robot.toml").write_text("m_Y = 2e6\n")
    (tmp_path / "s.toml").write_text('dt = 0.01\nsteps = 10\n[params]\nrobot = "robot.toml"\n')
    from runtime.scenario import load_scenario
    with pytest.raises(ValueError, match=r"robot.toml: m_Y: expected a number in \[0, 1000000\] kg, got 2000000.0"):
        load_scenario(tmp_path / "s.toml")


def test_the_shipped_infeasible_scenario_still_loads():
    from runtime.scenario import load_scenario, shipped_scenarios
    assert "ramp-too-steep" in shipped_scenarios()
    for name in shipped_scenarios():
        load_scenario(name)


# -- the documentation ---------------------------------------------------------------------------
def test_docs_robustness_lists_the_ranges_of_the_tables():
    """SR_UPDATE_DOCS=1 rewrites the section from the tables."""
    text = DOC.read_text()
    head, rest = text.split(BEGIN)
    _, tail = rest.split(END)
    current = f"{BEGIN}\n{documented_ranges()}\n{END}"
    if os.environ.get("SR_UPDATE_DOCS") == "1":
        DOC.write_text(head + current + tail)
    assert f"{BEGIN}{rest.split(END)[0]}{END}" == current, "docs/robustness.md: rerun with SR_UPDATE_DOCS=1"


# -- the same ranges for the Python constructors, the command line's overrides and batch runs --------
from runtime import Params, simulate_many, initial_state                       # noqa: E402
from runtime.control.estimator import EkfSettings                               # noqa: E402
from runtime.control.lqr import LqrGains                                        # noqa: E402
from runtime.control.nmpc import NmpcGains                                      # noqa: E402
from runtime.control.pid import Pid, PidGains                                   # noqa: E402
from runtime.control.ranges import (CONTROLLER_RANGES, ESTIMATOR_RANGES, LQR_RANGES, NMPC_RANGES,  # noqa: E402
                                    PID_RANGES)
from runtime.memory import MemoryBudgetExceeded                                 # noqa: E402
from runtime.scenario import MAX_STEPS, load_scenario                           # noqa: E402

SETTINGS_CLASSES = {"pid": (PidGains, PID_RANGES), "lqr": (LqrGains, LQR_RANGES), "nmpc": (NmpcGains, NMPC_RANGES),
                    "estimator": (EkfSettings, ESTIMATOR_RANGES)}
SETTINGS_CASES = [pytest.param(kind, key, id=f"{kind}.{key}") for kind, (_, ranges) in SETTINGS_CLASSES.items()
                  for key in ranges]


def test_the_task_files_and_the_constructors_share_one_table():
    assert TASK_RANGES["controller"] is CONTROLLER_RANGES
    assert TASK_RANGES["controller.pid"] is PID_RANGES and TASK_RANGES["controller.lqr"] is LQR_RANGES
    assert TASK_RANGES["controller.nmpc"] is NMPC_RANGES and TASK_RANGES["estimator"] is ESTIMATOR_RANGES


@pytest.mark.parametrize("kind, key", SETTINGS_CASES)
def test_a_constructor_refuses_a_setting_beyond_its_range_naming_the_argument(kind, key):
    cls, ranges = SETTINGS_CLASSES[kind]
    rng = ranges[key]
    for value in outside_ends(rng):
        with pytest.raises(ValueError, match=rf"^{key}: expected {re.escape(str(rng))}, got "):
            cls(**{key: value})


@pytest.mark.parametrize("kind", SETTINGS_CLASSES)
def test_a_constructor_refuses_a_setting_that_is_not_a_finite_number(kind):
    cls, ranges = SETTINGS_CLASSES[kind]
    key = next(iter(ranges))
    for value in ("1", None, True, math.nan, math.inf):
        with pytest.raises(ValueError, match=rf"^{key}: expected "):
            cls(**{key: value})


@pytest.mark.parametrize("key", CONTROLLER_RANGES)
def test_a_controller_refuses_a_rate_or_torque_limit_beyond_its_range(key):
    for value in outside_ends(CONTROLLER_RANGES[key]):
        with pytest.raises(ValueError, match=rf"^{key}: expected "):
            Pid(Params(), **{key: value})


def test_the_command_lines_overrides_get_the_scenario_files_ranges():
    scenario = load_scenario("tilted-pendulum")
    for dt in (2.0, 1e-10):
        with pytest.raises(ValueError, match=r"override: dt: expected a number in \[1e-09, 1\] s, got "):
            scenario.with_overrides(dt=dt)
    with pytest.raises(ValueError, match=r"override: dt and steps: the duration steps × dt: expected "):
        scenario.with_overrides(dt=1.0, steps=MAX_STEPS)
    assert scenario.with_overrides(dt=1.0, steps=10).steps == 10


def test_simulate_many_refuses_trajectories_beyond_the_memory_budget(monkeypatch):
    x0 = initial_state()
    monkeypatch.setenv("SR_MEMORY_FRACTION", "1e-12")
    with pytest.raises(MemoryBudgetExceeded, match=r"^trajectories: the run needs about .*\(3 trajectories of 11 states"):
        simulate_many(Params(), [x0] * 3, 0.01, 10, trajectories=True)
    assert simulate_many(Params(), [x0] * 3, 0.01, 10).status.tolist() == [0, 0, 0]   # no trajectories kept
    monkeypatch.delenv("SR_MEMORY_FRACTION")
    assert simulate_many(Params(), [x0] * 3, 0.01, 10, trajectories=True).trajectories.shape == (3, 11, 35)
