"""Input validation of the Python API: array conversion, state rules, messages, re-projection.

The rules are the C library's (c/spherical_robot.h, `sr_check_state`), and the
C code is what decides: `Model` calls `sr_check_state` / `sr_check_state_batch`
on every state it is given and only when C reports an error does this module
work out, in Python, *which* entry broke *which* rule.  The hot path therefore
costs one extra C call and no NumPy work.

A state x (35 float64, see runtime/state.py) is valid when

* every entry is finite;
* R_S is orthonormal with det +1: every entry of RᵀR − I and det R − 1 within
  ROTATION_TOL (= SR_ROTATION_TOL = 1e-6 of the double build);
* R_Y is a rotation about x: row 0 and column 0 are exactly e_x, and the rest
  is a rotation to ROTATION_TOL; R_P likewise about y (row and column 1 = e_y);
* |q_z − r| ≤ ROTATION_TOL · r.

Arrays: any real numeric dtype (integers, float16/32/64, longdouble) is
converted to float64.  Rejected, with a ValueError naming the argument:
complex (even with zero imaginary part: a complex state is a bug upstream),
bool (True is not a number of radians), object, strings, dates, ragged lists.

Instead of failing, a nearly valid state can be pulled onto the constraints
explicitly with `project_state(x, r)` (or `Model.project(x)`).
"""
import math

import numpy as np

from bindings._sr import ffi, lib

from .errors import KernelError
from .so3 import nearest_rotation, orthonormality, rot_x, rot_y
from .state import IDX_Q, IDX_QZ, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, NX, ROTATION_BLOCKS

ROTATION_TOL = float(lib.SR_ROTATION_TOL)
"""Tolerance of the state checks, exported from C (SR_ROTATION_TOL): entries of RᵀR − I,
det R − 1, and |q_z − r| / r."""

_REAL_KINDS = "iuf"
"""dtype kinds accepted for real arrays: signed and unsigned integers, floats."""
_KIND_NAMES = {"b": "bool", "c": "complex", "O": "object", "U": "string", "S": "bytes",
               "M": "datetime", "m": "timedelta", "V": "structured"}


def _entry_names():
    names = [""] * NX
    for block, idx in ROTATION_BLOCKS.items():
        for k, (i, j) in enumerate((i, j) for i in range(3) for j in range(3)):
            names[idx.start + k] = f"{block}[{i},{j}]"
    for k, axis in enumerate("xyz"):
        names[IDX_Q.start + k] = f"q_{axis}"
        names[IDX_WS.start + k] = f"w_S[{k}]"
    names[IDX_WY], names[IDX_WP] = "w_Y", "w_P"
    assert all(names), "the state layout has an entry without a name"
    return tuple(names)


STATE_ENTRY_NAMES = _entry_names()
"""Name of every entry of the state: STATE_ENTRY_NAMES[12] == "R_Y[1,0]"."""
_JOINT_AXIS = {"R_Y": 0, "R_P": 1}
"""The rotation about a fixed axis of each joint block (row and column `axis` equal e_axis)."""


# -- arrays ------------------------------------------------------------------------------------
def real_array(value, name, shape_tail, batch=True):
    """`value` as a C-contiguous float64 array of shape `shape_tail` (or (B,) + shape_tail if `batch`).

    Raises ValueError("<name>: ...") for a non-real dtype or a wrong shape.
    Finiteness is not checked here (C does it, and `describe_state` explains).
    """
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:      # ragged nested lists, unconvertible objects
        raise ValueError(f"{name}: expected an array of real numbers ({exc})") from None
    if raw.dtype.kind not in _REAL_KINDS:
        kind = _KIND_NAMES.get(raw.dtype.kind, str(raw.dtype))
        raise ValueError(f"{name}: expected real numbers (integer or float dtype), got {kind} "
                         f"(dtype {raw.dtype})")
    arr = np.ascontiguousarray(raw, dtype=np.float64)
    tail_ok = arr.shape[arr.ndim - len(shape_tail):] == shape_tail if arr.ndim >= len(shape_tail) else False
    if not tail_ok or arr.ndim > len(shape_tail) + (1 if batch else 0):
        want = [shape_tail, ("B",) + shape_tail] if batch else [shape_tail]
        raise ValueError(f"{name}: expected shape {' or '.join(map(str, want))}, got {arr.shape}")
    return arr


def check_finite(arr, name, entry_names=None):
    """Raise ValueError naming the first NaN or infinite entry of `arr` ("u[3, 1] is nan")."""
    if arr.size <= 16:                 # the common case, cheapest per call for small arrays
        if all(math.isfinite(v) for v in arr.flat):
            return
    elif np.isfinite(arr).all():
        return
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        index = tuple(int(i) for i in bad[0])
        label = f"{name}[{', '.join(map(str, index))}]" if index else name
        if entry_names is not None:
            label += f" ({entry_names[index[-1]]})"
        raise ValueError(f"{name}: {label} is {float(arr[index])!r}, expected a finite number")


