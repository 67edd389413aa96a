"""`identify-coverage` records the combinations a sensor log determines (the total mass, m_P c_P, the
hinge inertias, the dampings): their error against the truth, whether it is within the 2 % target
and whether the truth lies in the estimate's 95 % region."""
import types

import numpy as np
import pytest

from runtime.identification import coverage
from runtime.param_derivatives import PARAMETER_NAMES, PI_NAMES, inertial_parameters
from runtime.scenario import load_scenario

ROBOT = load_scenario("battery-geared").params


def fake_fit(params, names, sigma):
    return types.SimpleNamespace(names=tuple(names), params=params, sigma=np.asarray(sigma, dtype=float),
                                 correlation=np.eye(len(names)))


def test_the_combinations_are_the_robots_total_mass_first_moment_hinge_inertias_and_dampings():
    c = coverage.combinations_of(ROBOT.as_array())
    pi = dict(zip(PI_NAMES, inertial_parameters(ROBOT)))
    assert c["m_S + m_Y + m_P"][0] == pytest.approx(ROBOT.m_S + ROBOT.m_Y + ROBOT.m_P)
    np.testing.assert_allclose(c["m_P c_P"], ROBOT.m_P * np.asarray(ROBOT.c_P))
    assert c["JO_P_yy"][0] == pytest.approx(pi["JO_P_yy"])
    assert c["JO_Y_xx + JO_P_zz + n_Y^2 j_mY"][0] == pytest.approx(pi["JO_Y_xx"] + pi["JO_P_zz"]
                                                                   + ROBOT.n_Y ** 2 * ROBOT.j_mY)
    assert [c[k][0] for k in ("k_S", "k_Y", "k_P")] == [ROBOT.k_S, ROBOT.k_Y, ROBOT.k_P]


def test_a_combination_is_scored_by_its_relative_error_and_its_95_percent_region():
    truth = ROBOT.replace(m_P=ROBOT.m_P * 1.03)
    sigma_m = 0.03 * ROBOT.m_P / 1.5            # the 3 % error at 1.5 σ: inside
    out = coverage.combination_errors(fake_fit(ROBOT, ["m_P", "k_Y"], [sigma_m, 1e-3]), truth)
    first = out["m_P c_P"]
    assert first["relative_error"] == pytest.approx(0.03 / 1.03, rel=1e-6)
    assert first["within"] is False and first["inside"] is True
    assert out["k_Y"]["relative_error"] == 0 and out["k_Y"]["within"] is True
    # at 3 σ the truth is outside; a combination no free entry moves is not scored
    out = coverage.combination_errors(fake_fit(ROBOT, ["m_P", "k_Y"], [sigma_m / 2, 1e-3]), truth)
    assert out["m_P c_P"]["inside"] is False and out["k_S"]["inside"] is None


def test_the_summary_counts_each_combination_over_the_fits_that_move_it():
    trial = {"seed": 0, "names": ["k_Y"], "truth": [1.0], "estimate": [1.0], "sigma": [0.1], "inside": [True],
             "passed": True,
             "combinations": {"k_Y": {"inside": False, "within": True}, "k_S": {"inside": None, "within": True}}}
    result = coverage.summarise([trial, dict(trial, seed=1, combinations={
        "k_Y": {"inside": True, "within": False}, "k_S": {"inside": None, "within": True}})])
    assert result["combinations"] == {"k_Y": {"coverage": 0.5, "within": 0.5, "fits": 2}}
