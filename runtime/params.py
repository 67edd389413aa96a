"""Robot parameters, physical SI units: the general robot and the paper's twelve.

`Params` describes any robot of the yoke–pendulum architecture: each body by its
mass, centre of mass and inertia tensor about that centre, the motors' rotors
and gear ratios, gravity and the floor's slope.  `PaperParams` holds the paper's
twelve numbers (Section 5.2: rod lengths and masses); `Params.paper(...)` builds
the general description of the paper's robot from them (the C library's
sr_paper_params does the conversion, derived in derive/parameters.py), and
`Params()` is that robot with the printed values.

The C library decides which values are valid (sr_check_params and
sr_check_paper_params, the functions sr_model_init and sr_paper_params call):
the classes here ask it, and word its answer.  The order of the parameters is
read from the compiled module (SR_P_<name>, SR_PAPER_<name>), never assumed.
"""
import dataclasses
import math

import numpy as np

from bindings._sr import ffi, lib

SHAPES = {"r": (), "m_S": (), "j_S": (), "k_S": (), "m_Y": (), "c_Y": (3,), "J_Y": (3, 3), "k_Y": (),
          "m_P": (), "c_P": (3,), "J_P": (3, 3), "k_P": (), "j_mY": (), "n_Y": (), "j_mP": (), "n_P": (),
          "g": (), "slope": ()}
"""The general parameters: name -> shape (() scalar, (3,) a centre of mass, (3, 3) a tensor)."""
_TENSOR_ENTRIES = (("xx", 0, 0), ("yy", 1, 1), ("zz", 2, 2), ("xy", 0, 1), ("xz", 0, 2), ("yz", 1, 2))


def flat_names(name, shape):
    """The C vector's entry names of one parameter: r; c_Y_x, c_Y_y, c_Y_z; J_Y_xx .. J_Y_yz."""
    if shape == ():
        return (name,)
    if shape == (3,):
        return tuple(f"{name}_{a}" for a in "xyz")
    return tuple(f"{name}_{k}" for k, _, _ in _TENSOR_ENTRIES)


def parameter_order(names, module=lib, prefix="SR_P_", size="SR_NPARAM"):
    """names sorted by their index <prefix><name> in module; ValueError unless they are exactly
    the indices 0 .. <size>-1 of module, one each (no parameter missing on either side)."""
    indices = {name: getattr(module, f"{prefix}{name}", None) for name in names}
    missing = sorted(name for name, index in indices.items() if index is None)
    if missing:
        raise ValueError(f"Params: no {prefix} index in the C library for {', '.join(missing)}")
    if sorted(indices.values()) != list(range(getattr(module, size))):
        raise ValueError(f"Params: the fields {sorted(names)} do not match the C library's parameter "
                         f"indices {indices} ({size} = {getattr(module, size)})")
    return tuple(sorted(names, key=indices.get))


def _shown(value):
    """`value` for a one-line message: an array by its shape and dtype, anything else by a short repr."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} (dtype {value.dtype})"
    text = " ".join(repr(value).split())
    return text if len(text) <= 80 else text[:77] + "..."


def _real(owner, name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ValueError(f"{owner}.{name}: expected a real number, got {_shown(value)}")
    return float(value)


def _rule_text(rule):
    return ffi.string(lib.sr_param_rule_string(rule)).decode()


@dataclasses.dataclass(frozen=True)
class PaperParams:
    """The paper's twelve parameters; defaults are the values printed in Section 5.2.

    Damping coefficients are physical: k gives the torque −k·ω.  The paper's
    own simulations pair forces with tr(AᵀB), twice the dot product, so its
    printed k acts as a physical 2k: use `Params.paper_simulation()` to
    reproduce Section 5.3.
    """
    r: float = 0.3      # shell radius [m]
    m_S: float = 2.0    # shell mass [kg]
    k_S: float = 0.08   # shell damping [N m s/rad]
    b: float = 0.2      # yoke width, rods along y [m]
    h: float = 0.5      # yoke length, rods along x [m]
    m_b: float = 2.0    # mass of each b-rod [kg]
    m_h: float = 5.0    # mass of each h-rod [kg]
    k_Y: float = 0.02   # yoke damping [N m s/rad]
    l: float = 0.2      # pendulum length [m]
    m_P: float = 1.0    # pendulum mass [kg]
    k_P: float = 0.05   # pendulum damping [N m s/rad]
    g: float = 9.81     # gravity [m/s^2]

    def __post_init__(self):
        for name in PAPER_NAMES:
            object.__setattr__(self, name, _real("Params", name, getattr(self, name)))
        bad_index, rule = ffi.new("int *"), ffi.new("int *")
        if lib.sr_check_paper_params(ffi.new("double[]", list(self.as_array())), bad_index, rule) != lib.SR_OK:
            raise ValueError(self._rule_broken(PAPER_NAMES[bad_index[0]], rule[0]))

    def _rule_broken(self, name, rule):
        """The message for C's verdict: the parameters involved, the rule (C's text), the values."""
        text = _rule_text(rule)
        if rule == lib.SR_PARAM_RULE_YOKE_FITS:
            return (f"Params.b, Params.h: {text}: half-diagonal {0.5 * math.hypot(self.b, self.h):g} m, "
                    f"r = {self.r:g} m")
        if rule == lib.SR_PARAM_RULE_PENDULUM_FITS:
            return f"Params.l: {text}: l = {self.l:g} m, r = {self.r:g} m"
        return f"Params.{name}: {text}, got {getattr(self, name)!r}"

    def as_array(self):
        """The values in the C library's order (index SR_PAPER_<name>)."""
        return np.array([getattr(self, n) for n in PAPER_NAMES], dtype=np.float64)

    def as_dict(self):
        """The twelve parameters as a dict, name -> value, in the paper's order."""
        return {n: getattr(self, n) for n in PAPER_NAMES}

    def robot(self):
        """The general description of this robot (C: sr_paper_params)."""
        out = ffi.new("double[]", lib.SR_NPARAM)
        status = lib.sr_paper_params(ffi.new("double[]", list(self.as_array())), out)
        if status != lib.SR_OK:
            raise ValueError(f"Params: the paper's parameters {self.as_dict()} give no valid robot "
                             f"({ffi.string(lib.sr_status_string(status)).decode()})")
        return Params.from_array(np.frombuffer(ffi.buffer(out), dtype=np.float64), paper_params=self)


