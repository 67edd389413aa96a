"""`identify-coverage` tells a few far misses from intervals that are all too narrow: per entry the
spread of (estimate − truth)/σ, plain and robust, and the coverage over the fits that pass their
residual check."""
import numpy as np
import pytest

from runtime.identification import coverage


def trials(z, passed=None):
    """Seeded trials of one entry whose errors are z reported σ (σ = 0.1, truth 1)."""
    passed = [True] * len(z) if passed is None else passed
    return [{"seed": i, "names": ["k_Y"], "truth": [1.0], "estimate": [1.0 + 0.1 * e], "sigma": [0.1],
             "inside": [abs(e) <= 1.959964], "passed": ok} for i, (e, ok) in enumerate(zip(z, passed))]


def test_one_far_miss_raises_the_std_but_not_the_robust_std():
    z = list(np.random.default_rng(0).standard_normal(49)) + [9.0]
    spread = coverage.summarise(trials(z))["spread"]
    assert spread["std"][0] > 1.5
    assert spread["robust_std"][0] == pytest.approx(1.0, abs=0.25)


def test_intervals_all_too_narrow_raise_both():
    z = 2.0 * np.random.default_rng(0).standard_normal(50)
    spread = coverage.summarise(trials(z))["spread"]
    assert spread["std"][0] > 1.5 and spread["robust_std"][0] > 1.5


def test_the_coverage_over_passed_fits_leaves_out_the_fits_that_fail_their_residual_check():
    out = coverage.summarise(trials([0.0, 0.0, 5.0, 5.0], passed=[True, True, True, False]))
    assert out["coverage"] == [0.5]
    assert out["coverage_passed"] == [pytest.approx(2 / 3)]
