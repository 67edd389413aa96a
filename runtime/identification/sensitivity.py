"""The parameter sensitivities of the identification fit, from either source (`JACOBIANS`): the
analytic ones of the C library on the free columns alone (`Model.step_param_jacobian`,
`Model.param_jacobian` with `columns`) or finite differences computed in C, batched, on the same
columns (`Model.step_param_jacobian_fd`; the accelerations at p ± h)."""
import numpy as np

from ..model import Model
from ..param_derivatives import PARAMETER_NAMES
from ..params import Params
from ..state import NV

#: The sources of the parameter sensitivities a fit can use: the analytic ones of the C library, or
#: central differences computed in C, batched (per parameter the robot at p ± h, every state stepped
#: at once: `Model.step_param_jacobian_fd`).  Both reach the same optimum; "fd" is the reference
#: that the analytic sensitivities' speed-up is measured against.
JACOBIANS = ("analytic", "fd")


def step_sensitivity(model, x, u, h, method, idx, jacobian):
    """The steps' sensitivities (B, 12, len(idx)) to the free entries idx, of the `jacobian` source."""
    if jacobian == "fd":
        return model.step_param_jacobian_fd(x, u, h, method, columns=idx)
    return model.step_param_jacobian(x, u, h, method, columns=idx)


def accel_sensitivity(model, x, u, idx, jacobian):
    """∂ν̇/∂θ (B, 5, len(idx)) of the `jacobian` source: "fd" by central differences of the batched
    C accelerations at p ± h; where one side is no valid robot, the one-sided second-order
    difference (4 D(s) − D(2s)) / 2s from the other, as `Model.step_param_jacobian_fd`."""
    if jacobian != "fd":
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
