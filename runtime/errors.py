"""The exceptions of the Python API: a C kernel's error status as a ValueError naming the argument.

Kept apart from `model` so that `validation` (which raises them) and `model`
(which uses validation) do not import each other.
"""
from bindings._sr import ffi, lib

_STATUS_HINTS = {
    lib.SR_ERR_NONFINITE: "contains NaN or infinity",
    lib.SR_ERR_NOT_ROTATION: "holds a matrix that is not a rotation of the required kind "
                             "(R_S orthonormal with det +1, R_Y about x, R_P about y)",
    lib.SR_ERR_SINGULAR: "gives a singular generalized inertia",
    lib.SR_ERR_CONSTRAINT: "violates q_z = r",
    lib.SR_ERR_MODEL: "is not a valid sr_model: not filled by sr_model_init, or a parameter or constant that "
                      "the call reads changed since (its checksum differs); build a new Model",
}


class KernelError(ValueError):
    """A C kernel returned an error status (`.status`, one of the SR_* codes of c/spherical_robot.h).

    The message names the argument (`field`) and the rule; `message`, when given, replaces the
    generic text built from the status.  SR_ERR_MODEL is the model's fault whatever the call was
    given, so it names the model (field "model").
    """

    def __init__(self, field, status, detail="", message=None):
        if status == lib.SR_ERR_MODEL:
            field = "model"
        self.status = status
        self.field = field
        if message is None:
            hint = _STATUS_HINTS.get(status, ffi.string(lib.sr_status_string(status)).decode())
            message = f"{field}: {hint}{detail}"
        super().__init__(message)


class SimulationStopped(KernelError):
    """`Model.simulate` stopped before the end: the state became non-finite, drifted off the
    constraints, or gained energy without input (see docs/robustness.md).

    Attributes: `step` (1-based number of the step whose result failed), `time` (its start
    time, (step − 1)·dt), `trajectory` (the rows 0..step−1 computed before it, all valid),
    `state` (the offending state after `step`, or None if it was never formed), `status`.
    """

    def __init__(self, status, step, dt, trajectory, state, reason):
        self.step, self.time, self.trajectory, self.state = step, (step - 1) * dt, trajectory, state
        super().__init__("x", status, message=(
            f"x: simulation stopped at step {step} (t = {self.time:.6g} → {step * dt:.6g} s): {reason}; "
            f"the {len(trajectory)} rows computed before it are in the exception's .trajectory"))
