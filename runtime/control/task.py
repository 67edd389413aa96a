"""Benchmark task files: a scenario (params, initial state, dt, duration, method) plus
`[reference]`, `[controller]` and `[plant]` (docs/control.md, "Task files").

    task = load_task("circle")            # a shipped name (runtime/control/tasks/), or a path
    controller, reference = task.controller(), task.reference()

The scenario part is validated by runtime/scenario.py (`parse_scenario`); every bad
value here raises ValueError("<file>: <section>.<key>: <what is wrong>").
"""
import dataclasses
import importlib.resources
import math
import pathlib
import tomllib

import numpy as np


from .. import memory
from ..params import NAMES as PARAM_NAMES
from ..params import PAPER_NAMES, SHAPES
from ..scenario import ROBOT_RANGES, parse_scenario
from ..schema import Range, check_ranges, check_table
from .closed_loop import Noise
from .controller import DEFAULT_U_MAX
from .geometry import heading
from .lqr import GAIN_NAMES as LQR_GAIN_NAMES
from .lqr import Lqr, LqrGains
from .nmpc import GAIN_NAMES as NMPC_GAIN_NAMES
from .nmpc import NZ_N as NMPC_NZ
from .nmpc import Nmpc, NmpcC, NmpcGains
from .estimator import SETTING_NAMES as ESTIMATOR_SETTINGS
from .estimator import Ekf, EkfSettings, SensorEkf
from .pid import GAIN_NAMES, Pid, PidGains
from .ranges import CONTROLLER_RANGES, ESTIMATOR_RANGES, LQR_RANGES, NMPC_C_RANGES, NMPC_RANGES, PID_RANGES
from .reference import KINDS, SpeedHeading, path_points, circle_path, figure8_path, line_path, waypoints_path
from ..state import IDX_Q

#: Controller kinds: (class, its settings, the settings' names).
AVAILABLE_CONTROLLERS = {"pid": (Pid, PidGains, GAIN_NAMES), "lqr": (Lqr, LqrGains, LQR_GAIN_NAMES),
                         "nmpc": (Nmpc, NmpcGains, NMPC_GAIN_NAMES), "nmpc-c": (NmpcC, NmpcGains, NMPC_GAIN_NAMES)}
CONTROLLER_KINDS = tuple(AVAILABLE_CONTROLLERS)
_SCENARIO_KEYS = {"description", "dt", "duration", "steps", "method", "params", "initial", "sensors", "friction"}
_REFERENCE_KEYS = {"kind", "speed", "heading", "offset", "radius", "size", "points"}
_NEEDS = {"speed": ("speed",), "heading": ("speed", "heading"), "line": ("speed", "offset"),
          "circle": ("speed", "radius"), "figure8": ("speed", "size"), "waypoints": ("speed", "points")}
#: The ranges of the numbers of a task file beyond its scenario's (runtime/scenario.py's
#: SCENARIO_RANGES): by table, the controllers' settings by kind ("controller.<kind>"); the
#: controllers' and the estimator's are those of their constructors (runtime/control/ranges.py).
TASK_RANGES = {
    "reference": {"speed": Range(-10, 10, "m/s", "the robot's speed: 10 m/s is 5 turns a second of a 0.3 m shell"),
                  "heading": Range(-1e3, 1e3, "rad", "an angle: further out it keeps too few digits"),
                  "offset": Range(-1e3, 1e3, "m", "a line's offset from the start"),
                  "radius": Range(0.05, 1e3, "m", "a circle: tighter than 5 cm no robot turns; its path table "
                                                  "holds a point every 5 mm"),
                  "size": Range(0.05, 1e3, "m", "a figure eight's lobe radius, as a circle's"),
                  "points": Range(-1e4, 1e4, "m", "a waypoint: its legs are tabled every 5 mm")},
    "controller": CONTROLLER_RANGES,
    "controller.pid": PID_RANGES,
    "controller.lqr": LQR_RANGES,
    "controller.nmpc": NMPC_RANGES,
    "estimator": ESTIMATOR_RANGES,
    "plant": {**ROBOT_RANGES,
              "noise_position_m": Range(0, 1e3, "m", "a standard deviation"),
              "noise_attitude_rad": Range(0, 10, "rad", "a standard deviation"),
              "noise_rate_rad_s": Range(0, 1e3, "rad/s", "a standard deviation"),
              "noise_seed": Range(0, 2**63 - 1, "", "a seed of NumPy's generator", whole=True)},
}
# The C NMPC takes the NMPC's settings, its horizon at most SR_NMPC_MAX_HORIZON.
TASK_RANGES["controller.nmpc-c"] = NMPC_C_RANGES
#: Bytes per sample of a path table: points (2), arc length, tangent, curvature, and the
#: differences, segment lengths and turns that build them.
PATH_ROW_BYTES = 12 * 8
_NOISE_KEYS = {"noise_position_m": "position_m", "noise_attitude_rad": "attitude_rad",
               "noise_rate_rad_s": "rate_rad_s", "noise_seed": "seed"}


