"""Sweep files: a base scenario, the quantities to vary and how, a seed; and the inputs of sample i.

    description = "t-shape end point under +-10 % in every mass"
    scenario = "t-shape"          # a shipped scenario name, or a path relative to this file
    samples = 10000
    seed = 20261123
    samples_per_task = 500        # optional; default: tasks of about TASK_SECONDS (measured)

    [params.m_P]                  # a parameter by the paper's name (or a general one: PARAM_KEYS)
    uniform = [0.9, 1.1]
    relative = true               # a factor on the scenario's value (default: the value itself)

    [initial.theta_P]             # theta_Y, theta_P [rad], w_Y, w_P [rad/s]
    values = [0.0, 0.2, 0.4]      # a grid

    [torque.u_Y_scale]            # u_Y_scale, u_P_scale: factors on the scenario's yoke /
    normal = [1.0, 0.05]          # pendulum torques (a torque program per sample)

Each quantity has exactly one of `values = [...]` (a grid), `uniform = [low, high]` or
`normal = [mean, sd]`.  Sample i takes grid point i mod G of the product of all grids (in the
order of the quantities' names) and draws its random quantities, in the same order, from
`numpy.random.default_rng([seed, i])`: a sample's inputs depend on (seed, i) only, never on
how the samples are split into tasks or which machine runs them.

Every problem raises ValueError("<file>: <key>: <what is wrong>").
"""
import dataclasses
import importlib.resources
import math
import pathlib
import sys
import tomllib

import numpy as np

from bindings._sr import lib

from ..params import PAPER_NAMES, Params, paper_rows_to_params
from ..schema import Range, check_range, check_ranges, check_table
from ..scenario import ROBOT_RANGES, SCENARIO_RANGES, Scenario, load_scenario
from .robustness import CONTROL_RANGES, is_robustness, parse_robustness
from ..state import IDX_QZ, IDX_RP, IDX_RY, IDX_WP, IDX_WY, IDX_UP, IDX_UY, pendulum_angle, rot_x, rot_y, yoke_angle

#: A sweep varies parameters by the paper's names (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P,
#: g: each sample's robot is then built from them) or by the entries of the C parameter vector
#: (m_Y, c_P_z, J_Y_xx, slope, ...: the general robot's fields).
GENERAL_KEYS = tuple(n[len("SR_P_"):] for n in sorted(dir(lib)) if n.startswith("SR_P_"))
PARAM_KEYS = tuple(sorted(set(PAPER_NAMES) | set(GENERAL_KEYS)))

_TOP_KEYS = {"description", "scenario", "samples", "seed", "samples_per_task", "params", "initial", "torque"}
_KINDS = ("values", "uniform", "normal")
#: What a sweep may vary, by group.
INITIAL_KEYS = ("theta_Y", "theta_P", "w_Y", "w_P")
TORQUE_KEYS = ("u_Y_scale", "u_P_scale")
#: Largest sample count (the sample index is part of every seed; results are one row each).
MAX_SAMPLES = 10**9
#: A normal draw is mean + sd z with |z| < 14 (NumPy's ziggurat: its tail ends near 3.65 + 36.7/3.65),
#: so |mean| + NORMAL_REACH sd finite keeps every draw finite.
NORMAL_REACH = 100.0

#: A factor (`relative = true`) on a scenario's value.
FACTOR = Range(-1e3, 1e3, "", "a factor on the scenario's value")
#: The ranges of the numbers of a sweep file: its top level, and what a quantity's numbers may be
#: (a value of `values`, `uniform` or a `normal`'s mean: the range of what it varies, a parameter's
#: that of robot files (ROBOT_RANGES), FACTOR when `relative`; a normal's sd: at most that range's width).
SWEEP_RANGES = {
    "": {"samples": Range(1, MAX_SAMPLES, "", "the sample index is part of every seed; one result row each",
                          whole=True),
         "seed": Range(0, 2**63 - 1, "", "a seed of NumPy's generator", whole=True),
         "samples_per_task": Range(1, MAX_SAMPLES, "", "a task's samples (its arrays are sized before the run)",
                                   whole=True)},
    "initial": {key: SCENARIO_RANGES["initial"][key] for key in INITIAL_KEYS},
    "torque": {key: Range(-1e3, 1e3, "", "a factor on the scenario's torques") for key in TORQUE_KEYS},
}
#: A robustness sweep's `[control]` (runtime/sweep/robustness.py).
SWEEP_RANGES["control"] = CONTROL_RANGES


