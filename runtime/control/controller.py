"""The controller interface: measured state -> motor torques (u_Y, u_P), at a rate, within limits.

A controller is sampled every 1/rate s on the (possibly noisy) measured state; its torques are
held until the next sample (zero-order hold, runtime/control/closed_loop.py).  `Controller.update`
clips the design's torques to |u| ≤ u_max, counts the samples where a torque is at its limit, and times the
design's own computation (`solve_s`), so that every controller is measured the same way.
"""
import time

import numpy as np

from ..schema import check_arguments
from .ranges import CONTROLLER_RANGES

#: Default torque limit [N m]: the low end of the paper's 0.5–2 N m.
DEFAULT_U_MAX = 0.5
#: A torque within this fraction of u_max counts as saturated: clipped (PID, LQR) or held at its
#: bound by the optimiser (NMPC, whose QP returns the bound to rounding).
SATURATION_TOL = 1e-9


class Controller:
    """Base class: subclasses implement `compute(t, x, target) -> (u_Y, u_P)` before limits."""
    kind = "abstract"

    def __init__(self, params, rate, u_max=DEFAULT_U_MAX):
        check_arguments({"rate": rate, "u_max": u_max}, CONTROLLER_RANGES)
        self.params, self.rate, self.u_max = params, float(rate), float(u_max)
        self.samples = 0
        self.saturated = 0
        self.solve_s = []

    @property
    def period(self):
        """The sampling period [s], 1 / rate."""
        return 1.0 / self.rate

    def reset(self, x0):
        """Forget integrators and history; `x0` is the first measured state."""
        self.samples = self.saturated = 0
        self.solve_s = []

    def compute(self, t, x, target):
        """The raw torques (2,) [N m] at time t for the measured state x and the reference's target;
        subclasses implement it."""
        raise NotImplementedError

    def update(self, t, x, target):
        """Torques (2,) for the next period: the design's, clipped to ±u_max (counted when clipped)."""
        started = time.perf_counter()
        raw = np.asarray(self.compute(t, x, target), dtype=np.float64)
        self.solve_s.append(time.perf_counter() - started)
        if raw.shape != (2,) or not np.all(np.isfinite(raw)):
            raise ValueError(f"controller {self.kind}: returned torques {raw.tolist()} at t = {t:g} s, "
                             f"expected two finite numbers")
        u = np.clip(raw, -self.u_max, self.u_max)
        self.samples += 1
        if np.any(np.abs(u) >= self.u_max * (1 - SATURATION_TOL)):
            self.saturated += 1
        self.after_limits(raw, u)
        return u

    def after_limits(self, raw, u):
        """Hook for anti-windup: the torques asked for and the ones applied."""

    @property
    def saturated_fraction(self):
        """The fraction of the samples so far at which a torque was clipped to u_max."""
        return self.saturated / self.samples if self.samples else 0.0
