"""NMPC on the full non-linear model, built on the model as CasADi.

The model.  The reduced error coordinates of runtime/control/lqr_design.py (the yoke's attitude
error E = Log(Q_refᵀ Q) on SO(3), the pendulum, the rates in the yoke's frame, the cross-track
error) carry the whole dynamics of the rolling robot along a path: no term is dropped, only the
symmetry (where the robot is, the shell's phase about the hinge) is quotiented out.  Their field
is written here in CasADi around the exported `sr_accel` of generated/casadi/ (the same M and f as
the C kernels): `reduced_field` equals `lqr_design.field` on the C kernel to round-off (test).
One step of the prediction model is the classical RK4 of that field over one controller period.

The solver: real-time iterations (Diehl, Bock & Schlöder 2005; what acados and ACADO ship for
fast NMPC).  Multiple shooting over N periods: at every sample the nodes (z̄_k, ū_k) of the
previous solution, shifted by one period, are linearised (the RK4 step and its exact Jacobians
by CasADi's AD, one call of the mapped Function for all N nodes, compiled to C once and cached),
the gaps d_k = Φ(z̄_k, ū_k) − z̄_{k+1} kept, the initial value embedded (δz_0 = z_0 − z̄_0), and one
Gauss–Newton QP in the torques is solved with the torque limits as bounds (condensed: 2N unknowns,
qpOASES from the CasADi wheel).  The cost is quadratic in z and u (the LQR's Bryson weights, the
LQR's Riccati cost-to-go at the end), so Gauss–Newton's Hessian is the exact one.
Why not a converged NLP solve per sample: fatrop on the same OCP through Opti took 281 ms per
sample (p50, AMD EPYC), far above the 50 ms period; one RTI iteration takes ~1–2 ms and,
warm-started every period, tracks the converged solution (docs/control.md).

A slope in the model (`Params.slope`, along the plane's x axis) is fed forward in whichever
direction the path runs, as the LQR's (runtime/control/slope.py): the prediction and the operating
points are the flat model's, and the slope moves the operating point by (Δz*, Δu*) at the
reference's heading, speed and curvature.  To first order the plant's error from the sloped
operating point, z − Δz* under u − Δu*, moves as the flat model's from the flat one, so the NMPC
solves from the measured state shifted by −Δz* (`shifted_state`: its attitude, pendulum and rates)
for the flat model driven by u + d̂ − Δu*.  Its nodes' torques are the plant's, so the torque
limits hold the feedforward's share as well.  With `slope_estimate_s` > 0 the slope is the LQR's
online estimate instead (runtime/control/slope.py's `SlopeEstimator`: the world's slope vector and a
torque offset d from the measured rates against the flat model's one-period prediction), fed
through the same path, and d joins the prediction's offset: u + d̂ + d − Δu*.
"""
import dataclasses
import hashlib
import os
import pathlib
import shutil
import subprocess
import tempfile
import typing

import numpy as np

from .. import so3
from ..casadi_model import load, parameter_vector
from ..state import IDX_RP, IDX_RS, IDX_WP, IDX_WS, IDX_WY, rotations
from .controller import DEFAULT_U_MAX, Controller
from .geometry import cross_track_rate
from . import lqr_design as design
from .lqr import LqrGains, design_schedule
from .slope import SlopeFeedforward, slope_components
from .ranges import NMPC_RANGES

#: The NMPC's state: the robot's error coordinates, the cross-track error and its integral
#: (offset-free tracking of a robot heavier than the model); the speed's integrator is left out.
NZ_N = design.Z_IY + 1
Z_E = design.Z_E
#: The coordinates the torque offset is estimated from: the pendulum and the rates, which do not
#: depend on where the reference's nearest point falls (the attitude and e_y do, by its quantisation).
DISTURBANCE_ROWS = slice(design.Z_TH_P, design.Z_WP + 1)
#: The shell's rates in the yoke's frame: where the estimated acceleration acts (a slope's pull, a
#: body unlike the model's: what the torques cannot explain).
SHELL_ROWS = slice(design.Z_OM.start, design.Z_OM.stop)


def _casadi():
    import casadi
    return casadi