PAPER_NAMES = parameter_order(tuple(f.name for f in dataclasses.fields(PaperParams)),
                              prefix="SR_PAPER_", size="SR_NPAPER")
"""Paper parameter order of the C API: every field at its index SR_PAPER_<name> (checked at import)."""


def _as_shape(name, value, shape):
    """value as a float, a 3-tuple or a 3×3 tuple of tuples (symmetric); ValueError naming the field."""
    if shape == ():
        return _real("Params", name, value)
    try:
        array = np.asarray(value)
        if array.dtype.kind not in "iuf":      # complex, bool, strings, objects: not a length or an inertia
            raise TypeError
        array = array.astype(np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"Params.{name}: expected an array of real numbers of shape {shape}, "
                         f"got {_shown(value)}") from None
    if array.shape != shape:
        raise ValueError(f"Params.{name}: expected an array of real numbers of shape {shape}, got shape {array.shape}")
    if len(shape) == 2 and not np.array_equal(array, array.T, equal_nan=True):
        array = _symmetric(name, array)
    return tuple(map(tuple, array.tolist())) if len(shape) == 2 else tuple(array.tolist())


SYMMETRY_TOL = 1e-12
"""Largest asymmetry of an inertia tensor, relative to its largest entry, that is taken as rounding:
a tensor computed as R D Rᵀ is symmetric only to a few ulps."""


def _symmetric(name, array):
    """The symmetric part of a tensor whose asymmetry is rounding; ValueError with the asymmetry otherwise."""
    scale = np.abs(array).max()
    asymmetry = np.abs(array - array.T).max()
    if not asymmetry <= SYMMETRY_TOL * scale:       # also refuses NaN and inf off the diagonal
        raise ValueError(f"Params.{name}: an inertia tensor must be symmetric, got {array.tolist()} "
                         f"(largest |J - Jᵀ| = {asymmetry:.3g}, relative to its largest entry "
                         f"{asymmetry / scale if scale > 0 else float('inf'):.3g} > {SYMMETRY_TOL:g})")
    return 0.5 * array + 0.5 * array.T


DEFAULT = type("PaperDefault", (), {"__repr__": lambda self: "<the paper's value>"})()
"""The default of every Params field: the paper's robot's value."""


