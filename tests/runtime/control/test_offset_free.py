"""Offset-free tracking: the integrals act at any offset and do not wind up against the torque
limits (LQR and NMPC); the NMPC estimates a constant torque offset from its one-period prediction
error, in Python and in C alike."""
import dataclasses
import math

import numpy as np
import pytest

from runtime import so3
from runtime.control import lqr, nmpc
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.reference import SpeedHeading, Target
from runtime.params import Params
from runtime.state import initial_state

PARAMS = Params.paper_simulation()
SPEED = 0.2


def _rolling_along_x(speed, offset=0.0):
    return initial_state(R_S=so3.rot_z(-math.pi / 2), q=(0.0, offset, PARAMS.r), w_S=(-speed / PARAMS.r, 0.0, 0.0),
                         w_Y=speed / PARAMS.r, r=PARAMS.r)


def test_the_lqr_cross_track_integral_acts_at_a_large_offset():
    # Rolling parallel to a line, 0.2 m to its right (what a 10 % heavier pendulum on a 1.5 m circle
    # at 0.2 m/s leaves when the integral acts only near the path), with a cross-track weight that
    # leaves the torques free there: every sample of 1 s integrates it.
    controller = lqr.Lqr(PARAMS, rate=50.0, gains=lqr.LqrGains(cross_track_m=1.0, cross_track_integral_m_s=20.0))
    controller.reset(None)
    x = _rolling_along_x(SPEED)
    for k in range(50):
        controller.update(k / 50.0, x, Target(SPEED, 0.0, 0.0, -0.2))
    assert controller.saturated_fraction == 0.0
    assert np.isclose(controller.integrals[0], 50 * -0.2 / 50.0, rtol=1e-12)


def test_the_lqr_integrators_do_not_wind_up_while_a_torque_is_held_at_its_limit():
    # At rest, asked to roll at 0.5 m/s: the yoke torque is clipped at every sample, and the speed
    # integral's step would push it further; 2 s of it leave the speed integral at zero.
    controller = lqr.Lqr(PARAMS, rate=50.0)
    controller.reset(None)
    x = initial_state(R_S=so3.rot_z(-math.pi / 2), r=PARAMS.r)
    for k in range(100):
        controller.update(k / 50.0, x, Target(0.5, 0.0))
    assert controller.saturated_fraction == 1.0
    assert controller.integrals[1] == 0.0


@pytest.mark.parametrize("kind", [nmpc.Nmpc, nmpc.NmpcC])
def test_the_nmpc_cross_track_integral_acts_at_a_large_offset(kind):
    controller = kind(PARAMS, rate=20.0, gains=nmpc.NmpcGains(cross_track_m=1.0))
    controller.reset(None)
    x = _rolling_along_x(SPEED)
    for k in range(5):
        controller.update(k / 20.0, x, Target(SPEED, 0.0, 0.0, -0.2))
    assert controller.saturated_fraction == 0.0
    assert np.isclose(controller.integral, 5 * -0.2 / 20.0, rtol=1e-12)


@pytest.mark.parametrize("kind", [nmpc.Nmpc, nmpc.NmpcC])
def test_the_nmpc_integral_does_not_wind_up_while_a_torque_is_held_at_its_bound(kind):
    # Rolling 0.2 m right of the line, asked for 0.5 m/s more than it rolls: the yoke torque sits at its bound.
    controller = kind(PARAMS, rate=20.0, gains=nmpc.NmpcGains(cross_track_m=1.0))
    controller.reset(None)
    x = _rolling_along_x(0.0)
    for k in range(5):
        controller.update(k / 20.0, x, Target(0.5, 0.0, 0.0, -0.2))
    assert controller.saturated_fraction == 1.0
    assert controller.integral == 0.0


def _planted(kind, planted, gain):
    class Offset(kind):
        def update(self, t, x, target):
            return super().update(t, x, target) + planted

    controller = Offset(PARAMS, rate=20.0, gains=nmpc.NmpcGains(disturbance_gain=gain))
    simulate_closed_loop(PARAMS, controller, SpeedHeading(0.3, 0.0), _rolling_along_x(0.3), 3.0, 0.005)
    return controller.disturbance


@pytest.mark.parametrize("kind", [nmpc.Nmpc, nmpc.NmpcC])
def test_the_nmpc_disturbance_estimate_converges_to_a_planted_torque_offset(kind):
    planted = np.array([0.04, -0.03])
    assert np.allclose(_planted(kind, planted, 0.2), planted, rtol=0, atol=0.004)


@pytest.mark.parametrize("kind", [nmpc.Nmpc, nmpc.NmpcC])
def test_without_its_gain_the_nmpc_estimates_no_offset(kind):
    # Rolling at 0.3 m/s asked for 0.2: the prediction misses the state at every sample.
    controller = kind(PARAMS, rate=20.0, gains=nmpc.NmpcGains(disturbance_gain=0.0))
    controller.reset(None)
    x = _rolling_along_x(0.3)
    for k in range(3):
        controller.update(k / 20.0, x, Target(0.2, 0.0))
    assert np.array_equal(controller.disturbance, [0.0, 0.0])


