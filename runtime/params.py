"""Robot parameters by the paper's names (Section 5.2), physical SI units."""
import dataclasses
import math

import numpy as np

#: Parameter order of the C API (c/spherical_robot.h).
NAMES = ("r", "m_S", "k_S", "b", "h", "m_b", "m_h", "k_Y", "l", "m_P", "k_P", "g")
_POSITIVE = ("r", "m_S", "b", "h", "m_b", "m_h", "l", "m_P")
_NONNEGATIVE = ("k_S", "k_Y", "k_P", "g")


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
            if not math.isfinite(value):
                raise ValueError(f"Params.{name}: must be finite, got {value!r}")
            object.__setattr__(self, name, float(value))
        for name in _POSITIVE:
            if not getattr(self, name) > 0:
                raise ValueError(f"Params.{name}: must be > 0, got {getattr(self, name)!r}")
        for name in _NONNEGATIVE:
            if not getattr(self, name) >= 0:
                raise ValueError(f"Params.{name}: must be >= 0, got {getattr(self, name)!r}")
        half_diagonal = 0.5 * math.hypot(self.b, self.h)
        if half_diagonal > self.r:
            raise ValueError(f"Params.b, Params.h: the yoke (half-diagonal {half_diagonal:g} m) "
                             f"does not fit inside the shell (r = {self.r:g} m)")
        if self.l > self.r:
            raise ValueError(f"Params.l: the pendulum (l = {self.l:g} m) does not fit inside the shell (r = {self.r:g} m)")

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
        return np.array([getattr(self, n) for n in NAMES], dtype=np.float64)

    def as_dict(self):
        return {n: getattr(self, n) for n in NAMES}
