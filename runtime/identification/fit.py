"""Identification of a robot's parameters from a log: a multiple-shooting least-squares fit
(docs/identification.md, "Identifying a robot from a log").

    log = read_log("out/geared-log")
    fit = identify(log, Params.paper_simulation(), ["k_S", "k_Y", "k_P", "m_P"])
    fit.estimate, fit.sigma, fit.information, fit.residual_check

A sensor log is cut into segments of `segment` seconds on the IMU's sample grid.  The unknowns are
the named parameters θ, the IMU's biases b and the state at the start of every segment (12 error
coordinates about a start guess from the EKF); each segment is simulated from its start state
under the logged torques, its predicted IMU, encoder and fix readings are compared with the log,
and its end state with the next segment's start.  The differences are whitened by their
covariance: the sensors' declared noise plus what the process noise (the sensor set's torque
disturbance) does to the readings and to the end state inside the segment, linearised along the
segment.  Levenberg–Marquardt steps on the normal equations of the sparse Jacobian
(`levenberg_marquardt`) minimise the whitened sum of squares with the analytic Jacobian: the step
and parameter Jacobians of the C library chained along each segment, and the sensors' Jacobians.
A full-state log (its truth table) is fitted by the one-step prediction error of the velocities
instead, whitened by the process noise, with SciPy's `least_squares`.

The Fisher information JᵀJ of the whitened residuals at the optimum, with the start states and the
biases eliminated (Schur complement), gives the parameters' covariance and 95 % intervals; its
eigenvalues the rank and conditioning; the base parameters (runtime.param_derivatives) name the
combinations a rank-deficient fit still determines.
"""
import dataclasses
import functools
import math

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse
import scipy.stats
from bindings._sr import lib as _lib
from bindings.buffers import pointer

from ..blas import one_thread
from ..errors import KernelError
from ..model import Model
from ..param_derivatives import PARAMETER_NAMES, base_parameters, inertial_parameters
from ..params import SHAPES, Params, flat_names
from ..state import IDX_E_NU, IDX_E_XI_S, IDX_NU, IDX_RS, NE, NV
from .first_guess import _dpi_of, regressor_guess
from .segments import Rows, buffer, dlocal_batch, dretract_batch, segment_blocks
from .sensitivity import JACOBIANS, step_and_sensitivity

#: Where the fit starts the parameters: the regressor's linear least-squares first guess, or the nominal robot.
STARTS = ("regressor", "nominal")
#: Parameters a builder knows and the fit never frees: the shell's radius, the gear ratios, gravity, the slope.
KNOWN = ("r", "n_Y", "n_P", "g", "slope")
#: The shortest log [s] a fit accepts: two segments of the shortest length.
MIN_DURATION = 0.5
#: A whitened residual RMS within this of 1 passes the residual check.
RESIDUAL_TOLERANCE = 0.15
#: Eigenvalues of the scaled information below this fraction of the largest count as zero (not identified).
RANK_RTOL = 1e-9
#: Two-sided 95 % quantile of the normal distribution.
Z95 = float(scipy.stats.norm.ppf(0.975))
#: Standard deviation [rad, m, rad/s] of the weak prior on the first segment's start state: it fixes
#: what no sensor sees (the position without fixes, the heading without fixes or a magnetometer).
GAUGE_SIGMA = 10.0
#: Smallest standard deviation of an end-state difference, for a sensor set without process noise.
DEFECT_FLOOR = 1e-7
#: Evaluations of the sensor fit's first stage, which fits the start states and biases with the
#: parameters held (the segments, each fitted alone, disagree at their ends by the start guess's
#: errors, which are linear in the start states).
STATES_NFEV = 8
#: A sensor fit has converged when an undamped Gauss–Newton step would move no free parameter by
#: more than this fraction of its σ.  The first joint stage stops at RELINEARISE_SHIFT instead: the
#: covariance is linearised again where it stops, which moves the optimum by more than that.
CONVERGED_SHIFT = 0.05
RELINEARISE_SHIFT = 0.5


class IdentifyError(ValueError):
    """A log or a parameter set that cannot be identified: the message names what is wrong."""


def free_parameters(names):
    """The entries of the C parameter vector (`PARAMETER_NAMES`) that `names` frees: a field name
    (m_P, c_P, J_P) frees all its entries, an entry name (c_P_z, J_P_yy) one.  IdentifyError for an
    empty list, an unknown name, a repeated entry or a parameter the builder knows (KNOWN)."""
    if isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    if not names:
        raise IdentifyError("params: name at least one parameter to identify")
    out = []
    for name in names:
        base = name if name in SHAPES else next((f for f in SHAPES if name in flat_names(f, SHAPES[f])), None)
        if base is None:
            raise IdentifyError(f"params: {name!r} is not a parameter of the robot (fields: {', '.join(SHAPES)}; "
                                f"entries such as c_P_z, J_P_yy)")
        if base in KNOWN:
            raise IdentifyError(f"params: {name!r} is a constant of the robot's kind that the fit takes as known "
                                f"({', '.join(KNOWN)}), not one it identifies")
        entries = flat_names(base, SHAPES[base]) if name == base else (name,)
        for entry in entries:
            if entry in out:
                raise IdentifyError(f"params: {entry!r} named twice")
            out.append(entry)
    return tuple(out)


def bounds_of(entry, params, free=()):
    """(low, high) of one free entry: masses > 0, inertias and dampings >= 0, each coordinate of a
    centre of mass within the shell's radius; a tensor's diagonal entry within the triangle rule of
    a physical tensor (|J_a − J_b| <= J_c <= J_a + J_b) when the other two diagonal entries are held
    (`free`: all free entries), else >= 0.  The full rules (|c| < r, the tensor positive
    semidefinite) are C's checks of every candidate."""
    if entry in ("m_S", "m_Y", "m_P"):
        return 1e-9, math.inf
    if entry in ("j_S", "k_S", "k_Y", "k_P", "j_mY", "j_mP"):
        return 0.0, math.inf
    if entry.startswith("c_"):
        return -params.r, params.r
    if entry[-2] == entry[-1]:              # J_*_xx, J_*_yy, J_*_zz
        body, axis = entry[2], "xyz".index(entry[-1])
        others = [i for i in range(3) if i != axis]
        if any(f"J_{body}_{'xyz'[i] * 2}" in free for i in others):
            return 0.0, math.inf
        J = np.asarray(getattr(params, f"J_{body}"))
        a, b = J[others[0], others[0]], J[others[1], others[1]]
        return abs(a - b), a + b
    return -math.inf, math.inf


@dataclasses.dataclass
class _Data:
    """The log on the fit's node grid."""
    t: np.ndarray            # (n,) node times
    h: float                 # node spacing
    u: np.ndarray            # (n, 2) torques held from each node
    imu_row: np.ndarray      # (n,) IMU sample index or -1
    enc_row: np.ndarray
    fix_row: np.ndarray
    interval: np.ndarray     # (n,) index of the process-noise interval (torque period) of each node
    into: np.ndarray         # (n,) time since the start of the node's torque period
    tau: float               # the torque period
    skipped: int             # samples off the node grid


