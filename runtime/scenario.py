"""Scenario files: load and validate a TOML description of one simulation, and run it.

A scenario names everything a run needs: parameters (a preset plus
overrides by the paper's names), the initial state, the time step, the
length of the run, the integrator and a piecewise-constant motor torque
program.  The format is documented with a full example in
docs/scenarios.md; the three simulations of the paper's Section 5.3 ship in
runtime/scenarios/.

    scenario = load_scenario("t-shape")          # a shipped name, or a path to a .toml file
    result = run_scenario(scenario)              # trajectory, torques, energy, wall time

Every problem with a file raises ValueError("<file>: <key>: <what is wrong>").
Nothing here writes files or draws: see runtime/scenarios/report.py.
"""
import dataclasses
import importlib.resources
import math
import pathlib
import time
import tomllib

import numpy as np

from . import memory
from . import model as _model_module
from .errors import SimulationStopped
from .model import Model
from .params import NAMES as PARAM_NAMES
from .params import PAPER_NAMES, SHAPES, Params
from .so3 import rot_x, rot_y
from .state import IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, NU, NX
from .schema import Range, check_range, check_ranges, check_table, show
from .sensor_set import parse_sensors
from .validation import ROTATION_TOL, choice, describe_state

#: The paper's simulations in the order of Section 5.3 (`run all` runs them in this order).
PAPER_SCENARIOS = ("tilted-pendulum", "tilted-yoke", "t-shape")

#: Named parameter sets a scenario may start from (`[params] preset = ...`).
PRESETS = {"paper": Params.paper, "paper_simulation": Params.paper_simulation}

#: Largest number of steps of a run (runtime.model.MAX_STEPS, the one limit): a larger `steps`
#: (or duration / dt) is an error, not a MemoryError.
MAX_STEPS = _model_module.MAX_STEPS

_ANGLE = Range(-1e3, 1e3, "rad", "an angle: further out its rotation keeps too few digits")
_RATE = Range(-1e3, 1e3, "rad/s", "a rate: 10,000 turns a minute, far past any motor")
_TORQUE = Range(-1e3, 1e3, "N m", "a motor torque: the paper's motors give 0.5-2 N m")
_TIME = Range(0, 1e6, "s", "a time within a run: at most MAX_STEPS steps of at most 1 s, in practice far less")
#: The ranges of a robot's parameters (robot files, `[params]` of scenario and `[plant]` of task
#: files), by the general names and the paper's, each entry of a vector or tensor alike.  Which
#: values make a robot at all is C's parameter check; these bound what is computable.
ROBOT_RANGES = {
    **{name: Range(0, 100, "m", "a length: a robot of up to 100 m") for name in ("r", "b", "h", "l")},
    **{name: Range(0, 1e6, "kg", "a mass: up to 1000 t") for name in ("m_S", "m_Y", "m_P", "m_b", "m_h")},
    **{name: Range(0, 1e6, "kg m^2", "an inertia") for name in ("j_S", "j_mY", "j_mP")},
    **{name: Range(-1e6, 1e6, "kg m^2", "an inertia tensor's entry") for name in ("J_Y", "J_P")},
    **{name: Range(-100, 100, "m", "a centre of mass, inside a robot of up to 100 m") for name in ("c_Y", "c_P")},
    **{name: Range(0, 1e6, "N m s/rad", "a damping coefficient") for name in ("k_S", "k_Y", "k_P")},
    **{name: Range(-1e4, 1e4, "", "a gear ratio") for name in ("n_Y", "n_P")},
    "g": Range(0, 1e3, "m/s^2", "gravity: 100 g at most"),
    "slope": Range(-1.5707963267948966, 1.5707963267948966, "rad", "a floor's slope"),
}
#: The ranges of the numbers of a scenario file, by table ("" the top level).
SCENARIO_RANGES = {
    "": {"dt": Range(1e-9, 1.0, "s", "below 1 ns a step moves the state by less than its rounding; "
                                     "above 1 s no integrator follows the robot"),
         "steps": Range(1, MAX_STEPS, "", "the trajectory is kept in memory (MAX_STEPS)", whole=True),
         "duration": Range(0, 1e6, "s", "at most MAX_STEPS steps of at most 1 s", open_low=True),
         "friction": Range(0, 10, "", "a Coulomb friction coefficient: rubber on dry concrete is about 1",
                           open_low=True)},
    "params": ROBOT_RANGES,
    "initial": {"theta_Y": _ANGLE, "theta_P": _ANGLE, "R_S": Range(-1, 1, "", "a rotation's entry"),
                "R_Y": Range(-1, 1, "", "a rotation's entry"), "R_P": Range(-1, 1, "", "a rotation's entry"),
                "q": Range(-1e6, 1e6, "m", "a position: 1000 km from the origin at most"),
                "w_S": _RATE, "w_Y": _RATE, "w_P": _RATE},
    "torque": {"from_step": Range(1, MAX_STEPS, "", "a step of the run", whole=True),
               "to_step": Range(1, MAX_STEPS, "", "a step of the run", whole=True),
               "from_time": _TIME, "to_time": _TIME, "u_Y": _TORQUE, "u_P": _TORQUE},
}