def _so3_exp_casadi(ca, e):
    """Exp(e) and J_r⁻¹(e) in CasADi, with series below |e| = 1e-4 (no 0/0 in value or derivative)."""
    t2 = ca.dot(e, e)
    small = t2 < 1e-8
    safe = ca.if_else(small, 1.0, t2)
    t = ca.sqrt(safe)
    a = ca.if_else(small, 1 - t2 / 6, ca.sin(t) / t)
    b = ca.if_else(small, 0.5 - t2 / 24, (1 - ca.cos(t)) / safe)
    c = ca.if_else(small, 1.0 / 12 + t2 / 720, 1 / safe - (1 + ca.cos(t)) / (2 * t * ca.sin(t)))
    W = ca.skew(e)
    W2 = ca.mtimes(W, W)
    return ca.SX.eye(3) + a * W + b * W2, ca.SX.eye(3) + 0.5 * W + c * W2


def reduced_field():
    """casadi.Function (z[NZ_N], u[2], v, kappa, p) -> ż[NZ_N]: `lqr_design.field` (without the
    integrators) on the exported `sr_accel`; p the parameters in SR_P_* order."""
    ca = _casadi()
    accel = load("sr_accel")
    z, u = ca.SX.sym("z", NZ_N), ca.SX.sym("u", 2)
    v, kappa = ca.SX.sym("v"), ca.SX.sym("kappa")
    p = ca.SX.sym("p", accel.size1_in(2))
    r = p[_r_index()]
    exp_E, jr_inv = _so3_exp_casadi(ca, z[Z_E])
    Q = ca.mtimes(ca.DM(design.reference_attitude(0.0)), exp_E)       # the lift: R_S = Q, θ_Y = 0
    th = z[design.Z_TH_P]
    R_P = ca.vertcat(ca.horzcat(ca.cos(th), 0, ca.sin(th)), ca.horzcat(0, 1, 0),
                     ca.horzcat(-ca.sin(th), 0, ca.cos(th)))
    w_S = z[design.Z_OM] + ca.vertcat(-v / r, 0, 0)
    w_Y, w_P = z[design.Z_WY] + v / r, z[design.Z_WP]
    row_major = lambda M: ca.reshape(M.T, 9, 1)                       # noqa: E731  (SR_X_R_*: rows)
    x = ca.vertcat(row_major(Q), row_major(ca.SX.eye(3)), row_major(R_P), 0, z[design.Z_EY], r, w_S, w_Y, w_P)
    a = accel(x, u, p)
    e_z = ca.DM([0.0, 0.0, 1.0])
    q_dot = r * ca.cross(ca.mtimes(Q, w_S), e_z)
    s_dot = q_dot[0] / (1 - kappa * z[design.Z_EY])
    w_Q = w_S + ca.vertcat(w_Y, 0, 0)
    z_dot = ca.vertcat(ca.mtimes(jr_inv, w_Q - kappa * s_dot * ca.mtimes(Q.T, e_z)),
                       w_P,
                       a[0:3] - ca.cross(ca.vertcat(w_Y, 0, 0), w_S),
                       a[3], a[4], q_dot[1], z[design.Z_EY])
    return ca.Function("reduced_field", [z, u, v, kappa, p], [z_dot], ["z", "u", "v", "kappa", "p"], ["z_dot"])


def _r_index():
    from bindings._sr import lib
    return lib.SR_P_r


def node_function(period):
    """casadi.Function (z, u, v, kappa, p) -> (z⁺, A, B): one RK4 step of `reduced_field` over
    `period` and its Jacobians ∂z⁺/∂z (NZ_N×NZ_N) and ∂z⁺/∂u (NZ_N×2), by AD."""
    ca = _casadi()
    f = reduced_field()
    z, u = ca.SX.sym("z", NZ_N), ca.SX.sym("u", 2)
    v, kappa, p = ca.SX.sym("v"), ca.SX.sym("kappa"), ca.SX.sym("p", f.size1_in(4))
    z_next = _rk4(f, z, u, v, kappa, p, float(period))
    return ca.Function("nmpc_node", [z, u, v, kappa, p], [z_next, ca.jacobian(z_next, z), ca.jacobian(z_next, u)],
                       ["z", "u", "v", "kappa", "p"], ["z_next", "A", "B"])


def _rk4(f, z, u, v, kappa, p, h):
    k1 = f(z, u, v, kappa, p)
    k2 = f(z + h / 2 * k1, u, v, kappa, p)
    k3 = f(z + h / 2 * k2, u, v, kappa, p)
    k4 = f(z + h * k3, u, v, kappa, p)
    return z + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def cache_dir():
    """Where compiled prediction models are kept: $SR_CACHE_DIR, else ~/.cache/spherical_robot."""
    return pathlib.Path(os.environ.get("SR_CACHE_DIR") or pathlib.Path.home() / ".cache" / "spherical_robot")


