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



def test_the_segments_whitened_together_are_each_whitened_as_alone(problem):
    prob, blocks = problem
    whites = prob.covariances(blocks)
    assert len({len(w) for w in whites}) > 1       # segments of different lengths share the padding
    Ms = [np.hstack([blk["x"], blk["r"][:, None]] + ([blk["next"]] if blk["next"] is not None else []))
          for blk in blocks]
    together = prob.whiten_all(prob.stack_whitenings(whites), Ms)
    for white, M, W in zip(whites, Ms, together):
        np.testing.assert_allclose(W, prob.whiten(white, M), rtol=1e-9, atol=1e-9 * np.abs(W).max())