def _grid(log):
    """Node times on the IMU's grid and the samples of each kind at them."""
    imu = log.imu
    h = 1.0 / log.sensors.imu.rate
    t0 = float(imu.t[0])
    n = int(round((imu.t[-1] - t0) / h)) + 1
    t = t0 + h * np.arange(n)
    skipped = 0

    def rows(times):
        nonlocal skipped
        out = np.full(n, -1)
        k = np.round((np.asarray(times) - t0) / h).astype(int)
        ok = (k >= 0) & (k < n) & (np.abs(times - (t0 + k * h)) <= 1e-6 * h)
        skipped += int((~ok).sum())
        out[k[ok]] = np.flatnonzero(ok)
        return out

    fix_times = log.fixes["t_measured"] if log.fixes is not None and len(log.fixes) else np.empty(0)
    dts = np.diff(log.torques.t)
    tau = float(np.median(dts)) if len(dts) else h
    interval = np.floor((t - float(log.torques.t[0])) / tau + 1e-6).astype(int)
    into = np.clip(t - float(log.torques.t[0]) - interval * tau, 0.0, tau)
    into[into <= 1e-6 * tau] = 0.0
    return _Data(t=t, h=h, u=log.torque_at(t), imu_row=rows(imu.t), enc_row=rows(log.encoders.t),
                 fix_row=rows(fix_times), interval=interval, into=into, tau=tau, skipped=skipped)


def check_log(log, full_state=False):
    """IdentifyError for a log no fit can use: shorter than MIN_DURATION, torques all zero, or (full
    state) without a truth table."""
    duration = float(log.imu.t[-1] - log.imu.t[0])
    if duration < MIN_DURATION:
        raise IdentifyError(f"log: {duration:g} s of IMU samples; an identification needs at least {MIN_DURATION:g} s")
    if not np.any(log.torques.data != 0):
        raise IdentifyError("log: torques: every torque is zero; a robot that is not driven shows nothing of "
                            "its inertias")
    if full_state and (log.truth is None or len(log.truth) < 3):
        raise IdentifyError("log: a full-state fit needs the log's truth table (truth.csv / truth.parquet)")


@dataclasses.dataclass(frozen=True, eq=False)
class Fit:
    """The result of `identify`: the free entries `names`, their `nominal` and `estimate`, the
    standard deviations `sigma` (NaN where not identified) and 95 % intervals `low`, `high`; the
    marginal Fisher information `information` of the named parameters (n, n), `correlation`;
    `rank`, `condition` (of the information scaled by the nominal values), `identified` (n,) bool,
    `on_bound` {name: "lower"/"upper"}; `combinations`: [{"name", "value", "sigma", "identified"}]
    for the base parameters the free entries enter; `null_directions`: [{name: weight}] the
    combinations the log cannot separate; `biases` (6,) and their sigma; `residual_check`: {"rms",
    "chi2", "dof", "p_value", "passed"}; `residuals` {kind: (t, whitened residuals)} for plots;
    `params` the estimated robot; `nfev`, `status`, `message` of the solver; `start` the free
    entries where the fit started them (`STARTS`); `converged`: the solver stopped at the optimum
    (a sensor fit: its Gauss–Newton step `shift` of the parameters, in σ, below CONVERGED_SHIFT),
    not at its budget;
    an unconverged fit's estimates and intervals are not the optimum's, and its message says so."""
    names: tuple
    nominal: np.ndarray
    estimate: np.ndarray
    sigma: np.ndarray
    low: np.ndarray
    high: np.ndarray
    information: np.ndarray
    correlation: np.ndarray
    rank: int
    condition: float
    identified: np.ndarray
    on_bound: dict
    combinations: list
    null_directions: list
    biases: np.ndarray
    bias_sigma: np.ndarray
    residual_check: dict
    residuals: dict
    params: Params
    nfev: int
    status: int
    message: str
    mode: str
    start: np.ndarray = None
    converged: bool = True
    shift: float = math.nan


def _inverse_cholesky(S):
    """L⁻¹ (lower triangular) of S = L Lᵀ."""
    Linv, info = scipy.linalg.lapack.dtrtri(np.linalg.cholesky(S), lower=1)
    if info:
        raise np.linalg.LinAlgError(f"dtrtri: {info}")
    return Linv


@functools.cache
def _geqrf_work(shape):
    """LAPACK's workspace size for dgeqrf on a matrix of `shape` (its query; what SciPy's `qr` asks
    for every call)."""
    return int(scipy.linalg.lapack.dgeqrf(np.zeros(shape), lwork=-1)[-2][0])


def _upper_triangle(M, n):
    """The first n rows of R (n, M's columns; zero rows below M's) of M = Q R: the R of
    `scipy.linalg.qr(M, mode="r")`, the same LAPACK call (dgeqrf) without SciPy's checks and
    workspace query per call."""
    qr, _, _, info = scipy.linalg.lapack.dgeqrf(M, lwork=_geqrf_work(M.shape), overwrite_a=True)
    if info < 0:
        raise ValueError(f"dgeqrf: illegal value in argument {-info}")
    R = np.zeros((n, M.shape[1]))
    k = min(n, M.shape[0])
    R[:k] = np.triu(qr[:k])
    return R


