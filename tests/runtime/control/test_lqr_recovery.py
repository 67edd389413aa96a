"""The LQR's recovery at a large error (c/src/sr_control.c, runtime/control/lqr_law.py): off by default,
the C law equals the NumPy law with it (errors clipped, integrals held, the speed reference lowered),
the comparison fails when the NumPy law leaves the clip out, and bad settings are refused by name."""
import dataclasses

import numpy as np
import pytest

from runtime.control import lqr
from runtime.control.lqr_law import recovering_law
from runtime.control.reference import Target
from runtime.params import Params
from tests.runtime.control.test_lqr_heading_tight import rolling

PARAMS = Params.paper_simulation()
RATE, U_MAX = 50.0, 0.5
#: A small design grid (two speeds, three curvatures): the schedule's design is most of these tests' time.
GRID = dict(v_min=0.2, v_max=0.4, n_speeds=2, kappa_max=0.5, n_curvatures=3)
GAINS = lqr.LqrGains(**GRID, recovery_cross_track_m=0.1, recovery_heading_rad=0.1, recovery_slow=0.3,
                     recovery_rise_s=0.1)


def controller(gains=GAINS):
    c = lqr.Lqr(PARAMS, RATE, U_MAX, gains=gains, schedule=lqr.design_schedule(PARAMS, RATE, U_MAX, gains))
    c.reset(None)
    return c


def law(c, x, target, integrals, kappa, tight, clipped, recovery_before, recovery):
    g = c.gains
    return recovering_law(c.schedule, PARAMS.r, x, target, integrals, kappa, c.period, U_MAX, g.kappa_rate,
                          g.steady_rate_m_s, tight_before=tight, clipped_before=clipped, tight_band=g.tight_band_m,
                          tight_rise=g.tight_rise_s, tight_fall=g.tight_fall_s, tight_wait=g.tight_wait,
                          recovery=recovery, recovery_before=recovery_before)


def test_the_recovery_is_off_by_default():
    gains = lqr.LqrGains(**GRID)
    assert lqr.recovery_settings(gains) == (0.0, 0.0, 0.0, 1.0)
    c = controller(gains)
    assert (c._c.recovery_cross_track, c._c.recovery_heading, c._c.recovery_slow) == (0.0, 0.0, 0.0)
    c.compute(0.0, rolling(np.random.default_rng(1), 1.0, spread=0.0), Target(0.3, 0.0, 0.5, 1.0))
    assert c._memory.recovery == 0.0


def test_the_c_law_equals_the_numpy_law_with_the_recovery():
    rng = np.random.default_rng(21)
    c = controller()
    recoveries, clipped_errors = [], 0
    for run in range(6):
        c.reset(None)
        integrals, kappa, tight, clipped, recovery = np.zeros(2), None, 0.0, False, 0.0
        for k in range(50):
            # Runs in and out of the bounds: the cross-track error and the heading error now small, now large.
            far = (k // 10) % 2 == 1
            x = rolling(rng, rng.normal(0, 0.2 if far and run % 2 else 0.03))
            target = Target(0.3, 0.0, 0.5, rng.normal(0, 0.3 if far and run % 2 == 0 else 0.02))
            clipped_errors += abs(target.cross_track) > 0.1
            raw = c.compute(0.0, x, target)
            raw_np, _, integrals, kappa, tight, recovery = law(c, x, target, integrals, kappa, tight, clipped,
                                                                recovery, lqr.recovery_settings(c.gains))
            clipped = bool(np.any(np.abs(raw_np) > U_MAX))
            assert np.allclose(raw, raw_np, rtol=1e-10, atol=1e-12)
            assert c._memory.recovery == pytest.approx(recovery, rel=0, abs=1e-15)
            assert np.allclose(c.integrals, integrals, rtol=1e-12, atol=1e-14)
            recoveries.append(recovery)
    assert max(recoveries) == 1.0 and 0 < np.mean(recoveries) < 0.9    # it came in full and went again
    assert clipped_errors > 20


def test_the_comparison_fails_when_the_numpy_law_leaves_the_clip_out():
    c = controller(dataclasses.replace(GAINS, recovery_slow=0.0))
    x, target = rolling(np.random.default_rng(22), spread=0.3), Target(0.3, 0.0, 0.5, 0.3)
    raw = c.compute(0.0, x, target)
    raw_np, *_ = law(c, x, target, np.zeros(2), None, 0.0, False, 0.0, (0.0, 0.0, 0.0, 1.0))
    assert not np.allclose(raw, raw_np, rtol=1e-6, atol=1e-6)
    raw_np, *_ = law(c, x, target, np.zeros(2), None, 0.0, False, 0.0, lqr.recovery_settings(c.gains))
    assert np.allclose(raw, raw_np, rtol=1e-10, atol=1e-12)


def test_beyond_the_bound_the_torques_no_longer_grow_with_the_error_and_the_integrals_hold():
    x = rolling(np.random.default_rng(0), spread=0.0)
    raws = []
    for e_y in (0.15, 0.3, 0.6):
        c = controller(dataclasses.replace(GAINS, recovery_slow=0.0))
        raws.append(c.compute(0.0, x, Target(0.3, 0.0, 0.5, e_y)))
        assert np.array_equal(c.integrals, [0.0, 0.0])
    assert np.array_equal(raws[0], raws[1]) and np.array_equal(raws[0], raws[2])
    c = controller(dataclasses.replace(GAINS, recovery_slow=0.0))
    c.compute(0.0, x, Target(0.3, 0.0, 0.5, 0.05))
    assert c.integrals[0] != 0.0


@pytest.mark.parametrize("name, value", [("recovery_cross_track_m", -0.1), ("recovery_heading_rad", -0.1),
                                         ("recovery_heading_rad", 4.0), ("recovery_slow", 1.0),
                                         ("recovery_slow", -0.1), ("recovery_rise_s", 0.0)])
def test_bad_recovery_settings_are_refused_by_name(name, value):
    with pytest.raises(ValueError, match=name):
        lqr.LqrGains(**{name: value})


def test_the_c_schedule_refuses_bad_recovery_settings():
    from bindings._sr import lib
    c = controller()
    assert lib.sr_lqr_check(c._c) == lib.SR_OK
    c._c.recovery_rise = 0.0
    assert lib.sr_lqr_check(c._c) == lib.SR_ERR_ARG
    c._c.recovery_rise = float("nan")
    assert lib.sr_lqr_check(c._c) == lib.SR_ERR_NONFINITE
    c._c.recovery_rise, c._c.recovery_slow = 0.1, 1.0
    assert lib.sr_lqr_check(c._c) == lib.SR_ERR_ARG


def test_the_nmpc_refuses_the_recovery_by_name():
    from runtime.control.nmpc import NmpcGains
    for name in ("recovery_cross_track_m", "recovery_heading_rad", "recovery_slow"):
        with pytest.raises(ValueError, match=name):
            NmpcGains(**{name: 0.1})
