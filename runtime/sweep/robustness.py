"""Robustness sweeps: the closed loops on the estimator over many robots drawn around the model.

A sweep file with a `[control]` table (docs/control.md, "Robustness over many robots") runs, for
every drawn plant, each of its tasks with each of its controllers on the C EKF of simulated
sensors, the plant differing from the controllers' model:

    description = "..."
    samples = 6000               # runs: plants x tasks x controllers
    seed = 20261126
    samples_per_task = 6

    [control]
    tasks = ["circle", "line", "figure8"]     # shipped control tasks (their scenario and reference)
    controllers = ["lqr", "nmpc-c"]           # nmpc-c takes the task's nmpc settings
    sensors = "default"                       # a shipped sensor set or a sensors file
    mass = 0.20                  # every mass a factor uniform in 1 +- mass (m_S, m_b, m_h, m_P)
    damping = 0.30               # every damping a factor uniform in 1 +- damping (k_S, k_Y, k_P)
    centre_of_mass_m = 0.01      # the pendulum's centre of mass moved uniformly within this ball
    slope_fraction = 0.25        # a slope uniform within +- this fraction of the plant's climbing limit
    position_m = 0.05            # the robot placed off the path's start, uniform within +- this in x and y
    heading_deg = 5.0            # ... and turned off its tangent, uniform within +- this
    rms_m = 0.03                 # success: second-half cross-track RMS <= rms_m
    coverage = 0.90              # ... and progress along the path >= coverage x the reference's length
    duration = 60.0              # optional: every task cut to at most this many seconds (a smoke run)

Sample i is run (i mod C) of plant i // C, C = tasks x controllers (task-major): the first 6 P
samples are P plants, each on every task and controller.  A plant's draws come from
`numpy.random.default_rng([seed, plant])` in a fixed order (masses, dampings, centre of mass,
slope and its direction, start errors, the sensors' seed), so every run of a plant sees the same
robot and the same sensor noise, and a sample's inputs depend on the file and i alone.

The slope lies along the plane's x axis (the model's `slope`); its random direction is the task
turned about the vertical by `slope_direction_rad` (start pose and path together).  The reference
is laid from the task's start pose; the robot starts `dx0_m`, `dy0_m` off it and turned by
`dpsi0_rad`; its filter starts at the robot's true pose (to within the filter's own start spread,
runtime/control/estimator.py).  A plant is counted apart when its steady torque at the reference's
speed would exceed u_max: its operating point on the flat at the path's curvatures (yoke and
pendulum torques) plus the slope's pull along the heading (the whole of it where the path turns
through every heading).  Where Newton finds no operating point from level rolling (a centre of mass
moved off the pendulum's plane can do that) the steady torque is NaN and the plant is counted apart
for that reason (`APART_REASONS`); either way its runs are made.
"""
import dataclasses
import functools
import math

import numpy as np

from ..blas import one_thread
from ..control.metrics import second_half_stats
from ..schema import Range, check_ranges, check_table
from ..so3 import rot_z
from ..state import IDX_Q, IDX_RS

#: The masses and dampings drawn, by the paper's names.
MASSES = ("m_S", "m_b", "m_h", "m_P")
DAMPINGS = ("k_S", "k_Y", "k_P")
#: The drawn inputs of a run, in the order they are drawn (after the run's plant, task and controller).
DRAWN = MASSES + DAMPINGS + ("c_P_dx_m", "c_P_dy_m", "c_P_dz_m", "slope_fraction", "slope_direction_rad",
                             "dx0_m", "dy0_m", "dpsi0_rad", "sensor_seed")
#: Integer input columns: which plant, task and controller a run is, the sensors' seed.
INT_INPUTS = ("plant", "task", "controller", "sensor_seed")
#: The outcome of a run.
OUTCOMES = ("status", "steps_done", "cross_track_rms_m", "cross_track_max_m", "progress", "steady_torque_nm",
            "slope_rad", "counted_apart", "success", "saturated_fraction", "estimate_position_rms_m")