class _Problem:
    """The multiple-shooting problem of a sensor log."""

    def __init__(self, log, params, free, segment, method, x_guess, bias_guess, jacobian="analytic", x_sigma=None):
        self.log, self.params, self.free, self.method, self.jacobian = log, params, free, method, jacobian
        self.idx = [PARAMETER_NAMES.index(n) for n in free]
        self.nf = len(free)
        self.theta_start = params.as_array()[self.idx]
        self.data = d = _grid(log)
        n = len(d.t)
        per = max(2, int(round(segment / d.h)))
        starts = list(range(0, n - 1, per))
        if len(starts) > 1 and n - 1 - starts[-1] < per // 2:     # a short tail joins the segment before
            starts.pop()
        self.starts = np.array(starts)
        self.ends = np.append(self.starts[1:], n - 1)
        self.S = len(self.starts)
        self.xref = np.array(x_guess[self.starts])
        # the start guess's standard deviations (its 12 error coordinates) at the segments' starts
        self.xsig = None if x_sigma is None else np.asarray(x_sigma, dtype=float)[self.starts, :NE]
        self.b0 = np.asarray(bias_guess, dtype=float)
        self.mount = log.sensors.imu.mount
        sensors = log.sensors
        self.sig_imu = np.repeat([sensors.imu.gyro_noise, sensors.imu.accel_noise], 3)
        self.sig_enc = sensors.encoders.step / math.sqrt(12)
        self.sig_fix = sensors.fixes.noise if sensors.fixes is not None else 1.0
        self.fix_xy = log.fixes.select("x", "y") if log.fixes is not None else np.empty((0, 2))
        self.q2 = sensors.process.generalized() ** 2
        self.ncols = self.nf + 6 + NE * self.S
        self.chol = None
        self._stacked = (None, None)       # (the whitenings, `stack_whitenings` of them)
        self._csr = (None, None)           # (the segments' widths, the Jacobian's CSR structure)
        self.buffers = {}                   # an evaluation's large arrays, reused (segments.buffer)
        self._cache = (None, None)
        self.layouts = {}                   # where each set of segments' readings sit (segments._layout)
        self.nfev = 0
        self.progress = None
        self.hold_parameters = False        # the parameters' columns zero: only the states and biases move

    # -- the unknowns ---------------------------------------------------------------------------
    def split(self, z):
        return z[:self.nf], z[self.nf:self.nf + 6], z[self.nf + 6:].reshape(self.S, NE)

    def model(self, theta):
        p = self.params.as_array()
        p[self.idx] = theta
        try:
            return Model(Params.from_array(p))
        except ValueError as exc:
            raise IdentifyError(f"the fit reached a robot the model refuses ({exc}); the named parameters may not be "
                                f"identifiable from this log, or the nominal robot is too far from the truth") from None

    def _dretract(self, model, x, d):
        """(x ⊕ d, ∂ local(x ⊕ d, x ⊕ (d + δ)) / ∂δ (12, 12)) by central differences of the group maps
        (exact maps, no dynamics); the start-state unknowns are offsets about a fixed guess."""
        x0, D = dretract_batch(model, x, d)
        return x0[0], D[0]

    def _dlocal(self, model, a, b):
        """(∂ local(a ⊕ δ, b)/∂δ, ∂ local(a, b ⊕ δ)/∂δ) at δ = 0, central differences."""
        A, B = dlocal_batch(model, a, b)
        return A[0], B[0]

    # -- one evaluation -------------------------------------------------------------------------
    def segment_blocks(self, z):
        """Per segment: raw residuals r (noise-scaled readings, then the end-state difference), their
        Jacobian blocks (theta, bias, own start, next start), and what the whitening needs; all
        segments evaluated together (runtime.identification.segments).  The blocks' chains and
        rows are views of arrays the problem reuses (`buffers`): valid until its next evaluation."""
        theta, b, Dz = self.split(z)
        model = self.model(theta)
        x0, D = dretract_batch(model, self.xref, Dz)
        has = np.arange(self.S) < self.S - 1
        nxt = (np.roll(x0, -1, axis=0), np.roll(D, -1, axis=0), has)
        return segment_blocks(self, model, np.arange(self.S), x0, D, b, nxt,
                              sensitivities=not self.hold_parameters, buffers=self.buffers)

    def segment_block(self, model, s, start, nxt, b, sensitivities=True):
        """One segment's block: simulated from start = (x0, D) under the logged torques; the
        end-state difference to nxt = (x0 of the next segment, its D) unless nxt is None.  The
        readings are ordered by time, at one time IMU, encoders, fix; `rows` keeps, per reading row,
        its node, kind (0 IMU, 1 encoders, 2 fix), ∂y/∂x, ∂y/∂ν̇ and noise σ.  Without
        `sensitivities` the parameters' columns are left zero (the start-state fit holds them)."""
        x0, D = start
        after = None if nxt is None else (np.asarray(nxt[0])[None], np.asarray(nxt[1])[None], np.ones(1, bool))
        return segment_blocks(self, model, np.array([s]), np.asarray(x0)[None], np.asarray(D)[None], b, after,
                              sensitivities)[0]

    def fit_starts(self, z):
        """Each segment's start state alone (the parameters and biases held): from its own readings,
        whitened as the joint fit whitens them, and the start guess as a prior with the guess's
        standard deviations (`x_sigma`: the EKF's, which carry the fixes' information about the
        position and the heading that a single segment cannot see); a small Levenberg–Marquardt
        fit per segment.  The guesses then move there (the fit's offsets start at zero).  The
        segments are not chained: a chain carries one segment's error in the heading or the
        position through every later start, where only a few fixes per segment can pull it back."""
        theta, b, _ = self.split(z)
        model = self.model(theta)
        for s in range(self.S):
            x_ref = self.xref[s]
            cache, white = {}, {}
            prior = None if self.xsig is None else 1.0 / np.maximum(self.xsig[s], DEFECT_FLOOR)

            def evaluate(dv, x_ref=x_ref, prior=prior, s=s, white=white):
                key = dv.tobytes()
                if key not in cache:
                    cache.clear()
                    start = self._dretract(model, x_ref, dv)
                    blk = self.segment_block(model, s, start, None, b, sensitivities=False)
                    if not white:       # the readings weighed as the joint fit weighs them
                        white["w"] = self.covariances([blk], first=s)[0]
                    r, J = self.whiten(white["w"], blk["r"]), self.whiten(white["w"], blk["x"])
                    if prior is not None:
                        r = np.concatenate([r, prior * dv])
                        J = np.vstack([J, np.diag(prior)])
                    cache[key] = (r, J, blk)
                return cache[key]

            sol = scipy.optimize.least_squares(lambda dv: evaluate(dv)[0], np.zeros(NE),
                                               jac=lambda dv: evaluate(dv)[1], method="lm", max_nfev=20)
            self.xref[s] = model.retract(x_ref, sol.x)
        self._cache = (None, None)

    def _noise_parts(self, s, blk):
        """What the process noise's forces w_j of a segment's torque periods js do (`noise_map`):
        (js, P (12, 5 len(js)) their effect on Φ⁻¹ δx once they entered, enters (len(js),) the node
        where each enters the state (a large number for none), Minv (L + 1, 5, 5))."""
        d = self.data
        model, X, Phi = blk["model"], blk["X"], blk["Phi"]
        k0, last_node = self.starts[s], self.ends[s]
        js = np.unique(d.interval[k0:last_node + 1])
        P = np.zeros((NE, 5 * len(js)))
        enters = np.full(len(js), np.iinfo(int).max)
        Minv = np.linalg.inv(model.inertia_batch(X))
        later = d.interval[k0 + 1:last_node + 1]
        # w_j enters the state at the first node of a later period, κ_j (none for the last period)
        first_after = np.searchsorted(later, js, side="right")
        entering = np.flatnonzero(first_after < len(later))
        if entering.size:               # one batched solve for every period's entry
            kappa = first_after[entering] + 1
            Bk = np.zeros((len(kappa), NE, 5))
            Bk[:, IDX_E_NU] = Minv[kappa - 1] * d.tau
            P.reshape(NE, -1, 5)[:, entering] = np.swapaxes(np.linalg.solve(Phi[kappa], Bk), 0, 1)
            enters[entering] = kappa
        return js, P, enters, Minv

    def _own_period(self, s, blk, Minv):
        """(n, 5): what each noise-scaled reading of a segment sees directly of its own torque
        period's force w (per unit force): the accelerometer's M⁻¹ w, and the velocities' jump so
        far, M⁻¹ w t' at a time t' into the period (the truth's held force moves the velocities
        from the period's start, `runtime.sensor_sim`; the states of the fit's later nodes see
        the whole jump M⁻¹ w τ once the period has ended).  With a period longer than the IMU's,
        the readings inside it would otherwise miss that share: the gyroscope about the yoke's
        axis read 1.7 times its declared variance there."""
        rows = blk["rows"]
        node, sig = rows["node"], rows["sig"][:, None]
        into = self.data.into[self.starts[s] + node]
        M = Minv[node]
        return (np.einsum("rj,rjk->rk", rows["Hn"], M)
                + np.einsum("rj,rjk->rk", rows["Hx"][:, IDX_E_NU], M) * into[:, None]) / sig

    def noise_map(self, s, blk):
        """(A, Q): the effect on the segment's noise-scaled readings and on its end state (the last
        12 rows) of the process noise's forces w_j, one per torque period and held over it (the
        accelerometer reads M⁻¹ w_j, the velocities jump by M⁻¹ w_j τ at its end; a reading inside
        the period sees their jump so far, `_own_period`), w_j of covariance diag(Q)."""
        d = self.data
        Phi, rows = blk["Phi"], blk["rows"]
        k0 = self.starts[s]
        js, P, enters, Minv = self._noise_parts(s, blk)
        node, sig = rows["node"], rows["sig"][:, None]
        n = len(node)
        A = np.zeros((n + NE, 5 * len(js)))
        A[:n] = np.einsum("rj,rjk->rk", rows["Hx"], Phi[node]) @ P / sig * np.repeat(enters[None, :] <= node[:, None], 5, 1)
        c = np.searchsorted(js, d.interval[k0 + node])
        A[np.arange(n)[:, None], 5 * c[:, None] + np.arange(5)] += self._own_period(s, blk, Minv)
        A[n:] = (Phi[-1] @ P) * np.repeat(enters <= len(Phi) - 1, 5)
        return A, np.tile(self.q2 / d.tau, len(js))

    def end_covariance(self, s, blk):
        """The covariance (12, 12) of a segment's end state from the process noise inside it."""
        A, Q = self.noise_map(s, blk)
        E = A[blk["n_out"]:]
        return (E * Q) @ E.T + DEFECT_FLOOR ** 2 * np.eye(NE)

    def covariances(self, blocks, first=0):
        """Each segment's whitening W (Wᵀ W = C⁻¹) of its residual covariance, in units of the
        sensor noise: C = D + A Q Aᵀ (`noise_map`), D the unit noise of the readings and the floor
        of their end-state difference.  C is the covariance of a linear model along the segment
        (the state's deviation η = Φ⁻¹ δx jumps by P_j w_j where w_j enters; a reading sees Φ η
        and, at the IMU, its own period's w_j), so W is its innovations form: a Kalman filter on
        η, one torque period's readings at a time (their own w_j appended to the state), then the
        end-state difference, each innovation whitened by the Cholesky factor of its covariance.
        W is the inverse Cholesky factor of C: a few products per torque period, never a matrix
        of the segment's size.  Per segment a list of (rows, H (k, 12), L⁻¹ (k, k), K (12, k)): the
        slice of its rows, their sensitivity to η, the inverse Cholesky factor of their innovations'
        covariance and the gain of η's mean.  `blocks` are those of the segments first, first + 1, ..."""
        out = []
        for s, blk in enumerate(blocks, start=first):
            out.append(self._innovations(s, blk))
        return out

    def _innovations(self, s, blk):
        d = self.data
        Phi, rows = blk["Phi"], blk["rows"]
        k0 = self.starts[s]
        js, P, enters, Minv = self._noise_parts(s, blk)
        root_q = np.sqrt(self.q2 / d.tau)
        Pw = (P.reshape(NE, -1, 5) * root_q).swapaxes(0, 1)        # (periods, 12, 5), w_j in unit noise
        node, sig = rows["node"], rows["sig"]
        n = blk["n_out"]
        H = np.einsum("rj,rjk->rk", rows["Hx"], Phi[node]) / sig[:, None]
        G = self._own_period(s, blk, Minv) * root_q     # the direct reading of its own period's w_j
        period = np.searchsorted(js, d.interval[k0 + node])
        bounds = np.searchsorted(period, np.arange(len(js) + 1))
        Sigma = np.zeros((NE, NE))
        steps = []
        Sa = np.zeros((NE + 5, NE + 5))
        T = np.zeros((NE, NE + 5))
        T[:, :NE] = np.eye(NE)
        last = len(Phi) - 1
        for j in range(len(js)):
            lo, hi = bounds[j], bounds[j + 1]
            T[:, NE:] = Pw[j] if enters[j] <= last else 0.0
            Sa[:NE, :NE] = Sigma
            Sa[:NE, NE:] = 0.0
            Sa[NE:, :NE] = 0.0
            Sa[NE:, NE:] = np.eye(5)
            if hi > lo:
                Ha = np.concatenate([H[lo:hi], G[lo:hi]], axis=1)
                HS = Ha @ Sa
                Linv = _inverse_cholesky(HS @ Ha.T + np.eye(hi - lo))
                V = Linv @ HS                   # L⁻¹ H Σ
                steps.append((slice(lo, hi), H[lo:hi], Linv, T @ (V.T @ Linv)))    # T Σ Hᵀ S⁻¹
                Sa -= V.T @ V
            Sigma = T @ Sa @ T.T
            Sigma = 0.5 * (Sigma + Sigma.T)
        if len(blk["r"]) > n:           # the end-state difference, in units of its floor
            Hd = Phi[-1] / DEFECT_FLOOR
            steps.append((slice(n, n + NE), Hd, _inverse_cholesky(Hd @ Sigma @ Hd.T + np.eye(NE)), None))
        return steps

    @staticmethod
    def whiten(white, M):
        """W M for a segment's whitening `white` (`covariances`): the innovations of M's rows,
        each whitened; M (rows,) or (rows, m)."""
        vec = M.ndim == 1
        M = M[:, None] if vec else M
        out = np.empty(M.shape)
        mean = np.zeros((NE, M.shape[1]))
        for rows, H, Linv, K in white:
            Y = M[rows] / DEFECT_FLOOR if K is None else M[rows]
            innovation = Y - H @ mean
            out[rows] = Linv @ innovation
            if K is not None:
                mean += K @ innovation
        return out[:, 0] if vec else out

    @staticmethod
    def stack_whitenings(whites):
        """The segments' whitenings (`covariances`) packed for `whiten_all` (C `sr_ident_whiten`):
        {"n_steps" (S,) the steps of each segment, "step_rows" the rows of each step, "unit" what a
        step's rows are divided by first (the end-state difference's floor, else 1), and the steps'
        H (k, 12), L⁻¹ (k, k) and gains (12, k, zero for the end-state difference) flattened one
        after the other}."""
        steps = [st for w in whites for st in w]
        k = [st[0].stop - st[0].start for st in steps]
        return {"n_steps": np.array([len(w) for w in whites], dtype=np.int64),
                "step_rows": np.array(k, dtype=np.int64),
                "unit": np.array([1.0 if st[3] is not None else DEFECT_FLOOR for st in steps]),
                "H": np.concatenate([np.ravel(st[1]) for st in steps]),
                "L": np.concatenate([np.ravel(st[2]) for st in steps]),
                "K": np.concatenate([np.ravel(st[3]) if st[3] is not None else np.zeros(NE * m)
                                     for st, m in zip(steps, k)])}

    @staticmethod
    def whiten_all(stacked, Ms, buffers=None):
        """[W_s M_s] for every segment s at once (`stack_whitenings`): `whiten`'s recursion in C
        (`sr_ident_whiten`), on the segments' rows as `segments.rows` stacks them (a `Rows`), or on
        a list of arrays (stacked first); the result in `buffers`' array "W" (`segments.buffer`)."""
        if not isinstance(Ms, Rows):
            Ms = [np.asarray(M, dtype=float) for M in Ms]
            Ms = Rows(np.concatenate([M.ravel() for M in Ms]), [M.shape for M in Ms])
        n_rows = np.array([m for m, _ in Ms.shapes], dtype=np.int64)
        width = np.array([w for _, w in Ms.shapes], dtype=np.int64)
        out = buffer(buffers, "W", Ms.data.size)
        work = np.empty((NE + 1) * int(width.max()))
        status = _lib.sr_ident_whiten(len(n_rows), pointer(n_rows, "long"), pointer(width, "long"),
                                      pointer(stacked["n_steps"], "long"), pointer(stacked["step_rows"], "long"),
                                      pointer(stacked["unit"]), pointer(stacked["H"]), pointer(stacked["L"]),
                                      pointer(stacked["K"]), pointer(Ms.data), pointer(out), pointer(work))
        if status != _lib.SR_OK:
            raise KernelError("whitening", status)
        return Rows(out, Ms.shapes)

    def assemble(self, z):
        """(residuals, sparse Jacobian, segment blocks) at z.  Each segment's whitened residuals r_s
        and Jacobian J_s (columns θ, b, its start and the next) enter compressed: with the QR
        factorisation [J_s r_s] = Q [[R, c], [0, ρ]], the rows (c, ρ) and Jacobian (R; 0) have the
        same sum of squares, gradient and Gauss–Newton matrix as the segment's own, at a few
        dozen rows instead of its readings' hundreds."""
        if self._cache[0] is not None and np.array_equal(self._cache[0], z):
            return self._cache[1]
        blocks = self.segment_blocks(z)
        if self.chol is None:
            self.chol = self.covariances(blocks)
        if self._stacked[0] is not self.chol:
            self._stacked = (self.chol, self.stack_whitenings(self.chol))
        rs, data = [], []
        for M in self.whiten_all(self._stacked[1], blocks[0]["stack"], self.buffers):
            m = M.shape[1] - 1
            R = _upper_triangle(M, m + 1)
            r = R[:, m].copy()
            r[m] = abs(r[m])
            data.append(R[:m, :m].ravel())
            rs.append(r)
        # the weak prior on the first start state (the gauge no sensor fixes)
        _, _, Dz = self.split(z)
        rs.append(Dz[0] / GAUGE_SIGMA)
        data.append(np.full(NE, 1.0 / GAUGE_SIGMA))
        r = np.concatenate(rs)
        indices, indptr = self._pattern(blocks)
        J = scipy.sparse.csr_matrix((np.concatenate(data), indices.copy(), indptr.copy()), shape=(len(r), self.ncols))
        self.n_residuals = sum(len(blk["r"]) for blk in blocks) + NE
        self._cache = (z.copy(), (r, J, blocks))
        self.nfev += 1
        if self.progress is not None:
            self.progress()
        return self._cache[1]

    def _pattern(self, blocks):
        """The CSR structure (indices, indptr) of `assemble`'s Jacobian, the same at every
        evaluation: per segment its compressed rows R (m, m), m its columns (θ, b, its start and
        the next's, ascending), then the row of its remaining residual, empty; then the gauge's
        diagonal on the first start state."""
        key = tuple(blk["M"].shape[1] for blk in blocks)
        if self._csr[0] != key:
            indices, counts = [], []
            for s, blk in enumerate(blocks):
                cols = np.concatenate([np.arange(self.nf + 6), self.nf + 6 + NE * s + np.arange(NE)]
                                      + ([self.nf + 6 + NE * (s + 1) + np.arange(NE)] if blk["next"] is not None else []))
                indices.append(np.tile(cols, len(cols)))
                counts += [len(cols)] * len(cols) + [0]
            indices.append(self.nf + 6 + np.arange(NE))
            counts += [1] * NE
            self._csr = (key, (np.concatenate(indices).astype(np.int32),
                               np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)))
        return self._csr[1]

    def align_headings(self, z):
        """Turn each segment's start about the vertical so that neighbouring segments agree in the
        heading.  Fitted alone (`fit_starts`), a segment sees its heading only through its one or
        two fixes and the filter's estimate, whose σ is a tenth of a radian over the first seconds:
        neighbours then disagree at their ends by up to 0.3 rad, a rotation of whole segments that
        the states' first stage does not close.  A turn δ about the vertical through a segment's
        start is a symmetry of the IMU's and the encoders' readings on level ground (it moves the
        fixes only), and it turns the segment's end by the same δ, so the heading differences
        y_s (the next start's heading minus the end's) become y_s + δ_{s+1} − δ_s.  The turns
        minimise Σ_s ((y_s + δ_{s+1} − δ_s)/c)² + Σ_s (δ_s/σ_s)², σ_s the filter's σ of the
        heading at the segment's start and c the median |y_s| (the differences the model's own
        errors leave; a smoother of the heading as a random walk): where the filter is sure the
        heading stays, and an uncertain stretch takes its heading from its sure neighbours.  On a
        slope the turn is no symmetry, and the starts are left as they are."""
        if self.xsig is None or self.S < 2 or self.params.slope != 0.0:
            return
        theta, _, _ = self.split(z)
        model, d = self.model(theta), self.data
        R = self.xref[:, IDX_RS].reshape(-1, 3, 3)
        lengths = self.ends - self.starts
        Re = np.array([model.simulate(self.xref[s], d.h, lengths[s], u=d.u[k0:k0 + lengths[s]], method=self.method,
                                      energy_tol=None)[-1, IDX_RS] for s, k0 in enumerate(self.starts[:-1])])
        y = heading_of(R[1:] @ Re.reshape(-1, 3, 3).transpose(0, 2, 1))
        # the heading's σ: the filter's σ of the shell's rotation (right-trivialised) along the vertical
        sig = np.sqrt(np.sum(R[:, 2, :] ** 2 * self.xsig[:, IDX_E_XI_S] ** 2, axis=1))
        c = max(float(np.median(np.abs(y))), DEFECT_FLOOR)
        A = np.vstack([(np.eye(self.S, k=1) - np.eye(self.S))[:-1] / c, np.diag(1.0 / np.maximum(sig, DEFECT_FLOOR))])
        delta = np.linalg.lstsq(A, np.concatenate([-y / c, np.zeros(self.S)]), rcond=None)[0]
        cos, sin = np.cos(delta), np.sin(delta)
        Rz = np.zeros((self.S, 3, 3))
        Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = cos, -sin, sin, cos, 1.0
        self.xref[:, IDX_RS] = (Rz @ R).reshape(-1, 9)
        self._cache = (None, None)

    def z0(self):
        return np.concatenate([self.theta_start, self.b0, np.zeros(NE * self.S)])

    def bounds(self):
        lo = np.full(self.ncols, -np.inf)
        hi = np.full(self.ncols, np.inf)
        for i, name in enumerate(self.free):
            lo[i], hi[i] = bounds_of(name, self.params, self.free)
        return lo, hi

    def residual_series(self, z):
        """{kind: (t, whitened residuals (n, m))} along the log: each segment's residuals whitened by
        their covariance (`covariances`), so that a right model leaves unit white noise."""
        blocks = self.assemble(z)[2]
        out = {"imu": ([], []), "encoders": ([], []), "fixes": ([], [])}
        for s, blk in enumerate(blocks):
            w = self.whiten(self.chol[s], blk["r"])
            rows = blk["rows"]
            for code, kind, m in ((0, "imu", 6), (1, "encoders", 2), (2, "fixes", 2)):
                sel = np.flatnonzero(rows["kind"] == code)
                if sel.size:
                    out[kind][0].append(self.data.t[self.starts[s] + rows["node"][sel[::m]]])
                    out[kind][1].append(w[sel].reshape(-1, m))
        return {k: (np.concatenate(t), np.concatenate(v)) for k, (t, v) in out.items() if t}


