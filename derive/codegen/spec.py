"""The description of one kernel: name, inputs, outputs and docs (listed by `kernels`, printed by `emit`)."""
import dataclasses


@dataclasses.dataclass(frozen=True)
class Output:
    name: str
    exprs: tuple
    doc: str
    local_names: tuple = ()   # set: assigned to these C locals (for the solve) instead of the output array


@dataclasses.dataclass(frozen=True)
class Kernel:
    name: str
    doc: str
    inputs: tuple          # subset of ("p", "c", "x", "u"), in argument order
    outputs: tuple         # Output instances, written in this order
    solve: bool = False    # outputs are the locals of joint_first_system; write ν̇ = M⁻¹ f instead
    definitions: tuple = ()  # (symbol, expression) intermediates the outputs use (newton_euler.Program)
    finite_or_untouched: bool = True  # write the outputs only if all are finite, else return SR_GEN_NONFINITE
    lanes: bool = False    # also emit sr_gen_<name>_lanes: the kernel over n states, branch-free (emit.emit_lanes);
    #                        its first input a model array (read once), the others rows of x, u or nud
