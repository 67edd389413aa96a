"""A sensor set (runtime/sensor_set.py): the default is the shipped file, a `[sensors]` section
changes the default by the keys it gives, in scenario, task and standalone sensors files, and
every wrong value is a ValueError naming the file and the key."""
import copy
import dataclasses
import math
import re
import tomllib

import pytest

from runtime.control.task import parse_task
from runtime.scenario import parse_scenario
from runtime.sensor_set import (SENSOR_RANGES, EncoderSpec, FixSpec, HeadingSpec, ImuSpec, ProcessNoise, SensorSet,
                                load_sensor_set, parse_sensors, sensor_set_path)

SCENARIO = {"dt": 0.01, "steps": 10, "params": {"preset": "paper_simulation"}}


def test_the_default_set_is_the_shipped_default_file():
    assert load_sensor_set("default") == SensorSet.default()


def test_the_default_file_writes_every_key_out():
    table = tomllib.loads(sensor_set_path("default").read_text())["sensors"]
    assert table == SensorSet.default().as_table()


def test_the_default_set_is_the_one_of_the_estimation_targets():
    s = SensorSet.default()
    assert (s.imu.body, s.imu.lever, s.imu.rate) == ("yoke", (0.0, 0.0, -0.05), 200.0)
    assert s.imu.rotation == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    assert (s.imu.gyro_noise, s.imu.gyro_bias, s.imu.accel_noise, s.imu.accel_bias) == (0.003, 0.005, 0.02, 0.05)
    assert (s.imu.gyro_bias_rw, s.imu.accel_bias_rw) == (1e-5, 1e-4)       # a MEMS IMU's bias instability
    assert (s.encoders.counts_per_rev, s.encoders.rate) == (4096, 200.0)
    assert s.fixes == FixSpec(rate=2.0, noise=0.01, latency=0.0)
    assert s.heading is None
    assert s.process == ProcessNoise(0.01, 0.01, 0.01)


def test_a_set_survives_its_table():
    s = SensorSet(imu=ImuSpec(body="pendulum", lever=(0.01, 0.0, -0.1), rate=100.0),
                  encoders=EncoderSpec(1024, 100.0), fixes=None, heading=HeadingSpec(5.0, 0.02),
                  process=ProcessNoise(0.0, 0.02, 0.03))
    assert SensorSet.from_table(copy.deepcopy(s.as_table())) == s


def test_a_section_changes_only_the_keys_it_gives():
    s = parse_sensors({"imu": {"rate": 400.0}, "heading": {"noise": 0.1}, "fixes": False}, "f.toml")
    default = SensorSet.default()
    assert s.imu == dataclasses.replace(default.imu, rate=400.0)
    assert s.heading == HeadingSpec(noise=0.1)
    assert s.fixes is None and s.encoders == default.encoders and s.process == default.process


