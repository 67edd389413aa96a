"""A robot's sensor set: which sensors it carries, where, how fast and how noisy, and the process
noise its simulated truth (and an estimator) assumes (docs/estimation.md, "Sensor sets").

    sensors = SensorSet.default()                  # the shipped runtime/sensor_sets/default.toml
    sensors = load_sensor_set("my-robot.toml")     # a standalone sensors file ([sensors] section)
    scenario.sensors                               # a scenario's or task's [sensors], or None

A `[sensors]` section starts from the default set: each of its tables (`imu`, `encoders`,
`fixes`, `heading`, `process`) changes the keys it gives; `fixes = false` or `heading = false`
removes that sensor (the default set has fixes and no heading).  Every number has its range in
`SENSOR_RANGES` (runtime/schema.py); every problem is ValueError("<file>: sensors.<table>.<key>: ...").
"""
import dataclasses
import importlib.resources
import math
import pathlib
import tomllib

import numpy as np

from .schema import Range, check_ranges, check_table, show
from .sensors import BODIES, Mount

_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
_RATE = Range(1e-3, 1e4, "Hz", "a sample rate: an IMU samples at up to a few kHz; the samples of a run are "
                               "kept in memory")

#: The ranges of the numbers of a `[sensors]` section, by table (docs/robustness.md lists them).
SENSOR_RANGES = {
    "imu": {"lever": Range(-10, 10, "m", "a lever arm, inside a robot of a few metres"),
            "rotation": Range(-1, 1, "", "a rotation's entry"),
            "rate": _RATE,
            "gyro_noise": Range(0, 10, "rad/s", "a white noise's per-sample standard deviation"),
            "gyro_bias": Range(0, 10, "rad/s", "a bias's standard deviation per axis and run"),
            "accel_noise": Range(0, 1e3, "m/s^2", "a white noise's per-sample standard deviation"),
            "accel_bias": Range(0, 1e3, "m/s^2", "a bias's standard deviation per axis and run"),
            "gyro_bias_rw": Range(0, 1, "rad/s/sqrt(s)", "a bias's random walk: a MEMS gyroscope's is about "
                                                         "1e-5"),
            "accel_bias_rw": Range(0, 10, "m/s^2/sqrt(s)", "a bias's random walk: a MEMS accelerometer's is "
                                                           "about 1e-4"),
            "gyro_range": Range(1e-3, 1e4, "rad/s", "the gyroscope's full scale: a reading at or beyond it "
                                                    "is saturated"),
            "accel_range": Range(1e-3, 1e5, "m/s^2", "the accelerometer's full scale: a reading at or beyond "
                                                     "it is saturated")},
    "encoders": {"counts_per_rev": Range(1, 2**31, "", "an encoder's counts per revolution", whole=True),
                 "rate": _RATE},
    "fixes": {"rate": _RATE,
              "noise": Range(0, 1e3, "m", "a standard deviation per axis"),
              "latency": Range(0, 10, "s", "how long after its measurement a fix arrives")},
    "heading": {"rate": _RATE,
                "noise": Range(0, math.pi, "rad", "a standard deviation")},
    "process": {name: Range(0, 100, "N m/sqrt(Hz)", "a white torque disturbance's spectral density")
                for name in ("shell", "yoke", "pendulum")},
}

_KEYS = {"imu": {"body"} | set(SENSOR_RANGES["imu"]), **{k: set(v) for k, v in SENSOR_RANGES.items() if k != "imu"}}
_OPTIONAL = ("fixes", "heading")


