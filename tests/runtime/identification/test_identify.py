"""The identification fit (runtime.identification.fit, python -m runtime identify): it recovers
planted parameters within its intervals, refuses a log of another robot by its residual check,
respects the physical bounds and says when it ends on one, and names what is wrong with a bad log
or parameter set."""
import dataclasses
import json

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.estimation.logs import write_log
from runtime.identification import fit as fitmod
from runtime.identification import identify as cli
from runtime.identification.fit import IdentifyError, free_parameters, identify
from runtime.param_derivatives import PARAMETER_NAMES
from runtime.params import Params
from runtime.scenario import TorqueWindow, load_scenario, load_robot
from runtime.sensor_set import SensorSet

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params
TRUTH = NOMINAL.replace(k_S=0.2, k_Y=0.03, k_P=0.12, m_P=1.1)


def torques(duration, seed=1, period=0.25):
    """Piecewise-constant random torques: a rich enough program for a short fit."""
    rng = np.random.default_rng(seed)
    return tuple(TorqueWindow(i * period, (i + 1) * period, float(rng.uniform(-0.3, 0.3)),
                              float(rng.uniform(-0.15, 0.15))) for i in range(int(round(duration / period))))


def log_of(params, duration, seed=2, program=None):
    run = dataclasses.replace(SCENARIO, params=params, torques=torques(duration) if program is None else program,
                              steps=int(round(duration / SCENARIO.dt)))
    return simulate_log(run, SensorSet.default(), seed=seed)


@pytest.fixture(scope="module")
def short_log():
    return log_of(TRUTH, 1.0)


@pytest.fixture(scope="module")
def state_log():
    return log_of(TRUTH, 2.0)


def truth_of(names, params=TRUTH):
    return np.array([params.as_array()[PARAMETER_NAMES.index(n)] for n in names])


def test_a_full_state_fit_recovers_the_planted_parameters_within_its_intervals(state_log):
    fit = identify(state_log, NOMINAL, "k_S,k_Y,k_P,m_P", full_state=True)
    truth = truth_of(fit.names)
    assert np.all(fit.identified) and fit.rank == 4
    assert np.all(np.abs(fit.estimate - truth) <= 3 * fit.sigma), (fit.estimate, truth, fit.sigma)
    assert abs(fit.nominal[3] - truth[3]) > 3 * fit.sigma[3]      # m_P: the nominal value would fail the check
    assert fit.residual_check["passed"]


def test_a_sensor_log_fit_recovers_the_planted_parameters_within_its_intervals(short_log):
    fit = identify(short_log, NOMINAL, ["m_P", "k_Y"], segment=0.25)
    truth = truth_of(fit.names)
    assert np.all(np.abs(fit.estimate - truth) <= 3 * fit.sigma), (fit.estimate, truth, fit.sigma)
    assert abs(fit.nominal[0] - truth[0]) > 3 * fit.sigma[0]      # m_P: the nominal value would fail the check
    assert fit.residual_check["passed"], fit.residual_check
    assert np.all(np.abs(fit.biases[:3] - short_log.meta["truth_bias"]["gyro"]) <= 3 * fit.bias_sigma[:3])
    assert fit.converged and fit.shift <= fitmod.CONVERGED_SHIFT, fit.message


def test_a_sensor_fit_stopped_by_its_budget_says_it_did_not_converge(short_log):
    fit = identify(short_log, NOMINAL, ["m_P", "k_Y"], segment=0.25, max_nfev=2)
    assert not fit.converged and fit.shift > fitmod.CONVERGED_SHIFT
    assert "NOT converged" in fit.message
    assert "did not converge" in cli.report_md(fit, "log")
    assert cli.summary(fit, 0.0, "log", "robot")["converged"] is False


def test_a_fit_of_another_robots_log_fails_its_residual_check(state_log):
    other = log_of(TRUTH.replace(m_P=1.6, c_P=(0.0, 0.0, -0.2)), 2.0)
    same = identify(state_log, TRUTH, ["k_Y", "k_P"], full_state=True)
    wrong = identify(other, TRUTH, ["k_Y", "k_P"], full_state=True)
    assert same.residual_check["passed"], same.residual_check
    assert not wrong.residual_check["passed"] and wrong.residual_check["rms"] > 1.5


def test_the_total_mass_is_reported_as_a_combination_when_every_mass_is_free():
    # the paper's robot: the yoke's centre of mass at the shell's centre, so m_S and m_Y enter only summed
    paper = Params.paper_simulation()
    truth = paper.replace(m_S=2.5, m_Y=13.0)
    run = dataclasses.replace(SCENARIO, params=truth, torques=torques(2.0), steps=200)
    fit = identify(simulate_log(run, SensorSet.default(), seed=2), paper, "m_S,m_Y,m_P", full_state=True)
    assert list(fit.identified) == [False, False, True] and fit.rank == 2
    total = next(c for c in fit.combinations if c["name"] == "m_S + m_Y + m_P")
    assert total["identified"] and abs(total["value"] - truth.m_R) <= 3 * total["sigma"]
    assert set(fit.null_directions[0]) == {"m_S", "m_Y"}


