"""Sensor logs: one table per kind of record in a folder, as CSV and Parquet, and `log.json`
(docs/estimation.md, "Log schema").

    write_log(log, "out/circle-log")                   # <kind>.csv, <kind>.parquet, log.json
    log = read_log("out/circle-log")                   # Parquet if present, else CSV
    log.imu.t, log.imu.select("gyro_x", "gyro_y", "gyro_z"), log.skipped, log.gaps

`read_log` refuses a log it cannot trust with a `LogError` (a ValueError) naming the file and
what is wrong (a missing file or column, an unreadable value, time that does not increase), and
drops the samples it cannot use, counting them by reason (`nonfinite`: a NaN or infinite value;
`saturated`: an IMU reading at or beyond its full scale): no NaN reaches a `Log`.
"""
import dataclasses
import json
import pathlib

import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from ..atomic import atomic_path, write_text
from ..params import Params
from ..sensor_set import SensorSet
from ..state import COLUMN_INDEX, NX, STATE_COLUMNS

#: The truth's IMU biases (gyroscope [rad/s], accelerometer [m/s²], sensor axes) as they walk: the
#: truth table's last columns, optional (a truth without them is the state alone).
TRUTH_BIAS_COLUMNS = ("b_g_x", "b_g_y", "b_g_z", "b_a_x", "b_a_y", "b_a_z")
#: The columns of each kind of table, in order; `t` [s] is when the sample was taken (for fixes:
#: when it arrived; `t_measured` when it was measured).
COLUMNS = {
    "torques": ("t", "u_Y", "u_P"),
    "imu": ("t", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"),
    "encoders": ("t", "theta_Y", "theta_P"),
    "fixes": ("t", "t_measured", "x", "y"),
    "heading": ("t", "psi"),
    "truth": ("t", *STATE_COLUMNS, *TRUTH_BIAS_COLUMNS),
}
#: Tables every log has; the others as its sensor set says (fixes, heading) or when present (truth).
REQUIRED = ("torques", "imu", "encoders")
#: Reasons a sample is dropped, counted in `Log.skipped`.
SKIP_REASONS = ("nonfinite", "saturated")
#: Formats a log is written in and read from (file suffixes).
FORMATS = ("csv", "parquet")
#: The metadata file of a log folder.
META_FILE = "log.json"
#: `log.json`'s "format" and "version".
LOG_FORMAT, LOG_VERSION = "spherical-robot-log", 1
#: Default of `read_log(gap_periods=...)`.
GAP_PERIODS = 5


class LogError(ValueError):
    """A log that cannot be read as one: the message names the file and what is wrong."""


@dataclasses.dataclass(frozen=True, eq=False)
class Samples:
    """One table of a log: sample times `t` (n,) [s], strictly increasing, and the other columns
    `data` (n, len(columns) − 1), all finite; `columns` names them, `t` first."""
    columns: tuple
    t: np.ndarray
    data: np.ndarray

    def __len__(self):
        return len(self.t)

    def __getitem__(self, name):
        """One column (n,) by name (`t` too)."""
        if name == "t":
            return self.t
        try:
            return self.data[:, self.columns.index(name) - 1]
        except ValueError:
            raise KeyError(f"{name!r}: not a column of this table ({', '.join(self.columns)})") from None

    def select(self, *names):
        """Columns by name, (n, len(names))."""
        return np.column_stack([self[name] for name in names]) if names else np.empty((len(self), 0))

    def table(self):
        """The whole table (n, len(columns)), `t` first."""
        return np.column_stack([self.t, self.data])


@dataclasses.dataclass(frozen=True)
class Gap:
    """A stretch without samples of `kind` longer than the reader's `gap_periods` sample periods: from the
    sample at `t_from` to the next at `t_to` [s]."""
    kind: str
    t_from: float
    t_to: float


@dataclasses.dataclass(frozen=True, eq=False)
class Log:
    """A sensor log: torques (applied, zero-order hold: a row holds until the next), IMU, encoders,
    optional fixes and heading, optional truth; `sensors` the set that took it; `meta` the rest of
    log.json; `skipped` {reason: count} of samples dropped on reading (every reason of SKIP_REASONS),
    `skipped_by_kind` {kind: {reason: count}}; `gaps` the stretches without samples."""
    torques: Samples
    imu: Samples
    encoders: Samples
    fixes: Samples | None = None
    heading: Samples | None = None
    truth: Samples | None = None
    sensors: SensorSet = SensorSet.default()
    meta: dict = dataclasses.field(default_factory=dict)
    skipped: dict = dataclasses.field(default_factory=lambda: dict.fromkeys(SKIP_REASONS, 0))
    skipped_by_kind: dict = dataclasses.field(default_factory=dict)
    gaps: tuple = ()

    def tables(self):
        """{kind: Samples} of the tables the log has."""
        return {kind: getattr(self, kind) for kind in COLUMNS if getattr(self, kind) is not None}

    def torque_at(self, t):
        """The torques (…, 2) [N m] applied at time(s) t: the last row at or before t (the first row
        before the log's first time)."""
        i = np.searchsorted(self.torques.t, np.asarray(t, dtype=float), side="right") - 1
        return self.torques.data[np.clip(i, 0, len(self.torques) - 1)]

    def params(self):
        """The robot the log claims (log.json's "params", as `Params.as_json` writes it): a
        runtime.Params, or None when the log does not say."""
        table = self.meta.get("params")
        if table is None:
            return None
        where = "log.json: params"
        if not isinstance(table, dict):
            raise LogError(f"{where}: expected a table of parameters, got {type(table).__name__}")
        try:
            if "paper" in table:
                return Params.paper(**table["paper"])
            return Params(**table)
        except (TypeError, ValueError) as exc:
            raise LogError(f"{where}: {exc}") from None

    def truth_states(self):
        """The truth's states (n, 35) in the library's layout (runtime.state), or None without truth."""
        if self.truth is None:
            return None
        x = np.empty((len(self.truth), NX))
        x[:, COLUMN_INDEX] = self.truth.data[:, :len(STATE_COLUMNS)]
        return x

    def truth_biases(self):
        """The truth's IMU biases (n, 6) at the truth's times (TRUTH_BIAS_COLUMNS): its columns, else
        log.json's "truth_bias" held over the run (a log whose biases did not walk), else None."""
        if self.truth is None:
            return None
        if self.truth.columns[-len(TRUTH_BIAS_COLUMNS):] == TRUTH_BIAS_COLUMNS:
            return self.truth.data[:, -len(TRUTH_BIAS_COLUMNS):].copy()
        bias = self.meta.get("truth_bias")
        if bias is None:
            return None
        return np.tile(np.concatenate([bias["gyro"], bias["accel"]]), (len(self.truth), 1))


def samples(kind, t, data):
    """A `Samples` of `kind` (its COLUMNS) from times (n,) and the other columns (n, k); a truth may
    come without its bias columns."""
    t = np.ascontiguousarray(t, dtype=float)
    data = np.asarray(data, dtype=float)
    columns = COLUMNS[kind]
    if kind == "truth" and data.ndim == 2 and data.shape[1] == len(STATE_COLUMNS):
        columns = columns[:-len(TRUTH_BIAS_COLUMNS)]
    return Samples(columns, t, data.reshape(len(t), len(columns) - 1))


# -- writing ----------------------------------------------------------------------------------
def write_log(log, folder, formats=FORMATS):
    """Write `log` into `folder` (created if missing): every table as `<kind>.<format>` for each of
    `formats`, and log.json (its sensor set and meta); each file atomically.  The tables of an earlier
    log there that this one does not rewrite are deleted.  Returns the paths written."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown or not formats:
        raise ValueError(f"formats: expected some of {', '.join(FORMATS)}, got {formats!r}")
    written = []
    for kind, table in log.tables().items():
        arrow = pa.table({name: table.table()[:, i] for i, name in enumerate(table.columns)})
        for fmt in formats:
            target = folder / f"{kind}.{fmt}"
            with atomic_path(target) as tmp:
                if fmt == "csv":
                    _write_csv(table, tmp)
                else:
                    pq.write_table(arrow, tmp)
            written.append(target)
    meta = {"format": LOG_FORMAT, "version": LOG_VERSION, "kinds": list(log.tables()),
            "sensors": log.sensors.as_table(), **log.meta}
    write_text(folder / META_FILE, json.dumps(meta, indent=2) + "\n")
    for stale in (folder / f"{kind}.{fmt}" for kind in COLUMNS for fmt in FORMATS):
        if stale not in written:        # an earlier log's table: the folder never mixes two logs
            stale.unlink(missing_ok=True)
    return written + [folder / META_FILE]


def _write_csv(table, path):
    """A header naming the columns, then one row per sample in Python's shortest round-trip form
    (reading a number back gives the same double)."""
    lines = [",".join(table.columns)] + [",".join(map(repr, row)) for row in table.table().tolist()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


# -- reading ----------------------------------------------------------------------------------
def read_log(folder, format=None, sensors=None, gap_periods=GAP_PERIODS):
    """The `Log` in `folder`, from its `format` files ("csv" or "parquet"; None: Parquet when
    torques.parquet is there, else CSV).  `sensors` (a SensorSet) overrides the set of log.json
    (without either: the default set).  A gap longer than `gap_periods` sample periods is reported
    in `Log.gaps`.  LogError naming the file for a log that cannot be used."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        raise LogError(f"{folder}: no such log folder")
    if format is None:
        format = "parquet" if (folder / "torques.parquet").is_file() else "csv"
    if format not in FORMATS:
        raise ValueError(f"format: expected one of {', '.join(FORMATS)} or None, got {format!r}")
    meta = _read_meta(folder)
    if sensors is None:
        sensors = SensorSet.from_table(meta["sensors"], f"{folder / META_FILE}: sensors") \
            if "sensors" in meta else SensorSet.default()
    elif not isinstance(sensors, SensorSet):
        raise ValueError(f"sensors: expected a runtime.sensor_set.SensorSet, got {type(sensors).__name__}")
    kinds = list(REQUIRED) + [k for k in ("fixes", "heading") if getattr(sensors, k) is not None]
    if (folder / f"truth.{format}").is_file():
        kinds.append("truth")
    tables, by_kind, gaps = {}, {}, []
    for kind in kinds:
        path = folder / f"{kind}.{format}"
        if not path.is_file():
            why = "every log has one" if kind in REQUIRED else f"the sensor set has {kind}"
            raise LogError(f"{path}: missing ({why})")
        raw = _read_table(path, format, COLUMNS[kind], OPTIONAL.get(kind, ()))
        tables[kind], by_kind[kind] = _clean(kind, raw, sensors, path)
        if kind in REQUIRED and not len(tables[kind]):
            raise LogError(f"{path}: no usable samples")
        if kind not in ("torques", "truth"):
            gaps += _gaps(kind, tables[kind].t, gap_periods * getattr(sensors, kind).period)
    skipped = {reason: sum(counts[reason] for counts in by_kind.values()) for reason in SKIP_REASONS}
    return Log(**tables, sensors=sensors, meta={k: v for k, v in meta.items() if k not in _META_OWN},
               skipped=skipped, skipped_by_kind=by_kind, gaps=tuple(gaps))


_META_OWN = ("format", "version", "kinds", "sensors")
#: Columns a table may go without, all together.
OPTIONAL = {"truth": TRUTH_BIAS_COLUMNS}


def _read_meta(folder):
    path = folder / META_FILE
    if not path.is_file():
        return {}
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise LogError(f"{path}: not readable as JSON ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != LOG_FORMAT:
        raise LogError(f"{path}: not a log's metadata (expected \"format\": \"{LOG_FORMAT}\")")
    if meta.get("version") != LOG_VERSION:
        raise LogError(f"{path}: version {meta.get('version')!r}, this reader reads version {LOG_VERSION}")
    return meta


def _read_table(path, format, columns, optional=()):
    """The named columns of the file as float64 arrays {name: (n,)}, the `optional` ones (all or none)
    only when present; LogError for a missing column or an unreadable file or value."""
    try:
        if format == "csv":
            table = pa_csv.read_csv(path, convert_options=pa_csv.ConvertOptions(
                column_types={name: pa.float64() for name in columns}, strings_can_be_null=True))
        else:
            table = pq.read_table(path)
    except (pa.ArrowInvalid, pa.ArrowTypeError, OSError) as exc:
        raise LogError(f"{path}: not readable as {format.upper()} ({str(exc).splitlines()[0]})") from None
    missing = [name for name in columns if name not in table.column_names]
    if optional and set(missing) == set(optional):
        columns = [name for name in columns if name not in optional]
        missing = []
    if missing:
        raise LogError(f"{path}: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                       f"(a {path.stem} table has {', '.join(columns)})")
    out = {}
    for name in columns:
        column = table.column(name)
        try:
            column = column.cast(pa.float64())
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError, pa.ArrowTypeError):
            raise LogError(f"{path}: column {name}: expected numbers, got {column.type}") from None
        out[name] = column.to_numpy(zero_copy_only=False).astype(float)   # a null becomes NaN
    return out


def _clean(kind, raw, sensors, path):
    """(Samples, {reason: count}): rows with a non-finite value or a saturated reading dropped; then
    LogError where the time does not increase (or a fix is measured after it arrives)."""
    columns = tuple(name for name in COLUMNS[kind] if name in raw)
    table = np.column_stack([raw[name] for name in columns]) if len(raw["t"]) else np.empty((0, len(columns)))
    finite = np.isfinite(table).all(axis=1)
    keep = finite.copy()
    saturated = np.zeros_like(keep)
    if kind == "imu":
        imu = sensors.imu
        limits = np.array([imu.gyro_range] * 3 + [imu.accel_range] * 3)
        with np.errstate(invalid="ignore"):
            saturated = finite & (np.abs(table[:, 1:]) >= limits).any(axis=1)
        keep &= ~saturated
    counts = {"nonfinite": int((~finite).sum()), "saturated": int(saturated.sum())}
    rows = np.flatnonzero(keep)
    table = table[keep]
    t = table[:, 0]
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        i = back[0]
        raise LogError(f"{path}: time does not increase at data row {rows[i + 1] + 1}: t = {float(t[i + 1])!r} s "
                       f"after {float(t[i])!r} s (row {rows[i] + 1})")
    if kind == "fixes":
        late = np.flatnonzero(table[:, 1] > table[:, 0])
        if late.size:
            i = late[0]
            raise LogError(f"{path}: data row {rows[i] + 1}: t_measured = {float(table[i, 1])!r} s is after its "
                           f"arrival t = {float(table[i, 0])!r} s")
    return Samples(columns, np.ascontiguousarray(t), np.ascontiguousarray(table[:, 1:])), counts


def _gaps(kind, t, longest):
    jumps = np.flatnonzero(np.diff(t) > longest * (1 + 1e-9))
    return [Gap(kind, float(t[i]), float(t[i + 1])) for i in jumps]
