"""Emission: each kernel as C text, the header and source texts, and `write`, the one place that writes files.

The generated header includes the hand-written c/include/sr_real.h (the scalar type
`sr_real`, SR_C, SR_GEN_PIVOT_TOL and the SR_GEN_ status codes) and adds only
what is derived: sizes, layout macros, flop counts and prototypes.
"""
import hashlib
import pathlib
import re

import sympy as sp

from .. import param_derivatives as PD
from .. import parameters as P
from .. import sensors as SE
from .. import state as S
from .c_printer import Printer, Scheduler, count_flops, dependency_order
from .. import robot as R
from .constant_pool import ConstantsArray, pool_constants
from .joint_first import emit_shell_solve
from .kernels import INPUT_DOCS, array_layouts, input_symbols, kernels

ROOT = pathlib.Path(__file__).resolve().parents[2]
HEADER_NAME = "sr_generated.h"
SOURCE_NAME = "sr_generated.c"
HAND_WRITTEN_HEADER = "sr_real.h"   # in c/include/: what is chosen, not derived
PREFIX = "sr_gen_"


def emit_assignments(scheduler, assignments, declare):
    lines = []
    for name, expr in assignments:
        prefix = "const sr_real " if declare else ""
        lines.append(f"    {prefix}{name} = {scheduler.assign(name, expr)};")
    return lines


def input_entries(kernel, used, layouts):
    """(symbol, array, index) of every input symbol the kernel reads, in argument order."""
    table = input_symbols(kernel.inputs, layouts)
    missing = [s for s in used if s not in table]
    if missing:
        raise ValueError(f"kernel {kernel.name} uses symbols outside its inputs: {missing}")
    return [(sym, *table[sym]) for sym in sorted(used, key=lambda s: (kernel.inputs.index(table[s][0]), table[s][1]))]


#: The arrays that hold one state's data; a lanes kernel reads them per lane, the others once.
#: The strides are arguments: GCC 12 vectorises the loop with them, not with constant strides of 35.
PER_LANE = {"x": "x_stride*i", "u": "u_stride*i", "nud": "nud_stride*i"}


def scalar_guard(condition, status):
    """A test that must hold, in a scalar kernel: return `status` if it does not."""
    return f"    if (!({condition})) return {status};"


def lane_guard(condition, status):
    """The same test in a lanes kernel: no branch, the lane's flag cleared.  The flag is an sr_real
    and the test a select, so that the loop vectorises with the baseline x86-64 instructions (SSE2
    has no select of 64-bit integers by a comparison of doubles)."""
    return f"    good = ({condition}) ? good : 0;"


def emit_results(scheduler, results, finite_or_untouched, guard=scalar_guard):
    """Assign the outputs; with `finite_or_untouched`, only after checking that all are finite.

    One test of their sum clears the common case (a NaN or an infinity makes
    it non-finite); a sum that is not finite is decided value by value, so
    finite values whose sum overflows still pass.  The caller's arrays are
    written last, so they may alias the inputs.  In a lanes kernel
    (`lane_guard`) the outputs are always written and a non-finite sum
    clears the lane's flag: the caller decides such a lane by the scalar kernel.
    """
    if not finite_or_untouched:
        return [f"    {target} = {scheduler.assign(target, value)};" for target, value in results]
    names = [f"out_{i}" for i in range(len(results))]
    lines = [f"    const sr_real {n} = {scheduler.assign(n, value)};" for n, (_, value) in zip(names, results)]
    each = " && ".join(f"isfinite({n})" for n in names)
    if guard is lane_guard:
        total = names[0] if len(names) == 1 else "out_sum"
        if len(names) > 1:
            lines.append(f"    const sr_real out_sum = {scheduler.assign('out_sum', sp.Add(*sp.symbols(names, real=True)))};")
        lines.append(guard(f"SR_GEN_LANE_FINITE({total})", "SR_GEN_NONFINITE"))
    elif len(names) == 1:
        lines.append(f"    if (!{each}) return SR_GEN_NONFINITE;")
    else:
        lines.append(f"    const sr_real out_sum = {scheduler.assign('out_sum', sp.Add(*sp.symbols(names, real=True)))};")
        lines.append(f"    if (!isfinite(out_sum) && !({each})) return SR_GEN_NONFINITE;")
    lines += [f"    {target} = {n};" for n, (target, _) in zip(names, results)]
    return lines


