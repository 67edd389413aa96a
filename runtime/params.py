"""Robot parameters by the paper's names (Section 5.2), physical SI units.

The C library decides which values are valid (sr_check_params, the same function
sr_model_init calls): Params asks it, and words its answer.  The order of the
parameters is read from the compiled module (SR_P_<name>), never assumed.
"""
import dataclasses
import math

import numpy as np

from bindings._sr import ffi, lib

def parameter_order(names, module=lib):
    """names sorted by their index SR_P_<name> in module; ValueError unless they are exactly
    the indices 0 .. SR_NPARAM-1 of module, one each (no parameter missing on either side)."""
    indices = {name: getattr(module, f"SR_P_{name}", None) for name in names}
    missing = sorted(name for name, index in indices.items() if index is None)
    if missing:
        raise ValueError(f"Params: no SR_P_ index in the C library for {', '.join(missing)}")
    if sorted(indices.values()) != list(range(module.SR_NPARAM)):
        raise ValueError(f"Params: the fields {sorted(names)} do not match the C library's parameter "
                         f"indices {indices} (SR_NPARAM = {module.SR_NPARAM})")
    return tuple(sorted(names, key=indices.get))


@dataclasses.dataclass(frozen=True)
class Params:
    """The twelve parameters; defaults are the values printed in Section 5.2.

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
        for name in NAMES:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise ValueError(f"Params.{name}: expected a real number, got {value!r}")
            object.__setattr__(self, name, float(value))
        bad_index, rule = ffi.new("int *"), ffi.new("int *")
        if lib.sr_check_params(ffi.new("double[]", list(self.as_array())), bad_index, rule) != lib.SR_OK:
            raise ValueError(self._rule_broken(NAMES[bad_index[0]], rule[0]))

    def _rule_broken(self, name, rule):
        """The message for C's verdict: the parameters involved, the rule (C's text), the values."""
        text = ffi.string(lib.sr_param_rule_string(rule)).decode()
        if rule == lib.SR_PARAM_RULE_YOKE_FITS:
            return (f"Params.b, Params.h: {text}: half-diagonal {0.5 * math.hypot(self.b, self.h):g} m, "
                    f"r = {self.r:g} m")
        if rule == lib.SR_PARAM_RULE_PENDULUM_FITS:
            return f"Params.l: {text}: l = {self.l:g} m, r = {self.r:g} m"
        return f"Params.{name}: {text}, got {getattr(self, name)!r}"

    @classmethod
    def paper(cls, **overrides):
        """Section 5.2 as printed (same as `Params()`)."""
        return cls(**overrides)

    @classmethod
    def paper_simulation(cls, **overrides):
        """The physical equivalent of the paper's Section 5.3 runs: printed damping doubled.

        The paper's virtual work ⟨τ − kΩ, δΩ⟩ = tr((τ − kΩ)ᵀ δΩ) is twice the
        dot product of axial vectors, so k_S = 0.08 acts as 0.16 N m s/rad, and
        so on.  Its torques τΣ likewise act as 2τ N m: the 0.05 of Section 5.3.3
        is a physical 0.1 N m.
        """
        base = cls()
        values = {"k_S": 2 * base.k_S, "k_Y": 2 * base.k_Y, "k_P": 2 * base.k_P}
        values.update(overrides)
        return cls(**values)

    def as_array(self):
        """The values in the C library's order (index SR_P_<name>)."""
        return np.array([getattr(self, n) for n in NAMES], dtype=np.float64)

    def as_dict(self):
        return {n: getattr(self, n) for n in NAMES}


#: Parameter order of the C API: every field at its index SR_P_<name> (checked at import).
NAMES = parameter_order(tuple(field.name for field in dataclasses.fields(Params)))
