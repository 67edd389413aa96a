"""Sensor logs (runtime/estimation/logs.py): written as CSV and Parquet and read back from either
exactly; a log that cannot be trusted is a LogError naming the file, unusable samples are dropped
and counted by reason, gaps are reported, and no NaN reaches a Log."""
import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from runtime import initial_state
from runtime.estimation.logs import (COLUMNS, FORMATS, TRUTH_BIAS_COLUMNS, Gap, Log, LogError, read_log, samples,
                                     write_log)
from runtime.sensor_set import HeadingSpec, ImuSpec, SensorSet
from runtime.state import STATE_COLUMNS


def small_log(sensors=None):
    """One second of every kind: IMU and encoders at 200 Hz, fixes at 2 Hz, torques at 100 Hz, truth."""
    rng = np.random.default_rng(0)
    t_imu, t_tor = np.arange(200) / 200.0, np.arange(101) / 100.0
    x = np.tile(initial_state(theta_Y=0.1, w_S=(0.5, 0.0, 0.0)), (101, 1))
    from runtime.state import COLUMN_INDEX
    return Log(torques=samples("torques", t_tor, rng.normal(size=(101, 2))),
               imu=samples("imu", t_imu, rng.normal(size=(200, 6))),
               encoders=samples("encoders", t_imu, rng.normal(size=(200, 2))),
               fixes=samples("fixes", [0.1, 0.6], [[0.0, 1.0, 2.0], [0.5, 3.0, 4.0]]),
               truth=samples("truth", t_tor, x[:, COLUMN_INDEX]),
               sensors=sensors or SensorSet.default(), meta={"seed": 7})


def assert_same(a, b):
    for kind in COLUMNS:
        ta, tb = getattr(a, kind), getattr(b, kind)
        assert (ta is None) == (tb is None), kind
        if ta is not None:
            assert ta.columns == tb.columns and np.array_equal(ta.table(), tb.table()), kind


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_log_reads_back_exactly_from_either_format(tmp_path, fmt):
    log = small_log()
    write_log(log, tmp_path)
    back = read_log(tmp_path, format=fmt)
    assert_same(back, log)
    assert back.sensors == log.sensors and back.meta == {"seed": 7}
    assert back.skipped == {"nonfinite": 0, "saturated": 0} and back.gaps == ()


def test_the_truth_columns_are_the_trajectory_csv_state_columns_then_the_biases():
    from runtime.scenarios.report import CSV_COLUMNS
    assert COLUMNS["truth"] == ("t", *STATE_COLUMNS, *TRUTH_BIAS_COLUMNS)
    state = COLUMNS["truth"][:-len(TRUTH_BIAS_COLUMNS)]
    assert [c for c in CSV_COLUMNS if c in state] == list(state)


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_truths_walking_biases_read_back_per_row(tmp_path, fmt):
    log = small_log()
    walk = np.cumsum(np.full((len(log.truth), 6), 1e-4), axis=0)
    truth = samples("truth", log.truth.t, np.column_stack([log.truth.data, walk]))
    write_log(Log(**{**log.tables(), "truth": truth}, sensors=log.sensors, meta=log.meta), tmp_path)
    back = read_log(tmp_path, format=fmt)
    assert back.truth.columns == COLUMNS["truth"]
    assert np.array_equal(back.truth_biases(), walk)
    assert np.array_equal(back.truth_states(), log.truth_states())


def test_a_truth_without_bias_columns_holds_the_drawn_biases_of_log_json(tmp_path):
    log = small_log()
    drawn = {"gyro": [0.001, 0.002, 0.003], "accel": [0.01, 0.02, 0.03]}
    write_log(Log(**log.tables(), sensors=log.sensors, meta={"truth_bias": drawn}), tmp_path)
    back = read_log(tmp_path)
    assert back.truth.columns == ("t", *STATE_COLUMNS)
    assert np.array_equal(back.truth_biases(), np.tile(drawn["gyro"] + drawn["accel"], (len(back.truth), 1)))


def test_a_truth_with_some_bias_columns_only_is_refused(tmp_path):
    write_log(small_log(), tmp_path)
    table = pq.read_table(tmp_path / "truth.parquet")
    pq.write_table(table.append_column("b_g_x", pa.array(np.zeros(table.num_rows))), tmp_path / "truth.parquet")
    with pytest.raises(LogError, match=r"truth\.parquet: missing columns b_g_y"):
        read_log(tmp_path)