INT_OUTCOMES = ("status", "steps_done", "counted_apart", "success")
#: The perturbations by group, and their values on the controllers' model (`--rerun S --nominal GROUPS`).
GROUPS = {"masses": dict.fromkeys(MASSES, 1.0), "dampings": dict.fromkeys(DAMPINGS, 1.0),
          "centre_of_mass": dict.fromkeys(("c_P_dx_m", "c_P_dy_m", "c_P_dz_m"), 0.0),
          "slope": {"slope_fraction": 0.0}, "start": dict.fromkeys(("dx0_m", "dy0_m", "dpsi0_rad"), 0.0)}
#: Why a run is counted apart (the `counted_apart` outcome; 0: it is counted).
APART_REASONS = {1: "steady torque above u_max", 2: "no steady operating point"}
APART_TORQUE, APART_NO_OPERATING_POINT = 1, 2
#: Status of a run whose steady operating point could not be found or whose inputs are not a robot.
STATUS_BAD_PLANT = 5

_TOP_KEYS = {"description", "samples", "seed", "samples_per_task", "control"}
_CONTROL_KEYS = {"tasks", "controllers", "sensors", "mass", "damping", "centre_of_mass_m", "slope_fraction",
                 "position_m", "heading_deg", "rms_m", "coverage", "duration"}
#: The ranges of the numbers of `[control]`.
CONTROL_RANGES = {
    "mass": Range(0, 0.9, "", "a relative half-width: masses stay positive"),
    "damping": Range(0, 0.9, "", "a relative half-width: dampings stay positive"),
    "centre_of_mass_m": Range(0, 0.1, "m", "a ball's radius, inside the pendulum"),
    "slope_fraction": Range(0, 1, "", "a fraction of the plant's climbing limit"),
    "position_m": Range(0, 1, "m", "a start error"),
    "heading_deg": Range(0, 90, "deg", "a start error"),
    "rms_m": Range(0, 10, "m", "a cross-track RMS"),
    "coverage": Range(0, 1, "", "a fraction of the reference's path length"),
    "duration": Range(0.1, 1e4, "s", "a run's length; the plant's trajectory is held in memory"),
}
TOP_RANGES = {"samples": Range(1, 10**9, "", "runs", whole=True),
              "seed": Range(0, 2**63 - 1, "", "a seed of NumPy's generator", whole=True),
              "samples_per_task": Range(1, 10**9, "", "runs per task", whole=True)}


@dataclasses.dataclass(frozen=True)
class Column:
    """An input column of the result table (what the sweep store compares against the draws)."""
    name: str


