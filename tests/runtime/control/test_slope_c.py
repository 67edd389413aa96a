"""The slope estimate in C (`sr_slope_update`, c/src/sr_slope.c; runtime/control/slope.py's
SlopeEstimatorC) against `SlopeEstimator` in NumPy, sample for sample over recorded closed-loop runs."""
import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime.control.closed_loop import simulate_closed_loop
from runtime.control.offsets import offset_cases, with_controller
from runtime.control.slope import (CENTRE_SCALE_M, DAMPING_SCALE, MASS_SCALE, PRIOR_SD, SlopeEstimator,
                                   SlopeEstimatorC)
from runtime.control.task import load_task

#: The table's circle cases the runs come from: the slope (pendulum near the model's) and a pendulum
#: damped 20 % less (the damping column away from 0).
CASES = ("slope", "k_P -20")
DURATION_S = 20.0


def _recorded(change):
    """(flat params, period, [(x, u held)] of every estimator update) of lqr-slope's circle case `change`."""
    circle, line = (with_controller(load_task(name), "lqr-slope") for name in ("circle", "line"))
    task = next(c for c in offset_cases(circle, line) if c.name == "circle" and change in c.change).task
    controller = task.controller()
    samples, update = [], controller._estimator.update

    def recording(x, u):
        samples.append((np.array(x), np.array(u)))
        return update(x, u)
    controller._estimator.update = recording
    simulate_closed_loop(task.plant_params, controller, task.reference(), task.scenario.x0, DURATION_S,
                         task.scenario.dt)
    return task.scenario.params.replace(slope=0.0), controller.period, samples


@pytest.fixture(scope="module", params=CASES)
def recorded(request):
    return _recorded(request.param)


def _estimates(estimator):
    return np.concatenate([estimator.slope, estimator.torque_offset, estimator.pendulum, [estimator.pendulum_damping]])


def _replayed(recorded, plant=lambda c: None, prior_scale=0.0):
    """(NumPy's, C's) estimates (samples, 9) over the recorded run; `plant(c_struct)` plants an error in C's;
    `prior_scale` > 0: the weighted fit."""
    params, period, samples = recorded
    python = SlopeEstimator(params, period, 5.0, prior_scale=prior_scale)
    c = SlopeEstimatorC(params, period, 5.0, prior_scale=prior_scale)
    plant(c._c)
    out = []
    for x, u in samples:
        python.update(x, u)
        c.update(x, u)
        out.append((_estimates(python), _estimates(c)))
    return np.array([p for p, _ in out]), np.array([q for _, q in out])


def _conditions(recorded, prior_scale=0.0):
    """Per sample: the 2-norm condition of the system NumPy's update solved (the normal equations, plus the
    prior's precision when weighted; 1 before the first)."""
    params, period, samples = recorded
    python, out = SlopeEstimator(params, period, 5.0, prior_scale=prior_scale), []
    prior = np.diag(1 / (prior_scale * np.array(PRIOR_SD)) ** 2) if prior_scale > 0 else 0.0
    for x, u in samples:
        python.update(x, u)
        out.append(np.linalg.cond(python._normal + prior) if np.any(python._normal) else 1.0)
    return np.array(out)


def _mismatch(recorded, python, c):
    """Per sample: |θ_NumPy − θ_C| / |θ_NumPy| in the estimate's own scaled units (the columns' scales:
    1 rad, 1 N m, a tenth of m_P, 1 cm, 0.01 N m s), 0 before the first estimate."""
    params = recorded[0]
    scales = np.array([1, 1, 1, 1, MASS_SCALE * params.m_P] + 3 * [CENTRE_SCALE_M] + [DAMPING_SCALE])
    a, b = python / scales, c / scales
    size = np.linalg.norm(a, axis=1)
    return np.where(size > 0, np.linalg.norm(a - b, axis=1) / np.where(size > 0, size, 1), 0.0)


def test_the_c_estimate_is_numpys_over_a_whole_closed_loop_run(recorded):
    python, c = _replayed(recorded)
    assert np.abs(python).max(axis=0)[[0, 4, 8]].min() > 0            # slope, pendulum and damping estimated
    # Two solves of the same normal equations may differ by up to their condition times the rounding:
    # the first samples' systems are near 1e10 (the first estimate 1.8e-9 apart on one machine), from
    # the first second on near 1e7 (1e-9); each sample held to that.
    bound = np.maximum(1e-12, np.finfo(float).eps * _conditions(recorded))
    assert np.all(_mismatch(recorded, python, c) <= bound)
    # each quantity after the first second (the normal equations well conditioned) against its largest
    later = np.abs(python[50:] - c[50:]).max(axis=0) / np.abs(python).max(axis=0)
    assert later.max() <= 1e-8