def test_the_truth_comes_back_as_states_in_the_library_layout(tmp_path):
    write_log(small_log(), tmp_path)
    x = read_log(tmp_path).truth_states()
    assert np.array_equal(x[0], initial_state(theta_Y=0.1, w_S=(0.5, 0.0, 0.0)))


def test_torques_hold_until_the_next_row():
    log = small_log()
    u = log.torques.data
    assert np.array_equal(log.torque_at([0.0, 0.0149, 0.02, 5.0, -1.0]), u[[0, 1, 2, 100, 0]])


def test_the_sensor_set_of_the_reader_overrides_log_json(tmp_path):
    write_log(small_log(), tmp_path)
    sensors = SensorSet(heading=HeadingSpec())
    with pytest.raises(LogError, match=r"heading.csv: missing \(the sensor set has heading\)"):
        read_log(tmp_path, format="csv", sensors=sensors)


def test_a_log_without_log_json_is_read_with_the_default_set(tmp_path):
    write_log(small_log(SensorSet(fixes=None)), tmp_path)
    (tmp_path / "log.json").unlink()
    assert read_log(tmp_path).sensors == SensorSet.default()


# -- bad logs ----------------------------------------------------------------------------------------
def rewrite(path, fmt, change):
    """Apply `change` (a function of {column: array} -> {column: array}) to one table file."""
    if fmt == "csv":
        lines = path.read_text().splitlines()
        header = lines[0].split(",")
        cols = {h: [row.split(",")[i] for row in lines[1:]] for i, h in enumerate(header)}
        cols = change(cols)
        names = list(cols)
        rows = zip(*(cols[n] for n in names))
        path.write_text("\n".join([",".join(names)] + [",".join(map(str, r)) for r in rows]) + "\n")
    else:
        table = pq.read_table(path)
        cols = change({n: table.column(n).to_pylist() for n in table.column_names})
        pq.write_table(pa.table(cols), path)


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_missing_column_is_named(tmp_path, fmt):
    write_log(small_log(), tmp_path)
    rewrite(tmp_path / f"imu.{fmt}", fmt, lambda c: {k: v for k, v in c.items() if k != "accel_z"})
    with pytest.raises(LogError, match=rf"imu.{fmt}: missing column accel_z \(a imu table has t, gyro_x"):
        read_log(tmp_path, format=fmt)


def test_a_missing_table_is_named(tmp_path):
    write_log(small_log(), tmp_path, formats=("csv",))
    (tmp_path / "encoders.csv").unlink()
    with pytest.raises(LogError, match=r"encoders.csv: missing \(every log has one\)"):
        read_log(tmp_path)


@pytest.mark.parametrize("fmt", FORMATS)
def test_time_going_backwards_is_named_with_its_row(tmp_path, fmt):
    write_log(small_log(), tmp_path)

    def swap(c):
        c["t"][2], c["t"][3] = c["t"][3], c["t"][2]
        return c
    rewrite(tmp_path / f"encoders.{fmt}", fmt, swap)
    with pytest.raises(LogError, match=rf"encoders.{fmt}: time does not increase at data row 4: t = 0.01 s after "
                                       r"0.015 s \(row 3\)"):
        read_log(tmp_path, format=fmt)


def test_a_repeated_time_is_refused(tmp_path):
    write_log(small_log(), tmp_path, formats=("csv",))

    def repeat(c):
        c["t"][5] = c["t"][4]
        return c
    rewrite(tmp_path / "torques.csv", "csv", repeat)
    with pytest.raises(LogError, match="torques.csv: time does not increase at data row 6"):
        read_log(tmp_path)


#: A non-finite value as each format writes it: NaN, infinity, an empty (null) field.
NONFINITE = {"csv": ["nan", "inf", ""], "parquet": [float("nan"), float("inf"), None]}


@pytest.mark.parametrize("fmt, bad", [(fmt, bad) for fmt, values in NONFINITE.items() for bad in values])
def test_a_nonfinite_sample_is_skipped_and_counted(tmp_path, fmt, bad):
    write_log(small_log(), tmp_path)

    def spoil(c):
        c["gyro_y"][10] = bad
        return c
    rewrite(tmp_path / f"imu.{fmt}", fmt, spoil)
    log = read_log(tmp_path, format=fmt)
    assert log.skipped == {"nonfinite": 1, "saturated": 0}
    assert log.skipped_by_kind["imu"] == {"nonfinite": 1, "saturated": 0}
    assert len(log.imu) == 199 and np.isfinite(log.imu.table()).all()
    assert 10 / 200.0 not in log.imu.t


