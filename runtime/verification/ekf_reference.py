"""The error-state EKF of c/include/sr_ekf.h written out in NumPy, from the equations: the check
that the C filter (runtime.ekf) computes what the documentation says (docs/estimation.md).

It takes the model's pieces from the runtime (the step `Model.step`, the transition matrix as the
Lie–Euler step's Jacobian by CasADi's AD of the exported step `Model.casadi_step_jacobian`, the inertia, the sensors of runtime.sensors, the
retraction `Model.retract`) and writes the filter in its textbook form, without the C's
shortcuts: the full 18 × 18 transition, the inverse of M, the gain through a solve with S, the
Joseph form as the product (I − K H) P (I − K H)ᵀ + K R Kᵀ, the reset as G P Gᵀ with G the
right Jacobian of SO(3) as its power series, angle innovations wrapped through the unit circle.

Delayed fixes by stochastic cloning: marking a fix appends a copy of the whole error state (and
of x) to the state, so the covariance grows to (18 (1 + n)) square; every equation is then a
linear map T of that augmented error, P_aug ← T P_aug Tᵀ (+ the noise on the current block):
the current block moves by Φ, I − K H and G, the clones stay.

Recovery (`recover_after`): a sample refused after that many refusals of its kind in a row is
applied with P_aug and R multiplied by λ = NIS / gate before the update, literally.  On arrival the fix measures its
clone, H_aug reads that clone's q; the gain changes the current error only (Larsen's update: the
clones are not revised), then the clone is dropped.  Nothing of the C's projected bookkeeping.

Held disturbance (`update_imu_held`): the acceleration a = M⁻¹ w of the torque held over the
period is appended to the augmented state after the clones (prior 0, M⁻¹ D² M⁻¹ / hold) and the
sample reads it through ∂y/∂ν̇; its gain revises the current error and a (not the clones); later
samples move the current error alone; each predict within its period is the linear map e ← Φ e + g a
on ν's rows (g: the part of dt in the period), a ← a, with the torque noise over dt − g only; a is
dropped when its period ends.

Observability constraint (`constrained`): N (12, k), the directions the IMU and the encoders cannot
see in the error coordinates (`unobservable`), is taken at the start and after every predict at the
predicted state, and moved by every reset (N ← G N); the predict's F is replaced by
F − (F N − N') (Nᵀ N)⁻¹ Nᵀ with N' at the new state, the IMU's and the encoders' H by
H − H N (Nᵀ N)⁻¹ Nᵀ, both written out as such.

Every change of P_aug is announced to two hooks that do nothing here: `linear(T)` (the augmented
error e ← T e, T of any shape: a step, a gain, a reset, a clone, a block appended or dropped) and
`noise(rows, C, gain)` (then e[rows] += w, w of covariance C; for an update −K v, v its sample's noise); a gated sample announces nothing.  A
subclass that records them has the linear error system the filter assumes
(runtime/estimation/surrogate.py).
"""
import numpy as np

from .. import sensors
from ..state import IDX_E_NU, IDX_E_Q, IDX_E_XI_S, IDX_NU, IDX_Q, IDX_RS, NE, NV

NB = NE + 6
KINDS = ("imu", "encoders", "position", "heading")


def right_jacobian(phi):
    """Jr(φ) of SO(3), Exp(φ + ε) = Exp(φ) Exp(Jr(φ) ε) + O(ε²), as its power series
    Σₖ (−[φ]×)ᵏ / (k + 1)!: no closed form, whose 1 − cos t and t − sin t cancel for small angles."""
    W = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
    J, term = np.eye(3), np.eye(3)
    for k in range(1, 40):
        term = term @ (-W) / (k + 1)
        J = J + term
    return J