class _FullState:
    """The one-step prediction-error problem of a full-state log: the velocities at row k + 1 against
    one step of the model from row k, whitened by the process noise's velocity jump."""

    def __init__(self, log, params, free, method, jacobian="analytic"):
        self.params, self.free, self.method, self.jacobian = params, free, method, jacobian
        self.idx = [PARAMETER_NAMES.index(n) for n in free]
        self.nf = len(free)
        self.theta_start = params.as_array()[self.idx]
        self.X = log.truth_states()
        self.t = log.truth.t
        self.h = float(np.median(np.diff(self.t)))
        self.u = log.torque_at(self.t[:-1])
        q2 = log.sensors.process.generalized() ** 2
        if not np.all(q2 > 0):
            raise IdentifyError("sensors.process: a full-state fit weighs the velocities by the process noise; "
                                "the sensor set declares none on some axis")
        model = Model(params)
        Minv = np.linalg.inv(model.inertia_batch(self.X[:-1]))
        # whitened by the inverse of each row's Cholesky factor: one batched product per evaluation
        self.white = np.linalg.inv(np.linalg.cholesky((Minv * (q2 * self.h)) @ np.swapaxes(Minv, 1, 2)))
        self.ncols = self.nf
        self._cache = (None, None)
        self.nfev = 0
        self.progress = None

    model = _Problem.model

    def assemble(self, z, sparse=True):
        """(r, J, None) at z, J a CSR matrix as `_Problem.assemble` gives it, or with `sparse` False
        the dense (n, nf) array the optimizer takes (a CSR copy of a dense block costs more than
        the evaluation's products)."""
        if self._cache[0] is None or not np.array_equal(self._cache[0], z):
            model = self.model(z)
            pred, Jp = step_and_sensitivity(model, self.X[:-1], self.u, self.h, self.method, self.idx,
                                            self.jacobian)
            e = self.X[1:, IDX_NU] - pred[:, IDX_NU]
            Jp = Jp[:, IDX_E_NU]
            r = np.matmul(self.white, e[..., None])[..., 0]
            J = -np.matmul(self.white, Jp)
            self._cache = (z.copy(), (r.ravel(), J.reshape(-1, self.nf), None))
            self.nfev += 1
            if self.progress is not None:
                self.progress()
        r, J, _ = self._cache[1]
        return r, scipy.sparse.csr_matrix(J) if sparse else J, None

    def z0(self):
        return self.theta_start

    def bounds(self):
        lo, hi = zip(*(bounds_of(n, self.params, self.free) for n in self.free))
        return np.array(lo), np.array(hi)


