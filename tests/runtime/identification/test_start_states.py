"""The sensor fit's start states: each segment's start is fitted alone from its readings and the
start guess (the EKF's estimate, weighed by the filter's standard deviations), so that an error in
one segment's guess stays in that segment."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.fit import free_parameters, heading_of
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet
from runtime.state import IDX_RS

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


TURNED = (2, 3, 4)          # the segments whose guess is turned about the vertical
TURN = 0.3                  # rad


@pytest.fixture(scope="module")
def longer_guess():
    program = tuple(TorqueWindow(0.25 * k, 0.25 * (k + 1), 0.3 * (-1) ** k, 0.15 * (-1) ** (k // 2)) for k in range(8))
    run = dataclasses.replace(SCENARIO, torques=program, steps=int(round(2.0 / SCENARIO.dt)))
    log = simulate_log(run, SensorSet.default(), seed=5)
    x, b, sigma = fitmod._start_guess(log, NOMINAL, with_sigma=True)
    return log, x, b, sigma


def aligned_starts(longer_guess, align):
    """(model, the guesses before the turn, the starts after `fit_starts` and, with `align`,
    `align_headings`): 2 s in eight segments, the guesses of segments TURNED turned by TURN about
    the vertical and given a heading σ of 0.3 rad, the others one of 0.005 rad."""
    log, x, b, sigma = longer_guess
    prob = fitmod._Problem(log, NOMINAL, NAMES, SEGMENT, "rkmk4", x, b, x_sigma=sigma)
    model = prob.model(prob.theta_start)
    before = prob.xref.copy()
    prob.xsig[:, :3] = 0.005
    for s in TURNED:
        prob.xsig[s, :3] = 0.3
        gamma = prob.xref[s][IDX_RS].reshape(3, 3)[2]      # the vertical in the shell's frame
        prob.xref[s] = model.retract(prob.xref[s], np.r_[TURN * gamma, np.zeros(9)])
    prob.fit_starts(prob.z0())
    if align:
        prob.align_headings(prob.z0())
    return model, before, prob.xref


def heading_errors(model, before, after):
    """The heading [rad] of each start against its guess before the turn (about the vertical)."""
    return np.array([heading_of(a[IDX_RS].reshape(3, 3) @ b[IDX_RS].reshape(3, 3).T) for a, b in zip(after, before)])


def test_aligned_headings_bring_an_uncertain_stretch_back_to_its_sure_neighbours(longer_guess):
    model, before, after = aligned_starts(longer_guess, align=True)
    errors = heading_errors(model, before, after)
    # fitted alone the turned segments keep most of the turn (below); aligned, they follow their neighbours
    assert np.abs(errors).max() < 0.05, errors
    _, _, alone = aligned_starts(longer_guess, align=False)
    assert np.abs(heading_errors(model, before, alone)[list(TURNED)]).min() > 0.2
