"""The sensor fit's QR compression of a segment's whitened block (runtime.identification.fit
`_upper_triangle`, `_Problem.assemble`): the R of SciPy's `qr(mode="r")`, bit for bit, taken to as
many rows as the block's columns; the compressed blocks' places in the sparse Jacobian."""
import dataclasses

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.fit import _upper_triangle, free_parameters
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet
from runtime.state import NE


def scipy_rows(M, n):
    """SciPy's R of M, zero rows appended below a short M, its first n rows."""
    R = scipy.linalg.qr(M, mode="r", check_finite=False)[0]
    return np.vstack([R, np.zeros((max(0, n - R.shape[0]), M.shape[1]))])[:n]


@pytest.mark.parametrize("rows", [300, 37, 20])
def test_the_compressions_triangle_is_scipys_bit_for_bit(rows):
    M = np.random.default_rng(rows).standard_normal((rows, 37))
    assert np.array_equal(_upper_triangle(M.copy(), 37), scipy_rows(M, 37))


def test_the_comparison_sees_one_entry_below_the_diagonal():
    M = np.random.default_rng(1).standard_normal((300, 37))
    R = _upper_triangle(M.copy(), 37)
    R[5, 2] = 1e-300                    # a reflector's entry left below the diagonal
    assert not np.array_equal(R, scipy_rows(M, 37))


def coo_jacobian(prob):
    """`assemble`'s Jacobian as the COO assembly that its cached CSR structure replaced: segment s's
    compressed rows R (m, m) on its columns (θ, b, its start, the next's), a row for its remaining
    residual, then the gauge's diagonal; the values those of J at the same places."""
    rows, cols, row0 = [], [], 0
    for s in range(prob.S):
        c = np.concatenate([np.arange(prob.nf + 6), prob.nf + 6 + NE * s + np.arange(NE)]
                           + ([prob.nf + 6 + NE * (s + 1) + np.arange(NE)] if s + 1 < prob.S else []))
        rr, cc = np.meshgrid(row0 + np.arange(len(c)), c, indexing="ij")
        rows.append(rr.ravel())
        cols.append(cc.ravel())
        row0 += len(c) + 1
    rows.append(row0 + np.arange(NE))
    cols.append(prob.nf + 6 + np.arange(NE))
    return np.concatenate(rows), np.concatenate(cols)


@pytest.fixture(scope="module")
def assembled():
    """The problem of a 1 s log in 0.4 s segments and its Jacobian at the start."""
    rng = np.random.default_rng(4)
    program = tuple(TorqueWindow(i * 0.25, (i + 1) * 0.25, float(rng.uniform(-0.3, 0.3)),
                                 float(rng.uniform(-0.15, 0.15))) for i in range(4))
    scenario = load_scenario("battery-geared")
    run = dataclasses.replace(scenario, params=scenario.params.replace(k_S=0.2), torques=program, steps=100)
    log = simulate_log(run, SensorSet.default(), seed=3)
    x, b = fitmod._start_guess(log, scenario.params)
    prob = fitmod._Problem(log, scenario.params, free_parameters("k_S,m_P"), 0.4, "rkmk4", x, b)
    return prob, prob.assemble(prob.z0())[1]


def test_the_jacobians_cached_structure_is_the_coo_assemblys(assembled):
    prob, J = assembled
    rows, cols = coo_jacobian(prob)
    coo = scipy.sparse.csr_matrix((J.data, (rows, cols)), shape=J.shape)
    assert np.array_equal(J.toarray(), coo.toarray())
    assert np.array_equal(J.indices, coo.indices) and np.array_equal(J.indptr, coo.indptr)
    cols = cols.copy()
    cols[len(cols) // 2] += 1                       # one entry one column off
    planted = scipy.sparse.csr_matrix((J.data, (rows, cols)), shape=J.shape)
    assert not np.array_equal(J.toarray(), planted.toarray())
