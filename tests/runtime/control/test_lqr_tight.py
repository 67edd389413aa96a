"""The LQR's tight path gains (c/src/sr_control.c, runtime/control/lqr_law.py): the C law equals the
NumPy law with them scheduled in, their weight is bounded by the error, rises slowly and falls after a
clipped torque (holds without a fall time), below 0 to wait before they return, the integrators keep their torque across the schedule, and near the path they narrow
the loop's wander under the sensor set's torque noise."""
import numpy as np
import pytest

from runtime import so3
from runtime.control import lqr, noise_floor
from runtime.control.lqr_law import numpy_law
from runtime.control.reference import Target
from runtime.params import Params
from runtime.state import initial_state

PARAMS = Params.paper_simulation()
RATE, U_MAX = 50.0, 0.5
#: A small design grid (one speed, three curvatures): the schedule's design is most of these tests' time.
GRID = dict(v_min=0.3, n_speeds=1, kappa_max=0.5, n_curvatures=3)
GAINS = lqr.LqrGains(**GRID)
#: The default sensor set's process noise: 0.01 N m/sqrt(Hz) on the shell's axes and both joints.
DENSITIES = np.full(5, 0.01)


def controller(gains=GAINS):
    """The LQR with these gains on the default gains' schedule (the tight settings tested here change
    the law's schedule of the gains, not their design)."""
    c = lqr.Lqr(PARAMS, RATE, U_MAX, gains=gains, schedule=lqr.design_schedule(PARAMS, RATE, U_MAX, GAINS))
    c.reset(None)
    return c


def rolling(rng, speed=0.3, spread=1.0):
    """A state near steady rolling along +x at `speed` (spread scales the departures)."""
    return initial_state(theta_P=spread * rng.normal(0, 0.05), R_S=so3.rot_z(-np.pi / 2) @ so3.exp(spread * rng.normal(0, 0.03, 3)),
                         w_S=(-speed / PARAMS.r + spread * rng.normal(0, 0.05), *(spread * rng.normal(0, 0.05, 2))),
                         w_Y=speed / PARAMS.r + spread * rng.normal(0, 0.05), w_P=spread * rng.normal(0, 0.1), r=PARAMS.r)


def near_path_target(rng):
    return Target(speed=0.3, heading=rng.normal(0, 0.02), curvature=rng.uniform(-0.5, 0.5),
                  cross_track=rng.normal(0, 0.02))


def test_the_tight_schedule_equals_the_numpy_law_over_runs_near_the_path():
    rng = np.random.default_rng(5)
    c = controller(lqr.LqrGains(**GRID, tight_rise_s=0.2, tight_fall_s=1.0))
    g = c.gains
    weights, falls = [], 0
    for _ in range(5):
        c.reset(None)
        integrals, kappa, weight, clipped = np.zeros(2), None, 0.0, False
        for _ in range(60):
            x, target = rolling(rng), near_path_target(rng)
            raw = c.compute(0.0, x, target)
            raw_np, u_np, integrals, kappa, weight = numpy_law(
                c.schedule, PARAMS.r, x, target, integrals, kappa, c.period, U_MAX, g.kappa_rate, g.steady_rate_m_s,
                tight_before=weight, clipped_before=clipped, tight_band=g.tight_band_m, tight_rise=g.tight_rise_s,
                tight_fall=g.tight_fall_s, tight_wait=g.tight_wait)
            falls += clipped and 0 < weight < weights[-1] if weights else 0
            clipped = bool(np.any(np.abs(raw_np) > U_MAX))
            assert np.allclose(raw, raw_np, rtol=1e-10, atol=1e-12)
            assert c.tight_weight == pytest.approx(weight, rel=0, abs=1e-15)
            assert np.allclose(c.integrals, integrals, rtol=1e-12, atol=1e-14)
            weights.append(weight)
    assert max(weights) > 0.02          # the tight gains did act in these runs
    assert falls > 0                    # ... and fell after clipped torques
    assert min(weights) < 0             # ... below 0 (the path's gains)


def test_the_comparison_fails_when_the_reference_leaves_the_tight_gains_out():
    rng = np.random.default_rng(6)
    c = controller(lqr.LqrGains(**GRID, tight_rise_s=0.02))       # one sample to full weight
    g = c.gains
    x, target = rolling(rng, spread=0.3), Target(0.3, 0.0, 0.0, 0.001)
    raw = c.compute(0.0, x, target)
    assert c.tight_weight > 0.9
    raw_np, *_ = numpy_law(c.schedule, PARAMS.r, x, target, np.zeros(2), None, c.period, U_MAX, g.kappa_rate,
                           g.steady_rate_m_s)
    assert not np.allclose(raw, raw_np, rtol=1e-6, atol=1e-6)


def test_the_weight_rises_by_one_period_over_the_rise_time_per_sample():
    c = controller()
    x = initial_state(R_S=so3.rot_z(-np.pi / 2), w_S=(-1.0, 0.0, 0.0), w_Y=1.0, r=PARAMS.r)
    for k in range(1, 6):
        c.compute(0.0, x, Target(0.3, 0.0, 0.0, 0.0))
        assert c.tight_weight == pytest.approx(k / (RATE * GAINS.tight_rise_s), rel=1e-12)


