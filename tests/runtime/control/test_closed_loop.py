"""Every shipped task with every controller (PID, LQR, NMPC) on a short horizon: the error shrinks, torques
stay within limits."""
import dataclasses

import numpy as np
import pytest

from runtime.control.benchmark import run_task
from runtime.control.closed_loop import Noise
from runtime.control.geometry import forward_speed, heading, wrap_angle
from runtime.control.task import load_task
from runtime.state import IDX_Q


CONTROLLERS = ["pid", "lqr", "nmpc"]


def short(name, duration, kind="pid", **changes):
    task = load_task(name).with_controller(kind)
    scenario = dataclasses.replace(task.scenario, steps=round(duration / task.scenario.dt))
    return dataclasses.replace(task, scenario=scenario, **changes)


@pytest.mark.parametrize("kind", CONTROLLERS)
def test_speed_step_approaches_the_reference_speed(kind):
    result, ref, metrics = run_task(short("speed-step", 6.0, kind))
    v = forward_speed(result.trajectory, 0.3)
    assert abs(v[-1] - 0.3) < 0.1 * abs(v[0] - 0.3)
    assert metrics["speed_settle_s"] is not None and metrics["speed_settle_s"] < 5.0


@pytest.mark.parametrize("kind", CONTROLLERS)
def test_heading_step_turns_toward_the_reference(kind):
    result, ref, _ = run_task(short("heading-step", 8.0, kind))
    e = np.abs(wrap_angle(ref.heading - heading(result.trajectory)))
    assert e[-1] < 0.5 * e[0]


@pytest.mark.parametrize("kind", CONTROLLERS)
def test_line_offset_shrinks(kind):
    result, ref, _ = run_task(short("line", 15.0, kind))
    e = ref.cross_track(result.trajectory[::10, IDX_Q][:, :2])
    assert abs(e[-1]) < abs(e[0]) and np.min(np.abs(e)) < 0.1 * abs(e[0])   # it reaches the line


@pytest.mark.parametrize("kind", CONTROLLERS)
@pytest.mark.parametrize("name", ["circle", "figure8", "square"])
def test_paths_started_on_the_path_stay_near_it(name, kind):
    result, ref, _ = run_task(short(name, 10.0, kind))
    e = ref.cross_track(result.trajectory[::10, IDX_Q][:, :2])
    assert np.max(np.abs(e)) < 0.5


@pytest.mark.parametrize("kind", CONTROLLERS)
@pytest.mark.parametrize("name", ["speed-step", "heading-step", "line", "circle", "figure8", "square"])
def test_torques_stay_within_their_limits(name, kind):
    task = short(name, 4.0, kind)
    result, _, metrics = run_task(task)
    assert np.max(np.abs(result.torques)) <= task.u_max
    assert 0.0 <= metrics["saturated_fraction"] <= 1.0


@pytest.mark.parametrize("kind", CONTROLLERS)
def test_a_smaller_torque_limit_is_respected_and_counted(kind):
    task = short("speed-step", 2.0, kind)
    task = dataclasses.replace(task, controllers=(dataclasses.replace(task.controllers[0], u_max=0.1),))
    result, _, metrics = run_task(task)
    assert np.max(np.abs(result.torques)) <= 0.1
    assert metrics["saturated_fraction"] > 0.5


@pytest.mark.parametrize("kind", CONTROLLERS)
def test_mismatched_noisy_plant_still_tracks_the_speed(kind):
    task = load_task("speed-step")
    plant = task.plant_params.with_changes(m_P=1.1, m_h=4.5, k_S=0.176, k_Y=0.036)
    task = dataclasses.replace(short("speed-step", 8.0, kind), plant_params=plant,
                               noise=Noise(position_m=0.002, attitude_rad=0.002, rate_rad_s=0.01, seed=1))
    result, _, _ = run_task(task)
    v = forward_speed(result.trajectory[-200:], plant.r)
    assert abs(v.mean() - 0.3) < 0.03


def test_the_shrinking_error_check_fails_for_a_controller_steering_the_wrong_way():
    from runtime.control.pid import Pid

    class WrongWay(Pid):
        def compute(self, t, x, target):
            u_Y, u_P = super().compute(t, x, target)
            return u_Y, -u_P

    task = short("heading-step", 8.0)
    reference = task.reference()
    from runtime.control.closed_loop import simulate_closed_loop
    controller = WrongWay(task.scenario.params, rate=task.rate, u_max=task.u_max, gains=task.gains)
    result = simulate_closed_loop(task.plant_params, controller, reference, task.scenario.x0, task.duration,
                                  task.scenario.dt, task.scenario.method)
    e = np.abs(wrap_angle(reference.heading - heading(result.trajectory)))
    assert not e[-1] < 0.5 * e[0]


def test_the_speed_check_fails_for_a_controller_without_its_speed_loop():
    from runtime.control.pid import PidGains
    task = short("speed-step", 6.0)
    task = dataclasses.replace(task, controllers=(dataclasses.replace(task.controllers[0],
                                                                      gains=PidGains(k_v=0.0, k_vi=0.0)),))
    result, _, metrics = run_task(task)
    v = forward_speed(result.trajectory, 0.3)
    assert metrics["speed_settle_s"] is None or metrics["speed_settle_s"] >= 5.0
    assert not abs(v[-1] - 0.3) < 0.1 * abs(v[0] - 0.3)