def compiled(function):
    """`function` compiled to C by CasADi's code generator and the system's cc (-O1), as a
    casadi.Function; cached under `cache_dir()` by the hash of the generated source, so the ~10 s
    compile is paid once per model version.  Without a C compiler: `function` itself (CasADi's
    virtual machine, ~15× slower)."""
    ca = _casadi()
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        return function
    with tempfile.TemporaryDirectory() as tmp:
        generator = ca.CodeGenerator(f"{function.name()}.c", {"with_header": False})
        generator.add(function)
        generator.generate(tmp + "/")
        source = pathlib.Path(tmp, f"{function.name()}.c").read_bytes()
        key = hashlib.sha256(source).hexdigest()[:16]
        library = cache_dir() / f"{function.name()}-{key}.so"
        if not library.exists():
            library.parent.mkdir(parents=True, exist_ok=True)
            partial = library.with_suffix(f".{os.getpid()}.tmp")
            subprocess.run([compiler, "-shared", "-fPIC", "-O1", "-o", str(partial), str(pathlib.Path(tmp, f"{function.name()}.c"))],
                           check=True, capture_output=True)
            os.replace(partial, library)     # atomic: a concurrent build never sees half a library
    return ca.external(function.name(), str(library))


@dataclasses.dataclass(frozen=True)
class NmpcGains(LqrGains):
    """Tuning of `Nmpc` (`[controller]` keys): the LQR's error sizes and design grid (the
    operating points are the horizon's reference), and the horizon."""
    torque_step_n_m: float = 0.1      # a change of torque from one node to the next worth the full cost
    cross_track_integral_m_s: float = 2.0    # ∫e_y dt (the horizon sees its overshoot)
    steady_rate_m_s: float = 0.005    # ∫e_y advances only while |ė_y| ≤ this [m/s] (the horizon sees the overshoot)
    disturbance_gain: float = 0.05    # the share of the offsets' one-sample update taken (0: no estimate)
    horizon: float = 30               # N nodes
    node_periods: float = 2           # controller periods per node: the horizon is N × node_periods / rate
    iterations: float = 1             # real-time iterations per sample
    tight_band_m: float = 0.0         # the LQR's tight gains: not the NMPC's
    #: The ranges of the settings (runtime/control/ranges.py: those of a task file's keys).
    RANGES: typing.ClassVar[dict] = NMPC_RANGES


GAIN_NAMES = tuple(f.name for f in dataclasses.fields(NmpcGains))

_NODES = {}
_TERMINAL_COSTS = {}
#: Gauss–Newton iterations of the first sample, from the operating points as the guess.
COLD_START_ITERATIONS = 8
#: A jump of the reference's heading between samples (a waypoint's corner) larger than this
#: starts the iterations afresh: the last solution's coordinates are relative to the old heading.
HEADING_JUMP_RAD = 0.3
#: The C NMPC's bound on a QP's factorisations, per unknown (an active-set solve from a cold start
#: frees or fixes each torque about once).
QP_MAX_ITERATIONS_PER_UNKNOWN = 4


class _Diverged(Exception):
    """The prediction or the QP gave no finite answer."""


