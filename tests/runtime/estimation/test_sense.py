"""Simulated sensor logs (runtime/estimation/sense.py, `python -m runtime sense`): the readings have
the declared noise, biases drawn per run that walk as declared, quantisation and latency; the
truth moves by the declared process noise; one seed gives one log; the mismatch case simulates
another robot than the log claims.  Short runs only."""
import dataclasses
import json
import math

import numpy as np
import pytest

from runtime import Model
from runtime.estimation.logs import read_log, write_log
from runtime.estimation.sense import main, mismatched, simulate_log
from runtime.scenario import parse_scenario
from runtime.sensor_set import EncoderSpec, FixSpec, HeadingSpec, ImuSpec, ProcessNoise, SensorSet
from runtime.sensors import encoders, position
from runtime.state import IDX_NU, NX

QUIET = ProcessNoise(0.0, 0.0, 0.0)


def at_rest(seconds=2.0, dt=0.005, **extra):
    """The paper's robot at rest on a level floor, no torque."""
    return parse_scenario({"dt": dt, "duration": seconds, "params": {"preset": "paper_simulation"}, **extra},
                          "rest.toml", "rest")


def rolling(seconds=1.0):
    """Both motors on: the joints turn through many encoder counts."""
    return parse_scenario({"dt": 0.005, "duration": seconds, "params": {"preset": "paper_simulation"},
                           "torque": [{"from_time": 0.0, "to_time": seconds, "u_Y": 0.3, "u_P": 0.05}]},
                          "roll.toml", "roll")


def test_gyro_and_accelerometer_noise_have_their_declared_standard_deviations():
    log = simulate_log(at_rest(), SensorSet(process=QUIET), seed=1)
    bias = log.meta["truth_bias"]
    gyro = log.imu.select("gyro_x", "gyro_y", "gyro_z") - bias["gyro"]
    accel = log.imu.select("accel_x", "accel_y", "accel_z") - bias["accel"] - [0.0, 0.0, 9.81]
    assert len(gyro) == 401
    # 1203 draws: the sample standard deviation is within 10 % at 4.9 sigma.
    assert abs(gyro.std() / 0.003 - 1) < 0.1 and abs(accel.std() / 0.02 - 1) < 0.1
    assert np.all(np.abs(gyro.mean(axis=0)) < 4 * 0.003 / math.sqrt(401))
    assert np.all(np.abs(accel.mean(axis=0)) < 4 * 0.02 / math.sqrt(401))


def test_without_noise_or_walk_the_imu_reads_its_bias_constantly_at_rest():
    sensors = SensorSet(imu=ImuSpec(gyro_noise=0.0, accel_noise=0.0, gyro_bias_rw=0.0, accel_bias_rw=0.0),
                        process=QUIET)
    log = simulate_log(at_rest(0.5), sensors, seed=2)
    bias = log.meta["truth_bias"]
    expected = np.array(bias["gyro"] + [b + g for b, g in zip(bias["accel"], (0.0, 0.0, 9.81))])
    assert np.abs(log.imu.data - expected).max() < 1e-12
    assert np.abs(bias["gyro"]).max() > 1e-4          # a bias was drawn at all
    assert np.array_equal(log.truth_biases(), np.tile(bias["gyro"] + bias["accel"], (len(log.truth), 1)))


def test_the_truth_carries_the_walking_biases_the_imu_reads():
    sensors = SensorSet(imu=ImuSpec(gyro_noise=0.0, accel_noise=0.0, gyro_bias_rw=1e-3, accel_bias_rw=1e-2),
                        process=QUIET)
    log = simulate_log(at_rest(0.5), sensors, seed=2)
    walk = log.truth_biases()
    assert np.ptp(walk, axis=0).min() > 1e-4
    assert np.abs(log.imu.data - walk - [0.0, 0.0, 0.0, 0.0, 0.0, 9.81]).max() < 1e-9
    bias = log.meta["truth_bias"]                     # the draw at t = 0
    assert np.array_equal(walk[0], bias["gyro"] + bias["accel"])


def test_biases_are_drawn_per_run_with_their_declared_spread():
    sensors = SensorSet(imu=ImuSpec(gyro_bias=0.005, accel_bias=0.05), process=QUIET)
    scenario = at_rest(0.005)
    draws = np.array([sum(simulate_log(scenario, sensors, seed=s).meta["truth_bias"].values(), [])
                      for s in range(200)])
    # 600 draws per sensor: within 15 % at 5 sigma.
    assert abs(draws[:, :3].std() / 0.005 - 1) < 0.15 and abs(draws[:, 3:].std() / 0.05 - 1) < 0.15


def test_encoders_read_whole_counts_within_half_a_count_of_the_truth():
    scenario = rolling()
    log = simulate_log(scenario, SensorSet(process=QUIET), seed=3)
    step = 2 * math.pi / 4096
    counts = log.encoders.data / step
    assert np.allclose(counts, np.round(counts), rtol=0, atol=1e-9)
    assert len(np.unique(counts[:, 0])) > 20           # the yoke moved through many counts
    model, x = Model(scenario.params), log.truth_states()
    truth = np.array([encoders(model, xk) for xk in x])   # encoders and truth share the 200 Hz grid
    assert np.abs(log.encoders.data - truth).max() <= step / 2 + 1e-12


