"""The regressor's linear least-squares first guess (runtime.identification.first_guess): from a
smoothed state estimate it lands nearer the truth than the nominal robot, inside the fit's bounds,
and the fit starts there unless told to start at the nominal robot."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.first_guess import regressor_guess, smoothed_motion
from runtime.param_derivatives import PARAMETER_NAMES
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params
TRUTH = NOMINAL.replace(k_S=0.2, k_Y=0.03, k_P=0.12, m_P=1.1)
NAMES = ("k_S", "k_Y", "k_P", "m_P")


def torques(duration, seed=1, period=0.25):
    rng = np.random.default_rng(seed)
    return tuple(TorqueWindow(i * period, (i + 1) * period, float(rng.uniform(-0.3, 0.3)),
                              float(rng.uniform(-0.15, 0.15))) for i in range(int(round(duration / period))))


@pytest.fixture(scope="module")
def log():
    run = dataclasses.replace(SCENARIO, params=TRUTH, torques=torques(2.0), steps=int(round(2.0 / SCENARIO.dt)))
    return simulate_log(run, SensorSet.default(), seed=2)


def truth_of(names, params=TRUTH):
    return np.array([params.as_array()[PARAMETER_NAMES.index(n)] for n in names])


def relative_error(theta, names):
    truth = truth_of(names)
    return np.abs(theta - truth) / np.abs(truth)


def bounds(names):
    lo, hi = zip(*(fitmod.bounds_of(n, NOMINAL, names) for n in names))
    return np.array(lo), np.array(hi)


def test_the_guess_from_the_logs_smoothed_truth_lands_nearer_the_truth_than_the_nominal_robot(log):
    X = log.truth_states()
    guess = regressor_guess(log.truth.t, X, log.torque_at(log.truth.t), NOMINAL, NAMES, bounds(NAMES))
    assert np.linalg.norm(relative_error(guess.theta, NAMES)) < 0.9 * np.linalg.norm(relative_error(guess.nominal, NAMES)), \
        (guess.theta, truth_of(NAMES))


def test_the_guess_from_the_ekfs_estimate_of_a_sensor_log_lands_nearer_the_truth_than_the_nominal_robot(log):
    x_guess, bias = fitmod._start_guess(log, NOMINAL)
    prob = fitmod._Problem(log, NOMINAL, NAMES, 0.5, "rkmk4", x_guess, bias)
    guess = fitmod.first_guess(log, NOMINAL, NAMES, prob, False, x_guess)
    assert np.linalg.norm(relative_error(guess.theta, NAMES)) < 0.9 * np.linalg.norm(relative_error(guess.nominal, NAMES)), \
        (guess.theta, truth_of(NAMES))


def test_a_guess_outside_the_bounds_is_clipped_into_them(log):
    lo, hi = bounds(NAMES)
    hi = hi.copy()
    hi[NAMES.index("m_P")] = 1.0            # the truth, 1.1, lies beyond
    guess = regressor_guess(log.truth.t, log.truth_states(), log.torque_at(log.truth.t), NOMINAL, NAMES, (lo, hi))
    assert guess.theta[NAMES.index("m_P")] < 1.0


@pytest.mark.parametrize("start", ["regressor", "nominal"])
def test_the_fit_starts_from_the_guess_unless_told_to_start_at_the_nominal_robot(log, start):
    fit = fitmod.identify(log, NOMINAL, NAMES, full_state=True, max_nfev=1, start=start)
    nominal = truth_of(NAMES, NOMINAL)
    if start == "nominal":
        assert np.array_equal(fit.start, nominal)
    else:
        assert np.linalg.norm(relative_error(fit.start, NAMES)) < 0.9 * np.linalg.norm(relative_error(nominal, NAMES))


def test_an_unknown_start_is_named(log):
    with pytest.raises(fitmod.IdentifyError, match="start"):
        fitmod.identify(log, NOMINAL, NAMES, full_state=True, start="truth")


def test_the_smoothing_keeps_a_linear_velocity_and_differentiates_it_exactly():
    t = 0.005 * np.arange(200)
    x = np.tile(SCENARIO.x0, (200, 1))
    from runtime.state import IDX_NU
    x[:, IDX_NU] = np.outer(t, [1.0, -2.0, 0.5, 3.0, -1.0])
    xs, nudot, _ = smoothed_motion(t, x)
    assert np.allclose(xs[:, IDX_NU], x[:, IDX_NU]) and np.allclose(nudot, [1.0, -2.0, 0.5, 3.0, -1.0])


def test_the_inertial_parameters_of_a_parameter_vector_are_those_of_its_robot():
    from runtime.identification.first_guess import _pi_of
    from runtime.param_derivatives import inertial_parameters
    from runtime.params import Params

    nominal = load_scenario("battery-geared").params
    for seed in range(5):
        # masses, centres of mass, dampings and rotor inertias moved; the tensors kept physical
        moved = np.array([n[:2] in ("m_", "c_", "k_", "j_") for n in PARAMETER_NAMES])
        p = nominal.as_array() * np.where(moved, np.random.default_rng(seed).uniform(0.7, 1.3, len(moved)), 1.0)
        robot = Params.from_array(p)
        np.testing.assert_array_equal(_pi_of(p), inertial_parameters(robot))


def _dpi_error(dpi_of, p, idx):
    """The largest difference of dpi_of(p, idx) from the central differences of `_pi_of`, relative
    to the derivative's largest entry (π is a cubic polynomial in p: the differences are exact to
    rounding but for h² times its third derivative)."""
    from runtime.identification.first_guess import _pi_of

    d = dpi_of(p, idx)
    fd = np.empty_like(d)
    for c, i in enumerate(idx):
        h = 1e-5 * max(abs(p[i]), 1e-2)
        hi, lo = p.copy(), p.copy()
        hi[i] += h
        lo[i] -= h
        fd[:, c] = (_pi_of(hi) - _pi_of(lo)) / (2 * h)
    return np.max(np.abs(d - fd)) / np.max(np.abs(fd))


def _moved_robot(seed):
    """The battery-geared robot's vector with every entry moved by up to ±30 % (not checked: π needs none)."""
    p = NOMINAL.as_array()
    return p * np.random.default_rng(seed).uniform(0.7, 1.3, len(p)) + 1e-3 * (p == 0)


def test_the_first_guess_derivative_of_the_inertial_parameters_equals_their_differences():
    from runtime.identification.first_guess import _dpi_of

    idx = list(range(len(PARAMETER_NAMES)))
    for seed in range(5):
        assert _dpi_error(_dpi_of, _moved_robot(seed), idx) < 1e-8


def test_the_derivative_check_fails_for_a_slightly_wrong_derivative():
    from runtime.identification.first_guess import _dpi_of

    idx = [PARAMETER_NAMES.index(n) for n in ("m_P", "c_P_x", "c_P_z", "J_P_yy")]

    def perturbed(p, cols):          # ∂J_O/∂c off by a part in 10⁶
        d = _dpi_of(p, cols).copy()
        d[:, 1:3] *= 1 + 1e-6
        return d

    assert _dpi_error(perturbed, _moved_robot(0), idx) > 1e-8