@dataclasses.dataclass(frozen=True)
class ControllerSpec:
    """One `[controller]` table (or one entry of `[[controller]]`): its kind, rate, limit and tuning."""
    kind: str
    rate: float
    u_max: float
    gains: object


@dataclasses.dataclass(frozen=True)
class Task:
    """A control task: the scenario, the reference, the controllers to run, the plant and its measurement
    noise."""
    name: str
    source: str
    scenario: object            # runtime.scenario.Scenario: the controller's model and x0
    reference_spec: dict
    controllers: tuple          # ControllerSpec, one per kind; the first is the task's default
    plant_params: object        # runtime.Params of the simulated robot
    noise: Noise
    estimator: object = None    # EkfSettings, or None: the controller reads the measurement itself

    @property
    def duration(self):
        """The task's length [s]."""
        return self.scenario.duration

    # The first controller's settings (a task run with one controller: `with_controller`).
    controller_kind = property(lambda self: self.controllers[0].kind, doc="The first controller's kind.")
    rate = property(lambda self: self.controllers[0].rate, doc="The first controller's rate [Hz].")
    u_max = property(lambda self: self.controllers[0].u_max, doc="The first controller's torque limit [N m].")
    gains = property(lambda self: self.controllers[0].gains, doc="The first controller's gains.")
    sensors = property(lambda self: self.scenario.sensors,
                       doc="The task's `[sensors]` (runtime.sensor_set.SensorSet), None without one.")

    @property
    def controller_kinds(self):
        """The kinds of controller the task names, its default first."""
        return tuple(c.kind for c in self.controllers)

    def with_controller(self, kind):
        """The task with only its controller of this kind."""
        for spec in self.controllers:
            if spec.kind == kind:
                return dataclasses.replace(self, controllers=(spec,))
        raise ValueError(f"{self.source}: no controller of kind {kind!r} (it has {', '.join(self.controller_kinds)})")

    def controller(self):
        """A new controller of the task's kind, rate, torque limit and gains, designed for the scenario's
        robot."""
        cls = AVAILABLE_CONTROLLERS[self.controller_kind][0]
        return cls(self.scenario.params, rate=self.rate, u_max=self.u_max, gains=self.gains)

    def make_estimator(self):
        """The filter on the controller's model (never the plant's): on the `[sensors]` a
        `SensorEkf`, else the `[estimator]`'s `Ekf`, else None."""
        if self.sensors is not None:
            return SensorEkf(self.scenario.params, self.sensors, self.scenario.x0, self.scenario.method,
                             hold=self.scenario.dt)
        return None if self.estimator is None else Ekf(self.scenario.params, self.estimator)

    def with_sensors(self, sensors):
        """The task on these sensors (runtime.sensor_set.SensorSet; None: on the state), instead of its
        own `[sensors]`, `[estimator]` and measurement noise."""
        return dataclasses.replace(self, scenario=dataclasses.replace(self.scenario, sensors=sensors),
                                   estimator=None, noise=Noise(seed=self.noise.seed))

    def path_length(self):
        """The length [m] of path a run needs: the distance at the reference speed and 2 m more."""
        return abs(self.reference_spec["speed"]) * self.duration + 2.0

    def memory_estimate(self):
        """{what: bytes} of the largest arrays a run of the task holds (runtime/memory.py): the
        plant's trajectory and torques, its contact forces, the estimates, the path table (its points, arc lengths,
        tangents, curvatures and the temporaries that build them), the NMPC's condensed problem."""
        steps = self.scenario.steps
        parts = {"trajectory": memory.trajectory_bytes(steps), "contact force": (steps + 1) * 3 * 8}
        spec, x0 = self.reference_spec, self.scenario.x0
        points = path_points(spec["kind"], self.path_length(), spec.get("radius"), spec.get("size"),
                             x0[IDX_Q][:2], spec.get("points"))
        if points is not None:
            parts["path table"] = points * PATH_ROW_BYTES
        if self.estimator is not None or self.sensors is not None:
            parts["estimates"] = (steps + 1) * memory.STATE_ROW_BYTES
        if self.sensors is not None:
            rate = sum(getattr(self.sensors, kind).rate for kind in ("imu", "encoders", "fixes", "heading")
                       if getattr(self.sensors, kind) is not None)
            # each sample: its reading's row and, in the closed loop's record, a tuple and a view of it
            parts["sensor samples"] = (math.floor(self.duration * rate) + 4) * 256
        nmpc = [c for c in self.controllers if c.kind == "nmpc"]
        if nmpc:
            n = max(int(c.gains.horizon) for c in nmpc)
            nz, nu = NMPC_NZ, 2 * n
            parts["NMPC problem"] = 8 * (3 * (n + 1) * nz * nu + 4 * nu * nu + 3 * n * nz * (nz + 2))
        return parts

    def check_memory(self, budget=None):
        """The bytes a run needs, or memory.MemoryBudgetExceeded naming the file when they exceed
        `budget` (default: the memory budget)."""
        return memory.check(self.source, self.memory_estimate(), budget)

    def reference(self):
        """The reference, built from the start pose (paths start at the robot, tangent to its heading)."""
        spec, x0 = self.reference_spec, self.scenario.x0
        start, psi0 = x0[IDX_Q][:2], float(heading(x0))
        speed = spec["speed"]
        length = self.path_length()
        kind = spec["kind"]
        if kind == "speed":
            return SpeedHeading(speed, spec.get("heading", psi0))
        if kind == "heading":
            return SpeedHeading(speed, spec["heading"])
        if kind == "line":
            return line_path(start, spec.get("heading", psi0), spec["offset"], length, speed)
        if kind == "circle":
            return circle_path(start, psi0, spec["radius"], length, speed)
        if kind == "figure8":
            return figure8_path(start, psi0, spec["size"], length, speed)
        return waypoints_path(start, spec["points"], speed)