def test_a_coarser_encoder_has_a_coarser_step():
    log = simulate_log(rolling(0.5), SensorSet(encoders=EncoderSpec(counts_per_rev=360), process=QUIET), seed=3)
    degrees = np.degrees(log.encoders.data)
    assert np.allclose(degrees, np.round(degrees), atol=1e-9)


def test_fixes_arrive_their_latency_after_they_measure():
    scenario = rolling()
    sensors = SensorSet(fixes=FixSpec(rate=10.0, noise=0.0, latency=0.25), process=QUIET)
    log = simulate_log(scenario, sensors, seed=4)
    t, t_measured = log.fixes.t, log.fixes["t_measured"]
    assert np.allclose(t - t_measured, 0.25) and np.allclose(t_measured, np.arange(8) / 10.0)
    model, x = Model(scenario.params), log.truth_states()
    rows = np.round(t_measured / 0.005).astype(int)
    assert np.allclose(log.fixes.select("x", "y"), [position(model, x[r]) for r in rows], atol=1e-15)


def test_a_heading_is_logged_when_the_set_has_one():
    log = simulate_log(at_rest(0.5), SensorSet(heading=HeadingSpec(rate=10.0, noise=0.0), process=QUIET), seed=5)
    assert len(log.heading) == 6 and np.allclose(log.heading["psi"], 0.0, atol=1e-12)


def test_a_saturating_gyro_is_clipped_to_its_full_scale_and_skipped_on_reading(tmp_path):
    sensors = SensorSet(imu=ImuSpec(gyro_range=0.5, gyro_noise=0.0), process=QUIET)
    log = simulate_log(rolling(), sensors, seed=6)          # the yoke spins up past 0.5 rad/s
    clipped = np.abs(log.imu.data[:, :3]).max(axis=1) == 0.5
    assert 10 < clipped.sum() < len(log.imu)
    write_log(log, tmp_path)
    back = read_log(tmp_path)
    assert back.skipped["saturated"] == clipped.sum() and len(back.imu) == len(log.imu) - clipped.sum()


def test_process_noise_moves_the_truth_by_its_declared_density():
    """Over one step dt from rest, Δν = M⁻¹ w dt with w of standard deviation q/√dt."""
    q, dt = ProcessNoise(0.01, 0.02, 0.03), 0.005
    scenario = at_rest(dt, dt=dt)
    dnu = np.array([simulate_log(scenario, SensorSet(process=q), seed=s).truth_states()[1, IDX_NU]
                    for s in range(300)])
    Minv = np.linalg.inv(Model(scenario.params).inertia(scenario.x0))
    expected = np.sqrt(np.diag(Minv @ np.diag(q.generalized() ** 2) @ Minv.T) * dt)
    # 300 draws: each standard deviation within 20 % at 4.9 sigma.
    assert np.all(np.abs(dnu.std(axis=0) / expected - 1) < 0.2)


def test_without_process_noise_the_robot_stays_at_rest():
    x = simulate_log(at_rest(0.5), SensorSet(process=QUIET), seed=7).truth_states()
    assert np.abs(x[:, IDX_NU]).max() < 1e-12


def test_one_seed_gives_one_log_and_another_another():
    a, b, c = (simulate_log(rolling(0.2), seed=s) for s in (8, 8, 9))
    assert np.array_equal(a.imu.data, b.imu.data) and np.array_equal(a.truth.data, b.truth.data)
    assert not np.array_equal(a.imu.data, c.imu.data)


def test_the_mismatch_case_simulates_another_robot_than_the_log_claims():
    scenario = rolling(0.5)
    nominal = simulate_log(scenario, SensorSet(process=QUIET), seed=1)
    log = simulate_log(scenario, SensorSet(process=QUIET), seed=1, plant_mismatch=True)
    assert log.meta["params"] == scenario.params.as_json() == nominal.meta["params"]
    assert log.meta["truth_params"] == mismatched(scenario.params).as_json()
    assert log.params() == scenario.params
    assert not np.allclose(log.truth.data, nominal.truth.data)


def test_mismatch_is_ten_percent_heavier_and_twenty_percent_less_damped():
    p = at_rest(0.005).params
    m = mismatched(p)
    for name in ("m_S", "m_Y", "m_P", "j_S"):
        assert getattr(m, name) == pytest.approx(1.1 * getattr(p, name)), name
    for name in ("k_S", "k_Y", "k_P"):
        assert getattr(m, name) == pytest.approx(0.8 * getattr(p, name)), name


def test_a_scenario_sensors_section_is_the_default_of_its_log():
    scenario = at_rest(0.1, sensors={"imu": {"rate": 100.0}, "fixes": False})
    log = simulate_log(scenario, seed=0)
    assert len(log.imu) == 11 and log.fixes is None


