"""The Jacobians of the identification fit, from one of three sources (`JACOBIANS`): the analytic
ones of the C library (the parameter sensitivities on the free columns alone, and a step's state
Jacobian with them in one pass: `Model.step_jacobians`, `Model.param_jacobian` with `columns`);
finite differences computed in C, batched, for the parameter columns (`Model.step_param_jacobian_fd`;
the accelerations at p ± h) beside the analytic state Jacobians; or finite differences for every
Jacobian, the state ones too (every state moved along each error direction, one batched step)."""
import numpy as np

from ..model import Model
from ..param_derivatives import PARAMETER_NAMES
from ..params import Params
from ..state import NE, NV

#: The sources of the Jacobians a fit can use: "analytic", the C library's; "fd", central
#: differences computed in C, batched, for the parameter columns (per parameter the robot at p ± h,
#: every state stepped at once: `Model.step_param_jacobian_fd`) with the analytic state Jacobians;
#: "fd-all", central differences for the state Jacobians as well.  All reach the same optimum; "fd"
#: is the reference that the analytic sensitivities' speed-up is measured against, "fd-all" a fit
#: with no analytic derivative at all.
JACOBIANS = ("analytic", "fd", "fd-all")

#: The step of the state Jacobians' central differences (error coordinates: rad, m, rad/s).
STATE_STEP = 6e-6


def step_sensitivity(model, x, u, h, method, idx, jacobian):
    """The steps' sensitivities (B, 12, len(idx)) to the free entries idx, of the `jacobian` source."""
    if jacobian != "analytic":
        return model.step_param_jacobian_fd(x, u, h, method, columns=idx)
    return model.step_param_jacobian(x, u, h, method, columns=idx)


def step_and_sensitivity(model, x, u, h, method, idx, jacobian):
    """(x_next, Jp): the steps (B, 35) and `step_sensitivity`'s Jp.  The analytic source gives both
    from one pass of the stages (`Model.step_and_param_jacobian`); the differences never evaluate
    the robot at p itself, so theirs is one batched `Model.step` more."""
    if jacobian == "analytic":
        return model.step_and_param_jacobian(x, u, h, method, columns=idx)
    return model.step(x, u, h, method), step_sensitivity(model, x, u, h, method, idx, jacobian)


def step_jacobians(model, x, u, h, method, idx, jacobian):
    """(F, Jp): the steps' state Jacobians (B, 12, 12) and their sensitivities (B, 12, len(idx)) to
    the free entries idx at the same states x (B, 35), of the `jacobian` source: analytic in one
    pass (`Model.step_jacobians`), or the differences' Jp beside the analytic F ("fd") or F by
    differences too ("fd-all")."""
    if jacobian == "analytic":
        return model.step_jacobians(x, u, h, method, columns=idx)
    return step_state_jacobian(model, x, u, h, method, jacobian), model.step_param_jacobian_fd(x, u, h, method,
                                                                                              columns=idx)


def step_state_jacobian(model, x, u, h, method, jacobian):
    """The steps' state Jacobians F (B, 12, 12) alone, of the `jacobian` source: by differences for
    "fd-all", else the analytic `Model.step_jacobian`."""
    if jacobian == "fd-all":
        return differenced_state_jacobian(model, x, u, h, method)
    return model.step_jacobian(x, u, h, method)[0]


def accel_state_jacobian(model, x, u, jacobian):
    """∂ν̇/∂x in the error coordinates (B, 5, 12) of the `jacobian` source: `Model.accel_jacobian`,
    or central differences of the batched C accelerations for "fd-all"."""
    if jacobian != "fd-all":
        return model.accel_jacobian(x, u)[0]
    return _differenced(model, x, u, lambda xs, us: model.accel(xs, us))


def differenced_state_jacobian(model, x, u, h, method):
    """F (B, 12, 12) of `Model.step_jacobian` by central differences: every state moved ± STATE_STEP
    along each error direction and stepped in one batch, the steps compared by `local`."""
    y0 = model.step(x, u, h, method)
    return _differenced(model, x, u, lambda xs, us: model.local(np.repeat(y0, 2 * NE, axis=0),
                                                               model.step(xs, us, h, method)))


def _differenced(model, x, u, value):
    """(value at x ⊕ s e_j − value at x ⊖ s e_j) / 2s for every error direction j, (B, m, 12); value
    takes the moved states and their torques, all 2·12·B at once."""
    n = len(x)
    steps = np.vstack([STATE_STEP * np.eye(NE), -STATE_STEP * np.eye(NE)])
    moved = model.retract(np.repeat(x, 2 * NE, axis=0), np.tile(steps, (n, 1)))
    v = np.asarray(value(moved, np.repeat(u, 2 * NE, axis=0))).reshape(n, 2, NE, -1)
    return np.swapaxes(v[:, 0] - v[:, 1], 1, 2) / (2 * STATE_STEP)


def accel_sensitivity(model, x, u, idx, jacobian):
    """∂ν̇/∂θ (B, 5, len(idx)) of the `jacobian` source: "fd" and "fd-all" by central differences of the batched
    C accelerations at p ± h; where one side is no valid robot, the one-sided second-order
    difference (4 D(s) − D(2s)) / 2s from the other, as `Model.step_param_jacobian_fd`."""
    if jacobian == "analytic":
        return model.param_jacobian(x, u, columns=idx)
    p = model.params.as_array()
    out = np.empty(x.shape[:-1] + (NV, len(idx)))

    def accel_at(i, step):
        q = p.copy()
        q[i] += step
        try:
            return Model(Params.from_array(q)).accel(x, u)
        except ValueError:
            return None

    for c, i in enumerate(idx):
        h = 6e-6 * (abs(p[i]) if p[i] != 0 else 1.0)
        plus, minus = accel_at(i, h), accel_at(i, -h)
        if plus is not None and minus is not None:
            out[:, :, c] = (plus - minus) / (2 * h)
            continue
        s, one = (h, plus) if plus is not None else (-h, minus)
        if one is None:
            raise ValueError(f"params: {PARAMETER_NAMES[i]} has no valid robot on either side of its value; "
                             "no difference exists")
        f0 = model.accel(x, u)
        out[:, :, c] = (4 * (one - f0) - (accel_at(i, 2 * s) - f0)) / (2 * s)
    return out
