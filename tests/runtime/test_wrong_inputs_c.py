"""The C API through cffi (bindings._sr), given wrong input of every kind it can receive from C: NULL
pointers, NaN/inf and overflow-size entries, unknown method codes, negative or absurd row counts,
bad time steps.  The contract (c/include/spherical_robot.h, docs/robustness.md): the status is one
of the documented codes and the one the wrong input calls for, every output is finite on SR_OK, and
a single-state kernel leaves its outputs untouched on error."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from wrong_inputs import HUGE, NONFINITE, SETTINGS

from bindings._sr import ffi, lib
from runtime import Model, Params, initial_state

NX, NU, NV, NE, NP = lib.SR_NX, lib.SR_NU, lib.SR_NV, lib.SR_NE, lib.SR_NPARAM
MODEL = Model(Params.paper_simulation())
X = initial_state(theta_Y=0.2, theta_P=0.4, w_S=[0.1, -0.2, 0.3], r=MODEL.params.r)
CODES = set(range(0, 11))
CANARY = 12345.678

#: name -> its arguments: "model", "method", "n", "dt", "failed", or (role, entries per row) for a
#: buffer: role "in" (state-like: x, y), "u", "d", "w" (inputs) or "out".
FUNCTIONS = {
    "sr_check_state": ["model", ("x", NX)],
    "sr_accel": ["model", ("x", NX), ("u", NU), ("out", NV)],
    "sr_inertia": ["model", ("x", NX), ("out", NV * NV)],
    "sr_rhs": ["model", ("x", NX), ("u", NU), ("out", NV)],
    "sr_energy": ["model", ("x", NX), ("out", 1)],
    "sr_equilibrium_residual": ["model", ("x", NX), ("out", NV)],
    "sr_so3_exp": [("w", 3), ("out", 9)],
    "sr_step": ["model", "method", ("x", NX), ("u", NU), "dt", ("out", NX)],
    "sr_retract": ["model", ("x", NX), ("d", NE), ("out", NX)],
    "sr_local": ["model", ("x", NX), ("y", NX), ("out", NE)],
    "sr_accel_jacobian": ["model", ("x", NX), ("u", NU), ("out", NV * NE), ("out", NV * NU)],
    "sr_step_jacobian": ["model", "method", ("x", NX), ("u", NU), "dt", ("out", NE * NE), ("out", NE * NU)],
    "sr_check_state_batch": ["model", "n", ("x", NX), "failed"],
    "sr_accel_batch": ["model", "n", ("x", NX), ("u", NU), ("out", NV), "failed"],
    "sr_checked_accel_batch": ["model", "n", ("x", NX), ("u", NU), ("out", NV), "failed"],
    "sr_step_batch": ["model", "method", "n", ("x", NX), ("u", NU), "dt", ("out", NX), "failed"],
    "sr_retract_batch": ["model", "n", ("x", NX), ("d", NE), ("out", NX), "failed"],
    "sr_local_batch": ["model", "n", ("x", NX), ("y", NX), ("out", NE), "failed"],
    "sr_accel_jacobian_batch": ["model", "n", ("x", NX), ("u", NU), ("out", NV * NE), ("out", NV * NU), "failed"],
    "sr_step_jacobian_batch": ["model", "method", "n", ("x", NX), ("u", NU), "dt", ("out", NE * NE),
                               ("out", NE * NU), "failed"],
    "sr_accel_param_jacobian": ["model", ("x", NX), ("u", NU), ("out", NV * NP)],
    "sr_accel_param_jacobian_batch": ["model", "n", ("x", NX), ("u", NU), ("out", NV * NP), "failed"],
    "sr_step_param_jacobian": ["model", "method", ("x", NX), ("u", NU), "dt", ("out", NE * NP)],
    "sr_step_param_jacobian_batch": ["model", "method", "n", ("x", NX), ("u", NU), "dt", ("out", NE * NP), "failed"],
    "sr_regressor": ["model", ("x", NX), ("a", NV), ("out", NV * lib.SR_NPI)],
    "sr_regressor_batch": ["model", "n", ("x", NX), ("a", NV), ("out", NV * lib.SR_NPI), "failed"],
}
VALID = {"x": X, "y": MODEL.retract(X, np.full(NE, 0.01)), "u": np.array([0.1, -0.1]),
         "d": np.linspace(-0.1, 0.1, NE), "w": np.array([0.1, 0.2, -0.3]), "a": np.array([0.5, -0.2, 0.1, 1.0, -2.0])}
#: Pointers a function may take as NULL (documented: u, zero torque; failed_row).
OPTIONAL = {"failed"}
FULL_CHECK = {"sr_check_state", "sr_check_state_batch", "sr_checked_accel_batch", "sr_step", "sr_step_batch",
              "sr_step_jacobian", "sr_step_jacobian_batch", "sr_accel_param_jacobian", "sr_accel_param_jacobian_batch",
              "sr_step_param_jacobian", "sr_step_param_jacobian_batch", "sr_regressor", "sr_regressor_batch",
              "sr_retract", "sr_local", "sr_retract_batch", "sr_local_batch"}
METHODS = {lib.SR_LIE_EULER, lib.SR_RKMK4, lib.SR_CF4}
#: The methods of the functions that take fewer (the parameter Jacobians: Lie-Euler and RKMK4).
METHODS_OF = {"sr_step_param_jacobian": {lib.SR_LIE_EULER, lib.SR_RKMK4},
              "sr_step_param_jacobian_batch": {lib.SR_LIE_EULER, lib.SR_RKMK4}}


@st.composite
def calls(draw, name):
    """(arguments as Python values, the mutation, the status it calls for or None for any documented)."""
    spec = FUNCTIONS[name]
    rows = draw(st.integers(1, 4)) if "n" in spec else 1
    methods = METHODS_OF.get(name, METHODS)
    args = {"n": rows, "dt": 0.01, "method": draw(st.sampled_from(sorted(methods)))}
    buffers = [np.tile(VALID[arg[0]], (rows, 1)).ravel() if arg[0] != "out" else np.full(rows * arg[1], CANARY)
               for arg in spec if isinstance(arg, tuple)]
    kinds = ["nonfinite", "huge", "null"]
    kinds += ["method"] if "method" in spec else []
    kinds += ["n"] if "n" in spec else []
    kinds += ["dt"] if "dt" in spec else []
    kind = draw(st.sampled_from(kinds))
    expect, null = None, None
    inputs = [i for i, arg in enumerate(a for a in spec if isinstance(a, tuple)) if arg[0] != "out"]
    if kind in ("nonfinite", "huge"):
        target = draw(st.sampled_from(inputs))
        buffers[target][draw(st.integers(0, buffers[target].size - 1))] = draw(
            st.sampled_from(NONFINITE if kind == "nonfinite" else HUGE))
        # The single-state kernels check only the entries of x they read (documented); the full
        # check, and every other input, refuses any NaN.
        partial = spec[[i for i, a in enumerate(spec) if isinstance(a, tuple)][target]][0] == "x" \
            and name not in FULL_CHECK
        expect = lib.SR_ERR_NONFINITE if kind == "nonfinite" and not partial else None
    elif kind == "null":
        pointers = [i for i, arg in enumerate(spec) if arg == "model" or arg == "failed" or isinstance(arg, tuple)]
        null = draw(st.sampled_from(pointers))
        expect = None if spec[null] in OPTIONAL or spec[null] == ("u", NU) else lib.SR_ERR_NULL
    elif kind == "method":
        args["method"] = draw(st.integers(-2**31, 2**31 - 1).filter(lambda m: m not in methods | {m | 16 for m in methods}))
        expect = lib.SR_ERR_ARG
    elif kind == "n":
        args["n"] = draw(st.sampled_from([-1, -2**63]))
        expect = lib.SR_ERR_ARG
    elif kind == "dt":
        args["dt"] = draw(st.sampled_from([0.0, -0.01, np.nan, np.inf, -np.inf]))
        expect = lib.SR_ERR_ARG
    return args, buffers, kind, expect, null


def invoke(name, args, buffers, null):
    spec = FUNCTIONS[name]
    c_args, failed, outs = [], ffi.new("long *", -7), []
    buffer_iter = iter(buffers)
    for i, arg in enumerate(spec):
        if i == null:
            c_args.append(ffi.NULL)
            if isinstance(arg, tuple):
                next(buffer_iter)
            continue
        if arg == "model":
            c_args.append(MODEL._model)
        elif arg == "failed":
            c_args.append(failed)
        elif arg in ("method", "n", "dt"):
            c_args.append(args[arg])
        else:
            buffer = next(buffer_iter)
            c_args.append(ffi.cast("double *", ffi.from_buffer(buffer)))
            if arg[0] == "out":
                outs.append(buffer)
    return getattr(lib, name)(*c_args), outs


def check_contract(status, outs, kind, expect, single):
    assert status in CODES, f"{kind}: undocumented status {status}"
    if expect is not None:
        assert status == expect, f"{kind}: status {status}, expected {expect}"
    if status == lib.SR_OK:
        assert all(np.all(np.isfinite(out)) for out in outs), f"{kind}: SR_OK with a non-finite output"
    elif single:
        assert all(np.all(out == CANARY) for out in outs), f"{kind}: an output was written on error"


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
@SETTINGS
@given(data=st.data())
def test_a_wrong_argument_gives_its_documented_status(name, data):
    args, buffers, kind, expect, null = data.draw(calls(name))
    status, outs = invoke(name, args, buffers, null)
    check_contract(status, outs, kind, expect, single="n" not in FUNCTIONS[name])


@pytest.mark.parametrize("status, out, expect", [
    (lib.SR_OK, np.array([np.nan]), None),                       # a NaN reported as success
    (99, np.array([CANARY]), None),                              # a status the header does not list
    (lib.SR_ERR_NONFINITE, np.array([0.0]), None),               # an output written on error
    (lib.SR_ERR_ARG, np.array([CANARY]), lib.SR_ERR_NULL),       # the wrong status for the input
])
def test_the_contract_check_fails_for_a_kernel_that_breaks_it(status, out, expect):
    with pytest.raises(AssertionError):
        check_contract(status, [out], "planted", expect, single=True)