def signature(kernel):
    args = [INPUT_DOCS[a][0] for a in kernel.inputs]
    if kernel.solve:
        args.append("sr_real a[SR_GEN_NV]")
    else:
        sizes = {"c": "SR_GEN_NCONST", "cg": "SR_GEN_GENERAL_NCONST", "p": "SR_GEN_NPARAM", "sc": "SR_GEN_NSC"}
        args += [f"sr_real {o.name}[{sizes.get(o.name, len(o.exprs))}]" for o in kernel.outputs]
    return f"int {PREFIX}{kernel.name}({', '.join(args)})"


def lanes_outputs(kernel):
    """The names of a lanes kernel's output arrays: `a` for the solve, else its outputs'."""
    return ["a"] if kernel.solve else [o.name for o in kernel.outputs]


def lanes_signature(kernel):
    """sr_gen_<name>_lanes: the kernel on n states; its first input read once (the model's array),
    the rows of the others (x, u, nud) and of every output array stride entries apart (a stride 0
    repeats one input row), a flag per state (1 or 0)."""
    once, each = kernel.inputs[0], kernel.inputs[1:]
    if once in PER_LANE or not each or any(a not in PER_LANE for a in each):
        raise ValueError(f"kernel {kernel.name}: lanes are emitted for a model array, then rows of {sorted(PER_LANE)}")
    args = [INPUT_DOCS[once][0], "long n"] + [f"const sr_real *restrict {a}, long {a}_stride" for a in each]
    args += [f"sr_real *restrict {name}, long {name}_stride" for name in lanes_outputs(kernel)]
    return f"void {PREFIX}{kernel.name}_lanes({', '.join(args)}, sr_real *restrict ok)"


def kernel_body(kernel, guard, row=""):
    """(symbols read, body lines after the reads) of a kernel, its tests written by `guard`, its
    outputs at `out[row + k]` (`{name}` in row: the output array's name)."""
    scheduler = Scheduler(Printer())
    defined = [symbol for symbol, _ in kernel.definitions]
    exprs = [value for _, value in kernel.definitions] + [e for o in kernel.outputs for e in o.exprs]
    temporaries, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), order="canonical")
    definitions, reduced = list(zip(defined, reduced[:len(defined)])), reduced[len(defined):]
    used = set().union(*(e.free_symbols for e in exprs)) - set(defined) if exprs else set()
    nodes = temporaries + definitions
    body = emit_assignments(scheduler, dependency_order(nodes, [s for s, _ in nodes] + reduced), declare=True)
    k, results = 0, []
    for out in kernel.outputs:
        values = reduced[k:k + len(out.exprs)]
        k += len(out.exprs)
        if out.local_names:
            body += emit_assignments(scheduler, list(zip(out.local_names, values)), declare=True)
        else:
            results += [(f"{out.name}[{i}]", v) for i, v in enumerate(values)]
    if kernel.solve:
        lines, results = emit_shell_solve(scheduler, "a", S.R_Y, {s.name for s in defined}, guard)
        body += lines
    results = [(target.replace("[", "[" + row.format(name=target.split("[")[0]), 1), value) for target, value in results]
    return used, body + emit_results(scheduler, results, kernel.finite_or_untouched, guard)


#: The arrays of a model (c/include/spherical_robot.h's sr_model) that kernels read.
MODEL_ARRAYS = ("p", "c", "cg")


def model_reads(kernel, layouts):
    """{array: sorted indices} of the model's entries (MODEL_ARRAYS) that the kernel's code loads: the
    inputs its outputs and definitions use, as `input_entries` reads them."""
    defined = {symbol for symbol, _ in kernel.definitions}
    exprs = [value for _, value in kernel.definitions] + [e for o in kernel.outputs for e in o.exprs]
    used = set().union(*(e.free_symbols for e in exprs)) - defined if exprs else set()
    reads = {}
    for _, array, index in input_entries(kernel, used, layouts):
        if array in MODEL_ARRAYS:
            reads.setdefault(array, set()).add(index)
    return {array: tuple(sorted(indices)) for array, indices in reads.items()}


def index_ranges(indices):
    """Sorted indices as ranges (first, end) of consecutive runs: (6, 7, 8, 30) -> ((6, 9), (30, 31))."""
    ranges = []
    for i in indices:
        if ranges and ranges[-1][1] == i:
            ranges[-1][1] = i + 1
        else:
            ranges.append([i, i + 1])
    return tuple(tuple(r) for r in ranges)


