"""The sensor fit's start states: each segment's start is fitted alone from its readings and the
start guess (the EKF's estimate, weighed by the filter's standard deviations), so that an error in
one segment's guess stays in that segment."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.fit import free_parameters
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params
NAMES = free_parameters("k_Y")
SEGMENT = 0.25


@pytest.fixture(scope="module")
def guess():
    program = (TorqueWindow(0.0, 0.25, 0.3, -0.1), TorqueWindow(0.25, 0.5, -0.2, 0.15))
    run = dataclasses.replace(SCENARIO, torques=program, steps=int(round(0.5 / SCENARIO.dt)))
    log = simulate_log(run, SensorSet.default(), seed=3)
    x, b, sigma = fitmod._start_guess(log, NOMINAL, with_sigma=True)
    return log, x, b, sigma


def fitted_starts(guess, sigma, turn):
    """The start states after `fit_starts`, the first segment's guess turned by `turn` rad about
    the vertical (the heading, which one segment's readings do not determine)."""
    log, x, b, _ = guess
    prob = fitmod._Problem(log, NOMINAL, NAMES, SEGMENT, "rkmk4", x, b, x_sigma=sigma)
    model = prob.model(prob.theta_start)
    turned = np.zeros(12)
    turned[2] = turn
    prob.xref[0] = model.retract(prob.xref[0], turned)
    guessed = prob.xref.copy()
    prob.fit_starts(prob.z0())
    return model, guessed, prob.xref


def test_an_error_in_one_segments_guess_does_not_pass_to_the_next(guess):
    model, guessed, fitted = fitted_starts(guess, guess[3], 0.3)
    # the second segment keeps its own (right) heading; a chain from the first's end would carry 0.3 rad
    assert abs(model.local(guessed[1], fitted[1])[2]) < 0.03
    assert abs(model.local(guessed[0], fitted[0])[2]) < 0.03


def test_the_guess_weighs_each_start_by_the_filters_standard_deviations(guess):
    tight = np.full_like(guess[3], 1e-9)
    model, guessed, fitted = fitted_starts(guess, tight, 0.0)
    # a guess known to 1e-9 holds its start; the readings alone move it further
    assert np.abs(model.local(guessed, fitted)).max() < 1e-6
    _, _, free = fitted_starts(guess, None, 0.0)
    assert np.abs(model.local(guessed, free)).max() > 1e-4


def test_the_joint_fit_starts_once_the_start_states_agree_with_the_parameters_held(guess, monkeypatch):
    log = guess[0]
    calls = []
    solve = fitmod.levenberg_marquardt

    def recording(evaluate, z0, lo, hi, max_nfev, **options):
        r, J = evaluate(z0)
        sol = solve(evaluate, z0, lo, hi, max_nfev, **options)
        calls.append((z0.copy(), 0.5 * float(r @ r), abs(J[:, :1]).max(), sol))
        return sol

    monkeypatch.setattr(fitmod, "levenberg_marquardt", recording)
    fitmod.identify(log, NOMINAL, "k_Y", segment=SEGMENT, max_nfev=2)
    (z0, cost0, theta_column, first), (z1, _, theta_column_joint, _) = calls[:2]
    # the first stage moves the states and biases only, and lowers the cost; the joint fit starts there
    assert theta_column == 0 and first.x[0] == z0[0] and first.cost < cost0
    np.testing.assert_array_equal(z1[1:], first.x[1:])
    assert theta_column_joint > 0
