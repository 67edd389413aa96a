"""LQR design on the reduced error coordinates of a rolling robot: the firmware's controller.

Why reduced coordinates.  Steady straight rolling is periodic in the full state (the shell turns,
and γ and R_Y with it), so `linearize` at one instant of it does not give a time-invariant
design model (docs/control.md, "Linearisations").  But the shell is a uniform sphere about its
centre: turning it about the yoke's hinge while the yoke joint turns back leaves every energy and
the rolling contact unchanged.  What the dynamics see is the yoke's attitude in the world,
Q = R_S R_Y, the pendulum's angle, and the rates in the yoke's frame, Ω = R_Yᵀ ω_S, ω_Y, ω_P.
In those, steady rolling along a path of constant curvature is an equilibrium (a *relative*
equilibrium of the full model), and an LQR designed on its linearisation is time-invariant.

The error coordinates z (NZ = 12), relative to a reference that rolls at v_ref along the heading
ψ_ref (a path's tangent at the nearest point, or the heading to hold):

    z[0:3]   E = Log(Q_ref(ψ_ref)ᵀ Q), Q_ref(ψ) = rot_z(ψ) rot_z(−π/2): the yoke's attitude error
             (yoke frame; heading, lean and the yoke's tilt about its hinge)
    z[3]     θ_P, the pendulum's angle
    z[4:7]   Ω − Ω_ref, Ω_ref = (−v_ref/r, 0, 0): the shell's rate in the yoke frame
    z[7]     ω_Y − v_ref/r
    z[8]     ω_P
    z[9]     e_y, the signed cross-track error (left positive; path tasks, else 0)
    z[10]    ∫ e_y dt            (path tasks)
    z[11]    ∫ (z[4] − z*[4]) dt (the shell's rolling rate: speed without steady error)

The operating point (z*, u*) at (v, κ) is steady rolling at speed v on a path of curvature κ:
the reduced field vanishes, with e_y = 0 and the contact point moving at v along the path
(`operating_point`, Newton on the field).  A = ∂F/∂z and B = ∂F/∂u there (`linearization`,
central differences of the field on the C kernel `accel`), discretised with a zero-order hold at
the controller's rate, and K from the discrete Riccati equation (`gains`).  The firmware law
(c/sr_control.c, `sr_lqr_control`) is u = u* − K (z − z*), with (z*, u*, K) interpolated
bilinearly in (v_ref, κ) over a grid of operating points.

The reduced field's eigenvalues at straight rolling equal the Floquet exponents of the full
model's periodic motion (runtime/stability.py): an independent check of this chart
(tests/runtime/control/test_lqr_design.py, and a row of make verify).
"""
import dataclasses
import math

import numpy as np

from .. import so3
from ..model import Model
from ..state import IDX_RP, IDX_RS, IDX_WP, IDX_WS, IDX_WY, initial_state, rotations

NZ = 12
Z_E, Z_TH_P, Z_OM, Z_WY, Z_WP, Z_EY, Z_IY, Z_IV = slice(0, 3), 3, slice(4, 7), 7, 8, 9, 10, 11
Z_OM_X = Z_OM.start               # the shell's rolling rate: the speed
#: The robot's own coordinates, z[:NZ_ROBOT] (attitude, pendulum, rates); then the path's and the integrators.
NZ_ROBOT = Z_EY
#: The unknowns of an operating point: z[:NZ_ROBOT], then the two torques.
W_Z, W_U = slice(0, NZ_ROBOT), slice(NZ_ROBOT, NZ_ROBOT + 2)
#: Below this (relative to the largest gain, for K), an operating point's or a gain's entry is rounding noise.
SYMMETRY_ZERO = 1e-13
#: Yoke attitude that rolls along +x (heading 0): R_S = rot_z(−π/2), θ_Y = 0 (docs/control.md).
Q_HEADING_0 = so3.rot_z(-math.pi / 2)


