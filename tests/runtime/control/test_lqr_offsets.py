"""The C law's feedforward of the offsets (`sr_lqr_control_offsets`, c/src/sr_control.c; its tables from
runtime/control/lqr.py's `feedforward_tables`) against the feedforward written out in NumPy
(`Lqr.numpy_feedforward`: SlopeSchedule, PendulumSchedule and the schedule's gain, runtime/control/slope.py)."""
import numpy as np
import pytest

from bindings._sr import ffi, lib
from bindings.buffers import pointer
from runtime.control import lqr
from runtime.params import Params
from tests.runtime.control.test_lqr import random_state, random_target

PARAMS = Params.paper_simulation()
GAINS = lqr.LqrGains(v_min=0.2, v_max=0.4, n_speeds=2, kappa_max=0.5, n_curvatures=3, slope_estimate_s=5.0,
                     pendulum_feedforward=0.7)


@pytest.fixture(scope="module")
def controller():
    return lqr.Lqr(PARAMS, 50.0, 0.5, GAINS)


def _random_offsets(controller, rng):
    """Random slope, torque offset and pendulum in the controller's estimate (what `offsets` reads)."""
    est = controller._estimator._c
    est.offsets.slope[0:2] = rng.normal(0, 0.05, 2).tolist()
    est.offsets.torque_offset[0:2] = rng.normal(0, 0.02, 2).tolist()
    est.offsets.pendulum[0:4] = np.concatenate([[rng.normal(0, 0.05)], rng.normal(0, 0.005, 3)]).tolist()


def _mismatch(controller, samples=40, seed=3, offsets=None):
    """The largest |C's feedforward − NumPy's| / |NumPy's| over random samples: the C law's u_raw with
    the offsets (`offsets`: the struct to pass, default the controller's) less its u_raw without them,
    from the same memory, against `numpy_feedforward`; and whether the memories agree after."""
    rng = np.random.default_rng(seed)
    worst, same_memory = 0.0, True
    for _ in range(samples):
        _random_offsets(controller, rng)
        x, target = random_state(rng), random_target(rng, path=rng.uniform() < 0.7)
        memory = ffi.new("sr_lqr_memory *")
        memory.integrals[0:2] = rng.normal(0, 0.1, 2).tolist()
        memory.kappa, memory.started = rng.uniform(-0.5, 0.5), 1
        plain, fed = ffi.new("sr_lqr_memory *", memory[0]), ffi.new("sr_lqr_memory *", memory[0])
        u, raw, raw_fed = np.empty(2), np.empty(2), np.empty(2)
        c_target = lqr.c_target(target)
        assert lib.sr_lqr_control(controller._c, controller._model._model, pointer(x), c_target, plain, pointer(u),
                                  pointer(raw)) == lib.SR_OK
        given = controller.offsets() if offsets is None else offsets
        assert lib.sr_lqr_control_offsets(controller._c, controller._model._model, pointer(x), c_target, given, fed,
                                          pointer(u), pointer(raw_fed)) == lib.SR_OK
        assert np.array_equal(u, np.clip(raw_fed, -0.5, 0.5))
        same_memory &= bytes(ffi.buffer(plain)) == bytes(ffi.buffer(fed))
        controller._memory.kappa = fed.kappa
        expected = controller.numpy_feedforward(target)
        worst = max(worst, np.abs(raw_fed - raw - expected).max() / np.abs(expected).max())
    return worst, same_memory


def test_the_c_feedforward_is_numpys_on_random_samples(controller):
    worst, same_memory = _mismatch(controller)
    assert worst <= 1e-12
    assert same_memory      # the feedforward moves no integral, curvature or tight weight


def test_the_comparison_fails_when_the_feedforward_is_dropped(controller):
    worst, _ = _mismatch(controller, samples=5, offsets=ffi.NULL)
    assert worst > 0.5


@pytest.mark.parametrize("table, entry", [("slope", "dz_up"), ("slope", "du_right"), ("pendulum", "dz")])
def test_the_comparison_fails_for_a_table_entry_perturbed(controller, table, entry):
    values = getattr(getattr(controller._c, table), entry)
    flat = ffi.cast("double *", values)
    n = ffi.sizeof(values) // ffi.sizeof("double")
    # a relative 1e-6 on every grid point's entry 3 (a non-zero column of each table)
    saved = [flat[i] for i in range(n)]
    step = {"dz_up": 12, "du_right": 2, "dz": 12}[entry]
    try:
        for i in range(3 if entry != "du_right" else 1, n, step):
            flat[i] = saved[i] * (1 + 1e-6)
        worst, _ = _mismatch(controller, samples=10)
    finally:
        for i in range(n):
            flat[i] = saved[i]
    assert worst > 1e-10


def test_without_the_offsets_the_law_is_sr_lqr_control(controller):
    # offsets NULL: the plain law, bit for bit
    rng = np.random.default_rng(5)
    x, target = random_state(rng), random_target(rng, path=True)
    out = []
    for call in (lambda m, u, r: lib.sr_lqr_control(controller._c, controller._model._model, pointer(x),
                                                    lqr.c_target(target), m, pointer(u), pointer(r)),
                 lambda m, u, r: lib.sr_lqr_control_offsets(controller._c, controller._model._model, pointer(x),
                                                            lqr.c_target(target), ffi.NULL, m, pointer(u), pointer(r))):
        u, r = np.empty(2), np.empty(2)
        assert call(ffi.new("sr_lqr_memory *"), u, r) == lib.SR_OK
        out.append(np.concatenate([u, r]))
    assert np.array_equal(out[0], out[1])


def test_sr_lqr_check_refuses_a_non_finite_table_entry_and_a_share_outside_0_1(controller):
    c = controller._c
    assert lib.sr_lqr_check(c) == lib.SR_OK
    saved = c.pendulum.du[0][2][1]
    c.pendulum.du[0][2][1] = float("nan")
    try:
        assert lib.sr_lqr_check(c) == lib.SR_ERR_NONFINITE
    finally:
        c.pendulum.du[0][2][1] = saved
    c.pendulum_share = 1.5
    try:
        assert lib.sr_lqr_check(c) == lib.SR_ERR_ARG
    finally:
        c.pendulum_share = GAINS.pendulum_feedforward
    assert lib.sr_lqr_check(c) == lib.SR_OK


def test_non_finite_offsets_are_refused_and_nothing_is_written(controller):
    rng = np.random.default_rng(6)
    x, target = random_state(rng), random_target(rng, path=True)
    offsets = ffi.new("sr_lqr_offsets *")
    offsets.pendulum[2] = float("inf")
    memory = ffi.new("sr_lqr_memory *")
    u = np.full(2, 7.0)
    assert lib.sr_lqr_control_offsets(controller._c, controller._model._model, pointer(x), lqr.c_target(target),
                                      offsets, memory, pointer(u), ffi.NULL) == lib.SR_ERR_NONFINITE
    assert np.all(u == 7.0) and memory.started == 0