@dataclasses.dataclass(frozen=True)
class RobustnessSpec:
    """A validated robustness sweep file (see the module)."""
    name: str
    source: str
    samples: int
    seed: int
    tasks: tuple
    controllers: tuple
    sensors: str
    mass: float = 0.20
    damping: float = 0.30
    centre_of_mass_m: float = 0.01
    slope_fraction: float = 0.25
    position_m: float = 0.05
    heading_deg: float = 5.0
    rms_m: float = 0.03
    coverage: float = 0.90
    duration: float | None = None
    samples_per_task: int | None = None
    description: str = ""

    @property
    def combos(self):
        """(task, controller) of run i mod C, task-major."""
        return tuple((t, c) for t in self.tasks for c in self.controllers)

    @property
    def quantities(self):
        """The input columns after `sample`."""
        return tuple(Column(n) for n in ("plant", "task", "controller") + DRAWN)

    def columns(self):
        """Every column of the result table, in order."""
        return ("sample",) + tuple(q.name for q in self.quantities) + OUTCOMES

    def arrow_types(self):
        """{column: Arrow type} of the integer columns (the others are float64)."""
        import pyarrow as pa
        return {name: pa.int32() if name in ("status", "counted_apart", "success") else pa.int64()
                for name in ("sample",) + INT_INPUTS + INT_OUTCOMES}

    def with_samples(self, samples):
        """The same sweep with another number of runs."""
        if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= 10**9:
            raise ValueError(f"--samples: expected a whole number from 1 to 1000000000, got {samples!r}")
        return dataclasses.replace(self, samples=samples)

    def identity(self):
        """What makes two runs the same sweep (JSON-ready; the resume check compares it)."""
        out = dataclasses.asdict(self)
        for key in ("name", "source", "samples_per_task", "description"):
            out.pop(key)
        out["tasks"], out["controllers"] = list(self.tasks), list(self.controllers)
        return {"robustness": out}

    def memory_estimate(self, samples_per_task, at_once=1):
        """{what: bytes} of the largest arrays: the result table, and one run of the longest task on
        each of `at_once` workers (its trajectory, estimates, sensor samples, path: runtime/control/task.py)."""
        longest = max(sum(_task(t, self.controllers[0], self.sensors, self.duration).memory_estimate().values())
                      for t in self.tasks)
        return {"result table": 3 * 8 * self.samples * len(self.columns()), "runs": at_once * longest}

    def draw(self, start, stop):
        """{input column: (stop-start,) array} of runs start..stop-1."""
        n, combos = stop - start, len(self.combos)
        out = {name: np.empty(n, dtype=np.int64 if name in INT_INPUTS else np.float64)
               for name in ("plant", "task", "controller") + DRAWN}
        for row, i in enumerate(range(start, stop)):
            plant, combo = divmod(i, combos)
            out["plant"][row] = plant
            out["task"][row], out["controller"][row] = divmod(combo, len(self.controllers))
            for name, value in self.plant_draws(plant).items():
                out[name][row] = value
        return out

    def plant_draws(self, plant):
        """{drawn input: value} of one plant (see the module)."""
        rng = np.random.default_rng([self.seed, plant])
        out = {name: rng.uniform(1 - self.mass, 1 + self.mass) for name in MASSES}
        out.update({name: rng.uniform(1 - self.damping, 1 + self.damping) for name in DAMPINGS})
        direction = rng.normal(size=3)
        shift = self.centre_of_mass_m * rng.uniform() ** (1 / 3) * direction / np.linalg.norm(direction)
        out.update(zip(("c_P_dx_m", "c_P_dy_m", "c_P_dz_m"), shift))
        out["slope_fraction"] = rng.uniform(-self.slope_fraction, self.slope_fraction)
        out["slope_direction_rad"] = rng.uniform(0.0, 2 * math.pi)
        out["dx0_m"], out["dy0_m"] = rng.uniform(-self.position_m, self.position_m, 2)
        out["dpsi0_rad"] = rng.uniform(-1, 1) * math.radians(self.heading_deg)
        out["sensor_seed"] = int(rng.integers(0, 2**63 - 1))
        return out

    def run_chunk(self, start, stop, nominal=()):
        """{column: array} of runs start..stop-1 (the sweep store's rows); `nominal`: groups of
        perturbations (GROUPS) left out.  The runs use one BLAS thread (runtime/blas.py), as a
        Dask worker's do: a row is the same in a worker, the serial mode and `--rerun`."""
        columns = {"sample": np.arange(start, stop, dtype=np.int64)}
        inputs = self.draw(start, stop)
        for group in nominal:
            inputs.update({k: np.full(stop - start, v) for k, v in with_nominal({}, [group]).items()})
        columns.update(inputs)
        with one_thread():
            rows = [run_one(self, {k: v[j] for k, v in inputs.items()}) for j in range(stop - start)]
        for name in OUTCOMES:
            dtype = np.int32 if name in ("status", "counted_apart", "success") else \
                np.int64 if name == "steps_done" else np.float64
            columns[name] = np.array([r[name] for r in rows], dtype=dtype)
        return columns


#: What two robustness sweeps must share for their runs to be runs of one study: the same plants
#: (seed and ranges), the same sensors and the same rule (`in_sweep`).
SAME_PLANTS = ("seed", "sensors", "mass", "damping", "centre_of_mass_m", "slope_fraction", "position_m",
               "heading_deg", "rms_m", "coverage", "duration")


def from_identity(identity, name, source):
    """The RobustnessSpec whose `identity()` is `identity` (as a sweep folder's manifest holds it)."""
    fields = dict(identity.get("robustness", {})) if isinstance(identity, dict) else {}
    try:
        fields["tasks"], fields["controllers"] = tuple(fields["tasks"]), tuple(fields["controllers"])
        return RobustnessSpec(name=name, source=source, **fields)
    except (KeyError, TypeError) as exc:
        raise ValueError(f"{source}: not the identity of a robustness sweep ({exc})") from None