def test_the_weight_is_bounded_by_the_cross_track_error_and_falls_at_once():
    c = controller(lqr.LqrGains(**GRID, tight_rise_s=0.02))
    x = initial_state(R_S=so3.rot_z(-np.pi / 2), w_S=(-1.0, 0.0, 0.0), w_Y=1.0, r=PARAMS.r)
    c.compute(0.0, x, Target(0.3, 0.0, 0.0, 0.0))
    assert c.tight_weight == 1.0
    c.compute(0.0, x, Target(0.3, 0.0, 0.0, 0.6 * GAINS.tight_band_m))
    assert c.tight_weight == pytest.approx(0.4, rel=1e-12)
    c.compute(0.0, x, Target(0.3, 0.0, 0.0, -2 * GAINS.tight_band_m))
    assert c.tight_weight == 0.0


def test_the_weight_falls_by_one_period_over_the_fall_time_after_a_clipped_torque():
    c = controller(lqr.LqrGains(**GRID, tight_rise_s=0.02, tight_fall_s=0.1))     # one sample up, five down
    x = initial_state(R_S=so3.rot_z(-np.pi / 2), w_S=(-1.0, 0.0, 0.0), w_Y=1.0, r=PARAMS.r)
    c.compute(0.0, x, Target(0.3, 0.0, 0.0, 0.0))
    assert c.tight_weight == 1.0 and c._memory.saturated == 0
    at_rest = initial_state(r=PARAMS.r)                 # asked to roll at 0.5 m/s: the torques clip
    c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
    assert c._memory.saturated == 1 and c.tight_weight == 1.0      # the clip is read at the next sample
    c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
    assert c.tight_weight == pytest.approx(1.0 - 0.2, rel=1e-12)
    c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
    assert c.tight_weight == pytest.approx(1.0 - 0.4, rel=1e-12)


@pytest.mark.parametrize("wait", [0.0, 0.25])
def test_the_weight_falls_no_lower_than_minus_the_wait(wait):
    c = controller(lqr.LqrGains(**GRID, tight_fall_s=0.1, tight_wait=wait))
    at_rest = initial_state(r=PARAMS.r)                 # the torques clip at every sample
    weights = []
    for _ in range(10):
        c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
        weights.append(c.tight_weight)
    assert weights[0] == pytest.approx(0.02 / GAINS.tight_rise_s)      # the first sample: nothing clipped before
    assert weights[1] == pytest.approx(max(weights[0] - 0.2, -wait))
    assert weights[-1] == -wait


def test_the_weight_holds_after_a_clipped_torque_without_a_fall_time():
    c = controller(lqr.LqrGains(**GRID, tight_fall_s=0.0))
    at_rest = initial_state(r=PARAMS.r)                 # asked to roll at 0.5 m/s: the torques clip
    c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
    assert c._memory.saturated == 1
    first = c.tight_weight
    c.compute(0.0, at_rest, Target(0.5, 0.0, 0.0, 0.0))
    assert c.tight_weight == first


def test_a_heading_reference_never_uses_the_tight_gains():
    c = controller(lqr.LqrGains(**GRID, tight_rise_s=0.02))
    x = initial_state(R_S=so3.rot_z(-np.pi / 2), w_S=(-1.0, 0.0, 0.0), w_Y=1.0, r=PARAMS.r)
    c.compute(0.0, x, Target(0.3, 0.0))
    assert c.tight_weight == 0.0


def test_the_integrators_move_the_same_torque_at_any_tight_weight():
    """The schedule moves only the robot's and the path's columns: an integral's torque is K_path's."""
    x = rolling(np.random.default_rng(7), spread=0.2)
    target = Target(0.3, 0.0, 0.0, 0.0)
    for rise in (1e3, 0.02):                              # weight ~0 and 1 at the first sample
        a, b = controller(lqr.LqrGains(**GRID, tight_rise_s=rise)), controller(lqr.LqrGains(**GRID, tight_rise_s=rise))
        b._memory.integrals[0] = 0.01
        diff = b.compute(0.0, x, target) - a.compute(0.0, x, target)
        K = a.schedule.at(0.3, 0.0)[2]
        assert np.allclose(diff, -K[:, 10] * 0.01, rtol=1e-9, atol=1e-15)


def test_the_tight_gains_keep_the_path_gains_integral_columns():
    s = lqr.design_schedule(PARAMS, RATE, U_MAX, GAINS)
    assert np.array_equal(s.K_tight[..., 10:], s.K_path[..., 10:])
    assert not np.allclose(s.K_tight[..., :10], s.K_path[..., :10])


@pytest.mark.parametrize("kappa", [0.0, 0.5])
def test_the_tight_gains_narrow_the_noise_floor_of_the_path(kappa):
    shipped = noise_floor.wander(PARAMS, DENSITIES, 0.3, kappa=kappa)
    tight = noise_floor.wander(PARAMS, DENSITIES, 0.3, kappa=kappa, tight=True)
    assert np.all(np.abs(np.linalg.eigvals(tight.A_cl)) < 1)
    assert tight.cross_track_m < 0.8 * shipped.cross_track_m


def test_the_nmpc_refuses_tight_gains_by_name():
    from runtime.control.nmpc import NmpcGains
    with pytest.raises(ValueError, match="tight_band_m"):
        NmpcGains(tight_band_m=0.05)
