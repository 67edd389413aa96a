"""The closed-loop firmware example (c/examples/firmware_lqr.c) equals the Python closed loop of the
same task bit for bit (double build, host), and its gain table, generated/lqr_task.h (written by
`make generate`), is the current design within the spread of LAPACK builds."""
import dataclasses
import pathlib
import re
import shutil
import subprocess
import tempfile

import numpy as np
import pytest

from conftest import ROOT
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.firmware import header, write_header
from runtime.control.firmware import firmware_task, slope_task, write_slope_vector

C_DIR = ROOT / "c"
SHIPPED = ROOT / "generated" / "lqr_task.h"
#: How far the checked-in table may be from a fresh design: LAPACK builds differ in the last bits
#: of the Riccati solution (about 1e-8 relative across CPUs); a change of the design moves it by far more.
RTOL, ATOL = 1e-7, 1e-10
MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(not (MAKE and shutil.which("cc")), reason="needs make and a C compiler")


def build_and_run(header_dir, build_dir):
    exe = build_dir / "firmware_lqr"
    subprocess.run([MAKE, "-s", "-C", str(C_DIR), f"BUILD={build_dir}",
                    f"CPPFLAGS=-DLQR_TASK_FROM_INCLUDE_PATH -I{header_dir}", str(exe)],
                   check=True, capture_output=True, text=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return np.loadtxt(out.splitlines()[1:], delimiter=",")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(firmware rows, Python closed-loop result, header text, build dir, controller) of the default task."""
    tmp = tmp_path_factory.mktemp("firmware")
    task, controller = write_header(tmp / "lqr_task.h")
    rows = build_and_run(tmp, tmp / "build")
    result = simulate_closed_loop(task.plant_params, controller, task.reference(), task.scenario.x0,
                                  task.duration, task.scenario.dt, task.scenario.method)
    return rows, result, (tmp / "lqr_task.h").read_text(), tmp, controller


def test_the_firmware_closed_loop_equals_the_python_closed_loop_bit_for_bit(runs):
    rows, result, *_ = runs
    assert rows.shape == (len(result.time), 38)
    assert np.array_equal(rows[:, 0], result.time)
    assert np.array_equal(rows[:, 1:36], result.trajectory)
    assert np.array_equal(rows[:, 36:38], result.torques)


def test_the_firmware_run_turns_the_robot_to_the_new_heading(runs):
    from runtime.control.geometry import heading
    rows, *_ = runs
    assert abs(heading(rows[-1, 1:36]) - np.pi / 2) < np.radians(3)


def test_the_bit_for_bit_check_fails_for_one_gain_changed_in_its_last_digits(runs):
    rows, _, text, tmp, controller = runs
    # The largest gain of the operating point the task uses (0.3 m/s, straight), 1e-12 relative.
    schedule = controller.schedule
    i, j = np.argmin(np.abs(schedule.speeds - 0.3)), np.argmin(np.abs(schedule.curvatures))
    gain = float(np.abs(schedule.K_heading[i, j]).max())
    literal = next(f"SR_C({v!r})" for v in (gain, -gain) if f"SR_C({v!r})" in text[text.index("/* K_heading */"):])
    at = text.index(literal, text.index("/* K_heading */"))
    changed = text[:at] + f"SR_C({float(literal[5:-1]) * (1 + 1e-12)!r})" + text[at + len(literal):]
    other = tmp / "perturbed"
    other.mkdir()
    (other / "lqr_task.h").write_text(changed)
    perturbed = build_and_run(other, tmp / "build-perturbed")
    assert not np.array_equal(perturbed[:, 1:36], rows[:, 1:36])


NUMBER = re.compile(r"SR_C\(([-0-9.e]+)\)")


def same_table(shipped, fresh):
    """The two headers' text equal but for their numbers, and every number within RTOL, ATOL."""
    a = np.array([float(v) for v in NUMBER.findall(shipped)])
    b = np.array([float(v) for v in NUMBER.findall(fresh)])
    return (a.shape == b.shape and bool(np.allclose(a, b, rtol=RTOL, atol=ATOL))
            and NUMBER.sub("", shipped) == NUMBER.sub("", fresh))


@pytest.fixture(scope="module")
def fresh_table():
    task = firmware_task()
    return header(task, task.controller())


def test_the_checked_in_table_is_the_current_design(fresh_table):
    # Not byte for byte: the Riccati solution's last bits depend on the machine's LAPACK (an AMD
    # EPYC with AVX-512 gave 2 of the 1634 numbers 1.1e-8 and 1.6e-8 relative from a table
    # written on a Zen 3 VM).
    assert same_table(SHIPPED.read_text(), fresh_table)


def test_the_table_comparison_fails_for_a_gain_changed_beyond_the_tolerance(fresh_table):
    at = fresh_table.index("SR_C(", fresh_table.index("/* K_heading */"))
    end = fresh_table.index(")", at)
    value = float(fresh_table[at + 5:end])
    changed = fresh_table[:at] + f"SR_C({value * (1 + 10 * RTOL) + 10 * ATOL!r})" + fresh_table[end + 1:]
    assert not same_table(changed, fresh_table)


def test_the_dispatcher_command_writes_the_table(fresh_table, tmp_path, capsys):
    from runtime.__main__ import main
    out = tmp_path / "lqr_task.h"
    assert main(["firmware-table", "--out", str(out)]) == 0
    assert out.read_text() == fresh_table


def _firmware_and_python(tmp, task):
    """(firmware rows, Python closed-loop result, header text, build dir, controller) of `task`."""
    controller = task.controller()
    text = header(task, controller)
    (tmp / "lqr_task.h").write_text(text)
    rows = build_and_run(tmp, tmp / "build")
    result = simulate_closed_loop(task.plant_params, controller, task.reference(), task.scenario.x0,
                                  task.duration, task.scenario.dt, task.scenario.method)
    return rows, result, text, tmp, controller


def _rebuilt_with(text, old, new, tmp):
    """The firmware's rows with `old` in the header text replaced by `new`."""
    changed = text.replace(old, new)
    assert changed != text
    other = pathlib.Path(tempfile.mkdtemp(prefix="perturbed", dir=tmp))
    (other / "lqr_task.h").write_text(changed)
    return build_and_run(other, other / "build")


def _assert_estimating_and_equal(rows, result, controller):
    """The estimate at work (it reads the heavier pendulum), and the firmware's rows the Python loop's bit for bit."""
    assert controller._estimator.pendulum[0] > 0.05 * controller.params.m_P
    assert rows.shape == (len(result.time), 38)
    assert np.array_equal(rows[:, 1:36], result.trajectory)
    assert np.array_equal(rows[:, 36:38], result.torques)


@pytest.fixture(scope="module")
def estimating_runs(tmp_path_factory):
    """`_firmware_and_python` of the slope task (firmware.slope_task) with the unweighted estimate."""
    return _firmware_and_python(tmp_path_factory.mktemp("firmware-estimate"), slope_task(slope_prior=0.0))


def test_the_firmware_with_the_slope_estimate_equals_the_python_closed_loop_bit_for_bit(estimating_runs):
    rows, result, text, _, controller = estimating_runs
    assert "LQR_TASK_SLOPE_ESTIMATE_S SR_C(5.0)" in text and "&LQR_TASK_PENDULUM_TABLE" in text
    assert "LQR_TASK_SLOPE_PRIOR SR_C(0.0)" in text
    _assert_estimating_and_equal(rows, result, controller)


def test_the_estimating_firmwares_check_fails_for_the_time_constant_changed_in_its_7th_digit(estimating_runs):
    rows, _, text, tmp, _ = estimating_runs
    perturbed = _rebuilt_with(text, "LQR_TASK_SLOPE_ESTIMATE_S SR_C(5.0)", "LQR_TASK_SLOPE_ESTIMATE_S SR_C(5.000001)",
                              tmp)
    assert not np.array_equal(perturbed[:, 1:36], rows[:, 1:36])


@pytest.fixture(scope="module")
def weighted_runs(tmp_path_factory):
    """`_firmware_and_python` of the slope task with the weighted estimate (slope_prior 1, as the
    path tasks ship it)."""
    return _firmware_and_python(tmp_path_factory.mktemp("firmware-weighted"), slope_task(slope_prior=1.0))


def test_the_firmware_with_the_weighted_slope_estimate_equals_the_python_closed_loop_bit_for_bit(weighted_runs):
    rows, result, text, _, controller = weighted_runs
    assert "LQR_TASK_SLOPE_PRIOR SR_C(1.0)" in text
    assert controller._estimator.prior_scale == 1.0      # the Python loop runs the weighted fit
    _assert_estimating_and_equal(rows, result, controller)


def test_the_weighted_firmwares_check_fails_when_the_firmware_runs_the_unweighted_estimate(weighted_runs):
    rows, _, text, tmp, _ = weighted_runs
    perturbed = _rebuilt_with(text, "LQR_TASK_SLOPE_PRIOR SR_C(1.0)", "LQR_TASK_SLOPE_PRIOR SR_C(0.0)", tmp)
    assert not np.array_equal(perturbed[:, 1:36], rows[:, 1:36])


def test_the_weighted_firmwares_check_fails_for_the_prior_scale_changed_in_its_7th_digit(weighted_runs):
    rows, _, text, tmp, _ = weighted_runs
    perturbed = _rebuilt_with(text, "LQR_TASK_SLOPE_PRIOR SR_C(1.0)", "LQR_TASK_SLOPE_PRIOR SR_C(1.000001)", tmp)
    assert not np.array_equal(perturbed[:, 1:36], rows[:, 1:36])


SLOPE_VECTOR = C_DIR / "examples" / "slope_vector" / "lqr_task.h"


def test_the_checked_in_slope_vector_is_what_make_generate_writes_now(tmp_path):
    """c/examples/slope_vector/lqr_task.h (the cross-test's weighted slope estimate on the Cortex-M4F)
    is the current design of the slope task, within the spread of LAPACK builds."""
    write_slope_vector(tmp_path)
    fresh = (tmp_path / "lqr_task.h").read_text()
    assert "LQR_TASK_SLOPE_PRIOR SR_C(1.0)" in fresh
    assert same_table(SLOPE_VECTOR.read_text(), fresh)