_TOP_KEYS = {"description", "dt", "steps", "duration", "method", "params", "initial", "torque", "sensors", "friction"}
_INITIAL_KEYS = {"theta_Y", "theta_P", "R_S", "R_Y", "R_P", "q", "w_S", "w_Y", "w_P"}
_TORQUE_KEYS = {"from_step", "to_step", "from_time", "to_time", "u_Y", "u_P"}


# -- data ---------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class TorqueWindow:
    """Constant motor torques (u_Y, u_P) [N m] on the steps whose start time t lies in [t_from, t_to).

    Windows given by step index in a file (`from_step`, `to_step`, inclusive,
    1-based) are stored as the time span they cover at the file's dt:
    t_from = (from_step − 1)·dt, t_to = to_step·dt.  At the file's dt the two
    readings select exactly the same steps; at another dt (a `--dt` override,
    a convergence study) the window keeps its physical time span.
    """
    t_from: float
    t_to: float
    u_Y: float = 0.0
    u_P: float = 0.0


@dataclasses.dataclass(frozen=True)
class Scenario:
    """A validated scenario.  `source` is the file it came from (for messages and summaries);
    `sensors` its `[sensors]` section (runtime.sensor_set.SensorSet), None without one."""
    name: str
    source: str
    params: Params
    x0: np.ndarray
    dt: float
    steps: int
    method: str
    torques: tuple = ()
    description: str = ""
    sensors: object = None
    friction: float = None    # μ of the floor, or None: where the motion needs more, its summary says so

    @property
    def duration(self):
        """The simulated time [s], steps * dt."""
        return self.steps * self.dt

    def with_overrides(self, dt=None, steps=None, method=None):
        """A copy with another time step, length or integrator (the command line's --dt, --steps, --method).

        A new dt without new steps keeps the duration (steps = duration / dt,
        which must be a whole number).  Torque windows keep their time spans.
        """
        where = f"{self.source}: override"
        keys = SCENARIO_RANGES[""]     # the ranges of the file's own keys
        new_dt = self.dt if dt is None else check_range(_positive_real(dt, f"{where}: dt"), keys["dt"], f"{where}: dt")
        if steps is not None:
            new_steps = check_range(_step_count(steps, f"{where}: steps"), keys["steps"], f"{where}: steps")
        elif dt is not None:
            new_steps = _whole_steps(self.duration, new_dt, f"{where}: dt")
        else:
            new_steps = self.steps
        if dt is not None or steps is not None:
            named = " and ".join(n for n, v in (("dt", dt), ("steps", steps)) if v is not None)
            check_range(new_steps * new_dt, keys["duration"], f"{where}: {named}: the duration steps × dt")
        new_method = self.method if method is None else _method_name(method, f"{where}: method")
        return dataclasses.replace(self, dt=new_dt, steps=new_steps, method=new_method)

    def torque_at_step_starts(self, count=None):
        """Torques (count, 2) [N m]: row k acts on the step that starts at t = k·dt (default count = steps).

        A step belongs to a window when its start time lies in [t_from, t_to);
        overlapping windows add.  Start times are compared in units of dt with a
        1e-9 allowance, so that 0.07 / 0.01 = 7.000000000000001 counts as 7.
        """
        count = self.steps if count is None else count
        u = np.zeros((count, NU))
        for window in self.torques:
            first = max(math.ceil(window.t_from / self.dt - 1e-9), 0)
            stop = min(math.ceil(window.t_to / self.dt - 1e-9), count)
            if stop > first:
                u[first:stop] += (window.u_Y, window.u_P)
        return u