def in_sweep(columns, part, whole, where):
    """The rows `columns` ({column: array}) of the sweep `part` as rows of the sweep `whole`: the
    task, controller and sample renumbered (sample = plant x C + the run's place in `whole`).
    `whole` must draw the same plants and judge by the same rule (SAME_PLANTS) and run every task
    and controller of `part`; ValueError naming `where` and the difference otherwise."""
    for key in SAME_PLANTS:
        if getattr(part, key) != getattr(whole, key):
            raise ValueError(f"{where}: its sweep's {key} is {getattr(part, key)!r}, {whole.name}'s is "
                             f"{getattr(whole, key)!r}: not the same plants and rule")
    for key in ("tasks", "controllers"):
        extra = [name for name in getattr(part, key) if name not in getattr(whole, key)]
        if extra:
            raise ValueError(f"{where}: its {key} {extra} are not among {whole.name}'s {list(getattr(whole, key))}")
    out = {name: np.asarray(values) for name, values in columns.items()}
    out["task"] = np.array([whole.tasks.index(t) for t in part.tasks], dtype=np.int64)[out["task"]]
    out["controller"] = np.array([whole.controllers.index(c) for c in part.controllers],
                                 dtype=np.int64)[out["controller"]]
    out["sample"] = out["plant"] * len(whole.combos) + out["task"] * len(whole.controllers) + out["controller"]
    beyond = out["sample"] >= whole.samples
    if beyond.any():
        raise ValueError(f"{where}: plant {int(out['plant'][beyond][0])} is beyond {whole.name}'s "
                         f"{whole.samples} runs (--samples)")
    return out


def is_robustness(data):
    """True for the table of a robustness sweep file (it has `[control]`)."""
    return isinstance(data, dict) and "control" in data


def parse_robustness(data, source="<sweep>", name="sweep"):
    """Validate a robustness sweep file's table into a RobustnessSpec; ValueError naming the key."""
    from ..control.task import load_task
    from ..sensor_set import load_sensor_set
    check_table(data, _TOP_KEYS, source)
    check_ranges(data, TOP_RANGES, source, sep=": ")
    for key in ("samples", "seed"):
        if key not in data:
            raise ValueError(f"{source}: {key}: missing (required)")
    control = data["control"]
    where = f"{source}: control"
    if not isinstance(control, dict):
        raise ValueError(f"{where}: expected a table, got {control!r}")
    check_table(control, _CONTROL_KEYS, where)
    check_ranges(control, CONTROL_RANGES, where)
    lists = {}
    for key in ("tasks", "controllers"):
        value = control.get(key)
        if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)) \
                or len(set(value)) != len(value):
            raise ValueError(f"{where}.{key}: expected a non-empty list of distinct names, got {value!r}")
        lists[key] = tuple(value)
    sensors = control.get("sensors", "default")
    try:
        load_sensor_set(sensors)
        for task in lists["tasks"]:
            base = load_task(task)
            if not base.reference_spec["kind"] in ("line", "circle", "figure8", "waypoints"):
                raise ValueError(f"{task}: a path task is needed (line, circle, figure8, waypoints), "
                                 f"got {base.reference_spec['kind']!r}")
            if base.scenario.params.paper_params is None:
                raise ValueError(f"{task}: its robot is not built from the paper's parameters (the masses "
                                 "and dampings are drawn by the paper's names)")
            for kind in lists["controllers"]:
                _task(task, kind, sensors, control.get("duration"))
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    numbers = {k: float(v) for k, v in control.items() if k in CONTROL_RANGES}
    return RobustnessSpec(name=name, source=source, samples=int(data["samples"]), seed=int(data["seed"]),
                          tasks=lists["tasks"], controllers=lists["controllers"], sensors=sensors,
                          samples_per_task=data.get("samples_per_task"),
                          description=str(data.get("description", "")), **numbers)


@functools.lru_cache(maxsize=32)
def _task(name, kind, sensors, duration=None):
    """The shipped task `name` with only its controller `kind`, on the sensor set `sensors`, cut to
    at most `duration` s."""
    from ..control.offsets import with_controller
    from ..control.task import load_task
    from ..sensor_set import load_sensor_set
    task = with_controller(load_task(name), kind).with_sensors(load_sensor_set(sensors))
    if duration is not None and duration < task.duration:
        steps = max(1, round(duration / task.scenario.dt))
        task = dataclasses.replace(task, scenario=dataclasses.replace(task.scenario, steps=steps))
    return task


