"""The excitation design (runtime/identification/excite.py, python -m runtime excite): its program
stays within the torque limit and the flip-over envelope, carries more information than the
random-phase multisine it starts from, is written as a scenario that runs the same torques, and
bad input gives named errors.  Short programs (2 s, two frequencies a motor, a few iterations)."""
import math

import numpy as np
import pytest

from runtime import __main__ as cli
from runtime.identification import excite
from runtime.model import Model
from runtime.params import Params
from runtime.scenario import load_scenario, run_scenario
from runtime.sensor_set import SensorSet
from runtime.state import absolute_inclinations, initial_state

NAMES = "k_S,k_Y,k_P"


def design(**changes):
    return excite.Design(NAMES, 2.0, **{"harmonics": 2, "f_high": 1.5, "sample": 0.05, "push": 0.0, **changes})


@pytest.fixture(scope="module")
def result():
    return excite.design_program(Params.paper_simulation(), design(), max_iterations=2)


def lean_of(torques, params=None):
    params = params or Params.paper_simulation()
    X = Model(params).simulate(initial_state(r=params.r), excite.DT, len(torques), u=torques, method=excite.METHOD,
                               energy_tol=None)
    return float(np.max(absolute_inclinations(X)[1]))


def test_the_program_stays_within_the_torque_limit(result):
    assert np.abs(result.torques).max() <= result.design.u_max * (1 + 1e-12)
    assert result.torques.shape == (result.design.steps, 2)


def test_the_program_stays_within_the_flip_over_envelope(result):
    assert lean_of(result.torques) <= result.design.max_lean


def test_a_tight_envelope_cuts_the_amplitude():
    d = design(max_lean=0.15)
    amplitude, u, _, lean = excite._within_envelope(Model(Params.paper_simulation()), d,
                                                     excite.random_coefficients(d))
    assert lean_of(excite.torques(d, excite.random_coefficients(d))) > 0.15    # the full program leaves it
    assert amplitude < 1 and lean <= 0.15 and lean_of(u) <= 0.15


def test_the_designed_program_carries_more_information_than_the_naive_one(result):
    naive_logdet = result.naive["random multisine"][0]
    # a factor e^1 in the volume of the confidence ellipsoid squared at least; the unoptimised start has 0
    assert result.logdet > naive_logdet + 1.0


def test_the_information_check_fails_for_the_unoptimised_program():
    unoptimised = excite.design_program(Params.paper_simulation(), design(), max_iterations=0)
    assert not unoptimised.logdet > unoptimised.naive["random multisine"][0] + 1.0


def test_the_information_is_the_sensitivities_gram_matrix(result):
    info, _ = excite.information(Model(Params.paper_simulation()), result.design, result.torques)
    assert np.allclose(info, info.T) and np.all(np.linalg.eigvalsh(info) > 0)
    assert math.isclose(excite.criterion(info)[0], result.logdet, rel_tol=1e-9)


def test_the_damping_weight_ranks_a_dampings_information_above_the_volume():
    names = ("m_P", "k_S", "k_Y")
    volume = np.diag([4.0, 1.0, 1.0])          # log det log 4, the dampings' variances 1
    dampings = np.diag([1.0, 1.5, 1.5])        # log det log 2.25: a smaller ellipsoid's volume loses
    assert np.linalg.slogdet(volume)[1] > np.linalg.slogdet(dampings)[1]
    # log 4 against log 2.25 + 2 (2 log 1.5): the weight of 2 on each damping's −log variance decides
    assert excite.weighted_criterion(dampings, names, 2.0) > excite.weighted_criterion(volume, names, 2.0)
    assert math.isclose(excite.weighted_criterion(volume, names, 0.0), math.log(4.0))


def test_the_process_information_of_a_damping_is_its_torque_squared_over_the_noise():
    # g = M ν̇ − f moves by −ω_P per unit k_P: I[k_P, k_P] = Σ sample (k_P ω_P)² / q_P², from the motion alone
    params = Params.paper_simulation()
    d = excite.Design("k_P,m_P", 2.0, sample=0.05)
    u = 0.3 * np.stack([np.sin(np.arange(d.steps) * 0.02), np.cos(np.arange(d.steps) * 0.05)], axis=1)
    info, lean = excite.process_information(Model(params), d, u)
    X = Model(params).simulate(initial_state(r=params.r), excite.DT, d.steps, u=u, method=excite.METHOD,
                               energy_tol=None)
    w_P = X[np.arange(0, d.steps, 5), -1]
    q = SensorSet.default().process.pendulum
    assert math.isclose(info[0, 0], d.sample * np.sum((params.k_P * w_P) ** 2) / q ** 2, rel_tol=1e-9)
    assert math.isclose(lean, lean_of(u), rel_tol=1e-12)


