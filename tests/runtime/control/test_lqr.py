"""The C controller `sr_lqr_control` (c/src/sr_control.c) against the law written out here in NumPy:
error coordinates, interpolation of the schedule, clipping, anti-windup, the curvature's rate limit."""
import dataclasses

import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import so3
from runtime.control import lqr
from runtime.control import lqr_design as design
from runtime.control.reference import Target
from runtime.model import Model
from runtime.params import Params
from runtime.state import IDX_WS, initial_state
from runtime.control.lqr_law import numpy_law

PARAMS = Params.paper_simulation()
RATE, U_MAX = 50.0, 0.5
MODEL_C = Model(PARAMS)._model


def schedule():
    return lqr.design_schedule(PARAMS, RATE, U_MAX)


def random_state(rng):
    return initial_state(theta_Y=rng.uniform(-np.pi, np.pi), theta_P=rng.uniform(-1, 1),
                         R_S=so3.random_rotation(rng), q=(*rng.normal(0, 2, 2), PARAMS.r),
                         w_S=rng.normal(0, 1, 3), w_Y=rng.normal(0, 1), w_P=rng.normal(0, 1), r=PARAMS.r)


def random_target(rng, path):
    return Target(speed=rng.uniform(0.0, 0.6), heading=rng.uniform(-np.pi, np.pi),
                  curvature=rng.uniform(-0.7, 0.7) if path else 0.0,
                  cross_track=rng.normal(0, 0.3) if path else None)


def c_error(x, target, integrals=(0.0, 0.0)):
    z = np.empty(design.NZ)
    status = lib.sr_lqr_error(MODEL_C,
                              ffi.cast("double *", ffi.from_buffer(x)), lqr.c_target(target),
                              ffi.new("double[2]", list(integrals)), ffi.cast("double *", ffi.from_buffer(z)))
    assert status == lib.SR_OK
    return z




def python_law(sched, x, target, integrals, kappa_before, tight_before=0.0, clipped_before=False, world_share=None):
    gains = lqr.LqrGains()
    return numpy_law(sched, PARAMS.r, x, target, integrals, kappa_before, 1 / RATE, U_MAX, gains.kappa_rate,
                     gains.steady_rate_m_s, tight_before, clipped_before, gains.tight_band_m, gains.tight_rise_s,
                     gains.world_share if world_share is None else world_share, gains.tight_fall_s, gains.tight_wait)


@pytest.mark.parametrize("path", [False, True])
def test_c_error_coordinates_equal_the_numpy_ones(path):
    rng = np.random.default_rng(1)
    for _ in range(200):
        x, target = random_state(rng), random_target(rng, path)
        integrals = rng.normal(size=2)
        expected = design.error_coordinates(x, PARAMS.r, target.speed, target.heading,
                                            target.cross_track if path else 0.0, integrals)
        # 1e-10: within 1e-4 rad of π, runtime.so3.log takes the axis from the skew part, which
        # loses digits there (1.4e-12 at 3.14147 rad among these states); the C log does not.
        assert np.allclose(c_error(x, target, integrals), expected, rtol=0, atol=1e-10)


def test_the_error_coordinates_vanish_at_the_reference():
    v, psi = 0.3, 0.7
    Q = design.reference_attitude(psi)
    x = initial_state(R_S=Q, w_S=(-v / PARAMS.r, 0, 0), w_Y=v / PARAMS.r, r=PARAMS.r)
    assert np.abs(c_error(x, Target(v, psi))).max() < 1e-15


@pytest.mark.parametrize("path", [False, True])
def test_c_law_equals_the_numpy_law_over_a_run_of_samples(path):
    rng = np.random.default_rng(2)
    sched = schedule()
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=sched)
    for trial in range(20):
        controller.reset(None)
        integrals, kappa, tight, clipped = np.zeros(2), None, 0.0, False
        for _ in range(10):
            x, target = random_state(rng), random_target(rng, path)
            raw = controller.compute(0.0, x, target)
            u = np.array(list(controller._u))
            raw_np, u_np, integrals, kappa, tight = python_law(sched, x, target, integrals, kappa, tight, clipped)
            clipped = bool(np.any(u_np != raw_np))
            assert np.allclose(raw, raw_np, rtol=1e-12, atol=1e-12)
            assert np.allclose(u, u_np, rtol=1e-12, atol=1e-12)
            assert np.array_equal(np.abs(u) == U_MAX, np.abs(u_np) == U_MAX)
            assert np.allclose(controller.integrals, integrals, rtol=1e-12, atol=1e-14)
            assert np.isclose(controller._memory.kappa, kappa, rtol=0, atol=1e-15)