def turned(task, psi):
    """The task turned about the vertical by ψ: its start attitude, and a line's direction with it."""
    x0 = task.scenario.x0.copy()
    x0[IDX_RS] = (rot_z(psi) @ x0[IDX_RS].reshape(3, 3)).ravel()
    spec = dict(task.reference_spec)
    if spec["kind"] == "line":
        spec["heading"] = spec.get("heading", 0.0) + psi
    return dataclasses.replace(task, scenario=dataclasses.replace(task.scenario, x0=x0), reference_spec=spec)


def plant_of(task, inputs):
    """The plant of a run: the task's robot with the drawn masses, dampings, centre of mass and slope."""
    from ..control.climbing import climbing_limit
    base = task.scenario.params
    paper = base.paper_params
    plant = base.with_changes(**{n: getattr(paper, n) * float(inputs[n]) for n in MASSES + DAMPINGS})
    c_P = np.asarray(plant.c_P, dtype=float) + [inputs["c_P_dx_m"], inputs["c_P_dy_m"], inputs["c_P_dz_m"]]
    plant = plant.replace(c_P=tuple(c_P))
    return plant.replace(slope=float(inputs["slope_fraction"]) * climbing_limit(plant, task.u_max))


def steady_torque(task, plant):
    """The largest steady torque [N m] the plant needs on the task's path at its speed (see the module);
    `task` is the run's, already `turned` by the slope's direction, so a line's heading is its
    heading against the slope."""
    from ..control.lqr_design import operating_point
    from ..model import Model
    spec = task.reference_spec
    curvatures = {"line": (0.0,), "circle": (1 / spec.get("radius", 1.0),),
                  "figure8": (1 / spec.get("size", 1.0), -1 / spec.get("size", 1.0))}.get(spec["kind"], (0.0,))
    flat = Model(plant.replace(slope=0.0))
    pull = plant.m_R * plant.g * plant.r * abs(math.sin(plant.slope))
    if spec["kind"] == "line":       # the turned line's heading against the plane's x axis (up the slope)
        pull *= abs(math.cos(spec.get("heading", 0.0)))
    worst = 0.0
    for kappa in curvatures:
        try:        # from the model's own operating point: one Newton solve instead of a continuation in κ
            _, u = operating_point(flat, abs(spec["speed"]), kappa,
                                   start=_model_operating_point(task.scenario.params, abs(spec["speed"]), kappa))
        except ValueError:
            _, u = operating_point(flat, abs(spec["speed"]), kappa)
        worst = max(worst, abs(u[0]) + pull, abs(u[1]))
    return worst


@functools.lru_cache(maxsize=64)
def _model_operating_point(params, speed, kappa):
    """The controllers' model's operating point (z*, u*) on the flat at (speed, κ)."""
    from ..control.lqr_design import operating_point
    from ..model import Model
    return operating_point(Model(params.replace(slope=0.0)), speed, kappa)


def progress(reference, positions):
    """How far along the path [m] the positions (in order) get: the arc length of the last one's
    nearest point less the first one's (matched in order, as the cross-track error is)."""
    hint = first = reference.nearest(positions[0], 0)[0]
    for p in positions[1:]:
        hint = reference.nearest(p, hint)[0]
    return float(reference.s[hint] - reference.s[first])


def judge(reference, t, positions, rms_limit, coverage):
    """(second-half cross-track RMS [m], its max [m], progress as a fraction of the reference's
    length over the run, success) of the positions (n, 2) at times t (n,) on a path reference.
    Success: the RMS within `rms_limit` and the progress at least `coverage`: a run that stalls on
    the path fails however close it stays, and so does one that runs far off it."""
    from ..control.loop_c import track
    # The path's own search (Path.cross_track, `progress`) in one C call: the same samples matched.
    cross_track, travelled = track(reference, positions)
    rms, largest = second_half_stats(t, cross_track)
    fraction = travelled / (abs(reference.speed) * (t[-1] - t[0]))
    return rms, largest, fraction, bool(rms <= rms_limit and fraction >= coverage)