def unobservable(model, x):
    """N(x) (12, k): the whole robot turned about the floor's normal (R_S → Rz(α) R_S = R_S Exp(α R_Sᵀ e_z),
    q → Rz(α) q; on a level floor only), then moved along the floor's x and y."""
    cols = []
    if model.params.slope == 0:
        n = np.zeros(NE)
        n[IDX_E_XI_S] = x[IDX_RS].reshape(3, 3).T @ np.array([0.0, 0.0, 1.0])
        q = x[IDX_Q]
        n[IDX_E_Q] = (-q[1], q[0])
        cols.append(n)
    for k in range(2):
        n = np.zeros(NE)
        n[IDX_E_Q.start + k] = 1.0
        cols.append(n)
    return np.column_stack(cols)


def nearest_with(A, N, B):
    """The matrix nearest A (Frobenius) with A N = B: A − (A N − B) (Nᵀ N)⁻¹ Nᵀ."""
    return A - (A @ N - B) @ np.linalg.solve(N.T @ N, N.T)


def wrapped(angle):
    """An angle difference brought into (−π, π] through the unit circle."""
    return float(np.angle(np.exp(1j * angle)))


class EkfReference:
    """The filter's state (x, b, P) and its counters; one method per equation of sr_ekf.h.
    `P` is the current error's block of the augmented covariance `P_aug`; `clones` the marked
    fixes' states by slot, in the order of their blocks."""

    def __init__(self, model, x0, bias, P0, method="rkmk4", recover_after=None, constrained=False):
        self.model, self.method = model, method
        self.recover_after = dict(recover_after or {})
        self.streak = dict.fromkeys(KINDS, 0)
        self.recovered = dict.fromkeys(KINDS, 0)
        self.x = np.array(x0, dtype=float)
        self.b = np.array(bias, dtype=float)
        self.P_aug = np.array(P0, dtype=float)
        self.clones = {}
        self.held = None                  # the held disturbance's mean (NV,), its block last in P_aug
        self.held_remaining = 0.0         # how much of its period is left [s]
        self.accepted = dict.fromkeys(KINDS, 0)
        self.gated = dict.fromkeys(KINDS, 0)
        self.nis = dict.fromkeys(KINDS, 0.0)
        self.N = unobservable(model, self.x) if constrained else None

    @property
    def P(self):
        """The covariance (18, 18) of the current error."""
        return self.P_aug[:NB, :NB].copy()

    @P.setter
    def P(self, value):
        self.P_aug[:NB, :NB] = value

    def linear(self, T):
        """Hook: the augmented error has become T e (T (new size, old size))."""

    def noise(self, rows, C, gain=None):
        """Hook: the augmented error's entries `rows` have then received noise of covariance C (an
        update's K R Kᵀ, with its `gain` K)."""

    def transform(self, A):
        """The current error e ← A e with the clones kept: P_aug ← T P_aug Tᵀ, T = diag(A, I)
        (the current block itself is set by the equation's own method)."""
        T = np.eye(len(self.P_aug))
        T[:NB, :NB] = A
        self.linear(T)
        P = self.P
        self.P_aug = T @ self.P_aug @ T.T
        self.P = P

    def mark_position(self, slot):
        """A fix measured now that arrives later: a clone of x and of the error."""
        self.drop(slot)
        n = len(self.P_aug)
        k = n - (NV if self.held is not None else 0)     # before the held disturbance's block
        T = np.vstack([np.eye(n)[:k], np.eye(NB, n), np.eye(n)[k:]])
        self.linear(T)
        self.P_aug = T @ self.P_aug @ T.T
        self.clones[slot] = self.x.copy()

    def drop(self, slot):
        """Forgets a clone (its rows and columns of P_aug)."""
        if slot in self.clones:
            k = NB * (1 + list(self.clones).index(slot))
            keep = np.r_[0:k, k + NB:len(self.P_aug)]
            self.linear(np.eye(len(self.P_aug))[keep])
            self.P_aug = self.P_aug[np.ix_(keep, keep)]
            del self.clones[slot]

    def process_noise(self, dt, torque_psd, gyro_bias_rw, accel_bias_rw):
        """Q (18, 18) over dt: white generalized torques on ν through M⁻¹, random-walk biases."""
        Minv = np.linalg.inv(self.model.inertia(self.x))
        s, y, p = torque_psd
        W = np.diag([s * s, s * s, s * s, y * y, p * p])
        Q = np.zeros((NB, NB))
        Q[IDX_E_NU, IDX_E_NU] = dt * Minv @ W @ Minv.T
        Q[NE:NE + 3, NE:NE + 3] = dt * gyro_bias_rw ** 2 * np.eye(3)
        Q[NE + 3:, NE + 3:] = dt * accel_bias_rw ** 2 * np.eye(3)
        return Q

    def propagate(self, F, Q):
        """Φ P Φᵀ + Q with Φ = diag(F, I₆): the biases do not enter the step."""
        Phi = np.eye(NB)
        Phi[:NE, :NE] = F
        return Phi @ self.P @ Phi.T + Q

    def predict(self, u, dt, torque_psd, gyro_bias_rw=0.0, accel_bias_rw=0.0):
        """x ← step(x, u, dt) by the filter's method; P ← Φ P Φᵀ + Q with F the Lie–Euler step's
        Jacobian at the prior x whatever the method (the filter's transition matrix,
        docs/estimation.md); with a held disturbance a, the step also moves ν by dt a, and a
        replaces the torque noise."""
        u = np.asarray(u, dtype=float)
        F, _ = self.model.casadi_step_jacobian(self.x, u, dt, "lie-euler")
        if self.held is not None:
            g = min(dt, self.held_remaining)
            Q = self.process_noise(dt, torque_psd, gyro_bias_rw, accel_bias_rw)
            Q[IDX_E_NU, IDX_E_NU] *= (dt - g) / dt
            self.x = self.model.step(self.x, u, dt, self.method)
            F = self.constrain_transition(F)
            self.x[IDX_NU] += g * self.held
            n = len(self.P_aug)
            T = np.eye(n)
            T[:NE, :NE] = F
            T[IDX_E_NU, n - NV:] = g * np.eye(NV)
            self.linear(T)
            self.noise(np.r_[0:NB], Q)
            self.P_aug = T @ self.P_aug @ T.T
            self.P = self.P + Q
            self.held_remaining -= g
            if not self.held_remaining > 1e-9 * dt:
                self.linear(np.eye(n)[:n - NV])
                self.P_aug = self.P_aug[:n - NV, :n - NV]
                self.held = None
            return
        Q = self.process_noise(dt, torque_psd, gyro_bias_rw, accel_bias_rw)
        self.x = self.model.step(self.x, u, dt, self.method)
        F = self.constrain_transition(F)
        P = self.propagate(F, Q)
        Phi = np.eye(NB)
        Phi[:NE, :NE] = F
        self.transform(Phi)
        self.noise(np.r_[0:NB], Q)
        self.P = P

    def constrain_transition(self, F):
        """With the constraint, F's nearest with F N = N(x) at the stepped x, which becomes N."""
        if self.N is None:
            return F
        N = unobservable(self.model, self.x)
        F = nearest_with(F, self.N, N)
        self.N = N
        return F

    def constrain_sample(self, H):
        """With the constraint, the IMU's or the encoders' H nearest with H N = 0."""
        if self.N is None:
            return H
        H = H.copy()
        H[:, :NE] = nearest_with(H[:, :NE], self.N, np.zeros((len(H), self.N.shape[1])))
        return H

    @staticmethod
    def accepts(nis, gate):
        """The chi-square gate."""
        return nis <= gate

    def admission(self, kind, nis, gate):
        """The gate with the recovery policy: None (refused, counted), or the factor λ by which the
        prior and the sample's noise are inflated for it (1 when it passes; NIS / gate when it
        recovers after `recover_after[kind]` refusals in a row)."""
        if self.accepts(nis, gate):
            return 1.0
        after = self.recover_after.get(kind, 0)
        if after > 0 and self.streak[kind] >= after:
            return nis / gate
        self.gated[kind] += 1
        self.streak[kind] += 1
        return None

    def admitted(self, kind, lam):
        """Counts an applied sample (`lam` > 1: a recovery)."""
        if lam > 1:
            self.recovered[kind] += 1
        else:
            self.accepted[kind] += 1
        self.streak[kind] = 0

    def gain(self, H, S):
        """K = P Hᵀ S⁻¹ (through a solve with S; S and P symmetric)."""
        return np.linalg.solve(S, H @ self.P).T

    def joseph(self, K, H, R):
        """(I − K H) P (I − K H)ᵀ + K R Kᵀ."""
        A = np.eye(NB) - K @ H
        return A @ self.P @ A.T + K @ R @ K.T

    def inject(self, e):
        """x ← x ⊕ e_d, b ← b + e_b."""
        self.x = self.model.retract(self.x, e[:NE])
        self.b = self.b + e[NE:]

    def reset(self, e):
        """P ← G P Gᵀ, G = I but Jr(e_ξ) on the shell's block."""
        G = np.eye(NB)
        G[IDX_E_XI_S, IDX_E_XI_S] = right_jacobian(e[IDX_E_XI_S])
        P = G @ self.P @ G.T
        self.transform(G)
        self.P = P
        if self.N is not None:
            self.N = G[:NE, :NE] @ self.N

    def _update(self, kind, r, H, R, gate):
        S = H @ self.P @ H.T + R
        nis = float(r @ np.linalg.solve(S, r))
        self.nis[kind] = nis
        lam = self.admission(kind, nis, gate)
        if lam is None:
            return False
        if lam != 1.0:
            self.P_aug = lam * self.P_aug
            R = lam * R
            S = H @ self.P @ H.T + R
        K = self.gain(H, S)
        e = K @ r
        P = self.joseph(K, H, R)
        self.transform(np.eye(NB) - K @ H)
        self.noise(np.r_[0:NB], K @ R @ K.T, K)
        self.P = P
        self.inject(e)
        self.reset(e)
        self.admitted(kind, lam)
        return True

    def update_imu(self, y, u, mount, sigma_gyro, sigma_accel, gate):
        """One IMU sample (6,) under the torques u; `sigma_accel` one number or one per axis (3,)."""
        yh, H = sensors.imu_jacobian(self.model, self.x, u, mount=mount, bias=self.b)
        H = self.constrain_sample(H)
        R = np.diag(np.concatenate([np.full(3, sigma_gyro), np.broadcast_to(sigma_accel, (3,))]) ** 2)
        return self._update("imu", np.asarray(y) - yh, H, R, gate)

    def update_imu_held(self, y, u, mount, sigma, torque_psd, hold, gate):
        """One IMU sample (6,) under the torques u that also reads the torque disturbance held over
        `hold` seconds (appended unless one is held already); `sigma` (6,) the readings' own noise."""
        yh, H = sensors.imu_jacobian(self.model, self.x, u, mount=mount, bias=self.b)
        _, _, Hn = sensors.imu_partials(self.model, self.x, np.zeros(NV), mount=mount, bias=self.b)
        H = self.constrain_sample(H)
        new = self.held is None
        if new:
            Minv = np.linalg.inv(self.model.inertia(self.x))
            s_, y_, p_ = torque_psd
            Qa = Minv @ np.diag([s_ * s_, s_ * s_, s_ * s_, y_ * y_, p_ * p_]) @ Minv.T / hold
            n = len(self.P_aug)
            P_aug = np.zeros((n + NV, n + NV))
            P_aug[:n, :n], P_aug[n:, n:] = self.P_aug, Qa
            self.linear(np.eye(n + NV, n))
            self.noise(np.r_[n:n + NV], Qa)
            self.P_aug, self.held, self.held_remaining = P_aug, np.zeros(NV), hold
        n = len(self.P_aug)
        H_aug = np.zeros((6, n))
        H_aug[:, :NB], H_aug[:, n - NV:] = H, Hn
        r = np.asarray(y) - yh - Hn @ self.held
        R = np.diag(np.asarray(sigma, dtype=float) ** 2)
        S = H_aug @ self.P_aug @ H_aug.T + R
        nis = float(r @ np.linalg.solve(S, r))
        self.nis["imu"] = nis
        lam = self.admission("imu", nis, gate)
        if lam is None:
            if new:
                self.linear(np.eye(n)[:n - NV])
                self.P_aug, self.held = self.P_aug[:n - NV, :n - NV], None
            return False
        if lam != 1.0:
            self.P_aug = lam * self.P_aug
            R = lam * R
            S = H_aug @ self.P_aug @ H_aug.T + R
        rows = np.r_[0:NB, n - NV:n]
        K = np.linalg.solve(S, H_aug @ self.P_aug[:, rows]).T
        T = np.eye(n)
        T[rows] -= K @ H_aug
        self.linear(T)
        self.noise(rows, K @ R @ K.T, K)
        self.P_aug = T @ self.P_aug @ T.T
        self.P_aug[np.ix_(rows, rows)] += K @ R @ K.T
        e = K[:NB] @ r
        self.held = self.held + K[NB:] @ r
        self.inject(e)
        self.reset(e)
        self.admitted("imu", lam)
        return True

    def update_encoders(self, y, sigma, gate):
        """One encoder sample (θ_Y, θ_P)."""
        yh, H = sensors.encoders_jacobian(self.model, self.x)
        H = self.constrain_sample(H)
        r = np.array([wrapped(y[0] - yh[0]), wrapped(y[1] - yh[1])])
        return self._update("encoders", r, H, sigma ** 2 * np.eye(2), gate)

    def update_position(self, y, sigma, gate):
        """One position fix (q_x, q_y)."""
        yh, H = sensors.position_jacobian(self.model, self.x)
        return self._update("position", np.asarray(y) - yh, H, sigma ** 2 * np.eye(2), gate)

    def update_heading(self, y, mount, sigma, gate):
        """One heading sample."""
        yh, H = sensors.heading_jacobian(self.model, self.x, mount)
        return self._update("heading", np.array([wrapped(y - yh)]), H[None, :], np.array([[sigma ** 2]]), gate)

    def update_position_delayed(self, slot, y, sigma, gate):
        """The fix y measured when `slot` was marked: H_aug reads its clone; the gain moves the
        current error alone, e ← e − K r, so P_aug ← T P_aug Tᵀ + K R Kᵀ with T = I but −K H in
        the clone's columns."""
        k = NB * (1 + list(self.clones).index(slot))
        yh, H = sensors.position_jacobian(self.model, self.clones[slot])
        R = sigma ** 2 * np.eye(2)
        H_aug = np.zeros((2, len(self.P_aug)))
        H_aug[:, k:k + NB] = H
        S = H_aug @ self.P_aug @ H_aug.T + R
        r = np.asarray(y) - yh
        nis = float(r @ np.linalg.solve(S, r))
        self.nis["position"] = nis
        lam = self.admission("position", nis, gate)
        if lam is None:
            self.drop(slot)
            return False
        if lam != 1.0:
            self.P_aug = lam * self.P_aug
            R = lam * R
            S = H_aug @ self.P_aug @ H_aug.T + R
        K = np.linalg.solve(S, H_aug @ self.P_aug[:, :NB]).T
        T = np.eye(len(self.P_aug))
        T[:NB] -= K @ H_aug
        self.linear(T)
        self.noise(np.r_[0:NB], K @ R @ K.T, K)
        self.P_aug = T @ self.P_aug @ T.T
        self.P = self.P + K @ R @ K.T
        e = K @ r
        self.drop(slot)
        self.inject(e)
        self.reset(e)
        self.admitted("position", lam)
        return True