def quantity_range(name, relative):
    """The Range of the values of the quantity `name` ("params.m_P", "initial.w_Y", ...)."""
    group, key = name.split(".", 1)
    if relative:
        return FACTOR
    if group == "params":
        base = key if key in ROBOT_RANGES else next(n for n in sorted(ROBOT_RANGES, key=len, reverse=True)
                                                    if key.startswith(n + "_"))
        return ROBOT_RANGES[base]
    return SWEEP_RANGES[group][key]


@dataclasses.dataclass(frozen=True)
class Quantity:
    """One varied quantity: `name` ("params.m_P"), `kind` ("values", "uniform", "normal"), its numbers."""
    name: str
    kind: str
    numbers: tuple
    relative: bool = False


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file.  `quantities` are sorted by name (the order of the grid and the draws)."""
    name: str
    source: str
    scenario: Scenario
    samples: int
    seed: int
    quantities: tuple
    samples_per_task: int | None = None
    description: str = ""

    @property
    def grid(self):
        """The quantities given as lists of values (the grid's axes)."""
        return tuple(q for q in self.quantities if q.kind == "values")

    @property
    def grid_size(self):
        """The number of points of the grid (1 without grid axes)."""
        return math.prod(len(q.numbers) for q in self.grid)

    def with_samples(self, samples):
        """The same sweep with another number of samples (ValueError unless a whole number from 1 to
        MAX_SAMPLES)."""
        return dataclasses.replace(self, samples=_count(samples, "--samples"))

    def identity(self):
        """What makes two runs the same sweep (the resume check compares it): JSON-ready."""
        s = self.scenario
        return {"scenario": {"name": s.name, "params": s.params.as_json(), "x0": s.x0.tolist(), "dt": s.dt,
                             "steps": s.steps, "method": s.method,
                             "torques": [dataclasses.asdict(w) for w in s.torques]},
                "samples": self.samples, "seed": self.seed,
                "quantities": [dataclasses.asdict(q) | {"numbers": list(q.numbers)} for q in self.quantities]}


# -- loading ---------------------------------------------------------------------------------
def _sweep_dir():
    return importlib.resources.files("runtime") / "sweep"


def shipped_sweeps():
    """The names of the shipped sweep files."""
    return sorted(p.name[:-5] for p in _sweep_dir().iterdir() if p.name.endswith(".toml"))


def load_sweep(name_or_path):
    """Read and validate a sweep: a shipped name (see `shipped_sweeps()`) or a path to a TOML file."""
    candidate = _sweep_dir() / f"{name_or_path}.toml"
    path = pathlib.Path(str(candidate)) if "/" not in str(name_or_path) and candidate.is_file() \
        else pathlib.Path(name_or_path)
    if not path.is_file():
        raise ValueError(f"{path}: no such sweep file (shipped sweeps: {', '.join(shipped_sweeps())})")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot be read ({exc.strerror})") from None
    if is_robustness(data):
        return parse_robustness(data, source=str(path), name=path.stem)
    return parse_sweep(data, source=str(path), name=path.stem, folder=path.parent)


def parse_sweep(data, source="<sweep>", name="sweep", folder=None):
    """Validate the table `data` (as read by tomllib) into a `SweepSpec`."""
    check_table(data, _TOP_KEYS, source)
    description = data.get("description", "")
    if not isinstance(description, str):
        raise ValueError(f"{source}: description: expected a string, got {description!r}")
    if "scenario" not in data or not isinstance(data["scenario"], str):
        raise ValueError(f"{source}: scenario: expected the name or path of the base scenario")
    base = data["scenario"]
    if folder is not None and ("/" in base or base.endswith(".toml")) and not pathlib.Path(base).is_absolute():
        base = str(pathlib.Path(folder) / base)
    try:
        scenario = load_scenario(base)
    except ValueError as exc:
        raise ValueError(f"{source}: scenario: {exc}") from None
    samples = _count(data.get("samples"), f"{source}: samples")
    seed = data.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"{source}: seed: expected a non-negative integer, got {seed!r}")
    per_task = data.get("samples_per_task")
    if per_task is not None:
        per_task = _count(per_task, f"{source}: samples_per_task")
    check_ranges(data, SWEEP_RANGES[""], source, sep=": ")
    quantities = []
    groups = {"params": PARAM_KEYS, "initial": INITIAL_KEYS, "torque": TORQUE_KEYS}
    for group, allowed in groups.items():
        table = data.get(group, {})
        check_table(table, set(allowed), f"{source}: {group}")
        for key, spec in table.items():
            quantities.append(_quantity(f"{group}.{key}", spec, f"{source}: {group}.{key}"))
    _check_param_names(data.get("params", {}), scenario, f"{source}: params")
    quantities.sort(key=lambda q: q.name)
    spec = SweepSpec(name=name, source=source, scenario=scenario, samples=samples, seed=seed,
                     quantities=tuple(quantities), samples_per_task=per_task, description=description)
    _check_grid_values(spec, source)
    return spec