def _number(value, where, low=None, whole=False):
    """`value` as a float (an int if `whole`), or ValueError naming `where`; `low`: an exclusive lower bound."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{where}: expected a number, got {show(value)}")
    if not math.isfinite(value):
        raise ValueError(f"{where}: must be finite, got {value!r}")
    if low is not None and not value > low:
        raise ValueError(f"{where}: must be > {low:g}, got {value!r}")
    if whole:
        if not float(value).is_integer():
            raise ValueError(f"{where}: expected a whole number, got {value!r}")
        return int(value)
    return float(value)


def _nonnegative(value, where):
    value = _number(value, where)
    if value < 0:
        raise ValueError(f"{where}: must be >= 0, got {value!r}")
    return value


def _set(obj, name, value):
    object.__setattr__(obj, name, value)


@dataclasses.dataclass(frozen=True)
class ImuSpec:
    """A 3-axis gyroscope and accelerometer on `body` ("shell", "yoke" or "pendulum") at `lever` (3,) [m]
    (the body's frame, from the shell centre), its axes `rotation` (3×3, the sensor's axes in the body's
    frame), sampled at `rate` [Hz].  Noises: white, per-sample standard deviations at that rate; biases:
    the standard deviation per axis of a constant drawn once per run.  A reading at or beyond
    `gyro_range` [rad/s] or `accel_range` [m/s²] in magnitude on any axis is saturated.
    `gyro_bias_rw` [rad/s/√s] and `accel_bias_rw` [m/s²/√s]: how fast the biases may wander in a
    run (a random walk's density, the IMU's bias instability), what an estimator allows for;
    the simulated truth holds its biases constant."""
    body: str = "yoke"
    lever: tuple = (0.0, 0.0, -0.05)
    rotation: tuple = _IDENTITY
    rate: float = 200.0
    gyro_noise: float = 0.003
    gyro_bias: float = 0.005
    accel_noise: float = 0.02
    accel_bias: float = 0.05
    gyro_range: float = 35.0
    accel_range: float = 160.0
    gyro_bias_rw: float = 1e-5
    accel_bias_rw: float = 1e-4

    def __post_init__(self):
        if not isinstance(self.body, str) or self.body not in BODIES:
            raise ValueError(f"ImuSpec.body: expected one of {', '.join(BODIES)}, got {show(self.body)}")
        try:
            mount = Mount(self.body, self.lever, self.rotation)
        except ValueError as exc:           # Mount names "mount.<field>"
            raise ValueError(f"ImuSpec.{str(exc).removeprefix('mount.')}") from None
        _set(self, "lever", mount.lever)
        _set(self, "rotation", mount.rotation)
        _set(self, "rate", _number(self.rate, "ImuSpec.rate", low=0))
        for name in ("gyro_noise", "gyro_bias", "accel_noise", "accel_bias", "gyro_bias_rw", "accel_bias_rw"):
            _set(self, name, _nonnegative(getattr(self, name), f"ImuSpec.{name}"))
        for name in ("gyro_range", "accel_range"):
            _set(self, name, _number(getattr(self, name), f"ImuSpec.{name}", low=0))

    @property
    def mount(self):
        """Where it sits, as runtime.sensors.Mount (the argument of `imu`, `heading` and their Jacobians)."""
        return Mount(self.body, self.lever, self.rotation)

    @property
    def period(self):
        """1 / rate [s]."""
        return 1.0 / self.rate


@dataclasses.dataclass(frozen=True)
class EncoderSpec:
    """Encoders on θ_Y and θ_P: `counts_per_rev` counts per revolution (a reading is a whole number of
    2π / counts_per_rev), sampled at `rate` [Hz]."""
    counts_per_rev: int = 4096
    rate: float = 200.0

    def __post_init__(self):
        counts = _number(self.counts_per_rev, "EncoderSpec.counts_per_rev", low=0, whole=True)
        _set(self, "counts_per_rev", counts)
        _set(self, "rate", _number(self.rate, "EncoderSpec.rate", low=0))

    @property
    def step(self):
        """The quantisation step 2π / counts_per_rev [rad]."""
        return 2 * math.pi / self.counts_per_rev

    @property
    def period(self):
        """1 / rate [s]."""
        return 1.0 / self.rate


@dataclasses.dataclass(frozen=True)
class FixSpec:
    """Position fixes of the shell centre's (x, y) in the inertial frame: `noise` [m] standard deviation
    per axis, `rate` [Hz], each arriving `latency` [s] after the instant it measures."""
    rate: float = 2.0
    noise: float = 0.01
    latency: float = 0.0

    def __post_init__(self):
        _set(self, "rate", _number(self.rate, "FixSpec.rate", low=0))
        _set(self, "noise", _nonnegative(self.noise, "FixSpec.noise"))
        _set(self, "latency", _nonnegative(self.latency, "FixSpec.latency"))

    @property
    def period(self):
        """1 / rate [s]."""
        return 1.0 / self.rate


@dataclasses.dataclass(frozen=True)
class HeadingSpec:
    """A magnetometer's heading of the IMU's x axis (runtime.sensors.heading, the IMU's mount): `noise`
    [rad] standard deviation, `rate` [Hz]."""
    rate: float = 10.0
    noise: float = 0.05

    def __post_init__(self):
        _set(self, "rate", _number(self.rate, "HeadingSpec.rate", low=0))
        _set(self, "noise", _nonnegative(self.noise, "HeadingSpec.noise"))

    @property
    def period(self):
        """1 / rate [s]."""
        return 1.0 / self.rate


@dataclasses.dataclass(frozen=True)
class ProcessNoise:
    """White torque disturbances: spectral densities [N·m/√Hz] of a torque on the shell (each of its
    three axes, shell frame) and on the yoke's and pendulum's joints, as generalized forces on
    (ω_S, ω_Y, ω_P).  Over a step dt such a disturbance is a constant of standard deviation q/√dt."""
    shell: float = 0.01
    yoke: float = 0.01
    pendulum: float = 0.01

    def __post_init__(self):
        for name in ("shell", "yoke", "pendulum"):
            _set(self, name, _nonnegative(getattr(self, name), f"ProcessNoise.{name}"))

    def generalized(self):
        """The densities (5,) along ν = (ω_S, ω_Y, ω_P): shell three times, yoke, pendulum."""
        return np.array([self.shell] * 3 + [self.yoke, self.pendulum])


@dataclasses.dataclass(frozen=True)
class SensorSet:
    """What a robot carries: an IMU, the joint encoders, optional position fixes and heading, and the
    process noise of its truth.  `SensorSet.default()` is runtime/sensor_sets/default.toml."""
    imu: ImuSpec = ImuSpec()
    encoders: EncoderSpec = EncoderSpec()
    fixes: FixSpec | None = FixSpec()
    heading: HeadingSpec | None = None
    process: ProcessNoise = ProcessNoise()

    def __post_init__(self):
        for name, cls, optional in (("imu", ImuSpec, False), ("encoders", EncoderSpec, False),
                                    ("fixes", FixSpec, True), ("heading", HeadingSpec, True),
                                    ("process", ProcessNoise, False)):
            value = getattr(self, name)
            if not isinstance(value, cls) and not (optional and value is None):
                raise ValueError(f"SensorSet.{name}: expected a {cls.__name__}{' or None' if optional else ''}, "
                                 f"got {show(value)}")

    @classmethod
    def default(cls):
        """The default set: IMU on the yoke at (0, 0, −0.05) m, axes along the yoke's, 200 Hz, gyroscope
        noise 0.003 rad/s and bias 0.005 rad/s, accelerometer 0.02 m/s² and 0.05 m/s²; encoders 4096
        counts per revolution at 200 Hz; fixes at 2 Hz with 1 cm noise, no latency; no magnetometer;
        process noise 0.01 N·m/√Hz on the shell and both joints."""
        return cls()

    @classmethod
    def from_table(cls, table, where="sensors"):
        """The set of a `[sensors]` table (as tomllib reads it): the default set changed by the tables it
        gives; ValueError("<where>.<table>.<key>: ...") for anything wrong."""
        check_table(table, set(_KEYS), where)
        parts = {}
        for name, spec_cls in (("imu", ImuSpec), ("encoders", EncoderSpec), ("fixes", FixSpec),
                               ("heading", HeadingSpec), ("process", ProcessNoise)):
            if name not in table:
                continue
            sub, at = table[name], f"{where}.{name}"
            if sub is False and name in _OPTIONAL:
                parts[name] = None
                continue
            if not isinstance(sub, dict):
                extra = " or false (no such sensor)" if name in _OPTIONAL else ""
                raise ValueError(f"{at}: expected a table{extra}, got {show(sub)}")
            check_table(sub, _KEYS[name], at)
            check_ranges(sub, SENSOR_RANGES[name], at)
            base = getattr(cls.default(), name) or spec_cls()
            parts[name] = _build(spec_cls, base, sub, at)
        return dataclasses.replace(cls.default(), **parts)

    def as_table(self):
        """The `[sensors]` table of this set (plain numbers, lists and strings: TOML's and JSON's);
        `SensorSet.from_table(s.as_table()) == s`."""
        out = {}
        for name in ("imu", "encoders", "fixes", "heading", "process"):
            spec = getattr(self, name)
            out[name] = False if spec is None else {
                f.name: (list(map(list, v)) if f.name == "rotation" else list(v) if f.name == "lever" else v)
                for f in dataclasses.fields(spec) for v in [getattr(spec, f.name)]}
        return out


def _build(spec_cls, base, table, where):
    """`base` (a spec) with the keys of `table` changed, each type-checked naming `<where>.<key>`."""
    changes = {}
    for key, value in table.items():
        at = f"{where}.{key}"
        if key == "body":
            if not isinstance(value, str) or value not in BODIES:
                raise ValueError(f"{at}: expected one of {', '.join(BODIES)}, got {show(value)}")
            changes[key] = value
        elif key == "lever":
            if not isinstance(value, list) or len(value) != 3:
                raise ValueError(f"{at}: expected a list of 3 numbers [m], got {show(value)}")
            changes[key] = tuple(_number(v, f"{at}[{i}]") for i, v in enumerate(value))
        elif key == "rotation":
            if not (isinstance(value, list) and len(value) == 3
                    and all(isinstance(row, list) and len(row) == 3 for row in value)):
                raise ValueError(f"{at}: expected a 3×3 matrix as a list of 3 rows of 3 numbers, got {show(value)}")
            changes[key] = tuple(tuple(_number(v, f"{at}[{i}][{j}]") for j, v in enumerate(row))
                                 for i, row in enumerate(value))
        else:
            changes[key] = _number(value, at, whole=key == "counts_per_rev")
    try:
        return dataclasses.replace(base, **changes)
    except ValueError as exc:               # "<Spec>.<field>: ..." from __post_init__
        message = str(exc)
        raise ValueError(f"{where}.{message.split('.', 1)[1]}" if "." in message.split(":")[0] else
                         f"{where}: {message}") from None


# -- files -----------------------------------------------------------------------------------
def sensor_set_dir():
    """The folder of the shipped sensor sets (runtime/sensor_sets/)."""
    return importlib.resources.files("runtime") / "sensor_sets"


def shipped_sensor_sets():
    """The names of the shipped sensor sets."""
    return sorted(p.name[:-5] for p in sensor_set_dir().iterdir() if p.name.endswith(".toml"))


def sensor_set_path(name_or_path):
    """The file of a shipped sensor set name, or `name_or_path` itself if it is not one."""
    candidate = sensor_set_dir() / f"{name_or_path}.toml"
    if "/" not in str(name_or_path) and candidate.is_file():
        return pathlib.Path(str(candidate))
    return pathlib.Path(name_or_path)


def load_sensor_set(name_or_path):
    """The set of a standalone sensors file (a shipped name or a path): a TOML file with one
    `[sensors]` section (and an optional `description`), as in a scenario file."""
    path = sensor_set_path(name_or_path)
    if not path.is_file():
        raise ValueError(f"{path}: no such sensors file (shipped: {', '.join(shipped_sensor_sets())})")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    check_table(data, {"description", "sensors"}, str(path))
    if "sensors" not in data:
        raise ValueError(f"{path}: sensors: missing (required): a sensors file holds one [sensors] section")
    return parse_sensors(data["sensors"], str(path))


def parse_sensors(table, source):
    """The `[sensors]` section `table` of the file `source`; errors read "<source>: sensors.<table>.<key>: ..."."""
    return SensorSet.from_table(table, f"{source}: sensors")