def heading_of(R):
    """The angle [rad] about the vertical of rotations R (..., 3, 3) near one about it."""
    return np.arctan2(R[..., 1, 0] - R[..., 0, 1], R[..., 0, 0] + R[..., 1, 1])


def _start_guess(log, params, with_sigma=False):
    """The EKF's estimate at every IMU time and its final biases (the fit's starting point), and
    with `with_sigma` the filter's standard deviations of the 18 error coordinates there.  The
    filter runs on the nominal robot with its gate open: the readings of a robot that differs from
    the nominal one are what the gate would refuse (on a robot within ±30 % it refused half of them
    and lost the motion), and a log to identify is taken as free of outliers.  The accelerometer is
    read with the largest axis's sigma (`accel_noise="largest"`), not the default held model: the
    held model trusts the accelerometer to its white noise, which only a filter on the right robot
    may do (on a robot 10-30 % off it lands the first guess farther from the truth)."""
    from ..estimation.estimate import estimate_log
    est = estimate_log(log, params, gate=1.0, accel_noise="largest")
    k = np.searchsorted(est.t, log.imu.t)
    k = np.clip(k, 0, len(est.t) - 1)
    return (est.x[k], est.biases[-1], est.sigma[k]) if with_sigma else (est.x[k], est.biases[-1])