# -- the command ---------------------------------------------------------------------------------
def test_sense_writes_a_log_its_truth_and_a_summary(tmp_path, capsys):
    scenario = tmp_path / "s.toml"
    scenario.write_text('dt = 0.005\nduration = 0.5\n[params]\npreset = "paper_simulation"\n'
                        '[[torque]]\nfrom_time = 0.0\nto_time = 0.5\nu_Y = 0.2\n')
    out = tmp_path / "log"
    assert main([str(scenario), "--out", str(out), "--seed", "3"]) == 0
    log_csv, log_parquet = read_log(out, format="csv"), read_log(out, format="parquet")
    assert np.array_equal(log_csv.imu.table(), log_parquet.imu.table())
    assert np.array_equal(log_csv.truth.table(), log_parquet.truth.table())
    assert log_csv.truth.data.shape == (101, NX + 6) and log_csv.sensors == SensorSet.default()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["seed"] == 3 and summary["samples"] == {"torques": 101, "imu": 101, "encoders": 101, "fixes": 2}
    again = simulate_log(parse_scenario(
        {"dt": 0.005, "duration": 0.5, "params": {"preset": "paper_simulation"},
         "torque": [{"from_time": 0.0, "to_time": 0.5, "u_Y": 0.2}]}, str(scenario), "s"), seed=3)
    assert np.array_equal(again.imu.data, log_parquet.imu.data)


def test_sense_runs_a_task_closed_loop_with_a_sensors_file(tmp_path):
    sensors = tmp_path / "sensors.toml"
    sensors.write_text("[sensors.imu]\nrate = 100.0\n")
    out = tmp_path / "log"
    assert main(["circle", "--out", str(out), "--duration", "0.2", "--sensors", str(sensors), "--quiet"]) == 0
    log = read_log(out)
    assert len(log.imu) == 21 and log.meta["kind"] == "task"
    assert np.abs(log.torques.data).max() > 0          # the controller acted


@pytest.mark.parametrize("argv, message", [
    (["no-such-run"], "no-such-run: no such scenario or task"),
    (["t-shape", "--sensors", "no-such.toml"], "no-such.toml: no such sensors file"),
])
def test_sense_names_what_it_cannot_use(tmp_path, capsys, argv, message):
    assert main(argv + ["--out", str(tmp_path / "log")]) == 2
    assert message in capsys.readouterr().err


def test_sense_refuses_an_out_that_is_a_file(tmp_path, capsys):
    (tmp_path / "f").write_text("")
    assert main(["t-shape", "--out", str(tmp_path / "f")]) == 2
    assert "is a file, expected a folder" in capsys.readouterr().err


def test_a_log_spec_is_a_frozen_dataclass():
    with pytest.raises(dataclasses.FrozenInstanceError):
        SensorSet.default().imu.rate = 1.0


def test_without_process_noise_a_tasks_truth_is_its_closed_loop_run():
    from runtime.control.closed_loop import simulate_closed_loop
    from runtime.control.task import load_task
    task = load_task("circle")
    task = dataclasses.replace(task, scenario=task.scenario.with_overrides(steps=100))
    log = simulate_log(task, SensorSet(process=QUIET))
    run = simulate_closed_loop(task.plant_params, task.controller(), task.reference(), task.scenario.x0,
                               task.duration, task.scenario.dt, method=task.scenario.method)
    assert np.abs(log.truth_states() - run.trajectory).max() < 1e-12
    assert np.abs(log.torques.data - run.torques).max() < 1e-12


def test_the_accelerometer_reads_the_acceleration_of_the_disturbance():
    """The disturbance held over a step moves ν̇ by M⁻¹ w: the reading by Hn M⁻¹ w (Hn: ∂y/∂ν̇)."""
    from runtime.sensors import imu_partials
    q, dt = ProcessNoise(0.01, 0.01, 0.01), 0.005
    scenario = at_rest(2.0, dt=dt)
    sensors = SensorSet(imu=ImuSpec(gyro_noise=0.0, accel_noise=0.0), process=q)
    felt = simulate_log(scenario, sensors, seed=11)
    unfelt = simulate_log(scenario, sensors, seed=11, disturbance_in_accel=False)
    assert np.array_equal(felt.truth.data, unfelt.truth.data)
    delta = felt.imu.data - unfelt.imu.data
    assert np.abs(delta[:, :3]).max() < 1e-12
    model = Model(scenario.params)
    _, _, Hn = imu_partials(model, scenario.x0, np.zeros(5), mount=sensors.imu.mount)
    Minv = np.linalg.inv(model.inertia(scenario.x0))
    G = Hn @ Minv
    expected = np.sqrt(np.diag(G @ np.diag(q.generalized() ** 2 / dt) @ G.T))[3:5]
    # x and y feel it at rest (a lever arm along the yoke's z axis: no tangential z); 400 draws per
    # axis (the last sample starts no step): within 20 % at 5.7 sigma.
    assert np.all(np.abs(delta[:-1, 3:5].std(axis=0) / expected - 1) < 0.2)
