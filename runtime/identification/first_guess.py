"""The linear least-squares first guess of an identification (docs/identification.md, "The start
point").

The equations of motion are linear in the inertial parameters and dampings π:
M(x) ν̇ − f(x, u = 0) = Y(x, ν̇) π = (0, 0, 0, u_Y, u_P) (`Model.regressor`).  Along a smoothed state
estimate (the EKF's over a sensor log, or a full-state log's truth) with ν̇ from a Savitzky–Golay
derivative, the stacked rows determine the base parameters β (the combinations of π the equations
of motion can identify, `base_parameters`) by linear least squares.  The named free entries θ are
then the robot nearest to β̂ in the metric of that fit, the entries not named held at their
nominal values: a small bounded least-squares fit in θ (π is polynomial in θ), with a weak pull to
the nominal value that only decides directions the rows leave undetermined.  The result is clipped
into the fit's bounds and, should it not be a physical robot, moved back towards the nominal one
until it is.
"""
import dataclasses

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.signal

from ..model import Model
from ..param_derivatives import NPI, PARAMETER_NAMES, PI_NAMES, base_parameters
from ..params import Params
from ..state import IDX_NU, NV

#: The Savitzky–Golay window [s] of the velocities' smoothing and derivative, and its polynomial order.
WINDOW_S = 0.06
ORDER = 2
#: The weight of the first solve's pull to the nominal value, relative to what the rows say about
#: each entry alone: small enough to leave every determined direction to the data, large enough
#: to fix the undetermined ones.
PRIOR_WEIGHT = 1e-4
#: The relative standard deviation of the nominal values in the final solve: a builder knows the
#: robot's parameters roughly.
NOMINAL_SPREAD = 0.3


@dataclasses.dataclass(frozen=True, eq=False)
class FirstGuess:
    """The first guess: the free entries `names`, their `nominal` and guessed `theta` (inside the
    fit's bounds, a physical robot); the base parameters' names, least-squares values `base` and
    their value at `theta` (`base_at_theta`); the number of regressor rows used."""
    names: tuple
    nominal: np.ndarray
    theta: np.ndarray
    base_names: tuple
    base: np.ndarray
    base_at_theta: np.ndarray
    rows: int


def smoothed_motion(t, x, window=WINDOW_S, order=ORDER):
    """(x, ν̇) along uniformly sampled states x (n, 35) at times t: the velocities replaced by their
    Savitzky–Golay smoothing and ν̇ their Savitzky–Golay derivative (window [s], polynomial order)."""
    h = float(np.median(np.diff(t)))
    n = max(order + 2, int(round(window / h)) | 1)
    if len(t) < n:
        raise ValueError(f"log: {len(t)} samples, the first guess's smoothing needs at least {n}")
    x = np.array(x, dtype=float)
    nu = x[:, IDX_NU]
    x[:, IDX_NU] = scipy.signal.savgol_filter(nu, n, order, axis=0)
    nudot = scipy.signal.savgol_filter(nu, n, order, deriv=1, delta=h, axis=0)
    return x, nudot, n