def task_dir():
    """The folder of the shipped task files."""
    return importlib.resources.files("runtime") / "control" / "tasks"


def shipped_tasks():
    """The names of the shipped tasks."""
    return sorted(p.name[:-5] for p in task_dir().iterdir() if p.name.endswith(".toml"))


def load_task(name_or_path):
    """The task of a shipped name or a path to a .toml file; ValueError naming the problem otherwise."""
    candidate = task_dir() / f"{name_or_path}.toml"
    path = pathlib.Path(str(candidate)) if "/" not in str(name_or_path) and candidate.is_file() \
        else pathlib.Path(name_or_path)
    if not path.is_file():
        raise ValueError(f"{path}: no such task file (shipped tasks: {', '.join(shipped_tasks())})")
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    return parse_task(data, source=str(path), name=path.stem)


def parse_task(data, source="<task>", name="task"):
    """The Task described by the table `data` (from the file `source`); ValueError naming the field and the
    problem."""
    check_table(data, _SCENARIO_KEYS | {"reference", "controller", "plant", "estimator"}, source)
    scenario = parse_scenario({k: v for k, v in data.items() if k in _SCENARIO_KEYS}, source, name)
    reference = _parse_reference(data.get("reference"), source)
    tables = data.get("controller")
    tables = tables if isinstance(tables, list) and tables else [tables]
    controllers = []
    for i, table in enumerate(tables):
        spec = ControllerSpec(*_parse_controller(table, source, "controller" if len(tables) == 1 else f"controller[{i}]"))
        if spec.kind in (c.kind for c in controllers):
            raise ValueError(f"{source}: controller[{i}].kind: {spec.kind!r} appears twice")
        per = spec.rate * scenario.dt
        if not 1e-300 < per < 1e300 or abs(1 / per - round(1 / per)) > 1e-9 * (1 / per):
            raise ValueError(f"{source}: controller.rate: the period 1/{spec.rate:g} s is not a whole number of "
                             f"steps dt = {scenario.dt:g} s")
        controllers.append(spec)
    plant, noise = _parse_plant(data.get("plant", {}), scenario.params, source)
    estimator = _parse_estimator(data["estimator"], source) if "estimator" in data else None
    if scenario.sensors is not None and (estimator is not None or noise.active):
        raise ValueError(f"{source}: sensors: a task on sensors is estimated by the filter on them; "
                         f"[estimator] and [plant]'s noise_* (the full state measured) do not apply")
    return Task(name=name, source=source, scenario=scenario, reference_spec=reference,
                controllers=tuple(controllers), plant_params=plant, noise=noise, estimator=estimator)