def _check_param_names(table, scenario, where):
    """Either the paper's names (for a scenario of the paper's robot) or the general entries, not both."""
    paper_only = sorted(set(table) - set(GENERAL_KEYS))
    if not paper_only:
        return
    if scenario.params.paper_params is None:
        raise ValueError(f"{where}.{paper_only[0]}: a parameter of the paper's robot, and the scenario's "
                         "robot is not built from the paper's parameters")
    general_only = sorted(set(table) - set(PAPER_NAMES))
    if general_only:
        raise ValueError(f"{where}: vary the paper's parameters ({', '.join(paper_only)}) or the general "
                         f"ones ({', '.join(general_only)}), not both")


def _quantity(name, table, where):
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table with one of {', '.join(_KINDS)}, got {table!r}")
    check_table(table, set(_KINDS) | {"relative"}, where)
    kinds = [k for k in _KINDS if k in table]
    if len(kinds) != 1:
        raise ValueError(f"{where}: give exactly one of {', '.join(_KINDS)}, got {kinds or 'none'}")
    kind = kinds[0]
    numbers = table[kind]
    if not isinstance(numbers, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                and math.isfinite(v) for v in numbers):
        raise ValueError(f"{where}.{kind}: expected a list of finite numbers, got {numbers!r}")
    numbers = tuple(float(v) for v in numbers)
    if kind == "values" and not numbers:
        raise ValueError(f"{where}.values: the grid is empty")
    if kind == "uniform" and (len(numbers) != 2 or not numbers[0] <= numbers[1]):
        raise ValueError(f"{where}.uniform: expected [low, high] with low <= high, got {list(numbers)}")
    if kind == "uniform" and not math.isfinite(numbers[1] - numbers[0]):
        raise ValueError(f"{where}.uniform: the width high - low of {list(numbers)} overflows; "
                         f"expected a width below {sys.float_info.max:.4g}")
    if kind == "normal" and (len(numbers) != 2 or not numbers[1] >= 0):
        raise ValueError(f"{where}.normal: expected [mean, sd] with sd >= 0, got {list(numbers)}")
    if kind == "normal" and not math.isfinite(abs(numbers[0]) + NORMAL_REACH * numbers[1]):
        raise ValueError(f"{where}.normal: |mean| + {NORMAL_REACH:g} sd of {list(numbers)} overflows; "
                         f"expected it below {sys.float_info.max:.4g} (every draw must be finite)")
    relative = table.get("relative", False)
    if not isinstance(relative, bool):
        raise ValueError(f"{where}.relative: expected true or false, got {relative!r}")
    rng = quantity_range(name, relative)
    checked = numbers[:1] if kind == "normal" else numbers
    for i, v in enumerate(checked):
        check_range(v, rng, f"{where}.{kind}[{i}]")
    if kind == "normal":
        check_range(numbers[1], Range(0, rng.high - rng.low, rng.unit, "a spread within the range's width"),
                    f"{where}.normal[1]")
    return Quantity(name=name, kind=kind, numbers=numbers, relative=relative)


def _check_grid_values(spec, source):
    """Grid points must make valid robots (random draws may not: those samples fail alone)."""
    for q in spec.grid:
        for v in q.numbers:
            if q.name.startswith("params."):
                key = q.name.split(".", 1)[1]
                robot = spec.scenario.params
                try:
                    if key in PAPER_NAMES and robot.paper_params is not None and _paper_quantities(spec):
                        base = getattr(robot.paper_params, key)
                        robot.with_changes(**{key: v * base if q.relative else v})
                    else:
                        values = robot.as_array()
                        column = getattr(lib, f"SR_P_{key}")
                        values[column] = v * values[column] if q.relative else v
                        Params.from_array(values)
                except ValueError as exc:
                    raise ValueError(f"{source}: {q.name}.values: {v:g} gives invalid parameters ({exc})") from None