def test_the_imu_mount_is_its_body_lever_and_rotation():
    spec = ImuSpec(body="shell", lever=(0.0, 0.1, 0.0), rotation=((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    assert (spec.mount.body, spec.mount.lever, spec.mount.rotation) == (spec.body, spec.lever, spec.rotation)


def test_the_encoder_step_is_a_count():
    assert EncoderSpec(4096).step == 2 * math.pi / 4096


def test_process_noise_along_nu_is_the_shell_three_times_then_the_joints():
    assert ProcessNoise(1.0, 2.0, 3.0).generalized().tolist() == [1.0, 1.0, 1.0, 2.0, 3.0]


# -- files -----------------------------------------------------------------------------------------
def test_a_scenario_file_takes_a_sensors_section():
    data = {**SCENARIO, "sensors": {"imu": {"body": "shell"}}}
    assert parse_scenario(data, "s.toml").sensors.imu.body == "shell"
    assert parse_scenario(dict(SCENARIO), "s.toml").sensors is None


def test_a_task_file_takes_a_sensors_section():
    data = {**SCENARIO, "reference": {"kind": "speed", "speed": 0.1}, "controller": {"kind": "pid"},
            "sensors": {"encoders": {"counts_per_rev": 1000}}}
    assert parse_task(data, "t.toml").sensors.encoders.counts_per_rev == 1000


def test_a_standalone_sensors_file_loads(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('description = "x"\n[sensors.fixes]\nlatency = 0.1\n')
    assert load_sensor_set(path).fixes.latency == 0.1


def test_a_standalone_file_with_another_table_is_refused_naming_it(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("[imu]\nrate = 100.0\n")
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: unknown key 'imu'; allowed: description, sensors"):
        load_sensor_set(path)


def test_a_missing_sensors_file_is_named(tmp_path):
    with pytest.raises(ValueError, match="no-such.toml: no such sensors file"):
        load_sensor_set(tmp_path / "no-such.toml")


# -- wrong values ----------------------------------------------------------------------------------
@pytest.mark.parametrize("table, message", [
    ({"imu": {"rate": 0.0}}, r"sensors.imu.rate: expected a number in \[0.001, 10000\] Hz, got 0.0"),
    ({"imu": {"gyro_noise": -1.0}}, r"sensors.imu.gyro_noise: expected a number in \[0, 10\] rad/s"),
    ({"encoders": {"counts_per_rev": 10.5}}, r"sensors.encoders.counts_per_rev: expected a whole number"),
    ({"fixes": {"latency": 11.0}}, r"sensors.fixes.latency: expected a number in \[0, 10\] s"),
    ({"process": {"yoke": 1e3}}, r"sensors.process.yoke: expected a number in \[0, 100\] N m/sqrt\(Hz\)"),
    ({"imu": {"lever": [0.0, 0.0, 20.0]}}, r"sensors.imu.lever\[2\]: expected a number in \[-10, 10\] m"),
    ({"imu": {"rate": "fast"}}, r"sensors.imu.rate: expected a number, got str 'fast'"),
    ({"imu": {"rate": math.nan}}, r"sensors.imu.rate: must be finite"),
    ({"imu": {"body": "wheel"}}, r"sensors.imu.body: expected one of shell, yoke, pendulum, got str 'wheel'"),
    ({"imu": {"rotation": [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}},
     r"sensors.imu.rotation: not a rotation matrix"),
    ({"imu": {"rotation": [[1.0, 0.0], [0.0, 1.0]]}}, r"sensors.imu.rotation: expected a 3×3 matrix"),
    ({"imu": {"rate": 100.0, "rates": 1}}, r"sensors.imu: unknown key 'rates'; allowed: "),
    ({"gps": {}}, r"sensors: unknown key 'gps'; allowed: encoders, fixes, heading, imu, process"),
    ({"encoders": False}, r"sensors.encoders: expected a table, got bool False"),
    ({"fixes": True}, r"sensors.fixes: expected a table or false \(no such sensor\), got bool True"),
])
def test_a_wrong_value_is_refused_naming_the_file_and_key(table, message):
    with pytest.raises(ValueError, match=rf"^f.toml: {message}"):
        parse_scenario({**SCENARIO, "sensors": table}, "f.toml")


def test_a_sensors_file_value_beyond_its_range_names_the_file_and_key(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("[sensors.heading]\nnoise = 4.0\n")
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: sensors.heading.noise: expected a number in "):
        load_sensor_set(path)


@pytest.mark.parametrize("make, message", [
    (lambda: ImuSpec(rate=0.0), "ImuSpec.rate: must be > 0"),
    (lambda: ImuSpec(gyro_range=-1.0), "ImuSpec.gyro_range: must be > 0"),
    (lambda: ImuSpec(rotation=((0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))), "ImuSpec.rotation: not a rotation"),
    (lambda: EncoderSpec(counts_per_rev=0), "EncoderSpec.counts_per_rev: must be > 0"),
    (lambda: FixSpec(latency=-0.1), "FixSpec.latency: must be >= 0"),
    (lambda: ProcessNoise(shell=math.inf), "ProcessNoise.shell: must be finite"),
    (lambda: SensorSet(imu=None), "SensorSet.imu: expected a ImuSpec, got NoneType"),
])
def test_a_wrong_spec_in_python_names_its_field(make, message):
    with pytest.raises(ValueError, match=rf"^{re.escape(message)}"):
        make()


def test_every_key_of_a_spec_but_the_body_has_a_range():
    for name, cls in (("imu", ImuSpec), ("encoders", EncoderSpec), ("fixes", FixSpec), ("heading", HeadingSpec),
                      ("process", ProcessNoise)):
        assert set(SENSOR_RANGES[name]) == {f.name for f in dataclasses.fields(cls)} - {"body"}, name


def _beyond(rng):
    """Values just outside `rng`'s ends."""
    if rng.whole:
        return [rng.low - 1, rng.high + 1]
    return [rng.low - max(abs(rng.low), 1.0) * 1e-9, rng.high + max(abs(rng.high), 1.0) * 1e-9]


@pytest.mark.parametrize("table, key", [(t, k) for t, ranges in SENSOR_RANGES.items() for k in ranges])
def test_a_value_beyond_its_range_is_a_named_error_at_load(table, key):
    for value in _beyond(SENSOR_RANGES[table][key]):
        entry = {"lever": [value, 0.0, 0.0], "rotation": [[value, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}
        with pytest.raises(ValueError, match=rf"^f.toml: sensors.{table}.{key}(\[0\])*: expected a "):
            parse_scenario({**SCENARIO, "sensors": {table: {key: entry.get(key, value)}}}, "f.toml")