def _parse_estimator(table, source):
    where = f"{source}: estimator"
    check_table(table, {"kind", *ESTIMATOR_SETTINGS}, where)
    if table.get("kind") != "ekf":
        raise ValueError(f"{where}.kind: expected \"ekf\", got {table.get('kind')!r}")
    check_ranges(table, TASK_RANGES["estimator"], where)
    return EkfSettings(**{k: _real(v, f"{where}.{k}", positive=k != "rate", nonnegative=k == "rate")
                          for k, v in table.items() if k != "kind"})


def _real(value, where, positive=False, nonnegative=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}: expected a number, got {type(value).__name__} {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"{where}: must be finite, got {value!r}")
    if positive and not value > 0:
        raise ValueError(f"{where}: must be > 0, got {value!r}")
    if nonnegative and not value >= 0:
        raise ValueError(f"{where}: must be >= 0, got {value!r}")
    return float(value)


def _parse_reference(table, source):
    where = f"{source}: reference"
    if table is None:
        raise ValueError(f"{where}: missing (required): give kind = one of {', '.join(KINDS)}")
    check_table(table, _REFERENCE_KEYS, where)
    check_ranges(table, TASK_RANGES["reference"], where)
    kind = table.get("kind")
    if kind not in KINDS:
        raise ValueError(f"{where}.kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    for key in _NEEDS[kind]:
        if key not in table:
            raise ValueError(f"{where}.{key}: missing (required for kind = {kind!r})")
    spec = {"kind": kind}
    for key in ("speed", "heading", "offset"):
        if key in table:
            spec[key] = _real(table[key], f"{where}.{key}")
    for key in ("radius", "size"):
        if key in table:
            spec[key] = _real(table[key], f"{where}.{key}", positive=True)
    if "points" in table:
        pts = table["points"]
        if not (isinstance(pts, list) and pts and all(isinstance(p, list) and len(p) == 2 for p in pts)):
            raise ValueError(f"{where}.points: expected a non-empty list of [x, y] pairs in m, got {pts!r}")
        spec["points"] = np.array([[_real(v, f"{where}.points[{i}][{j}]") for j, v in enumerate(p)]
                                   for i, p in enumerate(pts)])
        if np.any(np.hypot(*np.diff(spec["points"], axis=0).T) == 0):
            raise ValueError(f"{where}.points: two consecutive points are equal")
    return spec


def _parse_controller(table, source, name="controller"):
    where = f"{source}: {name}"
    if table is None:
        raise ValueError(f"{where}: missing (required): give kind = \"pid\", \"lqr\" or \"nmpc\"")
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table, got {type(table).__name__} {table!r}")
    kind = table.get("kind")
    if kind not in CONTROLLER_KINDS:
        raise ValueError(f"{where}.kind: expected one of {', '.join(CONTROLLER_KINDS)}, got {kind!r}")
    _, gains_cls, gain_names = AVAILABLE_CONTROLLERS[kind]
    check_table(table, {"kind", "rate", "u_max", *gain_names}, where)
    check_ranges(table, TASK_RANGES["controller"] | TASK_RANGES[f"controller.{kind}"], where)
    rate = _real(table.get("rate", 50.0), f"{where}.rate", positive=True)
    u_max = _real(table.get("u_max", DEFAULT_U_MAX), f"{where}.u_max", positive=True)
    try:
        gains = gains_cls(**{k: _real(v, f"{where}.{k}", nonnegative=True)
                             for k, v in table.items() if k in gain_names})
    except ValueError as exc:
        if str(exc).startswith(source):
            raise
        raise ValueError(f"{where}.{exc}") from None
    return kind, rate, u_max, gains


def _parse_plant(table, params, source):
    where = f"{source}: plant"
    check_table(table, set(PARAM_NAMES) | set(PAPER_NAMES) | set(_NOISE_KEYS), where)
    check_ranges(table, TASK_RANGES["plant"], where)
    overrides = {k: (_real(v, f"{where}.{k}") if SHAPES.get(k, ()) == () else v)
                 for k, v in table.items() if k not in _NOISE_KEYS}
    try:
        plant = params.with_changes(**overrides)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    noise = {}
    for key, field in _NOISE_KEYS.items():
        if key in table:
            if key == "noise_seed":
                if isinstance(table[key], bool) or not isinstance(table[key], int) or table[key] < 0:
                    raise ValueError(f"{where}.{key}: expected a non-negative whole number, got {table[key]!r}")
                noise[field] = table[key]
            else:
                noise[field] = _real(table[key], f"{where}.{key}", nonnegative=True)
    return plant, Noise(**noise)