@dataclasses.dataclass(frozen=True)
class Result:
    """What a run produced.  Row n of `trajectory`, `energy` and `torques` belongs to t = n·dt.

    `torques[n]` is the torque the program prescribes from t = n·dt on (the
    torque of step n+1); the last row, which starts no step, is what the
    program would prescribe at the final time.
    """
    scenario: Scenario
    time: np.ndarray          # (steps+1,)
    trajectory: np.ndarray    # (steps+1, 35)
    torques: np.ndarray       # (steps+1, 2)
    energy: np.ndarray        # (steps+1,)
    wall_time_s: float        # simulation, energy and contact force evaluation
    contact_force: np.ndarray = None   # (steps+1, 3) [N], plane frame (Model.contact_force)


# -- loading ------------------------------------------------------------------------------
def shipped_scenarios():
    """Names of the scenarios in runtime/scenarios/: the paper's first, in Section 5.3 order, then the rest."""
    names = sorted(p.name[:-5] for p in _scenario_dir().iterdir() if p.name.endswith(".toml"))
    return [n for n in PAPER_SCENARIOS if n in names] + [n for n in names if n not in PAPER_SCENARIOS]


def scenario_path(name_or_path):
    """The file of a shipped scenario name, or `name_or_path` itself if it is not one."""
    candidate = _scenario_dir() / f"{name_or_path}.toml"
    if "/" not in str(name_or_path) and candidate.is_file():
        return pathlib.Path(str(candidate))
    return pathlib.Path(name_or_path)