def read_set_macros(ks, layouts):
    """SR_GEN_READS_<kernel>(R): the kernel's read set of the model as data, one R(array, first, end) per
    range of consecutive entries, for every kernel (empty for one that reads no model array)."""
    lines = []
    for k in ks:
        reads = model_reads(k, layouts)
        items = [f"R({array}, {first}, {end})" for array in MODEL_ARRAYS for first, end in index_ranges(reads.get(array, ()))]
        lines.append(f"#define SR_GEN_READS_{k.name}(R) {' '.join(items)}".rstrip())
    return "\n".join(lines)


def emit_kernel(kernel, layouts):
    """C text of one kernel and its flop count."""
    used, body = kernel_body(kernel, scalar_guard)
    reads = [f"    const sr_real {sym.name} = {array}[{index}];" for sym, array, index in input_entries(kernel, used, layouts)]
    body = reads + body + ["    return SR_GEN_OK;"]
    doc = f"/* {kernel.doc} */"
    return "\n".join([doc, signature(kernel), "{", *body, "}", ""]), count_flops(body)


def lanes_doc(kernel):
    return (f"/* sr_gen_{kernel.name} on n states, for the batch calls: one loop without branches that the"
            " compiler vectorises across states (the same expressions, so each lane's result is the scalar"
            " kernel's, bit for bit); every output is written, and ok[i] is cleared where the scalar kernel"
            " would fail (or its outputs' sum overflows: decide such a state by the scalar kernel)."
            " GCC vectorises it at -O3 (or -O2 -fvect-cost-model=dynamic), for AVX2 too (SR_LANES_CLONES)"
            + (", with more run-time alias tests of its output arrays than GCC 12 makes by default"
               " (--param vect-max-version-for-alias-checks=100, in the builds)" if len(lanes_outputs(kernel)) > 1 else "")
            + ". */")


ASSIGNMENT = re.compile(r"^\s*const sr_real (\w+) = (.*);$")
NAME = re.compile(r"\b[A-Za-z_]\w*\b")


def hoisted(body, once):
    """(before the loop, in the loop): the body's assignments that read only the names `once` (the
    model array's entries), the SR_GEN_ functions and what is so assigned before them, moved out of
    the loop; every other line kept in order.  GCC 12 keeps a loop with a call (the sine of the
    slope) scalar."""
    known, before, inside = set(once), [], []
    for line in body:
        m = ASSIGNMENT.match(line)
        names = set(NAME.findall(m.group(2))) - {"SR_C"} if m else None
        if m and all(n in known or n.startswith("SR_GEN_") for n in names):
            known.add(m.group(1))
            before.append(line)
        else:
            inside.append(line)
    return before, inside


def emit_lanes(kernel, layouts):
    """C text of sr_gen_<name>_lanes (see `lanes_doc`)."""
    used, body = kernel_body(kernel, lane_guard, row="{name}_stride*i + ")
    entries = input_entries(kernel, used, layouts)
    once = [f"    const sr_real {sym.name} = {array}[{index}];" for sym, array, index in entries if array not in PER_LANE]
    each = [f"    const sr_real {sym.name} = {array}[{PER_LANE[array]} + {index}];"
            for sym, array, index in entries if array in PER_LANE]
    before, inside = hoisted(body, [sym.name for sym, array, _ in entries if array not in PER_LANE])
    loop = each + ["    sr_real good = 1;"] + inside + ["    ok[i] = good;"]
    return "\n".join([lanes_doc(kernel), "SR_LANES_CLONES " + lanes_signature(kernel), "{", *once, *before, "    long i;",
                      "    for (i = 0; i < n; ++i) {", *("    " + line for line in loop), "    }", "}", ""])


def provenance():
    """Digest of the derivation sources (every derive/**/*.py, by path), so a generated file names exactly what it came from."""
    package = ROOT / "derive"
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py"), key=lambda p: p.relative_to(package).as_posix()):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def banner():
    return (f"/* GENERATED FILE, DO NOT EDIT: written by `make generate` (python -m derive) from the derive/ package "
            f"[sha256 of its sources {provenance()}], SymPy {sp.__version__}. */\n")