def test_a_fit_that_ends_on_a_bound_says_so(state_log, monkeypatch):
    # truth k_Y = 0.03 but the yoke's damping is asked to absorb a heavier claimed pendulum: it wants k_Y < 0
    claimed = NOMINAL.replace(k_S=0.2, k_P=0.12, m_P=1.1, J_Y=np.asarray(NOMINAL.J_Y) * 3)
    fit = identify(state_log, claimed, ["k_Y"], full_state=True)
    assert fit.on_bound == {"k_Y": "lower"} and fit.estimate[0] >= 0
    monkeypatch.setattr(fitmod, "bounds_of", lambda entry, params, free=(): (-np.inf, np.inf))
    with pytest.raises(IdentifyError, match="k_Y: must be >= 0"):       # what the bound held back
        identify(state_log, claimed, ["k_Y"], full_state=True)


@pytest.mark.parametrize("names, message", [
    ("", "name at least one parameter"),
    ("m_Q", "'m_Q' is not a parameter"),
    ("c_P_w", "'c_P_w' is not a parameter"),
    ("r", "'r' is a constant of the robot's kind"),
    ("n_Y", "'n_Y' is a constant of the robot's kind"),
    ("c_P,c_P_z", "'c_P_z' named twice"),
])
def test_impossible_parameter_sets_are_named(names, message):
    with pytest.raises(IdentifyError, match=message):
        free_parameters(names)


def test_field_names_free_all_their_entries():
    assert free_parameters("c_P,k_Y") == ("c_P_x", "c_P_y", "c_P_z", "k_Y")


def test_bad_logs_are_named(short_log):
    with pytest.raises(IdentifyError, match="at least 0.5 s"):
        identify(log_of(TRUTH, 0.2), NOMINAL, "k_Y")
    still = log_of(TRUTH, 1.0, program=())
    with pytest.raises(IdentifyError, match="every torque is zero"):
        identify(still, NOMINAL, "k_Y")
    without_truth = dataclasses.replace(short_log, truth=None)
    with pytest.raises(IdentifyError, match="needs the log's truth table"):
        identify(without_truth, NOMINAL, "k_Y", full_state=True)
    with pytest.raises(IdentifyError, match="segment"):
        identify(short_log, NOMINAL, "k_Y", segment=0.0)


def test_the_command_writes_the_report_and_a_robot_file_scenarios_read(state_log, tmp_path, capsys):
    write_log(state_log, tmp_path / "log", formats=("csv",))
    out = tmp_path / "fit"
    status = cli.main([str(tmp_path / "log"), "--params", "k_S,k_Y,k_P,m_P", "--full-state", "--out", str(out),
                       "--quiet"])
    assert status == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(cli.REPORT_FILES)
    robot = load_robot(out / "params.toml")
    summary = json.loads((out / "summary.json").read_text())
    assert robot.m_P == pytest.approx(summary["parameters"][3]["estimate"])
    assert "Residual check passes" in (out / "report.md").read_text()


def test_the_command_exits_2_naming_a_bad_parameter(state_log, tmp_path, capsys):
    write_log(state_log, tmp_path / "log", formats=("csv",))
    assert cli.main([str(tmp_path / "log"), "--params", "m_Q", "--out", str(tmp_path / "fit"), "--quiet"]) == 2
    assert "'m_Q' is not a parameter" in capsys.readouterr().err


def test_the_coverage_command_counts_the_fits_whose_interval_holds_the_truth(tmp_path):
    from runtime.identification import coverage
    out = tmp_path / "coverage.json"
    assert coverage.main(["--params", "k_Y,m_P", "--fits", "2", "--duration", "1", "--full-state",
                          "--out", str(out)]) == 0
    result = json.loads(out.read_text())
    inside = np.array([t["inside"] for t in result["trials"]], dtype=float)
    assert result["coverage"] == inside.mean(axis=0).tolist() and len(result["trials"]) == 2
    first = result["trials"][0]
    assert first["inside"] == (np.abs(np.subtract(first["estimate"], first["truth"]))
                               <= 1.959964 * np.array(first["sigma"])).tolist()


def test_the_start_fits_segments_skip_the_parameter_sensitivities_and_nothing_else(short_log):
    x, b = fitmod._start_guess(short_log, NOMINAL)
    prob = fitmod._Problem(short_log, NOMINAL, free_parameters("k_S,m_P"), 0.5, "rkmk4", x, b)
    model = prob.model(prob.theta_start)
    start = prob._dretract(model, prob.xref[0], np.zeros(12))
    full = prob.segment_block(model, 0, start, None, b)
    held = prob.segment_block(model, 0, start, None, b, sensitivities=False)
    np.testing.assert_array_equal(held["r"], full["r"])
    # the state columns: the step's F alone against F from the one pass with the sensitivities,
    # two kernels that differ only in rounding
    np.testing.assert_allclose(held["x"], full["x"], rtol=1e-10, atol=1e-10 * np.abs(full["x"]).max())
    assert np.any(full["th"] != 0) and not np.any(held["th"])
