"""The model as CasADi Functions, as `make generate` wrote them into generated/casadi/.

    from runtime import casadi_model
    accel = casadi_model.load("sr_accel")            # accel(x[35], u[2], p) -> nu_dot[5]
    step = casadi_model.load("sr_step_rkmk4")        # step(x[35], u[2], dt, p) -> x_next[35]
    p = casadi_model.parameter_vector(Params())

They are derived from the same M and f as the C kernels (derive/casadi_model.py), agree with
them to round-off (tests/runtime/test_casadi_model.py), and are plain SX Functions: CasADi's
AD, code generation, `map` and the NLP solvers take them as they are (acados too).  The state
and parameter layouts are those of the C (SR_X_*, SR_P_*).
"""
import pathlib

import numpy as np

from .params import Params
from .validation import choice

FOLDER = pathlib.Path(__file__).resolve().parents[1] / "generated" / "casadi"
NAMES = ("sr_accel", "sr_step_lie_euler", "sr_step_rkmk4", "sr_step_cf4")


def path(name):
    """The serialized Function `name` (one of NAMES) in generated/casadi/."""
    return FOLDER / f"{choice(name, 'name', NAMES, 'Function')}.casadi"


def load(name):
    """casadi.Function `name` (one of NAMES), deserialized from generated/casadi/."""
    import casadi

    file = path(name)
    if not file.exists():
        raise ValueError(f"casadi_model.load: {file} is missing; run `make generate`")
    return casadi.Function.load(str(file))


def parameter_vector(params):
    """p for the Functions: the parameters in SR_P_* order."""
    if not isinstance(params, Params):
        raise ValueError(f"casadi_model.parameter_vector: params must be a runtime.Params, got {type(params).__name__}")
    return np.array(params.as_array(), dtype=float)
