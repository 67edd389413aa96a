"""The sensor fit's QR compression of a segment's whitened block (runtime.identification.fit
`_upper_triangle`, `_Problem.assemble`): the R of SciPy's `qr(mode="r")`, bit for bit, taken to as
many rows as the block's columns."""
import numpy as np
import pytest
import scipy.linalg

from runtime.identification.fit import _upper_triangle


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
