"""The sensor fit's whitening of a segment (runtime.identification.fit._Problem.covariances): the
innovations form of the covariance the process noise and the sensors' noise give its residuals."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.fit import DEFECT_FLOOR, free_parameters
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params


@pytest.fixture(scope="module")
def problem():
    """A 1 s log cut into 0.4 s segments (the last one longer) and its blocks at the start guess."""
    rng = np.random.default_rng(4)
    program = tuple(TorqueWindow(i * 0.25, (i + 1) * 0.25, float(rng.uniform(-0.3, 0.3)),
                                 float(rng.uniform(-0.15, 0.15))) for i in range(4))
    run = dataclasses.replace(SCENARIO, params=NOMINAL.replace(k_S=0.2), torques=program, steps=100)
    log = simulate_log(run, SensorSet.default(), seed=3)
    x, b = fitmod._start_guess(log, NOMINAL)
    prob = fitmod._Problem(log, NOMINAL, free_parameters("k_S,m_P"), 0.4, "rkmk4", x, b)
    return prob, prob.segment_blocks(prob.z0())


@pytest.fixture(scope="module")
def whitened(problem):
    """(W, C) of the first segment of a 1 s log (0.4 s segments), with its end-state difference:
    W applied to the identity and C = D + A Q Aᵀ from the noise map."""
    prob, blocks = problem
    blk = blocks[0]
    assert blk["next"] is not None
    A, Q = prob.noise_map(0, blk)
    floor = np.ones(len(blk["r"]))
    floor[blk["n_out"]:] = DEFECT_FLOOR
    C = np.diag(floor ** 2) + (A * Q) @ A.T
    W = prob.whiten(prob.covariances([blk])[0], np.eye(len(C)))
    return W, C


def test_the_whitening_turns_the_residuals_covariance_into_the_identity(whitened):
    W, C = whitened
    np.testing.assert_allclose(W @ C @ W.T, np.eye(len(C)), atol=1e-8)


def test_a_whitened_residual_depends_only_on_the_readings_up_to_its_own(whitened):
    W, _ = whitened
    assert np.count_nonzero(np.triu(W, 1)) == 0
    assert np.all(np.diag(W) > 0)



def rows_close(W, reference):
    """W within 1e-9 of the reference, relative to each row's largest entry (the end-state rows,
    in units of their floor, are far larger than the readings')."""
    scale = np.abs(reference).max(axis=1, keepdims=True)
    return bool(np.all(np.abs(W - reference) <= 1e-9 * (np.abs(reference) + scale)))


def test_the_segments_whitened_together_are_each_whitened_as_alone(problem):
    prob, blocks = problem
    whites = prob.covariances(blocks)
    assert len({len(w) for w in whites}) > 1       # segments of different lengths
    Ms = [np.hstack([blk["x"], blk["r"][:, None]] + ([blk["next"]] if blk["next"] is not None else []))
          for blk in blocks]
    together = prob.whiten_all(prob.stack_whitenings(whites), Ms)
    for white, M, W in zip(whites, Ms, together):
        assert rows_close(W, prob.whiten(white, M))
    packed = prob.stack_whitenings(whites)
    packed["K"] = packed["K"].copy()
    packed["K"][np.argmax(np.abs(packed["K"]))] *= 1 + 1e-6       # one gain entry, the largest
    planted = prob.whiten_all(packed, Ms)
    assert not all(rows_close(W, prob.whiten(white, M)) for white, M, W in zip(whites, Ms, planted))


@pytest.fixture(scope="module")
def at_the_truth():
    """A 10 s log of the nominal robot whose truth steps (and holds its torque disturbance) every
    10 ms while the IMU reads every 5 ms, and the fit's problem at the truth: the true robot, the
    true biases and the true states at the segments' starts, so that its residuals are the noise
    alone."""
    rng = np.random.default_rng(8)
    program = tuple(TorqueWindow(i * 0.25, (i + 1) * 0.25, float(rng.uniform(-0.3, 0.3)),
                                 float(rng.uniform(-0.15, 0.15))) for i in range(40))
    run = dataclasses.replace(SCENARIO, torques=program, steps=1000)
    assert run.dt == 2 / SensorSet.default().imu.rate
    log = simulate_log(run, SensorSet.default(), seed=5)
    truth = log.truth_states()
    x = truth[np.round(log.imu.t / run.dt).astype(int)]       # only the segments' starts are used
    return fitmod._Problem(log, NOMINAL, free_parameters("k_S"), 0.5, "rkmk4", x, log.truth_biases()[0])


def _yoke_gyro_variance(prob):
    """The whitened yoke-axis gyroscope readings' mean square (the IMU's x axis) at the IMU's
    samples between two of the truth's steps."""
    blocks = prob.segment_blocks(prob.z0())
    squares = []
    for s, (blk, white) in enumerate(zip(blocks, prob.covariances(blocks))):
        w, rows = prob.whiten(white, blk["r"]), blk["rows"]
        gyro_x = np.flatnonzero(rows["kind"] == 0)[::6]
        steps = prob.data.t[prob.starts[s] + rows["node"][gyro_x]] / SCENARIO.dt      # the truth's steps
        inside = gyro_x[np.abs(steps - np.round(steps)) > 0.25]
        squares.append(w[inside] ** 2)
    squares = np.concatenate(squares)
    assert len(squares) > 900
    return float(squares.mean())


def test_a_reading_inside_a_torque_period_is_whitened_to_unit_variance(at_the_truth):
    assert 0.88 < _yoke_gyro_variance(at_the_truth) < 1.12


def test_without_the_velocities_jump_inside_the_period_the_yoke_gyro_reads_too_much(at_the_truth, monkeypatch):
    monkeypatch.setattr(at_the_truth.data, "into", np.zeros_like(at_the_truth.data.into))
    assert _yoke_gyro_variance(at_the_truth) > 1.3