def load_scenario(name_or_path):
    """Read and validate a scenario: a shipped name (see `shipped_scenarios()`) or a path to a TOML file."""
    path = scenario_path(name_or_path)
    if not path.is_file():
        shipped = ", ".join(shipped_scenarios())
        raise ValueError(f"{path}: no such scenario file (shipped scenarios: {shipped})")
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML (not UTF-8 text: {exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    return parse_scenario(data, source=str(path), name=path.stem)


def parse_scenario(data, source="<scenario>", name="scenario"):
    """Validate the table `data` (as read by tomllib) into a `Scenario`; `source` prefixes every error."""
    check_table(data, _TOP_KEYS, source)
    description = data.get("description", "")
    if not isinstance(description, str):
        raise ValueError(f"{source}: description: expected a string, got {show(description)}")
    params = _parse_params(data.get("params", {}), source)
    dt = _positive_real(_require(data, "dt", source), f"{source}: dt")
    if ("steps" in data) == ("duration" in data):
        raise ValueError(f"{source}: steps, duration: give exactly one of the two")
    if "steps" in data:
        steps = _step_count(data["steps"], f"{source}: steps")
    else:
        steps = _whole_steps(_positive_real(data["duration"], f"{source}: duration"), dt, f"{source}: duration")
    method = _method_name(data.get("method", "lie-euler"), f"{source}: method")
    x0 = _parse_initial(data.get("initial", {}), params, source)
    # The kernels' own check of the assembled state, in case a rule is not mirrored above.
    problem = describe_state(x0, params.r, "x0")
    if problem is not None:
        raise ValueError(f"{source}: initial: {problem}")
    torques = _parse_torques(data.get("torque", []), dt, steps, source)
    friction = _positive_real(data["friction"], f"{source}: friction") if "friction" in data else None
    check_scenario_ranges(data, source)
    sensors = parse_sensors(data["sensors"], source) if "sensors" in data else None
    return Scenario(name=name, source=source, params=params, x0=x0, dt=dt, steps=steps,
                    method=method, torques=torques, description=description, sensors=sensors, friction=friction)


def check_scenario_ranges(data, source):
    """Every number of the scenario table `data` inside its range of `SCENARIO_RANGES`."""
    check_ranges(data, SCENARIO_RANGES[""], source, sep=": ")
    check_ranges(data.get("params"), ROBOT_RANGES, f"{source}: params")
    check_ranges(data.get("initial"), SCENARIO_RANGES["initial"], f"{source}: initial")
    windows = data.get("torque", [])
    for i, window in enumerate(windows if isinstance(windows, list) else [], start=1):
        check_ranges(window, SCENARIO_RANGES["torque"], f"{source}: torque[{i}]")


def _scenario_dir():
    return importlib.resources.files("runtime") / "scenarios"


def _parse_params(table, source):
    """The robot: a preset (or a `robot` file, relative to the scenario's), then changes by the
    paper's names or the general ones (`Params.with_changes`); c_* as [x, y, z], J_* as 3x3 lists."""
    where = f"{source}: params"
    check_table(table, {"preset", "robot"} | set(PARAM_NAMES) | set(PAPER_NAMES), where)
    if "preset" in table and "robot" in table:
        raise ValueError(f"{where}: give a preset or a robot file, not both")
    preset = table.get("preset", "paper")
    if preset.__class__ is not str or preset not in PRESETS:
        raise ValueError(f"{where}.preset: unknown preset {show(preset)}; choose one of {sorted(PRESETS)}")
    changes = {key: (_real(value, f"{where}.{key}") if SHAPES.get(key, ()) == () else value)
               for key, value in table.items() if key not in ("preset", "robot")}
    try:
        base = _load_robot(table["robot"], source) if "robot" in table else PRESETS[preset]()
        params = base.with_changes(**changes) if changes else base
        Model(params)                  # C's checks too: M positive definite, no overflow
    except ValueError as exc:          # Params names the parameter ("Params.r: must be > 0")
        raise ValueError(f"{where}: {exc}") from None
    return params


def _load_robot(path, source):
    """A scenario's robot file, relative to the scenario file `source`."""
    if not isinstance(path, str):
        raise ValueError(f"robot: expected a file name, got {show(path)}")
    return load_robot(pathlib.Path(source).parent / path)


def load_robot(path):
    """The `Params` of a robot file (a TOML table of general parameters, docs/robots.md; the ones it
    leaves out are the paper's robot's); ValueError naming the file and the field otherwise."""
    full = pathlib.Path(path)
    try:
        table = tomllib.loads(full.read_text())
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"robot: cannot read {full}: {exc}") from None
    check_ranges(table, ROBOT_RANGES, str(full), sep=": ")
    unknown = sorted(set(table) - set(PARAM_NAMES))
    if unknown:
        raise ValueError(f"robot: {full}: unknown key(s) {', '.join(map(repr, unknown))}; allowed: "
                         f"{', '.join(PARAM_NAMES)}")
    try:
        return Model(Params(**table)).params     # C's checks of the whole robot too, naming this file
    except ValueError as exc:
        raise ValueError(f"robot: {full}: {exc}") from None


def _parse_initial(table, params, source):
    where = f"{source}: initial"
    check_table(table, _INITIAL_KEYS, where)
    for angle, matrix in (("theta_Y", "R_Y"), ("theta_P", "R_P")):
        if angle in table and matrix in table:
            raise ValueError(f"{where}: {angle}, {matrix}: give the angle or the matrix, not both")
    x0 = np.zeros(NX)
    x0[IDX_RS] = _rotation(table, "R_S", where, axis=None).ravel()
    x0[IDX_RY] = (_rotation(table, "R_Y", where, axis=0) if "R_Y" in table
                  else rot_x(_real(table.get("theta_Y", 0.0), f"{where}.theta_Y"))).ravel()
    x0[IDX_RP] = (_rotation(table, "R_P", where, axis=1) if "R_P" in table
                  else rot_y(_real(table.get("theta_P", 0.0), f"{where}.theta_P"))).ravel()
    q = _vector(table.get("q", [0.0, 0.0, params.r]), 3, f"{where}.q")
    if abs(q[2] - params.r) > ROTATION_TOL * params.r:
        raise ValueError(f"{where}.q: the centre must be at height q_z = r = {params.r:g} m "
                         f"(the shell rests on the plane), got q_z = {q[2]:g}")
    x0[IDX_Q] = q
    x0[IDX_WS] = _vector(table.get("w_S", [0.0, 0.0, 0.0]), 3, f"{where}.w_S")
    x0[IDX_WY] = _real(table.get("w_Y", 0.0), f"{where}.w_Y")
    x0[IDX_WP] = _real(table.get("w_P", 0.0), f"{where}.w_P")
    return x0


def _parse_torques(windows, dt, steps, source):
    if not isinstance(windows, list):
        raise ValueError(f"{source}: torque: expected an array of tables ([[torque]]), got {show(windows)}")
    parsed = []
    for i, table in enumerate(windows, start=1):
        where = f"{source}: torque[{i}]"
        if not isinstance(table, dict):
            raise ValueError(f"{where}: expected a table, got {show(table)}")
        check_table(table, _TORQUE_KEYS, where)
        by_step = {"from_step", "to_step"} & table.keys()
        by_time = {"from_time", "to_time"} & table.keys()
        if by_step and by_time:
            raise ValueError(f"{where}: give the window by step (from_step, to_step) or by time "
                             f"(from_time, to_time), not both")
        if by_time:
            t_from = _real(_require(table, "from_time", where), f"{where}.from_time")
            t_to = _real(_require(table, "to_time", where), f"{where}.to_time")
            if not 0 <= t_from < t_to:
                raise ValueError(f"{where}.from_time, to_time: need 0 <= from_time < to_time, "
                                 f"got [{t_from:g}, {t_to:g})")
            if t_from >= steps * dt:
                raise ValueError(f"{where}.from_time: {t_from:g} s is at or past the end of the run "
                                 f"({steps * dt:g} s): the window would select no step")
        else:
            first = _step_count(_require(table, "from_step", where), f"{where}.from_step")
            last = _step_count(_require(table, "to_step", where), f"{where}.to_step")
            if not 1 <= first <= last:
                raise ValueError(f"{where}.from_step, to_step: need 1 <= from_step <= to_step "
                                 f"(steps are numbered from 1), got {first}..{last}")
            if last > steps:
                raise ValueError(f"{where}.to_step: step {last} is past the end of the run ({steps} steps)")
            t_from, t_to = (first - 1) * dt, last * dt
        if "u_Y" not in table and "u_P" not in table:
            raise ValueError(f"{where}: give u_Y (yoke torque, N m), u_P (pendulum torque, N m) or both")
        parsed.append(TorqueWindow(t_from, t_to, _real(table.get("u_Y", 0.0), f"{where}.u_Y"),
                                   _real(table.get("u_P", 0.0), f"{where}.u_P")))
    return tuple(parsed)


# -- value checks (each names the key it checks) ----------------------------------------------
def _require(table, key, where):
    if key not in table:
        raise ValueError(f"{where}: {key}: missing (required)")
    return table[key]


def _real(value, where):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}: expected a number, got {show(value)}")
    if not math.isfinite(value):
        raise ValueError(f"{where}: must be finite, got {value!r}")
    return float(value)