def test_c_law_equals_the_numpy_law_with_part_of_the_cross_track_integral_in_the_world_frame():
    rng = np.random.default_rng(3)
    sched = schedule()
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, lqr.LqrGains(world_share=0.3, steady_rate_m_s=10.0), schedule=sched)
    controller.reset(None)
    integrals, kappa = np.zeros(4), None
    for _ in range(30):
        x, target = random_state(rng), random_target(rng, True)
        x[IDX_WS] *= 0.1                  # slow enough that the torques stay free and every sample integrates
        raw = controller.compute(0.0, x, target)
        raw_np, _, integrals, kappa, _ = numpy_law(sched, PARAMS.r, x, target, integrals, kappa, 1 / RATE, U_MAX,
                                                   controller.gains.kappa_rate, 10.0, world_share=0.3)
        assert np.allclose(raw, raw_np, rtol=1e-12, atol=1e-12)
        assert np.allclose(controller.integrals, integrals[:2], rtol=1e-12, atol=1e-14)
        assert np.allclose(controller.world_integral, integrals[2:], rtol=1e-12, atol=1e-14)
    assert np.abs(controller.world_integral).min() > 0


def test_the_world_part_of_the_cross_track_integral_turns_with_the_path():
    # 1 s at e_y = -2 cm heading +x, then heading -x: a pull fixed in the world (a slope) now pushes
    # the other way, and the world part reads the integral with the opposite sign.
    def after_one_second(share):
        controller = lqr.Lqr(PARAMS, RATE, U_MAX, lqr.LqrGains(world_share=share, steady_rate_m_s=10.0),
                             schedule=schedule())
        controller.reset(None)
        for k in range(50):
            controller.compute(k / RATE, _rolling(0.0), Target(0.2, 0.0, 0.0, -0.02))
        assert controller.saturated_fraction == 0.0 and controller._memory.saturated == 0
        return controller
    turned = Target(0.2, np.pi, 0.0, -0.02)
    in_world, along_path, flipped_path = after_one_second(1.0), after_one_second(0.0), after_one_second(0.0)
    assert np.isclose(in_world.world_integral[1], -0.02, rtol=1e-12) and in_world.integrals[0] == 0.0
    unflipped = along_path.compute(1.0, _rolling(np.pi), turned)
    flipped_path._memory.integrals[0] *= -1
    flipped = flipped_path.compute(1.0, _rolling(np.pi), turned)
    assert np.abs(flipped - unflipped).max() > 1e-3
    assert np.allclose(in_world.compute(1.0, _rolling(np.pi), turned), flipped, rtol=1e-12, atol=1e-14)


def _rolling(psi, speed=0.2):
    return initial_state(R_S=so3.rot_z(psi - np.pi / 2), w_S=(-speed / PARAMS.r, 0.0, 0.0), w_Y=speed / PARAMS.r,
                         r=PARAMS.r)


def test_the_law_comparison_fails_for_a_gain_perturbed_by_one_part_in_a_million():
    sched = schedule()
    K = sched.K_heading.copy()
    row, col = np.unravel_index(np.argmax(np.abs(K[2, 2])), K[2, 2].shape)   # v = 0.3 m/s, κ = 0
    K[2, 2, row, col] *= 1 + 1e-6
    perturbed = dataclasses.replace(sched, K_heading=K)
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=perturbed)
    controller.reset(None)
    x = initial_state(theta_P=0.1, R_S=so3.rot_z(-np.pi / 2) @ so3.exp([0.2, 0.1, 0.3]), w_S=(-1.0, 0.1, 0.2),
                      w_Y=1.1, w_P=0.3, r=PARAMS.r)
    target = Target(0.3, 0.0)
    raw = controller.compute(0.0, x, target)
    raw_np, *_ = python_law(sched, x, target, np.zeros(2), None)
    assert not np.allclose(raw, raw_np, rtol=1e-12, atol=1e-12)


def test_integrators_hold_while_a_torque_is_clipped():
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=schedule())
    controller.reset(None)
    x = initial_state(r=PARAMS.r)                     # at rest, asked to roll at 0.5 m/s: clipped
    raw = controller.compute(0.0, x, Target(0.5, 0.0, 0.0, 0.2))
    assert np.abs(raw).max() > U_MAX and controller._memory.saturated == 1
    assert np.array_equal(controller.integrals, [0.0, 0.0])