def identify(log, params, names, segment=0.5, method="rkmk4", full_state=False, max_nfev=60, progress=None,
             x_guess=None, bias_guess=None, jacobian="analytic", start="regressor"):
    """Fit the parameters `names` (see `free_parameters`) of the robot `params` (the others held) to
    `log` (runtime.estimation.logs.Log), with the IMU's biases and each segment's start state; or,
    `full_state`, to the log's truth by the one-step prediction error.  `segment` [s]: the
    multiple-shooting segments' length; `x_guess` (n_imu, 35) and `bias_guess` (6,) replace the
    EKF's start guess.  `max_nfev`: the evaluations of each of a sensor fit's two joint stages
    (before and after the covariance is linearised again; each stops early once converged,
    `CONVERGED_SHIFT`), of a full-state fit's solver.  `progress()` is called once per evaluation.  `jacobian`: the parameter
    sensitivities' source (`JACOBIANS`: "analytic", or "fd"/"fd-all", differences in C).  `start`
    (`STARTS`): the parameters' start, "regressor" the linear least-squares first guess
    (runtime.identification.first_guess) from the start guess's states (the log's truth for a
    full-state fit), "nominal" the robot's values.  Returns a `Fit`."""
    if not isinstance(params, Params):
        raise IdentifyError(f"robot: expected a runtime.Params, got {type(params).__name__}")
    free = free_parameters(names)
    if jacobian not in JACOBIANS:
        raise IdentifyError(f"jacobian: expected one of {', '.join(JACOBIANS)}, got {jacobian!r}")
    if start not in STARTS:
        raise IdentifyError(f"start: expected one of {', '.join(STARTS)}, got {start!r}")
    check_log(log, full_state)
    if not (isinstance(segment, (int, float)) and math.isfinite(segment) and segment > 0):
        raise IdentifyError(f"segment: expected a length > 0 in s, got {segment!r}")
    # The fit's products are small: one BLAS thread each (threads spinning for a busy core cost
    # far more than they gain on a shared 2-core machine).
    with one_thread():
        return _identify(log, params, free, segment, method, full_state, max_nfev, progress, x_guess, bias_guess,
                         jacobian, start)


