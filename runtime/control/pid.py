"""The PID baseline: speed through the yoke torque, heading and lateral error through the pendulum torque.

Two decoupled loops, the comparison most papers make (docs/control.md, "PID baseline"):

* speed: u_Y = u_ff + K_v e_v + K_vi ∫e_v with e_v = v_ref − v and the steady-rolling
  feed-forward u_ff = v_ref (k_S + k_Y) / r of the controller's model (in steady rolling the
  yoke torque only balances the shell and yoke damping: docs/control.md, the envelope);
* steering, a cascade of three loops.  The heading to hold is the reference's, or on a path
  ψ_t = ψ_path + atan(K_y e_y) (e_y the cross-track error, toward the path).  The yaw rate to
  roll at is ψ̇_ref = v_ref κ_path + K_ψ (ψ_t − ψ).  Leaning the rolling axis turns the robot
  (runtime/control/geometry.py), so the lean to hold is a PI on the yaw-rate error,
  φ_ref = K_r e_ψ̇ + K_ri ∫e_ψ̇, clipped to ±φ_max; and the pendulum torque is a PID on the
  lean, u_P = K_φ e_φ + K_φi ∫e_φ − K_φd φ̇ (a pendulum torque rolls the shell sideways, which
  tilts its rolling axis).
Rates (ψ̇, φ̇) are differences of the measured angles over one period.  The integrators stop
while their loop's torque is clipped (conditional anti-windup).
"""
import dataclasses
import math

from ..schema import check_arguments

from .controller import DEFAULT_U_MAX, Controller
from .geometry import forward_speed, heading, lean, lean_for_curvature, wrap_angle
from .ranges import PID_RANGES


@dataclasses.dataclass(frozen=True)
class PidGains:
    """Tuning of `Pid` (the `[controller]` keys of a task file); units in brackets."""
    k_v: float = 10.0       # yoke torque per speed error [N m s/m]
    k_vi: float = 0.5       # ... per integrated speed error [N m/m]
    k_y: float = 1.0        # heading correction per cross-track error, ψ_t = ψ_path + atan(k_y e_y) [1/m]
    k_psi: float = 0.3      # yaw rate per heading error [1/s]
    k_r: float = 1.0        # lean per yaw-rate error [s]
    k_ri: float = 0.3       # lean per integrated yaw-rate error [1]
    phi_max: float = 0.8    # largest lean asked for [rad]
    k_phi: float = 4.0      # pendulum torque per lean error [N m/rad]
    k_phii: float = 0.0     # ... per integrated lean error [N m/(rad s)]
    k_phid: float = 2.0     # ... per lean rate [N m s/rad]

    def __post_init__(self):
        check_arguments(dataclasses.asdict(self), PID_RANGES)


GAIN_NAMES = tuple(f.name for f in dataclasses.fields(PidGains))


class Pid(Controller):
    """Two PID loops: the yoke torque holds the speed, the pendulum torque steers by leaning the robot."""
    kind = "pid"

    def __init__(self, params, rate=50.0, u_max=DEFAULT_U_MAX, gains=PidGains()):
        super().__init__(params, rate, u_max)
        self.gains = gains

    def reset(self, x0):
        """Starts a run at x0: zeroes the integrals and takes the lean and heading of x0 as the last ones."""
        super().reset(x0)
        self.int_v = self.int_r = self.int_phi = 0.0
        self.last_phi, self.last_psi = float(lean(x0)), float(heading(x0))
        self._clipped = (False, False)

    def compute(self, t, x, target):
        """The torques of one sample for state x and the target."""
        g, p, dt = self.gains, self.params, self.period
        e_v = target.speed - float(forward_speed(x, p.r))
        u_ff = target.speed * (p.k_S + p.k_Y) / p.r
        if not self._clipped[0]:
            self.int_v += e_v * dt
        u_Y = u_ff + g.k_v * e_v + g.k_vi * self.int_v

        psi, phi = float(heading(x)), float(lean(x))
        psi_rate = float(wrap_angle(psi - self.last_psi)) / dt
        phi_rate = (phi - self.last_phi) / dt
        self.last_psi, self.last_phi = psi, phi
        psi_t = target.heading
        if target.cross_track is not None:
            psi_t += math.atan(-g.k_y * target.cross_track)
        e_rate = target.speed * target.curvature + g.k_psi * float(wrap_angle(psi_t - psi)) - psi_rate
        phi_ref = g.k_r * e_rate + g.k_ri * self.int_r
        if abs(phi_ref) < g.phi_max and not self._clipped[1]:
            self.int_r += e_rate * dt
        phi_ref = min(max(phi_ref, -g.phi_max), g.phi_max)
        e_phi = phi_ref - phi
        if not self._clipped[1]:
            self.int_phi += e_phi * dt
        u_P = g.k_phi * e_phi + g.k_phii * self.int_phi - g.k_phid * phi_rate
        return u_Y, u_P

    def after_limits(self, raw, u):
        """Records which torques were clipped (anti-windup: their integrals stop at the next sample)."""
        self._clipped = (bool(raw[0] != u[0]), bool(raw[1] != u[1]))
