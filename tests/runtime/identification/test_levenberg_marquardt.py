"""The sensor-log fit's solver (runtime.identification.fit.levenberg_marquardt): Levenberg–Marquardt
on the sparse Jacobian's normal equations reaches SciPy's least-squares optimum, keeps to its
bounds, and treats a candidate the model refuses as a rejected step."""
import numpy as np
import pytest
import scipy.optimize
import scipy.sparse

from runtime.identification.fit import IdentifyError, levenberg_marquardt

T = np.linspace(0.0, 4.0, 40)
Y = 2.5 * np.exp(-1.3 * T) + 0.4 * np.sin(3.0 * T) + 0.01 * np.random.default_rng(0).standard_normal(T.size)


def residuals(z):
    a, k, b = z
    return a * np.exp(-k * T) + b * np.sin(3.0 * T) - Y


def jacobian(z):
    a, k, b = z
    e = np.exp(-k * T)
    return np.column_stack([e, -a * T * e, np.sin(3.0 * T)])


def evaluate(z):
    return residuals(z), scipy.sparse.csr_matrix(jacobian(z))


def test_it_reaches_scipys_optimum():
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    sol = levenberg_marquardt(evaluate, np.array([1.0, 0.3, 0.0]), lo, hi, 100)
    ref = scipy.optimize.least_squares(residuals, [1.0, 0.3, 0.0], jac=jacobian, xtol=1e-12, ftol=1e-12)
    assert sol.status in (2, 3)
    np.testing.assert_allclose(sol.x, ref.x, rtol=1e-6)


def test_a_bound_holds_and_the_optimum_on_it_is_scipys():
    lo, hi = np.array([-np.inf, -np.inf, -np.inf]), np.array([np.inf, 1.0, np.inf])
    sol = levenberg_marquardt(evaluate, np.array([1.0, 0.3, 0.0]), lo, hi, 200)
    ref = scipy.optimize.least_squares(residuals, [1.0, 0.3, 0.0], jac=jacobian, bounds=(lo, hi), xtol=1e-12,
                                       ftol=1e-12)
    assert sol.x[1] <= 1.0
    np.testing.assert_allclose(sol.x, ref.x, rtol=1e-5)


def test_a_refused_candidate_is_a_rejected_step_not_an_error():
    def refusing(z):
        if z[1] > 1.0:          # the "model" refuses these robots, as Model refuses an unphysical one
            raise IdentifyError("refused")
        return evaluate(z)

    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    sol = levenberg_marquardt(refusing, np.array([1.0, 0.3, 0.0]), lo, hi, 200)
    assert sol.x[1] <= 1.0
    assert 0.5 * np.sum(residuals(sol.x) ** 2) < 0.5 * np.sum(residuals(np.array([1.0, 0.3, 0.0])) ** 2)


def test_it_stops_at_the_evaluation_budget():
    calls = []

    def counted(z):
        calls.append(1)
        return evaluate(z)

    sol = levenberg_marquardt(counted, np.array([1.0, 0.3, 0.0]), np.full(3, -np.inf), np.full(3, np.inf), 3)
    assert len(calls) == sol.nfev <= 3 and sol.status == 0


@pytest.mark.parametrize("start", [[0.5, 3.0, 1.0], [5.0, 0.01, -1.0]])
def test_it_converges_from_far_starts(start):
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    sol = levenberg_marquardt(evaluate, np.array(start), lo, hi, 200)
    ref = scipy.optimize.least_squares(residuals, [1.0, 0.3, 0.0], jac=jacobian, xtol=1e-12, ftol=1e-12)
    np.testing.assert_allclose(sol.x, ref.x, rtol=1e-5)



def test_its_shift_is_the_step_to_the_exact_optimum_in_sigmas_on_a_linear_problem():
    # for a linear least-squares problem the Gauss-Newton step is exact: the shift at a point is
    # the largest |optimum - point| / sigma of the watched entries, numpy's lstsq and inverse
    # giving both independently
    rng = np.random.default_rng(1)
    A, y = rng.standard_normal((30, 4)), rng.standard_normal(30)
    z0 = np.array([3.0, -2.0, 1.0, 0.5])
    best = np.linalg.lstsq(A, y, rcond=None)[0]
    sigma = np.sqrt(np.diag(np.linalg.inv(A.T @ A)))
    for watch in (None, 2):
        sol = levenberg_marquardt(lambda z: (A @ z - y, scipy.sparse.csr_matrix(A)), z0, np.full(4, -np.inf),
                                  np.full(4, np.inf), 1, watch=watch)
        assert sol.nfev == 1 and sol.status == 0
        n = 4 if watch is None else watch
        np.testing.assert_allclose(sol.shift, np.max(np.abs(best - z0)[:n] / sigma[:n]), rtol=1e-9)


def test_it_stops_once_the_shift_is_below_its_tolerance():
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    start = np.array([1.0, 0.3, 0.0])
    full = levenberg_marquardt(evaluate, start, lo, hi, 200)
    early = levenberg_marquardt(evaluate, start, lo, hi, 200, stol=0.05)
    assert early.status == 1 and early.message.startswith("converged")
    assert early.shift <= 0.05 < levenberg_marquardt(evaluate, start, lo, hi, early.nfev - 1).shift
    assert early.nfev < full.nfev
    sigma = np.sqrt(np.diag(np.linalg.inv(jacobian(full.x).T @ jacobian(full.x))))
    assert np.all(np.abs(early.x - full.x) <= 0.06 * sigma)
