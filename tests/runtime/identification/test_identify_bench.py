"""The fit's Jacobian source (`identify(..., jacobian=)`) and `python -m runtime identify-bench`: the
fit with finite differences computed in C reaches the analytic fit's optimum without the analytic
sensitivities, and the bench records both fits, their ratio and the optima's distance."""
import json

import numpy as np
import pytest

from runtime.identification import bench
from runtime.identification.coverage import simulated_log
from runtime.identification.fit import IdentifyError, identify
from runtime.model import Model


@pytest.fixture(scope="module")
def state_log():
    return simulated_log("k_Y,k_P,m_P", 1.0, seed=3)


def test_a_finite_difference_fit_reaches_the_analytic_optimum_without_the_analytic_sensitivities(state_log,
                                                                                                monkeypatch):
    log, nominal, _ = state_log
    analytic = identify(log, nominal, "k_Y,k_P,m_P", full_state=True)

    def refuse(*args, **kwargs):
        raise AssertionError("the finite-difference fit called the analytic sensitivity")

    monkeypatch.setattr(Model, "step_param_jacobian", refuse)
    fd = identify(log, nominal, "k_Y,k_P,m_P", full_state=True, jacobian="fd")
    assert np.all(np.abs(fd.estimate - analytic.estimate) <= 1e-3 * analytic.sigma)
    np.testing.assert_allclose(fd.sigma, analytic.sigma, rtol=1e-4)


def test_an_unknown_jacobian_source_is_named(state_log):
    log, nominal, _ = state_log
    with pytest.raises(IdentifyError, match="jacobian"):
        identify(log, nominal, "k_Y", full_state=True, jacobian="complex-step")


def test_the_bench_keeps_both_fits_their_ratio_and_the_optima_distance(tmp_path, capsys):
    assert bench.main(["--params", "k_Y,m_P", "--params", "k_P", "--duration", "1", "--rounds", "1",
                       "--out", str(tmp_path)]) == 0
    (written,) = tmp_path.glob("*.json")
    record = json.loads(written.read_text())
    assert record["cpu"] and record["date"] and record["log"]["mode"] == "full-state"
    assert [r["params"] for r in record["fits"]] == ["k_Y,m_P", "k_P"]
    result = record["fits"][0]
    assert result["speedup_wall"] == result["fd"]["wall_s"] / result["analytic"]["wall_s"]
    a, f = np.array(result["analytic"]["estimate"]), np.array(result["fd"]["estimate"])
    assert result["max_difference_sigma"] == pytest.approx(np.max(np.abs(a - f) / result["analytic"]["sigma"]))
    assert "analytic faster by" in capsys.readouterr().out


def test_the_bench_keeps_every_rounds_cpu_time_and_ratio(state_log):
    log, nominal, _ = state_log
    result = bench.compare(log, nominal, "k_P", rounds=2, full_state=True)
    a, f = result["analytic"]["cpu_s_rounds"], result["fd"]["cpu_s_rounds"]
    assert len(a) == len(f) == 2 and result["analytic"]["cpu_s"] == min(a) and result["fd"]["cpu_s"] == min(f)
    assert result["speedup_cpu_rounds"] == [f[0] / a[0], f[1] / a[1]]


@pytest.mark.parametrize("k_Y", [0.04, 0.0], ids=["central", "one-sided at the bound"])
def test_the_finite_difference_acceleration_sensitivity_is_the_analytic_one(state_log, k_Y):
    from runtime.identification.sensitivity import accel_sensitivity
    from runtime.param_derivatives import PARAMETER_NAMES
    log, nominal, _ = state_log
    model = Model(nominal.replace(k_Y=k_Y))
    X, U = log.truth_states()[:5], log.torque_at(log.truth.t[:5])
    idx = [PARAMETER_NAMES.index(n) for n in ("m_P", "k_Y", "j_mY", "c_P_z")]
    fd, exact = accel_sensitivity(model, X, U, idx, "fd"), accel_sensitivity(model, X, U, idx, "analytic")
    scale = np.abs(exact).max(axis=(0, 1))
    assert np.all(np.abs(fd - exact).max(axis=(0, 1)) <= 1e-6 * scale)