def with_nominal(inputs, groups):
    """The inputs of a run with the perturbations of `groups` (names of GROUPS) set to the model's
    values: which perturbation makes a run fail."""
    unknown = sorted(set(groups) - set(GROUPS))
    if unknown:
        raise ValueError(f"--nominal: {unknown[0]!r} is not one of {', '.join(GROUPS)}")
    out = dict(inputs)
    for group in groups:
        out.update(GROUPS[group])
    return out


def engine(controller, reference):
    """How a run is simulated: the whole loop in C where it runs the controller ("c-loop": the LQR),
    else the plant, sensors and filter in C under the controller's Python ("c")."""
    from ..control.loop_c import supports
    return "c-loop" if supports(controller, reference) else "c"


def mismatch_psd(spec, task):
    """The filter's white torque [N m/sqrt(Hz)] for the plants the sweep draws around the task's robot
    (runtime.control.estimator.mismatch_torque_psd at the sweep's largest slope, centre-of-mass shift
    and damping change, the reference's speed): the filter knows the ranges, never the plant."""
    from ..control.climbing import climbing_limit
    from ..control.estimator import mismatch_torque_psd
    params = task.scenario.params
    return mismatch_torque_psd(params, task.sensors, slope_rad=spec.slope_fraction * climbing_limit(params, task.u_max),
                               centre_of_mass_m=spec.centre_of_mass_m, damping=spec.damping,
                               speed=abs(task.reference_spec["speed"]))


def run_one(spec, inputs):
    """The outcome {OUTCOMES: value} of one run with these inputs (a row of `draw`)."""
    from ..control.benchmark import estimate_errors
    from ..control.closed_loop import simulate_on_sensors
    from ..control.estimator import SensorEkf
    from ..errors import KernelError
    task_name, kind = spec.combos[int(inputs["task"]) * len(spec.controllers) + int(inputs["controller"])]
    task = turned(_task(task_name, kind, spec.sensors, spec.duration), float(inputs["slope_direction_rad"]))
    out = dict.fromkeys(OUTCOMES, math.nan)
    out.update(status=0, steps_done=0, counted_apart=0, success=0)
    try:
        plant = plant_of(task, inputs)
    except ValueError as exc:
        out["status"] = getattr(exc, "status", STATUS_BAD_PLANT)
        return out
    out["slope_rad"] = plant.slope
    try:
        out["steady_torque_nm"] = steady_torque(task, plant)
        out["counted_apart"] = APART_TORQUE if out["steady_torque_nm"] > task.u_max else 0
    except ValueError:      # Newton found no operating point: the torque is unknown (NaN), the run is made
        out["counted_apart"] = APART_NO_OPERATING_POINT
    reference = task.reference()
    x0 = task.scenario.x0.copy()
    x0[IDX_Q.start:IDX_Q.start + 2] += [inputs["dx0_m"], inputs["dy0_m"]]
    x0[IDX_RS] = (rot_z(float(inputs["dpsi0_rad"])) @ x0[IDX_RS].reshape(3, 3)).ravel()
    s = task.scenario
    estimator = SensorEkf(s.params, task.sensors, x0, s.method, mismatch_psd=mismatch_psd(spec, task), hold=s.dt)
    controller = task.controller()
    try:
        result = simulate_on_sensors(plant, controller, reference, x0, task.duration, s.dt, estimator,
                                     task.sensors, s.method, int(inputs["sensor_seed"]),
                                     engine=engine(controller, reference), record_samples=False)
    except KernelError as exc:
        out["status"] = exc.status
        return out
    every = max(1, round(1 / (task.rate * s.dt)))     # the controller's samples, as `make control` does
    rms, largest, fraction, ok = judge(reference, result.time[::every], result.trajectory[::every, IDX_Q][:, :2],
                                       spec.rms_m, spec.coverage)
    out.update(steps_done=len(result.time) - 1, cross_track_rms_m=rms, cross_track_max_m=largest, progress=fraction,
               success=int(ok), saturated_fraction=result.saturated_fraction,
               estimate_position_rms_m=estimate_errors(result)["position_rms_m"])
    return out