def _identify(log, params, free, segment, method, full_state, max_nfev, progress, x_guess, bias_guess, jacobian,
              start):
    if full_state:
        prob = _FullState(log, params, free, method, jacobian)
    else:
        x_sigma = None
        if x_guess is None:
            x_guess, guess_b, x_sigma = _start_guess(log, params, with_sigma=True)
            bias_guess = guess_b if bias_guess is None else bias_guess
        prob = _Problem(log, params, free, segment, method, np.asarray(x_guess), np.zeros(6) if bias_guess is None
                        else bias_guess, jacobian, x_sigma)
    prob.progress = progress
    if start == "regressor":
        prob.theta_start = first_guess(log, params, free, prob, full_state, x_guess).theta
    if not full_state:
        prob.fit_starts(prob.z0())
        prob.align_headings(prob.z0())
    lo, hi = prob.bounds()
    with np.errstate(invalid="ignore"):
        z0 = np.clip(prob.z0(), np.where(np.isfinite(lo), lo + 1e-12 * np.maximum(1, abs(lo)), lo),
                     np.where(np.isfinite(hi), hi - 1e-12 * np.maximum(1, abs(hi)), hi))

    if not full_state:
        # first the start states and biases alone: until the segments agree at their ends, the
        # parameters would move to absorb the start guess's errors (seen: to their bounds)
        prob.hold_parameters = True
        z0 = levenberg_marquardt(lambda z: prob.assemble(z)[:2], z0, lo, hi, STATES_NFEV).x
        prob.hold_parameters = False
        prob.chol = None            # the covariance where the segments agree
        prob._cache = (None, None)
    if full_state:
        opts = dict(jac=lambda z: prob.assemble(z, sparse=False)[1], bounds=(lo, hi), method="trf", x_scale="jac",
                    max_nfev=max_nfev, xtol=1e-8, ftol=1e-8, gtol=1e-10)
        sol = scipy.optimize.least_squares(lambda z: prob.assemble(z, sparse=False)[0], z0, **opts)
    else:
        def evaluate(z):
            r, J, _ = prob.assemble(z)
            return r, J

        sol = levenberg_marquardt(evaluate, z0, lo, hi, max_nfev, stol=RELINEARISE_SHIFT, watch=prob.nf)
        prob.chol = None            # the covariance at the optimum, then the refinement
        prob._cache = (None, None)
        sol = levenberg_marquardt(evaluate, sol.x, lo, hi, max_nfev, stol=CONVERGED_SHIFT, watch=prob.nf)
    return _report(prob, sol, free, params, full_state)


@dataclasses.dataclass
class Solution:
    """What `levenberg_marquardt` returns: the point `x`, its `cost` ½‖r‖², the evaluations `nfev`,
    `status` (0 the evaluations ran out, 1 converged: a Gauss–Newton step would move no watched
    entry by more than `stol` σ, 2 the cost stopped falling, 3 the step became negligible, 4 no step lowers
    the cost), a `message` and `shift`, the largest step of a watched entry that an undamped
    Gauss–Newton step from x would take, in units of its standard deviation (`_shift`)."""
    x: np.ndarray
    cost: float
    nfev: int
    status: int
    message: str
    shift: float = math.inf


def levenberg_marquardt(evaluate, z0, lo, hi, max_nfev, ftol=1e-8, xtol=1e-8, damping=1e-2, stol=0.0, watch=None):
    """Minimise ½‖r(z)‖² for lo <= z <= hi by Levenberg–Marquardt steps on the normal equations
    (JᵀJ + λ diag(d²)) δ = −Jᵀr, d the largest column norms of J seen so far (the scaling
    SciPy's x_scale="jac" uses), λ adapted by the gain ratio (Nielsen's rule), a step leaving the
    bounds projected onto them and the entries on a bound that the gradient pushes outwards held.
    `evaluate(z)` -> (r, J sparse); an `IdentifyError` (a candidate robot the model refuses)
    counts as a rejected step.  Converged (status 1) when the undamped Gauss–Newton step would
    move none of the first `watch` entries (None: all) by more than `stol` of its standard
    deviation (`_shift`).  The multiple-shooting Jacobian has a
    dozen global columns and a band of start-state columns, so JᵀJ is small and nearly block
    tridiagonal and one Cholesky factorisation of it costs milliseconds; SciPy's dense
    trust-region solver instead takes an SVD of the whole Jacobian at every iteration, most of the
    fit's time."""
    z = np.array(z0, dtype=float)
    r, J = evaluate(z)
    nfev = 1
    cost = 0.5 * float(r @ r)
    d = np.zeros(len(z))
    lam, nu = damping, 2.0
    status, message = 0, "the maximum number of evaluations is reached"
    fresh = True

    def normal_equations(z, r, J, d):
        A = (J.T @ J).toarray()
        g = J.T @ r
        d = np.maximum(d, np.sqrt(np.diag(A)))
        d[d == 0] = 1.0
        # entries on a bound that the gradient pushes outwards are held (the active set)
        free = ~(((z <= lo) & (g > 0)) | ((z >= hi) & (g < 0)))
        return A, g, d, free, _shift(A, g, d, free, len(z) if watch is None else watch)

    while True:
        if fresh:
            A, g, d, free, shift = normal_equations(z, r, J, d)
            fresh = False
            if shift <= stol:
                status, message = 1, f"converged: a Gauss–Newton step would move the estimates by {shift:.2g} σ"
                break
        if nfev >= max_nfev:
            break
        free = ~(((z <= lo) & (g > 0)) | ((z >= hi) & (g < 0)))
        try:
            c = scipy.linalg.cho_factor(A[np.ix_(free, free)] + lam * np.diag(d[free] ** 2), check_finite=False)
        except np.linalg.LinAlgError:
            lam, nu = lam * nu, 2 * nu
            continue
        step = np.zeros(len(z))
        step[free] = -scipy.linalg.cho_solve(c, g[free], check_finite=False)
        step = np.clip(z + step, lo, hi) - z
        predicted = -float(g @ step + 0.5 * step @ (A @ step))
        if np.linalg.norm(d * step) <= xtol * (xtol + np.linalg.norm(d * z)):
            status, message = 3, "the step became negligible"
            break
        if predicted <= 0 and lam <= 1e16:      # the projection turned the step uphill: a shorter one
            lam, nu = lam * nu, 2 * nu
            continue
        try:
            r_new, J_new = evaluate(z + step)
            cost_new = 0.5 * float(r_new @ r_new)
        except IdentifyError:
            cost_new = math.inf
        nfev += 1
        rho = (cost - cost_new) / predicted if predicted > 0 else -1.0
        if rho > 1e-3:
            reduction = cost - cost_new
            z, r, J, cost = z + step, r_new, J_new, cost_new
            fresh = True
            lam *= max(1 / 3, 1 - (2 * rho - 1) ** 3)
            nu = 2.0
            if reduction <= ftol * cost:
                status, message = 2, "the cost stopped falling"
                break
        else:
            lam, nu = lam * nu, 2 * nu
            if lam > 1e16:
                status, message = 4, "no step lowers the cost"
                break
    if fresh:                   # stopped at a new point: what is left from there
        shift = normal_equations(z, r, J, d)[4]
    return Solution(x=z, cost=cost, nfev=nfev, status=status, message=message, shift=shift)


def _shift(A, g, d, free, watch):
    """max |δ_i| / σ_i over the first `watch` entries that are free: the undamped Gauss–Newton step
    δ = −A⁻¹ g of the free entries (the others held), each in units of its standard deviation
    σ_i = √(A⁻¹)_ii (A regularised by 1e-12 of its scale, d², against a direction nothing
    determines); 0 with no such entry, inf if A is not positive definite.  A step measured in
    σ is what matters for an interval; the cost's decrease ½ gᵀ A⁻¹ g is not: it stays large
    along a direction of the start states that the log barely determines, where the quadratic
    model does not hold and the steps creep (a 1 s log's fit did, its parameters settled)."""
    idx = np.flatnonzero(free)
    watched = np.flatnonzero(idx < watch)
    if not watched.size:
        return 0.0
    Af = A[np.ix_(idx, idx)]
    try:
        c = scipy.linalg.cho_factor(Af + 1e-12 * np.diag(d[idx] ** 2), check_finite=False)
    except np.linalg.LinAlgError:
        return math.inf
    step = scipy.linalg.cho_solve(c, g[idx], check_finite=False)[watched]
    unit = np.zeros((len(idx), watched.size))
    unit[watched, np.arange(watched.size)] = 1.0
    var = np.einsum("ij,ij->j", unit, scipy.linalg.cho_solve(c, unit, check_finite=False))
    return float(np.max(np.abs(step) / np.sqrt(var)))