def choice(value, name, choices, kind="value"):
    """`value` if it is one of the strings `choices`, else ValueError naming `name` and the choices.

    The one check of every argument that names one of a fixed set (an integrator, a Function):
    a non-string (a list, None, a number) is refused like an unknown name, not looked up in a
    dict, where an unhashable value would raise TypeError.
    """
    if value.__class__ is not str or value not in choices:
        raise ValueError(f"{name}: unknown {kind} {value!r}; choose one of {', '.join(sorted(choices))}")
    return value

# -- the state rules ----------------------------------------------------------------------------
def describe_state(x, r, name="x"):
    """Why the single state `x` (35,) breaks the rules of `sr_check_state`, or None if it does not.

    `name` is how the caller calls x ("x", "x0", "x[3]"); messages read
    "x: x[12] (R_Y[1,0]) is nan, expected a finite number".
    """
    x = np.asarray(x, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        i = int(bad[0])
        return f"{name}: {name}[{i}] ({STATE_ENTRY_NAMES[i]}) is {float(x[i])!r}, expected a finite number"
    hint = "; Model.project(x) or runtime.project_state(x, r) re-projects a nearly valid state"
    for block, idx in ROTATION_BLOCKS.items():
        R = x[idx].reshape(3, 3)
        where = f"{name}: {block} ({name}[{idx.start}:{idx.stop}])"
        axis = _JOINT_AXIS.get(block)
        if axis is not None:
            for i in range(3):
                for entry, (a, b) in ((R[axis, i], (axis, i)), (R[i, axis], (i, axis))):
                    want = 1.0 if i == axis else 0.0
                    if entry != want:
                        about = "xy"[axis]
                        return (f"{where} must be a rotation about {about}: {block}[{a},{b}] = {float(entry)!r} "
                                f"must be exactly {want:g} (row and column {axis} equal e_{about}){hint}")
        defect, det = orthonormality(R)
        if det < 0:
            return f"{where} is not a rotation: det = {det:.6g}, a reflection (needs det = +1){hint}"
        if defect > ROTATION_TOL:
            return (f"{where} is not orthonormal: max |RᵀR − I| = {defect:.3g} exceeds the tolerance "
                    f"{ROTATION_TOL:g}{hint}")
        if abs(det - 1) > ROTATION_TOL:
            return f"{where} is not a rotation: |det R − 1| = {abs(det - 1):.3g} exceeds {ROTATION_TOL:g}{hint}"
    dz = x[IDX_QZ] - r
    if abs(dz) > ROTATION_TOL * r:
        return (f"{name}: {name}[{IDX_QZ}] (q_z) = {float(x[IDX_QZ])!r} must equal r = {r:g} (the shell rests on the plane): "
                f"off by {dz:.3g}, tolerance {ROTATION_TOL * r:.3g} = {ROTATION_TOL:g}·r{hint}")
    return None


def check_states(model_ptr, x, r, name="x"):
    """Run sr_check_state (x of shape (35,)) or sr_check_state_batch ((B, 35)); on failure raise
    KernelError with the detailed message of `describe_state` (the failing row named "x[i]")."""
    ptr = ffi.from_buffer("double[]", x)
    if x.ndim == 1:
        status, row, row_name, state = lib.sr_check_state(model_ptr, ptr), None, name, x
    else:
        failed = ffi.new("long *")
        status = lib.sr_check_state_batch(model_ptr, x.shape[0], ptr, failed)
        row = failed[0]
        row_name = f"{name}[{row}]" if row >= 0 else name
        state = x[row] if row >= 0 else None
    if status == lib.SR_OK:
        return
    # A model that is not valid is refused before any state is looked at: nothing to describe.
    message = describe_state(state, r, row_name) if state is not None and status != lib.SR_ERR_MODEL else None
    raise KernelError(row_name, status, message=message)


# -- re-projection ------------------------------------------------------------------------------
def project_state(x, r):
    """The nearest valid state: R_S by its polar factor, R_Y (R_P) by the nearest rotation about x (y),
    q_z = r.  x (35,) or (B, 35); returns a new array.  Speeds and q_x, q_y are kept.

    R_Y's angle is atan2(R[2,1] − R[1,2], R[1,1] + R[2,2]) (nearest in the Frobenius norm among
    rotations about x), R_P's atan2(R[0,2] − R[2,0], R[0,0] + R[2,2]).  Non-finite entries cannot be
    projected and raise ValueError.  This is an explicit choice: the API never projects silently.
    """
    x = real_array(x, "x", (NX,))
    check_finite(x, "x", STATE_ENTRY_NAMES)
    if not (isinstance(r, (int, float, np.floating, np.integer)) and np.isfinite(r) and r > 0):
        raise ValueError(f"r: expected a positive finite radius, got {r!r}")
    out = x.copy()
    for row in out.reshape(-1, NX):
        row[IDX_RS] = nearest_rotation(row[IDX_RS].reshape(3, 3)).ravel()
        RY, RP = row[IDX_RY].reshape(3, 3), row[IDX_RP].reshape(3, 3)
        ty = np.arctan2(RY[2, 1] - RY[1, 2], RY[1, 1] + RY[2, 2])
        tp = np.arctan2(RP[0, 2] - RP[2, 0], RP[0, 0] + RP[2, 2])
        row[IDX_RY] = rot_x(ty).ravel()
        row[IDX_RP] = rot_y(tp).ravel()
        row[IDX_QZ] = r
    return out