def test_the_damping_phase_holds_the_yoke_and_drives_the_pendulum_within_the_envelope():
    d = excite.Design(NAMES, 4.0, harmonics=2, f_high=1.5, sample=0.05, push=0.5, max_lean=0.6)
    model = Model(Params.paper_simulation())
    u0 = excite.torques(d, excite.random_coefficients(d), 0.05)
    u, amplitude, weighted, sigma, lean = excite.damping_phase(model, d, u0)
    half = d.steps // 2
    assert np.allclose(u[:half], amplitude * u0[:half])
    assert np.ptp(u[half:, 0]) == 0 and abs(u[-1, 0]) == pytest.approx(amplitude * d.u_max)
    assert np.abs(u[half:, 1]).max() == pytest.approx(amplitude * d.u_max, rel=0.05)
    assert lean_of(u) <= d.max_lean and np.abs(u).max() <= d.u_max * (1 + 1e-12)
    assert sigma[0] < excite.sigmas(excite.process_information(model, d, u0)[0])[0]     # k_S better seen


def test_the_scenario_file_runs_the_designed_torques(result, tmp_path):
    path = tmp_path / "excite.toml"
    path.write_text(excite.scenario_text(result))
    scenario = load_scenario(path)
    assert scenario.steps == result.design.steps and scenario.method == excite.METHOD
    assert np.array_equal(scenario.torque_at_step_starts(), result.torques)
    assert run_scenario(scenario).trajectory.shape == (result.design.steps + 1, 35)


def test_the_command_writes_a_scenario_and_reports(tmp_path, capsys):
    out = tmp_path / "p.toml"
    assert cli.main(["excite", "--params", "k_S", "--duration", "2", "--harmonics", "2", "--iterations", "1",
                     "--f-high", "1.5", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "log det" in printed and "predicted sigma" in printed
    assert load_scenario(out).steps == 200


def test_a_robot_file_is_named_relative_to_the_scenario(result, tmp_path):
    robot = tmp_path / "robots" / "r.toml"
    robot.parent.mkdir()
    robot.write_text("k_S = 0.2\n")
    path = tmp_path / "excite.toml"
    path.write_text(excite.scenario_text(result, robot, path))
    assert 'robot = "robots/r.toml"' in path.read_text()
    assert load_scenario(path).params.k_S == 0.2


@pytest.mark.parametrize("names, message", [
    ("k_X", "params: unknown parameter 'k_X'"),
    ("k_S,k_S", "params: k_S is named twice"),
    ("", "params: name at least one parameter"),
])
def test_bad_parameter_names_are_named(names, message):
    with pytest.raises(ValueError, match=message):
        excite.Design(names, 2.0)


def test_a_whole_field_stands_for_its_entries():
    assert excite.Design("c_P", 2.0).names == ("c_P_x", "c_P_y", "c_P_z")


@pytest.mark.parametrize("changes, message", [
    ({"duration": -1.0}, "duration: -1 is outside"),
    ({"duration": 2.03}, "duration: 2.03 s is not a whole number"),
    ({"u_max": math.nan}, "u_max: expected a finite number"),
    ({"max_lean": 2.0}, "max_lean: 2 is outside"),
    ({"f_high": 30.0}, "f_high: 30 Hz is above the hold's Nyquist frequency"),
    ({"f_low": 1.0, "f_high": 0.5}, "f_low, f_high: need f_low < f_high"),
    ({"harmonics": 0}, "harmonics: expected a whole number"),
    ({"hold": 0.015}, "hold: 0.015 s is not a whole number of steps"),
    ({"push": 0.95}, "push: 0.95 is outside"),
    ({"push": 0.01}, "push: 0.01 of 2 s is shorter than one hold"),
    ({"damping_weight": -1.0}, "damping_weight: -1 is outside"),
])
def test_bad_design_settings_are_named(changes, message):
    with pytest.raises(ValueError, match=message):
        excite.Design(NAMES, **{"duration": 2.0, **changes})


def test_too_many_frequencies_for_the_band_are_named():
    with pytest.raises(ValueError, match="harmonics: 9 distinct frequencies do not fit"):
        excite.Design(NAMES, 2.0, harmonics=9, f_high=2.0).frequencies()


def test_the_command_names_bad_input(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["excite", "--params", "nope", "--duration", "2", "--out", str(tmp_path / "p.toml")])
    assert exc.value.code == 2 and "params: unknown parameter 'nope'" in capsys.readouterr().err
    assert not (tmp_path / "p.toml").exists()