def layout_macros():
    """Index macros of the state blocks, the inputs and the parameters: each layout written once, here."""
    assert sum(n for _, _, n in S.STATE_BLOCKS) == S.NX
    lines = ["/* Layout of x[SR_GEN_NX]: offset of each block (matrices row-major; nu = (w_S, w_Y, w_P) starts at SR_X_w_S). */"]
    lines += [f"#define SR_X_{name} {offset}" for name, offset, _ in S.STATE_BLOCKS]
    lines += ["/* Layout of u[SR_GEN_NU]. */"]
    lines += [f"#define SR_U_{name} {index}" for name, index in S.INPUT_NAMES]
    assert sum(n for _, _, n in S.ERROR_BLOCKS) == S.NE
    lines += ["/* Layout of the error state d[SR_GEN_NE] (tangent coordinates of x, right-trivialised: x (+) d). */"]
    lines += [f"#define SR_E_{name} {offset}" for name, offset, _ in S.ERROR_BLOCKS]
    lines += ["/* Layout of p[SR_GEN_NPARAM], the parameters of the general robot, derive/parameters.py (SI). */"]
    lines += [f"#define SR_P_{s.name} {i}" for i, s in enumerate(P.PARAMETERS)]
    lines += ["/* Layout of pp[SR_GEN_NPAPER], the paper's parameters (Section 5.2, SI), for sr_gen_paper_params. */"]
    lines += [f"#define SR_PAPER_{s.name} {i}" for i, s in enumerate(P.PAPER_PARAMETERS)]
    lines += ["/* Layout of pi[SR_GEN_NPI], the parameters the equations of motion are linear in (the regressor's"
              " columns, derive/param_derivatives.py): per body m, m c, the tensor about O, the damping; the rotors. */"]
    lines += [f"#define SR_PI_{s.name} {i}" for i, s in enumerate(PD.INERTIAL_PARAMETERS)]
    lines += ["/* The bodies a sensor is mounted on (derive/sensors.py). */"]
    lines += [f"#define SR_BODY_{name} {i}" for i, name in enumerate(SE.BODIES)]
    lines += ["/* Layout of sc[SR_GEN_NSC], the sensor kernels' constants (sr_gen_sensor_constants). */"]
    lines += [f"#define SR_SC_{s.name} {i}" for i, s in enumerate(SE.CONSTANTS)]
    blocks = (("MOUNT", SE.MOUNT_BLOCKS, SE.NMOUNT, "the sensor mount mount[SR_GEN_NMOUNT]: lever arm in the body's frame, mounting rotation R_m (sensor axes in the body's frame, row-major)"),
              ("BIAS", SE.BIAS_BLOCKS, SE.NBIAS, "the IMU's biases bias[SR_GEN_NBIAS], sensor frame"),
              ("IMU", SE.IMU_BLOCKS, SE.NIMU, "an IMU reading y[SR_GEN_NIMU], sensor frame"),
              ("EB", SE.ESTIMATOR_BLOCKS, SE.NEB, "the estimator's error state [d | b_g | b_a] (SR_GEN_NEB), the columns of the sensor Jacobians"))
    for prefix, table, size, what in blocks:
        assert sum(n for _, _, n in table) == size
        lines += [f"/* Layout of {what}. */"]
        lines += [f"#define SR_{prefix}_{name} {offset}" for name, offset, _ in table]
    return "\n".join(lines)