def _count(value, where):
    rng = SWEEP_RANGES[""]["samples"]
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{where}: expected {rng}, got {value!r}")
    return int(check_range(int(value), rng, where))


# -- the inputs of samples start..stop-1 ----------------------------------------------------------
def quantity_values(spec, start, stop):
    """{quantity name: (n,) values} of samples start..stop-1 (as drawn, before `relative` applies)."""
    if hasattr(spec, "draw"):                 # a robustness sweep draws its own
        return spec.draw(start, stop)
    n = stop - start
    values = {q.name: np.empty(n) for q in spec.quantities}
    grid = spec.grid
    randoms = [q for q in spec.quantities if q.kind != "values"]
    for row, i in enumerate(range(start, stop)):
        point = i % spec.grid_size
        for q in reversed(grid):              # mixed radix: the last name varies fastest
            point, digit = divmod(point, len(q.numbers))
            values[q.name][row] = q.numbers[digit]
        if randoms:
            rng = np.random.default_rng([spec.seed, i])
            for q in randoms:
                a, b = q.numbers
                values[q.name][row] = rng.uniform(a, b) if q.kind == "uniform" else rng.normal(a, b)
    return values


def sample_inputs(spec, start, stop):
    """(params (n, 12) array, x0 (n, 35), u (n, steps, 2) or the shared (steps, 2), values dict).

    Parameters are an array, not Params: a random draw may leave the physical range (a negative
    mass from a wide normal), and that sample then fails alone in C with its status.
    """
    values = quantity_values(spec, start, stop)
    base = spec.scenario
    n = stop - start
    paper = _paper_quantities(spec)
    if paper:       # the paper's names: vary them, then build each sample's robot (C: sr_paper_params)
        rows = np.tile(base.params.paper_params.as_array(), (n, 1))
        for q in paper:
            col = PAPER_NAMES.index(q.name.split(".", 1)[1])
            rows[:, col] = values[q.name] * rows[:, col] if q.relative else values[q.name]
        params = paper_rows_to_params(rows)
    else:
        params = np.tile(base.params.as_array(), (n, 1))
    x0 = np.tile(base.x0, (n, 1))
    u = base.torque_at_step_starts()
    factors = {}
    for q in spec.quantities:
        group, key = q.name.split(".", 1)
        v = values[q.name]
        if group == "params":
            if not paper:           # (the paper's names were applied above)
                col = getattr(lib, f"SR_P_{key}")
                params[:, col] = v * params[:, col] if q.relative else v
        elif group == "initial":
            _set_initial(x0, key, v, q.relative)
        else:
            factors[key] = v * 1.0 if q.relative else v
    x0[:, IDX_QZ] = params[:, lib.SR_P_r]     # the shell rests on the plane: q_z = r
    if factors:
        scale = np.ones((n, 1, 2))
        scale[:, 0, IDX_UY] = factors.get("u_Y_scale", 1.0)
        scale[:, 0, IDX_UP] = factors.get("u_P_scale", 1.0)
        u = u[None, :, :] * scale
    return params, x0, u, values


def _paper_quantities(spec):
    """The params quantities, if they are to be read by the paper's names (see `PARAM_KEYS`), else ()."""
    params = [q for q in spec.quantities if q.name.startswith("params.")]
    if params and spec.scenario.params.paper_params is not None and all(
            q.name.split(".", 1)[1] in PAPER_NAMES for q in params):
        return params
    return ()


def _set_initial(x0, key, v, relative):
    if key in ("theta_Y", "theta_P"):
        block, rot, read = (IDX_RY, rot_x, yoke_angle) if key == "theta_Y" else (IDX_RP, rot_y, pendulum_angle)
        angles = v * read(x0) if relative else v
        x0[:, block] = np.stack([rot(a).ravel() for a in angles])
    else:
        index = IDX_WY if key == "w_Y" else IDX_WP
        x0[:, index] = v * x0[:, index] if relative else v
