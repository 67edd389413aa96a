"""Whether rolling without slipping holds along a motion: the contact force's extremes and flags.

The model assumes that the shell rolls without slipping and never leaves the floor.  The floor's
force on the shell (`Model.contact_force`, plane frame: F_z normal, (F_x, F_y) tangential) says
whether that is physical: a floor pushes only (F_n > 0), and Coulomb friction of coefficient μ
holds the contact only while |F_t| ≤ μ F_n.  `contact_summary` reports, for a sampled motion, the
least normal force and the largest friction ratio |F_t|/F_n with their times, and flags where the
motion needs more than the floor gives (docs/model.md "The contact force"):

* ``lift-off``: F_n ≤ 0 at some sample (the robot would jump); margin = the least F_n [N];
* ``slide``: |F_t|/F_n > μ at some sample, μ given (the robot would slide); margin = μ minus the
  largest ratio (negative: the friction coefficient the motion lacks).

The friction ratio is taken over the samples with F_n > 0 (where F_n ≤ 0 no μ suffices, and the
lift-off flag says so).
"""
import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class ContactFlag:
    """Where a motion needs more of the floor than it gives: its kind (``slide``, ``lift-off``), the
    first time it happens, the time of the worst sample, and the margin there (see the module)."""
    kind: str
    time_s: float
    worst_time_s: float
    margin: float

    def message(self, friction=None):
        """One line saying what would happen, when, and by how much."""
        if self.kind == "lift-off":
            return (f"the normal force falls to {self.margin:.4g} N at t = {self.worst_time_s:.6g} s (first <= 0 at "
                    f"t = {self.time_s:.6g} s): the robot would leave the floor")
        return (f"the motion needs friction {friction - self.margin:.4g} > mu = {friction:g} at t = {self.worst_time_s:.6g} s "
                f"(first above mu at t = {self.time_s:.6g} s; margin {self.margin:.4g}): the robot would slide")

    def as_json(self):
        """The flag as a JSON-ready dict."""
        return {"kind": self.kind, "time_s": self.time_s, "worst_time_s": self.worst_time_s, "margin": self.margin}


def friction_ratio(F):
    """|F_t|/F_n per sample of F (n, 3); NaN where F_n ≤ 0."""
    F = np.asarray(F, dtype=float).reshape(-1, 3)
    normal = F[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(normal > 0, np.hypot(F[:, 0], F[:, 1]) / normal, np.nan)


def contact_flags(time, F, friction=None):
    """The `ContactFlag`s of a motion sampled at `time` (n,) with contact forces F (n, 3) [N]:
    lift-off where F_n ≤ 0, slide where |F_t|/F_n > `friction` (μ; None: not checked)."""
    time, F = np.asarray(time, dtype=float), np.asarray(F, dtype=float).reshape(-1, 3)
    normal, ratio = F[:, 2], friction_ratio(F)
    flags = []
    lifted = np.flatnonzero(normal <= 0)
    if lifted.size:
        worst = int(np.argmin(normal))
        flags.append(ContactFlag("lift-off", float(time[lifted[0]]), float(time[worst]), float(normal[worst])))
    if friction is not None:
        sliding = np.flatnonzero(ratio > friction)
        if sliding.size:
            worst = int(np.nanargmax(ratio))
            flags.append(ContactFlag("slide", float(time[sliding[0]]), float(time[worst]), float(friction - ratio[worst])))
    return flags


def contact_summary(time, F, friction=None):
    """The "contact" entry of a run's summary: the least normal force and the largest friction ratio
    with their times, μ, and the flags (`contact_flags`).  The largest ratio is None when F_n ≤ 0
    at every sample."""
    time, F = np.asarray(time, dtype=float), np.asarray(F, dtype=float).reshape(-1, 3)
    ratio = friction_ratio(F)
    least = int(np.argmin(F[:, 2]))
    out = {"least_normal_force_N": float(F[least, 2]), "least_normal_force_time_s": float(time[least]),
           "largest_friction_ratio": None, "largest_friction_ratio_time_s": None}
    if np.isfinite(ratio).any():
        worst = int(np.nanargmax(ratio))
        out["largest_friction_ratio"] = float(ratio[worst])
        out["largest_friction_ratio_time_s"] = float(time[worst])
    out["friction"] = friction
    out["flags"] = [flag.as_json() for flag in contact_flags(time, F, friction)]
    return out