def regressor_guess(t, x, u, params, free, bounds, weights=None, window=WINDOW_S, order=ORDER):
    """The first guess of the free entries `free` (names of `PARAMETER_NAMES`) of the robot `params`
    from states x (n, 35) at uniform times t (n,) under torques u (n, 2); `bounds` (lo, hi) of the
    free entries; `weights` (5,) scale the equations' rows (1/σ of each generalized force's noise).
    Returns a `FirstGuess`."""
    model = Model(params)
    xs, nudot, n_win = smoothed_motion(t, x, window, order)
    # the torques pass the same filter as the velocities, so that both sides of Y π = b see the
    # same smoothing of the torque steps
    us = scipy.signal.savgol_filter(np.asarray(u, dtype=float), n_win, order, axis=0)
    keep = slice(n_win // 2, len(t) - n_win // 2)       # the filter's edges are extrapolations
    Y = model.regressor(xs[keep], nudot[keep])
    b = np.zeros((Y.shape[0], NV))
    b[:, 3:] = us[keep]
    base = base_parameters(model)
    kept = list(base.independent)
    B = base.values(np.eye(NPI))            # β = B π: the base parameters are linear in π
    idx = [PARAMETER_NAMES.index(n) for n in free]
    p0 = params.as_array()
    theta0 = p0[idx]
    scale = np.where(np.abs(theta0) > 0, np.abs(theta0), 1.0)
    lo, hi = (np.asarray(v, dtype=float) for v in bounds)

    def pi_of(theta):
        p = p0.copy()
        p[idx] = theta
        return _pi_of(p)

    rows = np.empty((Y.shape[0], NV, len(kept) + 1))     # [Y_kept | b], each equation's row
    rows[..., :-1] = Y[:, :, kept]
    rows[..., -1] = b

    def base_fit(w):
        """(β̂, R) of the rows weighed by w (5,).  Y π = Y_kept β with β = π_kept + C π_dep: β̂ is a
        full-rank linear least-squares problem, solved from one QR factorisation of [Y_kept | b]:
        R and Qᵀb at once."""
        Ra = np.linalg.qr((rows * w[None, :, None]).reshape(-1, len(kept) + 1), mode="r")
        R = Ra[:-1, :-1]
        return scipy.linalg.solve_triangular(R, Ra[:-1, -1]), R

    def solve(fitted, prior):
        """θ nearest β̂ of `fitted` (`base_fit`'s) with the pull `prior` (per entry, on the relative
        change), and β̂."""
        beta, R = fitted
        RB = R @ B

        def residual(theta):
            return np.concatenate([RB @ pi_of(theta) - R @ beta, prior * (theta - theta0) / scale])

        def jacobian(theta):
            p = p0.copy()
            p[idx] = theta
            return np.vstack([RB @ _dpi_of(p, idx), np.diag(prior / scale)])

        sol = scipy.optimize.least_squares(residual, np.clip(theta0, lo, hi), jac=jacobian, bounds=(lo, hi),
                                           x_scale=scale, method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
        return sol.x, beta

    w = np.ones(NV) if weights is None else np.asarray(weights, dtype=float)
    # first the rows alone (a pull of PRIOR_WEIGHT of what the rows say about each entry alone, which
    # only settles what they leave undetermined) ...
    fitted = base_fit(w)
    alone = np.linalg.norm(fitted[1] @ B @ _dpi_of(p0, idx), axis=0) * scale
    theta, beta = solve(fitted, PRIOR_WEIGHT * np.where(alone > 0, alone, alone.max(initial=0.0) or 1.0))
    # ... then weighed by what they leave: each equation by its residuals' RMS, the rows counted
    # once per smoothing window (the filter correlates its neighbours), against the nominal values
    # known within NOMINAL_SPREAD (one σ).  An entry the rows see poorly stays near its nominal value.
    e = np.einsum("nij,j->ni", Y, pi_of(theta)) - b
    sigma = np.sqrt(np.mean(e ** 2, axis=0))
    w = 1.0 / (np.where(sigma > 0, sigma, sigma.max(initial=0.0) or 1.0) * np.sqrt(n_win))
    theta, beta = solve(base_fit(w), np.full(len(idx), 1.0 / NOMINAL_SPREAD))
    theta = _physical(params, idx, theta, theta0, lo, hi)
    return FirstGuess(names=tuple(free), nominal=theta0, theta=theta, base_names=tuple(base.names(4)),
                      base=beta, base_at_theta=base.values(pi_of(theta)), rows=int(Y.size // NPI))


def _physical(params, idx, theta, theta0, lo, hi):
    """theta inside (lo, hi) strictly and a robot Params accepts: moved back along the line to the
    nominal theta0 (which is one) until it is."""
    margin = 1e-9 * np.maximum(1.0, np.abs(theta0))
    with np.errstate(invalid="ignore"):
        theta = np.clip(theta, np.where(np.isfinite(lo), lo + margin, lo), np.where(np.isfinite(hi), hi - margin, hi))
    p = params.as_array()
    for shrink in (1.0, 0.9, 0.75, 0.5, 0.25, 0.1, 0.0):
        p[idx] = theta0 + shrink * (theta - theta0)
        try:
            Params.from_array(p)
        except ValueError:
            continue
        return p[idx].copy()
    return theta0.copy()


def _pi_index():
    """Where `_pi_of` reads each body's m, c, J (3, 3) and k in the parameter vector and writes its
    m, k, m·c and JO in π, and the entries π copies."""
    at, pi_at = PARAMETER_NAMES.index, PI_NAMES.index
    pairs = (("xx", 0, 0), ("yy", 1, 1), ("zz", 2, 2), ("xy", 0, 1), ("xz", 0, 2), ("yz", 1, 2))
    bodies = []
    for body in ("Y", "P"):
        J = [[at(f"J_{body}_{''.join(sorted(a + b, key='xyz'.index))}") for b in "xyz"] for a in "xyz"]
        bodies.append((at(f"m_{body}"), [at(f"c_{body}_{a}") for a in "xyz"], np.array(J), at(f"k_{body}"),
                       pi_at(f"m_{body}"), pi_at(f"k_{body}"), [pi_at(f"mc_{body}_{a}") for a in "xyz"],
                       [pi_at(f"JO_{body}_{k}") for k, _, _ in pairs], [i for _, i, _ in pairs],
                       [j for _, _, j in pairs]))
    copied = ("m_S", "j_S", "k_S", "j_mY", "j_mP")
    return [pi_at(n) for n in copied], [at(n) for n in copied], bodies


_PI_INDEX = _pi_index()


def _dpi_of(p, idx):
    """∂π/∂p (NPI, len(idx)) of `_pi_of` at the parameter vector p, on the entries idx: exact (π is
    polynomial in p: m·c bilinear, J_O = J + m (|c|² I − c cᵀ) cubic)."""
    p = np.asarray(p, dtype=float)
    to, frm, bodies = _PI_INDEX
    full = np.zeros((NPI, len(p)))
    full[to, frm] = 1.0
    eye = np.eye(3)
    for m_at, c_at, J_at, k_at, m_to, k_to, mc_to, jo_to, rows, cols in bodies:
        m, c = p[m_at], p[c_at]
        full[m_to, m_at] = full[k_to, k_at] = 1.0
        full[mc_to, m_at] = c
        full[np.ix_(mc_to, c_at)] = m * eye
        full[jo_to, J_at[rows, cols]] = 1.0
        full[jo_to, m_at] = (c @ c * eye - np.outer(c, c))[rows, cols]
        for a in range(3):          # ∂/∂c_a of m (|c|² δ_rs − c_r c_s)
            d = 2 * c[a] * eye - np.outer(eye[a], c) - np.outer(c, eye[a])
            full[jo_to, c_at[a]] = m * d[rows, cols]
    return full[:, idx]


def _pi_of(p):
    """π of a parameter vector that need not pass the physical checks (a difference step may not):
    `inertial_parameters`' arithmetic on the vector's entries."""
    p = np.asarray(p, dtype=float)
    to, frm, bodies = _PI_INDEX
    out = np.empty(NPI)
    out[to] = p[frm]
    for m_at, c_at, J_at, k_at, m_to, k_to, mc_to, jo_to, rows, cols in bodies:
        m, c, J = p[m_at], p[c_at], p[J_at]
        JO = J + m * (c @ c * np.eye(3) - np.outer(c, c))
        out[m_to], out[k_to] = m, p[k_at]
        out[mc_to] = m * c
        out[jo_to] = JO[rows, cols]
    return out
