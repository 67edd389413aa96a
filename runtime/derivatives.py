"""Derivatives of the dynamics in the error coordinates of `runtime.group`.

`accel_jacobian` is C (c/sr_jacobians.c, from the symbolic derivatives of derive/derivatives.py);
`linearize` assembles the continuous-time error dynamics from it and the kinematics of the
group, whose derivatives are short enough to write here in closed form.
"""
import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .state import IDX_E_NU, IDX_E_Q, IDX_E_TH_P, IDX_E_TH_Y, IDX_E_XI_S, IDX_WS, NE, NU, NV, rotations



class DerivativeMethods:
    """`accel_jacobian` and `linearize` of `Model` (which provides _model, _state_and_input, _check)."""

    def accel_jacobian(self, x, u=None):
        """(Ja, Jb): ν̇(x ⊕ d, u + w) = ν̇(x, u) + Ja d + Jb w + O(|d|² + |w|²).

        Ja (5, 12), Jb (5, 2) for one state; (B, 5, 12), (B, 5, 2) for x (B, 35), u (B, 2) or None.
        """
        x, u = self._state_and_input(x, u)
        lead = x.shape[:-1]
        Ja, Jb = np.empty(lead + (NV, NE)), np.empty(lead + (NV, NU))
        if x.ndim == 1:
            self._check("x", lib.sr_accel_jacobian(self._model, pointer(x), pointer(u), pointer(Ja), pointer(Jb)))
            return Ja, Jb
        failed = ffi.new("long *")
        status = lib.sr_accel_jacobian_batch(self._model, x.shape[0], pointer(x), pointer(u), pointer(Ja), pointer(Jb), failed)
        self._check(f"x[{failed[0]}]" if failed[0] >= 0 else "x", status)
        return Ja, Jb

    def linearize(self, x, u=None):
        """(A, B), (12, 12) and (12, 2): the error dynamics δ̇ = A δ + B w of x(t) ⊕ δ(t) about the
        solution through x under u + w (batches: leading axis B).

        With ω = ω_S: δξ̇ = −ω × δξ + δω_S (right-trivialised, Ω_S = R_Sᵀ Ṙ_S), δθ̇_Y = δω_Y,
        δθ̇_P = δω_P, δq̇ = r P R_S (δω_S − ω × δξ) (from q̇ = r (R_S ω) × e_z; P picks
        (v_y, −v_x) of v × e_z), δν̇ = Ja δ + Jb w.
        """
        Ja, Jb = self.accel_jacobian(x, u)
        x = np.asarray(x, dtype=np.float64)
        lead = x.shape[:-1]
        w = x[..., IDX_WS]
        R_S = rotations(x)[0]
        W = -np.cross(w[..., None, :], np.eye(3))     # ⟦w⟧ of each state, row k = −(w × e_k); B = 0 too
        P = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
        A = np.zeros(lead + (NE, NE))
        B = np.zeros(lead + (NE, NU))
        nu_S = slice(IDX_E_NU.start, IDX_E_NU.start + 3)
        A[..., IDX_E_XI_S, IDX_E_XI_S] = -W
        A[..., IDX_E_XI_S, nu_S] = np.eye(3)
        A[..., IDX_E_TH_Y, IDX_E_NU.start + 3] = 1.0
        A[..., IDX_E_TH_P, IDX_E_NU.start + 4] = 1.0
        PR = self.params.r * (P @ R_S)
        A[..., IDX_E_Q, IDX_E_XI_S] = -PR @ W
        A[..., IDX_E_Q, nu_S] = PR
        A[..., IDX_E_NU, :] = Ja
        B[..., IDX_E_NU, :] = Jb
        return A, B