def header_text(ks, flops, n_constants, n_general_constants, reads):
    guard = "SR_GENERATED_H"
    protos = "\n".join(f"/* {k.doc} */\n{signature(k)};" for k in ks)
    protos += "".join(f"\n{lanes_doc(k)}\n{lanes_signature(k)};" for k in ks if k.lanes)
    flop_macros = "\n".join(f"#define SR_GEN_{k.name.upper()}_FLOPS {flops[k.name]}" for k in ks)
    float_names = "\n".join(f"#define {PREFIX}{k.name} {PREFIX}{k.name}_f" for k in ks)
    float_names += "".join(f"\n#define {PREFIX}{k.name}_lanes {PREFIX}{k.name}_lanes_f" for k in ks if k.lanes)
    return f"""{banner()}/*
 * Symbolic kernels of the spherical-robot model (Fiori 2024), derived in derive/.
 * Internal to the library: use the checked API of c/include/spherical_robot.h.
 * Every function returns SR_GEN_OK, SR_GEN_NONFINITE (a result is not finite) or, for accel,
 * SR_GEN_SINGULAR; outputs are caller-provided and written only on SR_GEN_OK (sr_gen_constants:
 * always, the caller checks them).
 */
#ifndef {guard}
#define {guard}

/* sr_real, SR_C, SR_GEN_PIVOT_TOL and the SR_GEN_ status codes: hand-written, in c/include/. */
#include "{HAND_WRITTEN_HEADER}"

#define SR_GEN_NPARAM {len(P.PARAMETERS)}
#define SR_GEN_NPAPER {len(P.PAPER_PARAMETERS)}
#define SR_GEN_NPI {len(PD.INERTIAL_PARAMETERS)}
#define SR_GEN_NCONST {n_constants}
#define SR_GEN_NCONST_NAMED {len(P.CONSTANTS)}
#define SR_GEN_GENERAL_NCONST {n_general_constants}
#define SR_GEN_GENERAL_NCONST_NAMED {len(R.general_constants())}
#define SR_GEN_NX {S.NX}
#define SR_GEN_NU {S.NU}
#define SR_GEN_NV {S.NV}
#define SR_GEN_NE {S.NE}
#define SR_GEN_NSC {SE.NCONST}
#define SR_GEN_NMOUNT {SE.NMOUNT}
#define SR_GEN_NBIAS {SE.NBIAS}
#define SR_GEN_NIMU {SE.NIMU}
#define SR_GEN_NEB {SE.NEB}

{layout_macros()}

/* Arithmetic operations (+ - * /) per call, counted in the emitted code after CSE. */
{flop_macros}

/* What each kernel reads of a model (sr_model's p, c or cg): SR_GEN_READS_<kernel>(R) expands to
 * R(array, first, end) for each run [first, end) of the entries of `array` that its code loads, and
 * to nothing for a kernel that reads none.  The read sets of the model's checksums (c/src/sr_argcheck.h). */
{reads}

/* The float build's symbols carry _f, so a float/double mismatch fails at link time. */
#ifdef SR_USE_FLOAT
{float_names}
#endif

{protos}

#endif /* {guard} */
"""


def source_text(emitted):
    return banner() + f'#include "{HEADER_NAME}"\n\n#include <math.h>\n\n' + "\n".join(text for text, _ in emitted)


GENERAL_CONSTANTS = ConstantsArray("cg", "general_constants", R.general_constants(), "kg_")


def write(out_dir):
    """The one place that writes files: generated/sr_generated.{{h,c}}."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ks, constants = pool_constants(kernels())
    ks, general_constants = pool_constants(ks, GENERAL_CONSTANTS)
    layouts = array_layouts(constants, general_constants)
    emitted = [emit_kernel(k, layouts) for k in ks]
    flops = {k.name: n for k, (_, n) in zip(ks, emitted)}
    emitted += [(emit_lanes(k, layouts), None) for k in ks if k.lanes]
    files = {HEADER_NAME: header_text(ks, flops, len(constants), len(general_constants), read_set_macros(ks, layouts)),
             SOURCE_NAME: source_text(emitted)}
    files.update(casadi_files())
    for name, text in files.items():
        path = out_dir / name
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text)
        tmp.replace(path)
    return [out_dir / n for n in files]


def file_format(function):
    """What casadi.Function.save writes (and Function.load reads), as text."""
    import casadi

    serializer = casadi.StringSerializer()
    serializer.pack(function)
    return serializer.encode()


def casadi_files():
    """The model as CasADi Functions (derive/casadi_model.py), serialized: casadi/<name>.casadi,
    and casadi/README.txt, which says they are generated and from what (a serialized Function
    has no room for a comment)."""
    import casadi

    from .. import casadi_model
    functions = casadi_model.functions()
    files = {f"casadi/{name}.casadi": file_format(f) for name, f in functions.items()}
    lines = [f"GENERATED FILE, DO NOT EDIT (nor the .casadi files beside it): written by `make generate` (python -m derive) from the derive/ package "
             f"[sha256 of its sources {provenance()}], SymPy {sp.__version__}, CasADi {casadi.__version__}.",
             "", "The model as CasADi Functions (derive/casadi_model.py); load one with casadi.Function.load(path)",
             "or runtime.casadi_model.load(name).  p is the parameter vector in SR_P_* order "
             "(runtime.Params(...).as_array()).", ""]
    for name, f in functions.items():
        ins = ", ".join(f"{f.name_in(i)}[{f.size1_in(i)}]" for i in range(f.n_in()))
        outs = ", ".join(f"{f.name_out(i)}[{f.size1_out(i)}]" for i in range(f.n_out()))
        lines.append(f"    {name}.casadi: {name}({ins}) -> {outs}")
    files["casadi/README.txt"] = "\n".join(lines) + "\n"
    return files
