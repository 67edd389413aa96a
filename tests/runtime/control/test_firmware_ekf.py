"""The firmware example on the estimator (c/examples/firmware_ekf_lqr.c: sensor samples in, the C EKF,
the LQR, torques out) equals the Python closed loop on the estimator bit for bit (double build, host)."""
import dataclasses
import shutil
import subprocess

import numpy as np
import pytest

from conftest import ROOT
from runtime.__main__ import main
from runtime.control.benchmark import run_task
from runtime.control.firmware import sample_events, write_ekf_headers

C_DIR = ROOT / "c"
DURATION = 4.0
MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(not (MAKE and shutil.which("cc")), reason="needs make and a C compiler")


def build(header_dir):
    """The double build of the example for the headers in `header_dir` (built there)."""
    exe = header_dir / "build" / "firmware_ekf_lqr"
    subprocess.run([MAKE, "-s", "-C", str(C_DIR), f"BUILD={header_dir / 'build'}", f"CPPFLAGS=-I{header_dir}",
                    str(exe)], check=True, capture_output=True, text=True)
    return exe


def run_firmware(exe, events):
    out = subprocess.run([str(exe)], input=events, check=True, capture_output=True, text=True).stdout
    return np.loadtxt(out.splitlines()[1:], delimiter=",")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(firmware executable, the Python run's events, its result, the controller's steps per sample)."""
    tmp = tmp_path_factory.mktemp("firmware-ekf")
    task = write_ekf_headers(tmp)
    task = dataclasses.replace(task, scenario=task.scenario.with_overrides(steps=round(DURATION / task.scenario.dt)))
    exe = build(tmp)
    result = run_task(task)[0]
    return exe, sample_events(result), result, round(1 / (task.rate * task.scenario.dt))


def same_run(rows, result, per):
    return (rows.shape == (len(result.control_time), 38) and np.array_equal(rows[:, 0], result.control_time)
            and np.array_equal(rows[:, 1:36], result.estimates)
            and np.array_equal(rows[:, 36:38], result.torques[:-1:per]))


def test_the_firmware_on_the_estimator_equals_the_python_closed_loop_bit_for_bit(runs):
    exe, events, result, per = runs
    assert same_run(run_firmware(exe, events), result, per)


def test_the_bit_for_bit_check_fails_for_one_imu_reading_changed_in_its_last_digit(runs):
    exe, events, result, per = runs
    lines = events.splitlines(keepends=True)
    at = next(i for i, line in enumerate(lines) if line.startswith("1 ") and float(line.split()[1]) > 1.0)
    fields = lines[at].split()
    fields[-1] = repr(float(np.nextafter(float(fields[-1]), np.inf)))
    lines[at] = " ".join(fields) + "\n"
    assert not same_run(run_firmware(exe, "".join(lines)), result, per)


def test_the_firmware_reads_the_imu_through_the_held_disturbance_as_the_closed_loop(runs, tmp_path):
    exe, events, result, per = runs
    header = (exe.parent.parent / "ekf_task.h").read_text()
    hold = next(line for line in header.splitlines() if line.startswith("#define EKF_TASK_TORQUE_HOLD "))
    assert float(hold.split("SR_C(")[1].rstrip(")")) == 0.005      # the task's plant step
    shutil.copy(exe.parent.parent / "lqr_task.h", tmp_path)
    (tmp_path / "ekf_task.h").write_text(header.replace(hold, "#define EKF_TASK_TORQUE_HOLD SR_C(0.0)"))
    assert not same_run(run_firmware(build(tmp_path), events), result, per)      # sr_ekf_update_imu_axes instead


def test_the_firmware_refuses_a_line_that_is_not_an_event(runs):
    exe = runs[0]
    done = subprocess.run([str(exe)], input="0 0.0\n7 0.1\n", capture_output=True, text=True)
    assert done.returncode == 1 and "line 2: not an event" in done.stderr


def test_the_checked_in_vector_of_the_cross_builds_is_what_make_generate_writes_now(tmp_path):
    """c/examples/ekf_lqr_vector/ (the cross-test's recorded input and headers) follows the control law
    and the filter: a change of either must be regenerated (`make generate`), not left stale."""
    assert main(["firmware-table", "--ekf-vector", str(tmp_path)]) == 0
    vector = C_DIR / "examples" / "ekf_lqr_vector"
    for name in ("lqr_task.h", "ekf_task.h", "events.txt"):
        assert (tmp_path / name).read_bytes() == (vector / name).read_bytes(), f"{name} is stale: run make generate"


@pytest.fixture(scope="module")
def slope_runs(tmp_path_factory):
    """`runs` of heading-step-sensors with lqr-slope's settings and the weighted slope estimate
    (slope_prior 1: what the path tasks ship; the example runs it on the filter's estimate)."""
    from runtime.control.offsets import with_controller
    from runtime.control.task import load_task
    tmp = tmp_path_factory.mktemp("firmware-ekf-slope")
    task = with_controller(load_task("heading-step-sensors"), "lqr-slope")
    spec = task.controllers[0]
    task = dataclasses.replace(task, controllers=(dataclasses.replace(
        spec, gains=dataclasses.replace(spec.gains, slope_prior=1.0)),))
    task = write_ekf_headers(tmp, task=task)
    task = dataclasses.replace(task, scenario=task.scenario.with_overrides(steps=round(DURATION / task.scenario.dt)))
    result = run_task(task)[0]
    return build(tmp), sample_events(result), result, round(1 / (task.rate * task.scenario.dt))


def test_the_firmware_on_the_estimator_with_the_weighted_slope_estimate_equals_the_python_loop_bit_for_bit(
        slope_runs):
    exe, events, result, per = slope_runs
    header = (exe.parent.parent / "lqr_task.h").read_text()
    assert "LQR_TASK_SLOPE_ESTIMATE_S SR_C(5.0)" in header and "LQR_TASK_SLOPE_PRIOR SR_C(1.0)" in header
    assert same_run(run_firmware(exe, events), result, per)


@pytest.mark.parametrize("old, new", [("LQR_TASK_SLOPE_PRIOR SR_C(1.0)", "LQR_TASK_SLOPE_PRIOR SR_C(0.0)"),
                                      ("LQR_TASK_SLOPE_ESTIMATE_S SR_C(5.0)", "LQR_TASK_SLOPE_ESTIMATE_S SR_C(0.0)")],
                         ids=["unweighted", "no-estimate"])
def test_the_slope_estimates_check_fails_when_the_firmware_runs_another_estimate(slope_runs, tmp_path, old, new):
    exe, events, result, per = slope_runs
    shutil.copy(exe.parent.parent / "ekf_task.h", tmp_path)
    header = (exe.parent.parent / "lqr_task.h").read_text()
    (tmp_path / "lqr_task.h").write_text(header.replace(old, new))
    assert not same_run(run_firmware(build(tmp_path), events), result, per)