def test_the_operating_points_curvature_follows_a_jump_at_the_bounded_rate():
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=schedule())
    controller.reset(None)
    x = initial_state(R_S=so3.rot_z(-np.pi / 2), w_S=(-1.0, 0.0, 0.0), w_Y=1.0, r=PARAMS.r)
    controller.compute(0.0, x, Target(0.3, 0.0, 0.5, 0.0))
    assert controller._memory.kappa == 0.5                        # the first sample takes it as it is
    for k in range(1, 4):
        controller.compute(0.0, x, Target(0.3, 0.0, -0.5, 0.0))
        assert np.isclose(controller._memory.kappa, 0.5 - k * 0.3 / RATE, rtol=0, atol=1e-15)


def test_a_schedule_with_a_nan_is_refused_by_name():
    bad = dataclasses.replace(schedule(), u_star=np.full_like(schedule().u_star, np.nan))
    with pytest.raises(ValueError, match="controller: the LQR schedule is not valid"):
        lqr.Lqr(PARAMS, RATE, U_MAX, schedule=bad)


def test_a_design_grid_larger_than_the_c_struct_is_refused_by_name():
    with pytest.raises(ValueError, match=r"^n_speeds: expected .*the C controller's grid holds SR_LQR_MAX_SPEEDS"):
        lqr.Lqr(PARAMS, RATE, U_MAX, gains=lqr.LqrGains(n_speeds=lib.SR_LQR_MAX_SPEEDS + 1))


def test_a_state_that_is_no_state_is_refused_by_name():
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=schedule())
    controller.reset(None)
    x = initial_state(r=PARAMS.r)
    x[0] = 2.0                                        # R_S no rotation
    with pytest.raises(ValueError, match="controller lqr: .*rotation"):
        controller.compute(0.0, x, Target(0.3, 0.0))


def test_the_operating_curvature_is_the_paths_curvature_averaged_over_the_preview_window():
    controller = lqr.Lqr(PARAMS, RATE, U_MAX, schedule=schedule())
    distances = controller.preview_distances(Target(0.3, 0.0))
    g = controller.gains
    assert np.isclose(distances.min(), g.preview_m - g.smoothing_m) and np.isclose(distances.max(), g.preview_m + g.smoothing_m)
    ahead = tuple(np.where(distances < 0.25, 0.5, -0.5))         # a switch of turn direction 0.25 m ahead
    target = Target(0.3, 0.0, 0.5, 0.0, curvature_ahead=ahead)
    assert controller.operating_curvature(target) == pytest.approx(np.mean(ahead))
    assert controller.operating_curvature(Target(0.3, 0.0, 0.5, 0.0)) == 0.5       # no preview given
    assert controller.operating_curvature(Target(0.3, 0.0)) == 0.0                 # no path


def _figure8_crossing_error(gains):
    from runtime.control.closed_loop import simulate_closed_loop
    from runtime.control.task import load_task
    from runtime.state import IDX_Q
    task = load_task("figure8").with_controller("lqr")
    reference = task.reference()
    controller = lqr.Lqr(task.scenario.params, task.rate, task.u_max, gains)
    result = simulate_closed_loop(task.plant_params, controller, reference, task.scenario.x0, 60.0,
                                  task.scenario.dt, task.scenario.method)
    e = reference.cross_track(result.trajectory[::10, IDX_Q][:, :2])
    return np.abs(e[result.time[::10] >= 40.0]).max()      # the lobes switch at about 42 s


def test_with_the_curvature_preview_the_lqr_follows_the_figure_eight_through_its_crossing():
    assert _figure8_crossing_error(lqr.LqrGains()) < 0.2


def test_the_crossing_check_fails_without_the_preview():
    """On the law whose tight gains hold after a clipped torque (tight_fall_s = 0): with the fall the
    tight gains leave the crossing's clipped turn, and that alone keeps it near 0.18 m."""
    assert _figure8_crossing_error(lqr.LqrGains(preview_m=0.0, smoothing_m=0.0, tight_fall_s=0.0)) > 0.2


def test_the_heading_weight_alone_moves_only_the_headings_riccati_weight():
    base, own = lqr.LqrGains().weights(0.5).q_diagonal(), lqr.LqrGains(heading_rad=0.02).weights(0.5).q_diagonal()
    assert own[2] == pytest.approx(1 / 0.02 ** 2)
    assert np.array_equal(np.delete(own, 2), np.delete(base, 2))
    assert np.array_equal(lqr.LqrGains(heading_rad=0.0).weights(0.5).q_diagonal(), base)


def test_a_negative_heading_weight_is_refused_by_name():
    with pytest.raises(ValueError, match="heading_rad"):
        lqr.LqrGains(heading_rad=-0.1)