@dataclasses.dataclass(frozen=True)
class Params:
    """A robot of the yoke–pendulum architecture; defaults: the paper's robot, Section 5.2.

    Shell: radius r, mass m_S, isotropic inertia j_S about its centre, damping k_S.  Yoke (rotates
    about the shell's x axis, hinge at the shell centre): mass m_Y, centre of mass c_Y (yoke frame,
    from the shell centre), inertia J_Y about c_Y (yoke frame), joint damping k_Y.  Pendulum
    (rotates about the yoke's y axis, hinge at the shell centre): m_P, c_P, J_P, k_P likewise in
    its own frame.  Motors: rotor inertias j_mY, j_mP about their axes and gear ratios n_Y, n_P
    (the yoke motor's rotor on the shell, the pendulum motor's on the yoke; u stays the torque
    at the joint).  g gravity, slope the floor's inclination [rad] (the inertial frame lies in
    the plane, x up the slope).  `paper_params`: the PaperParams this robot was built from, if any.
    """
    r: float = DEFAULT
    m_S: float = DEFAULT
    j_S: float = DEFAULT
    k_S: float = DEFAULT
    m_Y: float = DEFAULT
    c_Y: tuple = DEFAULT
    J_Y: tuple = DEFAULT
    k_Y: float = DEFAULT
    m_P: float = DEFAULT
    c_P: tuple = DEFAULT
    J_P: tuple = DEFAULT
    k_P: float = DEFAULT
    j_mY: float = DEFAULT
    n_Y: float = DEFAULT
    j_mP: float = DEFAULT
    n_P: float = DEFAULT
    g: float = DEFAULT
    slope: float = DEFAULT
    paper_params: PaperParams = dataclasses.field(default=None, compare=False, repr=False)

    def __post_init__(self):
        defaults = _paper_defaults()
        for name, shape in SHAPES.items():
            value = getattr(self, name)
            object.__setattr__(self, name, _as_shape(name, defaults[name] if value is DEFAULT else value, shape))
        if self.paper_params is None and defaults is not None and all(
                getattr(self, n) == defaults[n] for n in SHAPES):
            object.__setattr__(self, "paper_params", PaperParams())
        elif self.paper_params is not None and not self._built_from(self.paper_params):
            object.__setattr__(self, "paper_params", None)     # e.g. dataclasses.replace of a general field
        bad_index, rule = ffi.new("int *"), ffi.new("int *")
        if lib.sr_check_params(ffi.new("double[]", list(self.as_array())), bad_index, rule) != lib.SR_OK:
            raise ValueError(self._rule_broken(bad_index[0], rule[0]))

    def _built_from(self, paper):
        """Whether this robot is exactly the one the paper's parameters `paper` describe."""
        out = ffi.new("double[]", lib.SR_NPARAM)
        if lib.sr_paper_params(ffi.new("double[]", list(paper.as_array())), out) != lib.SR_OK:
            return False
        return np.array_equal(np.frombuffer(ffi.buffer(out), dtype=np.float64), self.as_array())

    def _rule_broken(self, index, rule):
        name, entry = FLAT_FIELDS[index]
        text = _rule_text(rule)
        value = getattr(self, name)
        if rule in (lib.SR_PARAM_RULE_INERTIA, lib.SR_PARAM_RULE_INSIDE):
            return f"Params.{name}: {text}, got {np.asarray(value).tolist()}" + (
                f" (r = {self.r:g} m)" if rule == lib.SR_PARAM_RULE_INSIDE else "")
        where = f"Params.{name}" if entry is None else f"Params.{name}[{entry}]"
        shown = value if entry is None else float(np.asarray(value)[entry])
        return f"{where}: {text}, got {shown!r}"

    @classmethod
    def paper(cls, **overrides):
        """The paper's robot from its twelve parameters (Section 5.2 as printed, with overrides by
        the paper's names: r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g)."""
        return PaperParams(**overrides).robot()

    @classmethod
    def paper_simulation(cls, **overrides):
        """The physical equivalent of the paper's Section 5.3 runs: printed damping doubled.

        The paper's virtual work ⟨τ − kΩ, δΩ⟩ = tr((τ − kΩ)ᵀ δΩ) is twice the
        dot product of axial vectors, so k_S = 0.08 acts as 0.16 N m s/rad, and
        so on.  Its torques τΣ likewise act as 2τ N m: the 0.05 of Section 5.3.3
        is a physical 0.1 N m.  Overrides by the paper's names.
        """
        base = PaperParams()
        values = {"k_S": 2 * base.k_S, "k_Y": 2 * base.k_Y, "k_P": 2 * base.k_P}
        values.update(overrides)
        return cls.paper(**values)

    @classmethod
    def from_array(cls, values, paper_params=None):
        """The robot of a parameter vector in the C library's order (SR_P_*)."""
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (lib.SR_NPARAM,):
            raise ValueError(f"Params: expected {lib.SR_NPARAM} values in SR_P_* order, got shape {values.shape}")
        fields = {}
        for index, (name, entry) in enumerate(FLAT_FIELDS):
            shape = SHAPES[name]
            if shape == ():
                fields[name] = float(values[index])
            else:
                array = fields.setdefault(name, np.zeros(shape))
                array[entry] = values[index]
                if len(shape) == 2:
                    array[entry[::-1]] = values[index]
        return cls(**fields, paper_params=paper_params)

    def replace(self, **changes):
        """A copy with some general fields changed (the paper's description no longer applies)."""
        return dataclasses.replace(self, paper_params=None, **changes)

    def with_changes(self, **changes):
        """A copy with changes by the paper's names or by the general ones (scenario and task files).

        For a robot built from the paper's parameters, changes that are all paper names (r, m_S,
        k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g) are made to those, and the robot is built again:
        a heavier m_P is a heavier rod, with its tensor.  Otherwise the names are the general
        fields (`replace`); a paper-only name (b, h, m_b, m_h, l) is then an error.
        """
        if self.paper_params is not None and set(changes) <= set(PAPER_NAMES):
            return Params.paper(**{**self.paper_params.as_dict(), **changes})
        paper_only = sorted(set(changes) - set(SHAPES))
        if paper_only:
            raise ValueError(f"Params.{paper_only[0]}: a parameter of the paper's robot (Params.paper), "
                             + ("which these changes of general fields leave" if self.paper_params is not None
                                else "and this robot is not built from the paper's parameters"))
        return self.replace(**changes)

    def as_array(self):
        """The values in the C library's order (index SR_P_<name>)."""
        out = np.empty(len(FLAT_FIELDS))
        for index, (name, entry) in enumerate(FLAT_FIELDS):
            value = getattr(self, name)
            out[index] = value if entry is None else np.asarray(value)[entry]
        return out

    def as_dict(self):
        """name -> value, NumPy arrays for c_* (shape (3,)) and J_* (shape (3, 3))."""
        return {n: (np.array(getattr(self, n)) if SHAPES[n] else getattr(self, n)) for n in SHAPES}

    def potential_range(self):
        """2 g (m_Y |c_Y| + m_P |c_P|): how far the yoke's and pendulum's potential can range [J]
        (m_P g l for the paper's robot); the C energy guard scales by the same."""
        return 2 * self.g * (self.m_Y * float(np.linalg.norm(self.c_Y)) + self.m_P * float(np.linalg.norm(self.c_P)))

    def as_json(self):
        """For summary files: the general values (lists for c_*, J_*), and the paper's twelve under
        "paper" when the robot was built from them."""
        out = {n: (list(map(list, v)) if SHAPES[n] == (3, 3) else list(v) if SHAPES[n] else v)
               for n, v in ((n, getattr(self, n)) for n in SHAPES)}
        if self.paper_params is not None:
            out["paper"] = self.paper_params.as_dict()
        return out

    @property
    def m_R(self):
        """The total (rolling) mass m_S + m_Y + m_P [kg]."""
        return self.m_S + self.m_Y + self.m_P