def reference_attitude(psi):
    """Q_ref(ψ) = rot_z(ψ) rot_z(−π/2): the yoke upright, rolling along the heading ψ."""
    return so3.rot_z(psi) @ Q_HEADING_0


def _pendulum_angle(x):
    R_P = np.asarray(x)[IDX_RP].reshape(3, 3)
    return math.atan2(R_P[0, 2], R_P[0, 0])      # R_P = rot_y(θ_P)


def error_coordinates(x, r, v_ref, psi_ref, cross_track=0.0, integrals=(0.0, 0.0)):
    """z (NZ,) of the state x against the reference (see the module's docstring)."""
    R_S, R_Y, _ = rotations(np.asarray(x))
    Q = R_S @ R_Y
    z = np.empty(NZ)
    z[Z_E] = so3.log(reference_attitude(psi_ref).T @ Q)
    z[Z_TH_P] = _pendulum_angle(x)
    z[Z_OM] = R_Y.T @ x[IDX_WS]
    z[Z_OM_X] += v_ref / r
    z[Z_WY] = x[IDX_WY] - v_ref / r
    z[Z_WP] = x[IDX_WP]
    z[Z_EY] = cross_track
    z[Z_IY], z[Z_IV] = integrals
    return z


def lift(z, v, r):
    """A full state whose error coordinates against (v, ψ_ref = 0, the path along the x axis) are z.

    The shell's phase about the hinge is free (the symmetry); this chooses θ_Y = 0, R_S = Q."""
    Q = reference_attitude(0.0) @ so3.exp(z[Z_E])
    w_S = z[Z_OM] + np.array([-v / r, 0.0, 0.0])
    return initial_state(theta_Y=0.0, theta_P=z[Z_TH_P], R_S=Q, q=(0.0, z[Z_EY], r), w_S=w_S,
                         w_Y=z[Z_WY] + v / r, w_P=z[Z_WP], r=r)


def _inverse_right_jacobian(e):
    """J_r⁻¹(e): d/dt Log(M) = J_r⁻¹(Log M) ω for Ṁ = M ⟦ω⟧."""
    t2 = float(e @ e)
    E = so3.hat(e)
    if t2 < 1e-10:
        c = 1.0 / 12.0 + t2 / 720.0
    else:
        t = math.sqrt(t2)
        c = 1.0 / t2 - (1.0 + math.cos(t)) / (2.0 * t * math.sin(t))
    return np.eye(3) + 0.5 * E + c * (E @ E)


def field(model, z, u, v, kappa, z_star_om_x=0.0):
    """ż (NZ,): the reduced dynamics along a reference of speed v and curvature κ (left positive).

    The reference's heading turns at ψ̇_ref = κ ṡ, ṡ = (q̇·t)/(1 − κ e_y) the foot point's speed."""
    r = model.params.r
    x = lift(z, v, r)
    a = model.accel(x, u)
    R_S = x[IDX_RS].reshape(3, 3)
    w_S, w_Y, w_P = x[IDX_WS], x[IDX_WY], x[IDX_WP]
    q_dot = r * np.cross(R_S @ w_S, [0.0, 0.0, 1.0])
    s_dot = q_dot[0] / (1.0 - kappa * z[Z_EY])
    w_Q = w_S + np.array([w_Y, 0.0, 0.0])            # R_Y = I in the lift: Q's body rate
    out = np.empty(NZ)
    out[Z_E] = _inverse_right_jacobian(z[Z_E]) @ (w_Q - kappa * s_dot * (R_S.T @ [0.0, 0.0, 1.0]))
    out[Z_TH_P] = w_P
    out[Z_OM] = a[0:3] - np.cross([w_Y, 0.0, 0.0], w_S)
    out[Z_WY], out[Z_WP] = a[3], a[4]
    out[Z_EY] = q_dot[1]
    out[Z_IY] = z[Z_EY]
    out[Z_IV] = z[Z_OM_X] - z_star_om_x
    return out


