"""The model's whole-state vector field for general-purpose ODE integrators (make verify's invariants,
the variational equations of runtime/verification/jacobians.py)."""
import numpy as np

from ..so3 import hat
from ..state import IDX_NU, IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, NX, rotations
from ..validation import project_state


def state_derivative(model, x, u=None):
    """ẋ for the whole 35-vector: Ṙ_S = R_S⟦ω_S⟧, Ṙ_Y = R_Y ω_Y Σ_Y, Ṙ_P = R_P ω_P Σ_P, q̇ = r R_S(ω_S × γ), ν̇.

    The dynamics live on SO(3)³; a Runge–Kutta integrator in ℝ³⁵ evaluates stages slightly
    off it, so the vector field is extended by projection (`project_state`).
    """
    xp = project_state(x, model.params.r)
    R_S, R_Y, R_P = rotations(xp)
    w = xp[IDX_WS]
    d = np.empty(NX)
    d[IDX_RS] = (R_S @ hat(w)).ravel()
    d[IDX_RY] = (R_Y @ hat([xp[IDX_WY], 0, 0])).ravel()
    d[IDX_RP] = (R_P @ hat([0, xp[IDX_WP], 0])).ravel()
    d[IDX_Q] = model.params.r * R_S @ np.cross(w, R_S[2])
    d[IDX_NU] = model.accel(xp, u)
    return d