def paper_rows_to_params(rows):
    """The general parameter vectors (n, SR_NPARAM) of paper parameter vectors (n, SR_NPAPER), by C's
    conversion without the paper's rules (sr_paper_params_unchecked): a sweep's batch then judges
    each sample alone (a negative rod mass, a negative m_Y: "parameter out of range").  A row whose
    conversion is not finite becomes NaN ("non-finite value")."""
    rows = np.ascontiguousarray(rows, dtype=np.float64)
    out = np.empty((len(rows), lib.SR_NPARAM))
    buffer = ffi.new("double[]", lib.SR_NPARAM)
    for i, row in enumerate(rows):
        if lib.sr_paper_params_unchecked(ffi.from_buffer("double[]", row), buffer) == lib.SR_OK:
            out[i] = np.frombuffer(ffi.buffer(buffer), dtype=np.float64)
        else:
            out[i] = np.nan
    return out


def _flat_fields():
    """(field, entry) for each SR_P_ index: entry None for a scalar, i for c_*, (i, j) for J_*."""
    entries = {}
    for name, shape in SHAPES.items():
        if shape == ():
            entries[name] = (name, None)
        elif shape == (3,):
            entries.update({f"{name}_{a}": (name, i) for i, a in enumerate("xyz")})
        else:
            entries.update({f"{name}_{k}": (name, (i, j)) for k, i, j in _TENSOR_ENTRIES})
    order = parameter_order(tuple(entries))
    return tuple(entries[n] for n in order)


FLAT_FIELDS = _flat_fields()
"""For each index of the C parameter vector: the Params field and the entry in it."""
NAMES = tuple(SHAPES)
"""The general fields, in declaration order."""

_DEFAULTS = []


def _paper_defaults():
    """The paper's robot's general values (computed once; None while computing them)."""
    if not _DEFAULTS:
        _DEFAULTS.append(None)
        robot = PaperParams().robot()
        _DEFAULTS[0] = {n: getattr(robot, n) for n in SHAPES}
    return _DEFAULTS[0]