def _positive_real(value, where):
    value = _real(value, where)
    if not value > 0:
        raise ValueError(f"{where}: must be > 0, got {value!r}")
    return value


def _step_count(value, where):
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{where}: expected a whole number, got {show(value)}")
    if value < 1:
        raise ValueError(f"{where}: must be >= 1, got {value}")
    if value > MAX_STEPS:
        raise ValueError(f"{where}: {value} is more than MAX_STEPS = {MAX_STEPS} (the trajectory is kept in memory)")
    return value


def _whole_steps(duration, dt, where):
    ratio = duration / dt
    if not ratio <= MAX_STEPS + 0.5:
        raise ValueError(f"{where}: {duration:g} s at dt = {dt:g} s is more than MAX_STEPS = {MAX_STEPS} steps "
                         f"(the trajectory is kept in memory)")
    steps = round(ratio)
    if steps < 1 or abs(steps * dt - duration) > 1e-9 * max(duration, dt):
        raise ValueError(f"{where}: the duration {duration:g} s is not a whole number of steps of dt = {dt:g} s")
    return steps


def _method_name(value, where):
    return choice(value, where, _model_module.METHODS, "integrator")   # METHODS looked up now: it may grow


def _vector(value, n, where):
    if not isinstance(value, list) or len(value) != n:
        raise ValueError(f"{where}: expected a list of {n} numbers, got {show(value)}")
    return np.array([_real(v, f"{where}[{i}]") for i, v in enumerate(value)])