def test_the_python_and_the_c_nmpc_estimate_the_same_offsets():
    # Rolling at 0.3 m/s asked for 0.2 on a straight line 5 cm off: the prediction misses the state
    # at every sample; both estimates take the same steps (to the two predictions' integrators).
    out = []
    for kind in (nmpc.Nmpc, nmpc.NmpcC):
        controller = kind(PARAMS, rate=20.0, gains=nmpc.NmpcGains(disturbance_gain=0.5))
        controller.reset(None)
        x = _rolling_along_x(0.3, 0.05)
        for k in range(3):
            controller.update(k / 20.0, x, Target(0.2, 0.0, 0.0, -0.05))
        out.append(np.concatenate([controller.disturbance, controller.shell_accel]))
    assert np.linalg.norm(out[0][2:]) > 0.01
    assert np.allclose(out[0], out[1], rtol=5e-3, atol=1e-5)


def _shipped_offset_rms(change, disturbance_gain=None, kind="nmpc-c"):
    """(second-half cross-track RMS [m], target [m]) of the offset table's case `change` (its task and
    plant, runtime/control/offsets.py) with the shipped tasks' NMPC in C (`kind` nmpc-c-slope: with the
    table's slope estimate), at the task's offset gain or at `disturbance_gain`."""
    from runtime.control.benchmark import run_task
    from runtime.control.offsets import offset_cases, with_controller
    from runtime.control.task import load_task

    def nmpc_c(name):
        task = with_controller(load_task(name), kind)
        if disturbance_gain is None:
            return task
        spec = task.controllers[0]
        gains = dataclasses.replace(spec.gains, disturbance_gain=disturbance_gain)
        return dataclasses.replace(task, controllers=(dataclasses.replace(spec, gains=gains),))

    [case] = [c for c in offset_cases(nmpc_c("circle"), nmpc_c("line")) if f"{c.name} {c.change}" == change]
    return run_task(case.task)[2]["cross_track_rms_m"], case.target_m


@pytest.mark.parametrize("change", ["circle slope 0.143 deg", "line slope 0.143 deg, across"])
def test_the_shipped_c_nmpc_holds_the_offset_tables_unknown_slope_within_its_target(change):
    # The offset estimate's shell acceleration carries the slope's pull (7.9 mm on the circle against
    # 10 mm, 1.2 mm on the line across against 5 mm, AMD EPYC); the next test: off, both miss.
    rms, target = _shipped_offset_rms(change)
    assert rms <= target


@pytest.mark.parametrize("change", ["circle slope 0.143 deg", "line slope 0.143 deg, across"])
def test_without_its_offset_estimate_the_shipped_c_nmpc_misses_the_unknown_slope(change):
    # The integral of e_y alone: 69 mm on the circle, 43 mm on the line across.
    rms, target = _shipped_offset_rms(change, disturbance_gain=0.0)
    assert rms > 2 * target


def test_with_the_slope_estimate_the_offset_estimate_takes_back_the_torque_offset_it_reads_into_the_yoke():
    # m_h +20 % on the circle: the slope estimate reads it as a torque offset on the pendulum (not a
    # slope), which the prediction adds; the NMPC's own offset, fitted against that prediction, takes
    # it back: 0.3 mm (AMD EPYC) against the 5 mm target.
    rms, target = _shipped_offset_rms("circle m_h +20 %", kind="nmpc-c-slope")
    assert rms <= target


def test_with_the_slope_estimate_and_the_offset_estimate_off_a_heavier_yoke_leaves_the_circle_further():
    # The slope estimate's torque offset alone moves the path: 4.2 mm against 0.3 mm (8.0 mm before the
    # estimate carried the pendulum joint's damping).
    rms, _ = _shipped_offset_rms("circle m_h +20 %", kind="nmpc-c-slope")
    rms_off, _ = _shipped_offset_rms("circle m_h +20 %", disturbance_gain=0.0, kind="nmpc-c-slope")
    assert rms_off > 5 * rms


def _raw_noise_speed_settle(disturbance_gain=None):
    """(the C NMPC's speed settle time [s] on circle-mismatch, raw noisy rates; the same on the nominal
    circle), circle-mismatch at its own offset gain or at `disturbance_gain`."""
    from runtime.control.benchmark import run_task
    from runtime.control.offsets import with_controller
    from runtime.control.task import load_task

    task = with_controller(load_task("circle-mismatch"), "nmpc-c")
    if disturbance_gain is not None:
        spec = task.controllers[0]
        spec = dataclasses.replace(spec, gains=dataclasses.replace(spec.gains, disturbance_gain=disturbance_gain))
        task = dataclasses.replace(task, controllers=(spec,))
    nominal = run_task(with_controller(load_task("circle"), "nmpc-c"))[2]["speed_settle_s"]
    return run_task(task)[2]["speed_settle_s"], nominal


def test_on_raw_noisy_rates_the_c_nmpcs_speed_settles_within_twice_the_nominal_circles():
    # The mismatch target's "≤ 2× nominal": 9.8 s against 2 × 5.35 s (AMD EPYC), circle-mismatch's
    # offset gain 0.01; the next test: at the default 0.05 the speed wanders outside ±5 % till 49.75 s.
    settle, nominal = _raw_noise_speed_settle()
    assert settle is not None and settle <= 2 * nominal


def test_at_the_default_offset_gain_the_shell_acceleration_chases_the_rate_noise_and_the_speed_does_not_settle():
    settle, nominal = _raw_noise_speed_settle(disturbance_gain=nmpc.NmpcGains().disturbance_gain)
    assert settle is None or settle > 2 * nominal