def operating_point(model, v, kappa=0.0, start=None, tol=1e-12, iterations=40):
    """(z*, u*) of steady rolling at v [m/s] on a path of curvature κ [1/m]: the field's body part
    and ė_y vanish and the contact point moves at v along the path (Newton, central differences).

    `start`: a nearby operating point (z*, u*) to start from; else level rolling with the holding
    torque of power balance, continued in κ in steps of κ r ≤ 0.01 (a turn's lean and torques are
    far from the straight ones)."""
    r, p = model.params.r, model.params

    def residual(w, kappa):
        z = np.zeros(NZ)
        z[:NZ_ROBOT] = w[W_Z]
        f = field(model, z, w[W_U], v, kappa)
        x = lift(z, v, r)
        q_dot_x = r * np.cross(x[IDX_RS].reshape(3, 3) @ x[IDX_WS], [0.0, 0.0, 1.0])[0]
        return np.concatenate([f[:NZ_ROBOT], [f[Z_EY], q_dot_x - v]])

    if start is not None:
        w = np.concatenate([start[0][:NZ_ROBOT], start[1]])
        kappas = [kappa]
    else:
        w = np.zeros(NZ_ROBOT + 2)
        w[W_U.start] = v * (p.k_S + p.k_Y) / r
        steps = max(1, int(math.ceil(abs(kappa) * r / 0.01)))
        kappas = np.linspace(0.0, kappa, steps + 1)
    for kappa_k in kappas:
        w = _newton(lambda w: residual(w, kappa_k), w, tol, iterations, v, kappa_k)
    # Entries that vanish by symmetry (straight rolling has no lean, no sideways rate, no
    # pendulum torque) come out of Newton as rounding noise, down to 1e-55: below the 1e-12 the
    # solve converges to, they are zeros (and a float firmware cannot even hold them).
    w = np.where(np.abs(w) < SYMMETRY_ZERO, 0.0, w)
    z = np.zeros(NZ)
    z[:NZ_ROBOT] = w[W_Z]
    return z, w[W_U].copy()


def _newton(residual, w, tol, iterations, v, kappa):
    for _ in range(iterations):
        res = residual(w)
        if np.abs(res).max() < tol:
            return w
        J = np.empty((w.size, w.size))
        for j in range(w.size):
            h = 1e-6 * max(1.0, abs(w[j]))
            wp, wm = w.copy(), w.copy()
            wp[j] += h
            wm[j] -= h
            J[:, j] = (residual(wp) - residual(wm)) / (2 * h)
        w = w - np.linalg.solve(J, res)
    raise ValueError(f"operating_point: no steady rolling found at v = {v} m/s, kappa = {kappa} 1/m "
                     f"(residual {np.abs(res).max():.3g})")


def linearization(model, z_star, u_star, v, kappa=0.0, h=1e-6):
    """(A, B), NZ×NZ and NZ×2: central differences of `field` at the operating point."""
    f = lambda z, u: field(model, z, u, v, kappa, z_star[Z_OM_X])   # noqa: E731
    A, B = np.empty((NZ, NZ)), np.empty((NZ, 2))
    for j in range(NZ):
        dz = np.zeros(NZ)
        dz[j] = h
        A[:, j] = (f(z_star + dz, u_star) - f(z_star - dz, u_star)) / (2 * h)
    for j in range(2):
        du = np.zeros(2)
        du[j] = h
        B[:, j] = (f(z_star, u_star + du) - f(z_star, u_star - du)) / (2 * h)
    return A, B