def _rotation(table, key, where, axis):
    """The 3×3 rotation `table[key]` (default I); `axis` 0 / 1: it must be a rotation about x / y."""
    where = f"{where}.{key}"
    value = table.get(key, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    if not (isinstance(value, list) and len(value) == 3 and all(isinstance(row, list) and len(row) == 3
                                                                 for row in value)):
        raise ValueError(f"{where}: expected a 3×3 matrix as a list of 3 rows of 3 numbers, got {show(value)}")
    R = np.array([[_real(v, f"{where}[{i}][{j}]") for j, v in enumerate(row)] for i, row in enumerate(value)])
    if axis is not None:               # the kernels' rule: row and column `axis` exactly e_axis
        name = "xy"[axis]
        for i in range(3):
            for a, b in ((axis, i), (i, axis)):
                want = 1.0 if i == axis else 0.0
                if R[a, b] != want:
                    raise ValueError(f"{where}[{a}][{b}]: must be exactly {want:g}: {key} is a rotation about "
                                     f"the {name} axis (row and column {axis + 1} equal to e_{name}); "
                                     f"or give theta_{key[-1]}")
    gram = R.T @ R - np.eye(3)
    defect, det = float(np.abs(gram).max()), float(np.linalg.det(R))
    if det < 0 or defect > ROTATION_TOL or abs(det - 1) > ROTATION_TOL:
        raise ValueError(f"{where}: not a rotation matrix (needs RᵀR = I and det R = +1 to {ROTATION_TOL:g}; "
                         f"got max |RᵀR − I| = {defect:.3g}, det R = {det:.6g})")
    return R


# -- running ------------------------------------------------------------------------------
def memory_estimate(scenario):
    """{what: bytes} of the arrays a run of `scenario` holds (runtime/memory.py)."""
    return {"trajectory": memory.trajectory_bytes(scenario.steps), "contact force": (scenario.steps + 1) * 3 * 8}


def check_memory(scenario, budget=None):
    """The bytes a run of `scenario` needs, or memory.MemoryBudgetExceeded naming the file when they
    exceed `budget` (default: the memory budget)."""
    return memory.check(scenario.source, memory_estimate(scenario), budget)


def run_scenario(scenario, progress=None):
    """Simulate `scenario`; `progress(done_steps, total_steps)` is called every few thousand steps.

    The loop stays in C (`Model.simulate`, with its guards).  If a guard stops the
    run, the `SimulationStopped` exception propagates with `.result`: a `Result`
    holding the rows computed before the failing step (see docs/robustness.md).  A run whose
    arrays would not fit the memory budget is refused first (`check_memory`).
    """
    check_memory(scenario)
    started = time.perf_counter()
    model = Model(scenario.params)
    steps = scenario.steps
    torques = scenario.torque_at_step_starts(steps + 1)
    try:
        trajectory = model.simulate(scenario.x0, scenario.dt, steps, torques[:steps], method=scenario.method,
                                    progress=progress)
    except SimulationStopped as exc:
        rows = len(exc.trajectory)
        exc.result = _result(model, scenario, exc.trajectory, torques[:rows], started)
        raise
    return _result(model, scenario, trajectory, torques, started)


def _result(model, scenario, trajectory, torques, started):
    energy = np.array([model.energy(x) for x in trajectory])
    contact = model.contact_force(trajectory, torques) if len(trajectory) else np.empty((0, 3))
    return Result(scenario=scenario, time=np.arange(len(trajectory)) * scenario.dt, trajectory=trajectory,
                  torques=torques, energy=energy, wall_time_s=time.perf_counter() - started, contact_force=contact)