def test_a_nan_time_is_skipped_too(tmp_path):
    write_log(small_log(), tmp_path, formats=("csv",))

    def spoil(c):
        c["t"][3] = "nan"
        return c
    rewrite(tmp_path / "encoders.csv", "csv", spoil)
    log = read_log(tmp_path)
    assert log.skipped_by_kind["encoders"]["nonfinite"] == 1 and np.isfinite(log.encoders.t).all()


@pytest.mark.parametrize("column, value, limits, saturated", [
    ("gyro_x", 35.0, {}, 1), ("gyro_z", -35.0, {}, 1), ("gyro_x", 34.99, {}, 0),
    ("accel_y", 160.0, {}, 1), ("accel_y", -159.9, {}, 0),
    ("gyro_x", 10.0, {"gyro_range": 10.0}, 1), ("accel_x", 20.0, {"accel_range": 20.0}, 1),
])
def test_a_reading_at_full_scale_is_skipped_as_saturated(tmp_path, column, value, limits, saturated):
    log = small_log(SensorSet(imu=ImuSpec(**limits)))
    log.imu.data[0, COLUMNS["imu"].index(column) - 1] = value
    write_log(log, tmp_path, formats=("parquet",))
    back = read_log(tmp_path)
    assert back.skipped == {"nonfinite": 0, "saturated": saturated}
    assert len(back.imu) == 200 - saturated


def test_a_gap_longer_than_the_allowed_periods_is_reported(tmp_path):
    log = small_log()
    keep = np.r_[0:50, 56:200]          # six periods from t = 0.245 s to 0.28 s
    write_log(Log(**{**log.__dict__, "encoders": samples("encoders", log.encoders.t[keep], log.encoders.data[keep])}),
              tmp_path)
    assert read_log(tmp_path, gap_periods=5).gaps == (Gap("encoders", 49 / 200, 56 / 200),)
    assert read_log(tmp_path, gap_periods=7).gaps == ()


def test_a_value_that_is_not_a_number_is_named(tmp_path):
    write_log(small_log(), tmp_path, formats=("csv",))

    def spoil(c):
        c["u_Y"][2] = "abc"
        return c
    rewrite(tmp_path / "torques.csv", "csv", spoil)
    with pytest.raises(LogError, match=r"torques.csv: not readable as CSV"):
        read_log(tmp_path)


def test_a_fix_measured_after_it_arrived_is_refused(tmp_path):
    log = small_log()
    log.fixes.data[1, 0] = 0.7
    write_log(log, tmp_path)
    with pytest.raises(LogError, match=r"fixes.parquet: data row 2: t_measured = 0.7 s is after its arrival t = 0.6 s"):
        read_log(tmp_path)


def test_a_log_json_of_something_else_is_refused(tmp_path):
    write_log(small_log(), tmp_path)
    (tmp_path / "log.json").write_text(json.dumps({"format": "other"}))
    with pytest.raises(LogError, match=r"log.json: not a log's metadata"):
        read_log(tmp_path)


def test_a_folder_that_is_not_there_is_named(tmp_path):
    with pytest.raises(LogError, match="nothing: no such log folder"):
        read_log(tmp_path / "nothing")


def test_the_robot_a_log_claims_comes_back_from_log_json(tmp_path):
    from runtime import Params
    for params in (Params.paper_simulation(), Params.paper_simulation().replace(slope=0.1)):
        log = small_log()
        write_log(Log(**{**log.__dict__, "meta": {"params": params.as_json()}}), tmp_path)
        assert read_log(tmp_path).params() == params
    assert small_log().params() is None


def test_a_claimed_robot_that_is_no_robot_is_named(tmp_path):
    log = small_log()
    write_log(Log(**{**log.__dict__, "meta": {"params": {"r": -1.0}}}), tmp_path)
    with pytest.raises(LogError, match=r"^log.json: params: "):
        read_log(tmp_path).params()


def test_a_log_written_over_another_leaves_none_of_its_tables(tmp_path):
    write_log(small_log(), tmp_path)
    log = small_log(SensorSet(fixes=None))
    write_log(Log(**{**log.__dict__, "fixes": None}), tmp_path, formats=("csv",))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["encoders.csv", "imu.csv", "log.json", "torques.csv",
                                                          "truth.csv"]
    assert read_log(tmp_path).fixes is None