@dataclasses.dataclass(frozen=True)
class Weights:
    """Bryson's rule: the largest error accepted in each coordinate, and the torque limit."""
    attitude_rad: tuple = (0.1, 0.1, 0.1)
    pendulum_rad: float = 0.3
    rate_rad_s: tuple = (0.3, 1.0, 1.0)
    yoke_rate_rad_s: float = 2.0
    pendulum_rate_rad_s: float = 2.0
    cross_track_m: float = 0.02
    cross_track_integral_m_s: float = 0.2
    speed_integral_rad: float = 0.5
    torque_n_m: float = 0.5

    def q_diagonal(self):
        """The state weights of the Riccati equation: one over the square of each bound."""
        return 1.0 / np.square(np.array([*self.attitude_rad, self.pendulum_rad, *self.rate_rad_s,
                                          self.yoke_rate_rad_s, self.pendulum_rate_rad_s,
                                          self.cross_track_m, self.cross_track_integral_m_s,
                                          self.speed_integral_rad]))


def discretize(A, B, period):
    """Zero-order hold: (A_d, B_d) = blocks of expm([[A, B], [0, 0]] T)."""
    from scipy.linalg import expm
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = expm(M * period)
    return E[:n, :n], E[:n, n:]


def gains(A, B, period, weights=Weights(), path=True):
    """K (2×NZ) of the discrete LQR; without a path, e_y and ∫e_y are left out (their columns 0)."""
    from scipy.linalg import solve_discrete_are
    keep = np.arange(NZ) if path else np.array([i for i in range(NZ) if i not in (Z_EY, Z_IY)])
    Ad, Bd = discretize(A[np.ix_(keep, keep)], B[keep], period)
    Qw = np.diag(weights.q_diagonal()[keep])
    Rw = np.eye(2) / weights.torque_n_m ** 2
    P = solve_discrete_are(Ad, Bd, Qw, Rw)
    K_keep = np.linalg.solve(Rw + Bd.T @ P @ Bd, Bd.T @ P @ Ad)
    K = np.zeros((2, NZ))
    K[:, keep] = np.where(np.abs(K_keep) < SYMMETRY_ZERO * np.abs(K_keep).max(), 0.0, K_keep)
    return K


@dataclasses.dataclass(frozen=True)
class Schedule:
    """Operating points on a grid: z_star (nv, nk, NZ), u_star (nv, nk, 2), K_path / K_heading (nv, nk, 2, NZ),
    and K_tight (nv, nk, 2, NZ) or None: the tighter path gains scheduled in near the path; K_heading_tight
    likewise: the stiffer heading gains scheduled in near a heading reference's heading."""
    speeds: np.ndarray
    curvatures: np.ndarray
    z_star: np.ndarray
    u_star: np.ndarray
    K_path: np.ndarray
    K_heading: np.ndarray
    K_tight: np.ndarray = None
    K_heading_tight: np.ndarray = None

    def at(self, v, kappa):
        """(z*, u*, K_path, K_heading) bilinearly interpolated, clamped to the grid."""
        def bracket(grid, value):
            if len(grid) == 1:
                return 0, 0, 0.0
            i = int(np.clip(np.searchsorted(grid, value) - 1, 0, len(grid) - 2))
            w = float(np.clip((value - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0))
            return i, i + 1, w
        i0, i1, wv = bracket(self.speeds, v)
        j0, j1, wk = bracket(self.curvatures, kappa)

        def mix(a):
            return ((1 - wv) * ((1 - wk) * a[i0, j0] + wk * a[i0, j1])
                    + wv * ((1 - wk) * a[i1, j0] + wk * a[i1, j1]))
        return mix(self.z_star), mix(self.u_star), mix(self.K_path), mix(self.K_heading)

    def tight_at(self, v, kappa):
        """K_tight bilinearly interpolated as `at` interpolates the others (None without tight gains)."""
        if self.K_tight is None:
            return None
        return dataclasses.replace(self, K_path=self.K_tight).at(v, kappa)[2]

    def heading_tight_at(self, v, kappa):
        """K_heading_tight interpolated as `at` interpolates the others (None without them)."""
        if self.K_heading_tight is None:
            return None
        return dataclasses.replace(self, K_path=self.K_heading_tight).at(v, kappa)[2]