def _wrap(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


class Nmpc(SlopeFeedforward, Controller):
    """Real-time-iteration NMPC (see the module's docstring); `rate` 20 Hz by default."""
    kind = "nmpc"

    def __init__(self, params, rate=20.0, u_max=DEFAULT_U_MAX, gains=NmpcGains()):
        super().__init__(params, rate, u_max)
        self.gains, self.n = gains, int(gains.horizon)
        self.node_periods = int(gains.node_periods)
        self.node_period = self.period * self.node_periods
        # The prediction is the flat model's; a slope in `params` is fed forward (see the module).
        flat = params.replace(slope=0.0)
        self.schedule = design_schedule(flat, rate, u_max, gains)
        # The online estimate (slope_estimate_s > 0) is the LQR's (runtime/control/slope.py), on the flat model.
        self._init_slope(params, flat, self.schedule, gains)
        self._p = parameter_vector(flat)
        q = gains.weights(u_max).q_diagonal()[:NZ_N]
        self._q_path = q
        self._q_heading = np.where(np.isin(np.arange(NZ_N), (design.Z_EY, design.Z_IY)), 0.0, q)
        self._r = 1.0 / u_max ** 2
        # ‖D U − (u_last, 0, …)‖²: the torques' changes from the last applied one and node to node.
        n2 = 2 * self.n
        self._D = np.eye(n2) - np.eye(n2, k=-2)
        self._r_step = 1.0 / gains.torque_step_n_m ** 2
        self._P_path, self._P_heading = self._terminal_costs()
        self._build_solver()
        self.reset(None)

    def _build_solver(self):
        """The prediction (the N nodes as one compiled CasADi Function) and the QP solver (DAQP)."""
        ca = _casadi()
        key = (self.node_period, self.n)
        if key not in _NODES:
            _NODES[key] = compiled(node_function(self.node_period).map(self.n))
        self._nodes = _NODES[key]
        # One period of the prediction, for the torque offset's estimate (compiled only when used).
        if self.gains.disturbance_gain > 0 and (self.period, 1) not in _NODES:
            _NODES[self.period, 1] = compiled(node_function(self.period))
        self._one_period = _NODES.get((self.period, 1))
        n2 = 2 * self.n
        self._qp = ca.conic("nmpc_qp", "daqp", {"h": ca.Sparsity.dense(n2, n2), "a": ca.Sparsity(0, n2)},
                            {"error_on_fail": False})

    def _terminal_costs(self):
        """The discrete Riccati cost-to-go of the prediction model at every operating point of the
        schedule, with the cross-track error (paths) and without it (speed and heading); cached
        (the Python and the C NMPC of a task share them, and building the node takes seconds)."""
        key = (self._p.tobytes(), self.node_period, self.u_max, self.gains)
        if key not in _TERMINAL_COSTS:
            _TERMINAL_COSTS[key] = self._riccati_costs()
        return _TERMINAL_COSTS[key]

    def _riccati_costs(self):
        from scipy.linalg import solve_discrete_are
        s = self.schedule
        shape = s.z_star.shape[:2] + (NZ_N, NZ_N)
        P_path, P_heading = np.zeros(shape), np.zeros(shape)
        body = np.arange(design.Z_EY)
        R = self._r * np.eye(2)
        node = node_function(self.node_period)
        for i, j in np.ndindex(shape[:2]):
            _, A, B = (out.full() for out in node(s.z_star[i, j][:NZ_N], s.u_star[i, j], s.speeds[i],
                                                   s.curvatures[j], self._p))
            P_path[i, j] = solve_discrete_are(A, B, np.diag(self._q_path), R)
            P_heading[i, j][np.ix_(body, body)] = solve_discrete_are(A[np.ix_(body, body)], B[body],
                                                                     np.diag(self._q_heading[body]), R)
        return P_path, P_heading

    def reset(self, x0):
        """Starts a run at x0: forgets the warm start, the heading, the integral and the torque offset."""
        super().reset(x0)
        self._guess, self._heading, self._u_last = None, 0.0, None
        self.integral = 0.0                     # ∫e_y dt [m s], the controller's own state
        self.disturbance = np.zeros(2)          # d̂ [N m]: the estimated constant offset of the torques
        self.shell_accel = np.zeros(3)          # â [rad/s²]: the estimated acceleration of the shell's rates
        self._offset = np.zeros(2)              # d̂ − f [N m]: what the prediction adds to the torques
        self._last = None                       # (z, u, v, κ) of the last sample: what d̂ is estimated from
        self.restarts = 0
        self._reset_slope()

    def preview_distances(self, target):
        """The horizon's nodes along the path at the reference speed: v T k, k = 0 .. N [m]."""
        return target.speed * self.node_period * np.arange(self.n + 1)

    def _references(self, v, kappas):
        """z* (N+1, NZ_N) and u* (N, 2) at speed v and the nodes' curvatures: `Schedule.at`,
        vectorised over the nodes (the same bilinear interpolation, clamped to the grid)."""
        s = self.schedule
        weights = []
        for grid, values in ((s.speeds, np.array([v])), (s.curvatures, np.asarray(kappas))):
            if len(grid) == 1:
                weights.append((np.zeros(len(values), int), np.zeros(len(values), int), np.zeros(len(values))))
                continue
            lo = np.clip(np.searchsorted(grid, values) - 1, 0, len(grid) - 2)
            w = np.clip((values - grid[lo]) / (grid[lo + 1] - grid[lo]), 0.0, 1.0)
            weights.append((lo, np.minimum(lo + 1, len(grid) - 1), w))
        (i0, i1, wv), (j0, j1, wk) = weights
        wv, wk = wv[0], wk[:, None]

        def mix(a):
            return ((1 - wv) * ((1 - wk) * a[i0[0], j0] + wk * a[i0[0], j1])
                    + wv * ((1 - wk) * a[i1[0], j0] + wk * a[i1[0], j1]))
        return mix(s.z_star)[:, :NZ_N], mix(s.u_star)[:-1]

    def slope_feedforward(self, target, kappa):
        """(Δz* (NZ,), Δu* (2,) [N m]): the operating point's move on the slope `self.slope` (the
        model's or the estimate) at the target's heading and speed and the curvature kappa
        (runtime/control/slope.py); None on a flat model without an estimate."""
        if self._slope_schedule is None:
            return None
        up, right = slope_components(self.slope, target.heading)
        return self._slope_schedule.at(target.speed, kappa, up, right)

    def _on_slope(self, x, target, kappa):
        """(the state the NMPC solves from, Δu* − d): x shifted by −Δz* on the slope (see the module),
        else x and 0.  With the online estimate, first updates it from the measured x, and its torque
        offset d (the plant moving as the model under u + d) joins the prediction's offset."""
        if self._estimator is not None:
            self._estimator.update(x, self._applied)
        move = self.slope_feedforward(target, kappa)
        if move is None:
            return x, np.zeros(2)
        if self._estimator is None:
            return shifted_state(x, -move[0], target.heading), move[1]
        return shifted_state(x, -move[0], target.heading), move[1] - self._estimator.torque_offset

    def compute(self, t, x, target):
        """The torques of one sample: solves the horizon's optimal control problem from state x for the
        target."""
        n, path = self.n, target.cross_track is not None
        v = float(target.speed)
        if path and target.curvature_ahead is not None and len(target.curvature_ahead) == n + 1:
            kappas = np.asarray(target.curvature_ahead, dtype=float)
        else:
            kappas = np.full(n + 1, float(target.curvature) if path else 0.0)
        x, feedforward = self._on_slope(x, target, float(kappas[0]))
        z0 = design.error_coordinates(x, self.params.r, v, target.heading, target.cross_track if path else 0.0,
                                      (self.integral if path else 0.0, 0.0))[:NZ_N]
        zs, us = self._references(v, kappas)
        jumped = abs(_wrap(target.heading - self._heading)) > HEADING_JUMP_RAD
        self._offset = self.disturbance - feedforward
        if not jumped:
            self._estimate_disturbance(z0)
        self.disturbance = self._offset + feedforward
        # The plant is modelled as the model driven by u + d̂ − Δu*: the torques that hold the
        # reference are u* − d̂ + Δu*, and every node of the prediction adds d̂ − Δu* to its torques.
        us = us - self._offset
        if self._guess is not None and jumped:
            self._guess = None                  # a corner: the last solution is in another frame
        self._heading = target.heading
        if self._guess is None:
            Z, U = zs.copy(), us.copy()
        else:                                   # the last solution, one node on when a node has passed
            Z, U = self._guess
            if self.samples % self.node_periods == 0:
                Z = np.vstack([Z[1:], Z[-1:]])
                U = np.vstack([U[1:], U[-1:]])
        s = self.schedule
        i = int(np.argmin(np.abs(s.speeds - v)))
        j = int(np.argmin(np.abs(s.curvatures - kappas[-1])))
        P = (self._P_path if path else self._P_heading)[i, j]
        q = self._q_path if path else self._q_heading
        try:
            Z, U = self._iterate(z0, Z, U, zs, us, v, kappas, q, P, cold=self._guess is None)
        except _Diverged:                        # a warm start gone bad: once more from the reference
            self.restarts += 1
            try:
                Z, U = self._iterate(z0, zs.copy(), us.copy(), zs, us, v, kappas, q, P, cold=True)
            except _Diverged:                    # no prediction at all: hold the reference's torques
                self._guess, self._last = None, None
                return np.clip(us[0], -self.u_max, self.u_max)
        self._guess, self._u_last = (Z, U), U[0].copy()
        self._last = (z0, U[0].copy(), v, float(kappas[0]))
        # The integral advances at any offset unless a torque is held at its bound (anti-windup) or
        # the error moves faster than steady_rate_m_s (a transient the loop is removing:
        # integrating it would force an overshoot of equal area), as the LQR's.
        e_y = target.cross_track
        if (path and np.all(np.abs(U[0]) < self.u_max * 0.999)
                and abs(cross_track_rate(x, self.params.r, target.heading)) <= self.gains.steady_rate_m_s):
            self.integral += self.period * e_y
        return U[0]

    def _estimate_disturbance(self, z):
        """d̂ += gain · argmin_δ ‖B₁ δ − (z − Φ₁(z⁻, u⁻ + d̂ − f))‖ over DISTURBANCE_ROWS: the last
        sample's z⁻ and torques u⁻ predicted over one period by the model with the offset (less this
        sample's slope feedforward Δu*, as the C NMPC's), against the measured z; B₁ the
        prediction's torque Jacobian.  d̂ − Δu* clipped to ±u_max."""
        gain = self.gains.disturbance_gain
        if self._last is None or gain == 0:
            return
        z_prev, u_prev, v, kappa = self._last
        z_pred, _, B = (out.full() for out in self._one_period(z_prev, u_prev + self._offset, v, kappa, self._p))
        z_pred = z_pred[:, 0]
        z_pred[SHELL_ROWS] += self.period * self.shell_accel
        residual = z - z_pred
        if not (np.all(np.isfinite(residual[DISTURBANCE_ROWS])) and np.all(np.isfinite(B[DISTURBANCE_ROWS]))):
            return
        # â is free on the shell's rows, so the least squares fits them exactly: the torque step is
        # the fit of the other rows (the pendulum, the joints' rates), â what is left on the shell's.
        rows = [i for i in range(DISTURBANCE_ROWS.start, DISTURBANCE_ROWS.stop) if not SHELL_ROWS.start <= i < SHELL_ROWS.stop]
        step = np.linalg.solve(B[rows].T @ B[rows], B[rows].T @ residual[rows])
        alpha = (residual[SHELL_ROWS] - B[SHELL_ROWS] @ step) / self.period
        if not (np.all(np.isfinite(step)) and np.all(np.isfinite(alpha))):
            return
        self._offset = np.clip(self._offset + gain * step, -self.u_max, self.u_max)
        self.shell_accel = self.shell_accel + gain * alpha

    def _iterate(self, z0, Z, U, zs, us, v, kappas, q, P, cold):
        # Cold start: iterate to convergence once (RTI's usual initialisation), then one per sample.
        for _ in range(COLD_START_ITERATIONS if cold else int(self.gains.iterations)):
            Z, U = self._iteration(z0, Z, U, zs, us, v, kappas, q, P)
        return Z, U

    def _iteration(self, z0, Z, U, zs, us, v, kappas, q, P):
        """One Gauss–Newton QP around the nodes (Z (N+1, NZ_N), U (N, 2)); the new nodes.
        Raises _Diverged when the prediction overflows or the QP fails."""
        n, nz = self.n, NZ_N
        z_next, A, B = (out.full() for out in self._nodes(Z[:n].T, (U + self._offset).T, v,
                                                          kappas[:n].reshape(1, n), self._p))
        if not (np.all(np.isfinite(z_next)) and np.all(np.isfinite(A)) and np.all(np.isfinite(B))):
            raise _Diverged
        z_next = z_next.T
        z_next[:, SHELL_ROWS] += self.node_period * self.shell_accel
        A = A.reshape(nz, n, nz).transpose(1, 0, 2)      # A[k]: nz×nz
        B = B.reshape(nz, n, 2).transpose(1, 0, 2)       # B[k]: nz×2
        gaps = z_next - Z[1:]
        # δz_{k+1} = A_k δz_k + B_k δu_k + d_k: δz_k = c_k + G_k δU (condensing).
        G = np.zeros((n + 1, nz, 2 * n))
        c = np.zeros((n + 1, nz))
        c[0] = z0 - Z[0]
        with np.errstate(over="ignore", invalid="ignore"):     # an unstable guess: checked below
            for k in range(n):
                G[k + 1] = A[k] @ G[k]
                G[k + 1][:, 2 * k:2 * k + 2] += B[k]
                c[k + 1] = A[k] @ c[k] + gaps[k]
            W = np.broadcast_to(q, (n + 1, nz))
            e = Z + c - zs                          # the predicted error at δU = 0
            Gs = G[1:n].reshape(-1, 2 * n)
            H = Gs.T @ (W[1:n].reshape(-1, 1) * Gs) + G[n].T @ P @ G[n] + self._r * np.eye(2 * n)
            g = Gs.T @ (W[1:n].reshape(-1) * e[1:n].reshape(-1)) + G[n].T @ P @ e[n] + self._r * (U - us).reshape(-1)
        if self._u_last is not None:
            step = self._D @ U.reshape(-1)
            step[:2] -= self._u_last
            H += self._r_step * (self._D.T @ self._D)
            g += self._r_step * (self._D.T @ step)
        if not (np.all(np.isfinite(H)) and np.all(np.isfinite(g))):
            raise _Diverged
        sol = self._qp(h=H, g=g, lbx=(-self.u_max - U).reshape(-1), ubx=(self.u_max - U).reshape(-1))
        dU = sol["x"].full().reshape(-1)
        if not (self._qp.stats()["success"] and np.all(np.isfinite(dU))):
            raise _Diverged
        Z_new = Z + c + (G @ dU)
        return Z_new, U + dU.reshape(n, 2)


def shifted_state(x, dz, psi_ref):
    """A state whose error coordinates (lqr_design.error_coordinates) against the heading ψ_ref are
    those of x plus dz (NZ,) in the yoke's attitude, the pendulum and the rates (the position, the
    cross-track error and the integrals are left): the shell's phase about the hinge is kept."""
    x = np.array(x, dtype=float)
    R_S, R_Y, R_P = (R.copy() for R in rotations(x))
    Q_ref = design.reference_attitude(psi_ref)
    E = so3.log(Q_ref.T @ R_S @ R_Y)
    x[IDX_RS] = (Q_ref @ so3.exp(E + dz[design.Z_E]) @ R_Y.T).ravel()
    x[IDX_RP] = (R_P @ so3.rot_y(dz[design.Z_TH_P])).ravel()
    x[IDX_WS] += R_Y @ dz[design.Z_OM]
    x[IDX_WY] += dz[design.Z_WY]
    x[IDX_WP] += dz[design.Z_WP]
    return x


class NmpcC(Nmpc):
    """`Nmpc`'s formulation with every sample in C (`sr_nmpc_step`, c/src/sr_nmpc.c, sr_nmpc.h): the
    same horizon, nodes, weights, integral, cost-to-go (computed here as `Nmpc`'s) and torque limits;
    a node's prediction is one RKMK4 step of the full model (`sr_step`) with its exact Jacobian
    (`sr_step_jacobian`) instead of CasADi's RK4 of the reduced field, the QP the library's box
    QP solver (`sr_boxqp_solve`) instead of DAQP.  No CasADi at run time."""
    kind = "nmpc-c"

    def __init__(self, params, rate=20.0, u_max=DEFAULT_U_MAX, gains=NmpcGains()):
        from bindings._sr import lib
        if gains.horizon > lib.SR_NMPC_MAX_HORIZON:     # before the design's seconds are spent
            raise ValueError(f"controller.horizon: the C NMPC holds at most {lib.SR_NMPC_MAX_HORIZON} nodes, "
                             f"got {gains.horizon:g}")
        super().__init__(params, rate, u_max, gains)

    def _build_solver(self):
        """The design as the C struct `sr_nmpc` (checked by `sr_nmpc_check`) and the C memory."""
        from bindings._sr import ffi, lib
        from ..model import Model
        s = self.schedule
        nv, nk = len(s.speeds), len(s.curvatures)
        if nv > lib.SR_LQR_MAX_SPEEDS or nk > lib.SR_LQR_MAX_CURVATURES:
            raise ValueError(f"controller: the design grid has {nv} speeds and {nk} curvatures; the C NMPC "
                             f"holds at most {lib.SR_LQR_MAX_SPEEDS} and {lib.SR_LQR_MAX_CURVATURES}")
        c = ffi.new("sr_nmpc *")
        c.horizon, c.node_periods = self.n, self.node_periods
        c.cold_iterations, c.iterations = COLD_START_ITERATIONS, int(self.gains.iterations)
        c.qp_max_iterations = QP_MAX_ITERATIONS_PER_UNKNOWN * 2 * self.n
        c.period, c.u_max, c.r, c.r_step = self.period, self.u_max, self._r, self._r_step
        c.steady_rate, c.heading_jump = self.gains.steady_rate_m_s, HEADING_JUMP_RAD
        c.disturbance_gain = self.gains.disturbance_gain
        c.q_path[0:NZ_N] = self._q_path.tolist()
        c.q_heading[0:NZ_N] = self._q_heading.tolist()
        c.n_speeds, c.n_curvatures = nv, nk
        c.speeds[0:nv] = s.speeds.tolist()
        c.curvatures[0:nk] = s.curvatures.tolist()
        for i, j in np.ndindex(nv, nk):
            k = i * nk + j
            c.z_star[k][0:NZ_N] = s.z_star[i, j][:NZ_N].tolist()
            c.u_star[k][0:2] = s.u_star[i, j].tolist()
            c.P_path[k][0:NZ_N * NZ_N] = self._P_path[i, j].ravel().tolist()
            c.P_heading[k][0:NZ_N * NZ_N] = self._P_heading[i, j].ravel().tolist()
        status = lib.sr_nmpc_check(c)
        if status != lib.SR_OK:
            raise ValueError(f"controller: the NMPC design is not valid for the C NMPC "
                             f"({ffi.string(lib.sr_status_string(status)).decode()})")
        self._ffi, self._lib, self._c = ffi, lib, c
        self._model = Model(self.params.replace(slope=0.0))
        self._memory = ffi.new("sr_nmpc_memory *")
        self._target = ffi.new("sr_nmpc_target *")
        self._curvatures = ffi.new("double[]", self.n + 1)
        self._u = np.zeros(2)

    def reset(self, x0):
        """Starts a run at x0: forgets the warm start, the heading, the integral and the torque offset
        (sr_nmpc_reset)."""
        super().reset(x0)
        self._lib.sr_nmpc_reset(self._memory)

    @property
    def memory(self):
        """The C controller's memory (`sr_nmpc_memory`, cffi): the last solution and the last QP."""
        return self._memory

    def hand_memory_to(self, other):
        """Sets `other`, a Python `Nmpc` of the same design, to this controller's memory: the guess,
        the last torques, the reference heading, the integral, the offsets, the last sample and the
        sample count, so that `other.compute` solves the next sample from where this one does (the
        two formulations compared sample by sample: runtime/control/nmpc_c.py, `lockstep_gaps`).
        Flat models without the slope estimate only (the memory holds the offsets less the slope's share)."""
        if self._slope_schedule is not None or other._slope_schedule is not None:
            raise ValueError("hand_memory_to: the memory holds the torque offset less the slope's feedforward; "
                             "only flat models without the slope estimate are handed over")
        m, n = self._memory, self.n
        if other.n != n or other.node_periods != self.node_periods:
            raise ValueError(f"hand_memory_to: the other NMPC has {other.n} nodes of {other.node_periods} periods, "
                             f"this one {n} of {self.node_periods}")
        real = lambda field, size: np.array(list(getattr(m, field))[:size])     # noqa: E731
        other.samples = m.samples
        other._guess = ((real("Z", (n + 1) * NZ_N).reshape(n + 1, NZ_N), real("U", 2 * n).reshape(n, 2))
                        if m.have_guess else None)
        other._u_last = real("u_last", 2) if m.have_u_last else None
        other._heading, other.integral = m.heading, m.integral
        other.disturbance, other.shell_accel = real("disturbance", 2), real("shell_accel", 3)
        other._last = (real("z_last", NZ_N), real("u_last", 2), m.v_last, m.kappa_last) if m.have_last else None

    def compute(self, t, x, target):
        """The torques of one sample of `sr_nmpc_step` for state x and the target."""
        from bindings.buffers import pointer
        from ..errors import KernelError
        ffi, lib, c = self._ffi, self._lib, self._target
        c.speed, c.heading = target.speed, target.heading
        c.path = target.cross_track is not None
        c.curvature_ahead = ffi.NULL
        kappa = 0.0
        if c.path:
            c.curvature, c.cross_track = target.curvature, target.cross_track
            kappa = float(target.curvature)
            ahead = target.curvature_ahead
            if ahead is not None and len(ahead) == self.n + 1:
                self._curvatures[0:self.n + 1] = np.asarray(ahead, dtype=float).tolist()
                c.curvature_ahead = self._curvatures
                kappa = float(ahead[0])
        # The slope's feedforward: the shifted state, and Δu* (less the estimate's torque offset) as
        # a part of the torque offset the C prediction adds (see the module): d̂ − Δu* in, d̂ back.
        x, feedforward = self._on_slope(x, target, kappa)
        x = np.ascontiguousarray(x, dtype=np.float64)
        self._memory.disturbance[0:2] = (self.disturbance - feedforward).tolist()
        status = lib.sr_nmpc_step(self._c, self._memory, self._model._model, pointer(x),
                                  c, pointer(self._u))
        if status == lib.SR_ERR_MODEL:
            raise KernelError("model", status, f" (controller {self.kind} at t = {t:g} s)")
        if status != lib.SR_OK:
            raise ValueError(f"controller {self.kind}: {ffi.string(lib.sr_status_string(status)).decode()} "
                             f"at t = {t:g} s")
        self.integral, self.restarts = self._memory.integral, self._memory.restarts
        self.disturbance = np.array(list(self._memory.disturbance)) + feedforward
        self.shell_accel = np.array(list(self._memory.shell_accel))
        return self._u.copy()
