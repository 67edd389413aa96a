"""The LQR's stiffer heading gains scheduled in near a heading reference's heading (c/src/sr_control.c,
runtime/control/lqr_law.py): off by default, the C law equals the NumPy law with them, their weight is
bounded by the heading error and rises over heading_rise_s, their integral columns are K_heading's, and
the C schedule refuses a band without a rise time."""
import dataclasses

import numpy as np
import pytest

from runtime import so3
from runtime.control import lqr
from runtime.control.lqr_law import numpy_law
from runtime.control.reference import Target
from runtime.params import Params
from runtime.state import initial_state

PARAMS = Params.paper_simulation()
RATE, U_MAX = 50.0, 0.5
#: A small design grid (one speed, three curvatures): the schedule's design is most of these tests' time.
GRID = dict(v_min=0.3, n_speeds=1, kappa_max=0.5, n_curvatures=3)
BAND = 0.1
GAINS = lqr.LqrGains(**GRID, heading_band_rad=BAND)


def controller(gains=GAINS):
    c = lqr.Lqr(PARAMS, RATE, U_MAX, gains=gains, schedule=lqr.design_schedule(PARAMS, RATE, U_MAX, GAINS))
    c.reset(None)
    return c


def rolling(rng, heading_error=0.0, spread=1.0):
    """A state rolling at 0.3 m/s along +x, turned by `heading_error` (left), with random departures."""
    return initial_state(theta_P=spread * rng.normal(0, 0.05),
                         R_S=so3.rot_z(heading_error - np.pi / 2) @ so3.exp(spread * rng.normal(0, 0.03, 3)),
                         w_S=(-1.0 + spread * rng.normal(0, 0.05), *(spread * rng.normal(0, 0.05, 2))),
                         w_Y=1.0 + spread * rng.normal(0, 0.05), w_P=spread * rng.normal(0, 0.1), r=PARAMS.r)


def law(c, x, target, integrals, kappa, weight, clipped, heading_band):
    g = c.gains
    return numpy_law(c.schedule, PARAMS.r, x, target, integrals, kappa, c.period, U_MAX, g.kappa_rate,
                     g.steady_rate_m_s, tight_before=weight, clipped_before=clipped, tight_fall=g.tight_fall_s,
                     tight_wait=g.tight_wait, heading_band=heading_band, heading_rise=g.heading_rise_s)


def test_the_heading_gains_are_off_by_default():
    gains = lqr.LqrGains(**GRID)
    assert gains.heading_band_rad == 0
    assert lqr.design_schedule(PARAMS, RATE, U_MAX, gains).K_heading_tight is None
    c = lqr.Lqr(PARAMS, RATE, U_MAX, gains=gains)
    c.reset(None)
    c.compute(0.0, rolling(np.random.default_rng(1), spread=0.0), Target(0.3, 0.0))
    assert c._c.heading_band == 0 and c.tight_weight == 0.0


def test_the_c_law_equals_the_numpy_law_with_the_heading_gains():
    rng = np.random.default_rng(11)
    c = controller(dataclasses.replace(GAINS, heading_rise_s=0.2, tight_fall_s=1.0))
    weights = []
    for _ in range(5):
        c.reset(None)
        integrals, kappa, weight, clipped = np.zeros(2), None, 0.0, False
        for _ in range(60):
            x, target = rolling(rng, rng.normal(0, 0.08)), Target(0.3, rng.normal(0, 0.01))
            raw = c.compute(0.0, x, target)
            raw_np, _, integrals, kappa, weight = law(c, x, target, integrals, kappa, weight, clipped, BAND)
            clipped = bool(np.any(np.abs(raw_np) > U_MAX))
            assert np.allclose(raw, raw_np, rtol=1e-10, atol=1e-12)
            assert c.tight_weight == pytest.approx(weight, rel=0, abs=1e-15)
            assert np.allclose(c.integrals, integrals, rtol=1e-12, atol=1e-14)
            weights.append(weight)
    assert max(weights) > 0.2           # the heading gains did act in these runs
    assert min(weights) < 0             # ... and fell below 0 after clipped torques


def test_the_comparison_fails_when_the_numpy_law_leaves_the_heading_gains_out():
    c = controller(dataclasses.replace(GAINS, heading_rise_s=0.02))       # one sample to full weight
    x, target = rolling(np.random.default_rng(12), 0.02, spread=0.3), Target(0.3, 0.0)
    raw = c.compute(0.0, x, target)
    assert c.tight_weight > 0.7
    raw_np, *_ = law(c, x, target, np.zeros(2), None, 0.0, False, 0.0)
    assert not np.allclose(raw, raw_np, rtol=1e-6, atol=1e-6)


def test_the_weight_rises_over_the_rise_time_and_is_bounded_by_the_heading_error():
    c = controller()
    x = rolling(np.random.default_rng(0), spread=0.0)
    for k in range(1, 4):
        c.compute(0.0, x, Target(0.3, 0.0))
        assert c.tight_weight == pytest.approx(k / (RATE * GAINS.heading_rise_s), rel=1e-12)
    fast = controller(dataclasses.replace(GAINS, heading_rise_s=0.02))
    fast.compute(0.0, x, Target(0.3, 0.0))
    assert fast.tight_weight == pytest.approx(1.0, abs=1e-9)     # the operating point's z*[2] is ~1e-14
    fast.compute(0.0, x, Target(0.3, 0.6 * BAND))          # the robot 0.6 band right of the heading
    assert fast.tight_weight == pytest.approx(0.4, abs=1e-9)
    fast.compute(0.0, x, Target(0.3, -2 * BAND))
    assert fast.tight_weight == 0.0


def test_the_heading_gains_keep_k_headings_integral_columns_and_stiffen_the_heading():
    s = lqr.design_schedule(PARAMS, RATE, U_MAX, GAINS)
    assert np.array_equal(s.K_heading_tight[..., 10:], s.K_heading[..., 10:])
    yaw = 2                             # z[2]: the heading error
    assert np.all(np.abs(s.K_heading_tight[:, :, 1, yaw]) > 2 * np.abs(s.K_heading[:, :, 1, yaw]))


def test_a_path_reference_never_uses_the_heading_gains():
    c = controller(dataclasses.replace(GAINS, tight_band_m=0.0, heading_rise_s=0.02))
    c.compute(0.0, rolling(np.random.default_rng(0), spread=0.0), Target(0.3, 0.0, 0.0, 0.0))
    assert c.tight_weight == 0.0


def test_the_c_schedule_refuses_a_heading_band_without_a_rise_time():
    c = controller()
    c._c.heading_rise = 0.0
    from bindings._sr import lib
    assert lib.sr_lqr_check(c._c) == lib.SR_ERR_ARG
    c._c.heading_rise = 1.0
    c._c.K_heading_tight[0][0] = float("nan")
    assert lib.sr_lqr_check(c._c) == lib.SR_ERR_NONFINITE
    c._c.heading_band = 0.0
    assert lib.sr_lqr_check(c._c) == lib.SR_OK            # unread without a band


def test_the_nmpc_refuses_the_heading_gains_by_name():
    from runtime.control.nmpc import NmpcGains
    with pytest.raises(ValueError, match="heading_band_rad"):
        NmpcGains(heading_band_rad=0.1)