def first_guess(log, params, free, prob, full_state, x_guess):
    """The regressor's first guess (`runtime.identification.first_guess.regressor_guess`) for
    `prob`'s free entries, from the log's truth (full state) or the start guess's states at the IMU's
    times; the equations weighed by the process noise's generalized forces."""
    if full_state:
        t, x = prob.t, prob.X
    else:
        t, x = np.asarray(log.imu.t, dtype=float), np.asarray(x_guess)
    q = np.sqrt(log.sensors.process.generalized() ** 2)
    weights = 1.0 / np.where(q > 0, q, q.max() if q.max() > 0 else 1.0)
    lo, hi = prob.bounds()
    return regressor_guess(t, x, log.torque_at(t), params, free, (lo[:len(free)], hi[:len(free)]), weights)


def _report(prob, sol, free, params, full_state):
    r, J, _ = prob.assemble(sol.x, sparse=False) if full_state else prob.assemble(sol.x)   # full state: dense
    nf = len(free)
    I = J.T @ J if full_state else (J.T @ J).toarray()
    if full_state:
        info = I
    else:                           # eliminate the start states and the biases
        g, l = slice(0, nf), slice(nf, None)
        Ill = I[l, l]
        info = I[g, g] - I[g, l] @ np.linalg.solve(Ill, I[l, g])
        gb = slice(0, nf + 6)
        lx = slice(nf + 6, None)
        info_gb = I[gb, gb] - I[gb, lx] @ np.linalg.solve(I[lx, lx], I[lx, gb])
    info = 0.5 * (info + info.T)
    theta = sol.x[:nf]
    nominal = params.as_array()[prob.idx]
    scale = np.where(np.abs(nominal) > 0, np.abs(nominal), 1e-3 * max(1.0, float(np.abs(nominal).max())))
    scaled = info * np.outer(scale, scale)
    evals, evecs = np.linalg.eigh(scaled)
    top = max(float(evals[-1]), 1e-300)
    keep = evals > RANK_RTOL * top
    rank = int(keep.sum())
    condition = float(top / evals[keep][0]) if rank else math.inf
    null = evecs[:, ~keep]
    identified = np.array([np.linalg.norm(null[i]) < 1e-3 for i in range(nf)]) if null.size else np.ones(nf, bool)
    cov_scaled = (evecs[:, keep] / evals[keep]) @ evecs[:, keep].T
    cov = cov_scaled * np.outer(scale, scale)
    sigma = np.sqrt(np.clip(np.diag(cov), 0, None))
    sigma[~identified] = np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(np.sqrt(np.diag(cov)), np.sqrt(np.diag(cov)))
    lo, hi = prob.bounds()
    lo, hi = lo[:nf], hi[:nf]
    on_bound = {}
    for i, n in enumerate(free):
        tol = 1e-6 * max(abs(theta[i]), scale[i])
        if np.isfinite(lo[i]) and theta[i] - lo[i] <= tol:
            on_bound[n] = "lower"
        elif np.isfinite(hi[i]) and hi[i] - theta[i] <= tol:
            on_bound[n] = "upper"
    p = params.as_array()
    p[prob.idx] = theta
    estimated = Params.from_array(p)
    combos = _combinations(params, estimated, prob.idx, cov, null, scale)
    nulls = [{free[i]: float(v[i]) for i in np.argsort(-np.abs(v)) if abs(v[i]) > 1e-3} for v in null.T]
    n_data = len(r) if full_state else prob.n_residuals - NE
    chi2 = float(np.sum(r[:len(r) - (0 if full_state else NE)] ** 2))
    dof = max(n_data - (nf if full_state else prob.ncols), 1)
    rms = math.sqrt(chi2 / dof)
    check = {"rms": rms, "chi2": chi2, "dof": dof, "p_value": float(scipy.stats.chi2.sf(chi2, dof)),
             "tolerance": RESIDUAL_TOLERANCE, "passed": bool(abs(rms - 1) <= RESIDUAL_TOLERANCE)}
    message = str(sol.message)
    if full_state:
        converged, shift = bool(sol.status > 0), math.nan
    else:
        converged, shift = bool(sol.shift <= CONVERGED_SHIFT), float(sol.shift)
        if not converged:
            message += (f"; NOT converged: a Gauss–Newton step would still move the estimates by {shift:.3g} σ "
                        f"(converged below {CONVERGED_SHIFT:g} σ), the estimates and intervals are not the "
                        f"optimum's")
    if full_state:
        biases, bsig = np.full(6, np.nan), np.full(6, np.nan)
        series = {"velocities": (prob.t[1:], r.reshape(-1, NV))}
    else:
        biases = sol.x[nf:nf + 6]
        ev, V = np.linalg.eigh(0.5 * (info_gb + info_gb.T))
        ok = ev > RANK_RTOL * ev[-1]
        cgb = (V[:, ok] / ev[ok]) @ V[:, ok].T
        bsig = np.sqrt(np.clip(np.diag(cgb)[nf:], 0, None))
        series = prob.residual_series(sol.x)
    return Fit(names=free, nominal=nominal, estimate=theta, sigma=sigma, low=theta - Z95 * sigma,
               high=theta + Z95 * sigma, information=info, correlation=corr, rank=rank, condition=condition,
               identified=identified, on_bound=on_bound, combinations=combos, null_directions=nulls,
               biases=biases, bias_sigma=bsig, residual_check=check, residuals=series, params=estimated,
               nfev=int(prob.nfev), status=int(sol.status), message=message,
               mode="full-state" if full_state else "sensors", start=prob.theta_start.copy(), converged=converged,
               shift=shift)


def _combinations(nominal, estimated, idx, cov, null, scale):
    """The base parameters (runtime.param_derivatives.base_parameters of the robot) that the free
    entries enter, with their value at the estimate, a sigma by the delta method and whether the
    log determines them (their gradient orthogonal to the information's null space)."""
    base = base_parameters(Model(estimated))
    G = np.zeros((base.rank, len(inertial_parameters(estimated))))
    for k, i in enumerate(base.independent):
        G[k, i] = 1.0
        G[k, list(base.dependent)] = base.combination[k]
    dpi = _dpi_of(estimated.as_array(), idx)
    values = base.values(inertial_parameters(estimated))
    nominal_values = base.values(inertial_parameters(nominal))
    out = []
    grads = G @ dpi * scale
    largest = np.abs(grads).max()
    for k, name in enumerate(base.names(4)):
        g = G[k] @ dpi
        if np.abs(grads[k]).max() <= 1e-9 * largest:
            continue
        gs = g * scale
        determined = bool(null.size == 0 or np.abs(null.T @ gs).max() <= 1e-3 * np.linalg.norm(gs))
        sigma = float(math.sqrt(max(g @ cov @ g, 0.0))) if determined else math.nan
        out.append({"name": name, "value": float(values[k]), "nominal": float(nominal_values[k]),
                    "sigma": sigma, "identified": determined})
    return out