def test_the_weighted_c_estimate_is_numpys_over_a_whole_closed_loop_run(recorded):
    python, c = _replayed(recorded, prior_scale=1.0)
    unweighted, _ = _replayed(recorded)
    assert np.abs(python - unweighted).max() > 1e-4                   # the weighting changes the estimate
    bound = np.maximum(1e-12, np.finfo(float).eps * _conditions(recorded, 1.0))
    assert np.all(_mismatch(recorded, python, c) <= bound)


def test_the_weighted_comparison_fails_for_the_prior_or_the_variance_changed(recorded):
    def prior(c):
        c.prior_precision[4] = c.prior_precision[4] * (1 + 1e-6)
    python, c = _replayed(recorded, prior, prior_scale=1.0)
    assert _mismatch(recorded, python, c).max() > 1e-8

    def variance(c):
        c.variance_sum[3] = 1e-6                                      # one rate's first weight moved
    python, c = _replayed(recorded, variance, prior_scale=1.0)
    assert _mismatch(recorded, python, c).max() > 1e-8


def test_weigh_refuses_a_negative_or_non_finite_prior_scale():
    from runtime.params import Params
    est = ffi.new("sr_slope_estimator *")
    assert lib.sr_slope_weigh(ffi.NULL, 1.0) == lib.SR_ERR_NULL
    assert lib.sr_slope_weigh(est, -1.0) == lib.SR_ERR_ARG
    assert lib.sr_slope_weigh(est, float("inf")) == lib.SR_ERR_NONFINITE
    assert lib.sr_slope_weigh(est, float("nan")) == lib.SR_ERR_NONFINITE
    assert not any(est.prior_precision)                               # unchanged by the refusals
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="slope_prior"):
            SlopeEstimatorC(Params.paper_simulation(), 0.02, 5.0, prior_scale=bad)


def test_the_comparison_fails_for_a_dropped_column(recorded):
    # the damping column zeroed: the full system singular, the pendulum never estimated
    def drop(c):
        c.factor[4] = 0.0
    python, c = _replayed(recorded, drop)
    assert _mismatch(recorded, python, c).max() > 1e-3


def test_the_comparison_fails_for_the_forgetting_factor_off(recorded):
    def off(c):
        c.forget = c.forget * (1 + 1e-5)
    python, c = _replayed(recorded, off)
    assert _mismatch(recorded, python, c).max() > 1e-8


def test_init_refuses_a_bad_period_or_time_constant():
    from runtime.params import Params
    p = np.ascontiguousarray(Params.paper_simulation().as_array())
    est = ffi.new("sr_slope_estimator *")
    ptr = ffi.cast("double *", ffi.from_buffer(p))
    assert lib.sr_slope_init(est, ptr, 0.02, 5.0) == lib.SR_OK
    assert lib.sr_slope_init(ffi.NULL, ptr, 0.02, 5.0) == lib.SR_ERR_NULL
    assert lib.sr_slope_init(est, ptr, 0.0, 5.0) == lib.SR_ERR_ARG
    assert lib.sr_slope_init(est, ptr, 0.02, -1.0) == lib.SR_ERR_ARG
    assert lib.sr_slope_init(est, ptr, 0.005 * lib.SR_SLOPE_MAX_STEPS + 0.001, 5.0) == lib.SR_ERR_ARG
    assert lib.sr_slope_init(est, ptr, float("nan"), 5.0) == lib.SR_ERR_NONFINITE
    with pytest.raises(ValueError, match="slope_estimate_s"):
        SlopeEstimatorC(Params.paper_simulation(), 0.02, 0.0)


def test_update_refuses_a_non_finite_torque_and_keeps_its_state(recorded):
    params, period, samples = recorded
    c = SlopeEstimatorC(params, period, 5.0)
    for x, u in samples[:60]:
        c.update(x, u)
    before = bytes(ffi.buffer(c._c))
    u = np.ascontiguousarray([np.nan, 0.0])
    x = np.ascontiguousarray(samples[60][0])
    assert lib.sr_slope_update(c._c, ffi.cast("double *", ffi.from_buffer(x)),
                               ffi.cast("double *", ffi.from_buffer(u))) == lib.SR_ERR_NONFINITE
    assert bytes(ffi.buffer(c._c)) == before
    with pytest.raises(ValueError, match="u_applied_before"):
        c.update(x, u)


def test_update_refuses_a_state_of_the_wrong_size_before_c_reads_it(recorded):
    params, period, samples = recorded
    c = SlopeEstimatorC(params, period, 5.0)
    before = bytes(ffi.buffer(c._c))
    with pytest.raises(ValueError, match="x: expected a state of"):
        c.update(samples[0][0][:-1], samples[0][1])
    assert bytes(ffi.buffer(c._c)) == before
