"""Emit the derived model as C99: a declarative list of kernels and one writer.

Each kernel is (name, inputs, outputs): inputs are the arrays it reads
(`p` parameters, `c` constants, `x` state, `u` input), outputs are named
arrays of SymPy expressions.  All kernels of a file share nothing at run
time; within a kernel common subexpressions are eliminated by SymPy's CSE.
`accel` additionally solves M ν̇ = f with an unrolled LDLᵀ factorization
(M is symmetric positive definite, so no pivoting is needed and no square
root is taken).

The scalar type is `sr_real` (double, or float with -DSR_USE_FLOAT), and
numeric literals go through SR_C() so both builds are clean under -Wall
-Wextra -Wpedantic -Werror.
"""
import dataclasses
import hashlib
import pathlib
import re

import sympy as sp
from sympy.printing.c import C99CodePrinter

from . import dynamics as D
from . import parameters as P
from . import state as S

ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADER_NAME = "sr_generated.h"
SOURCE_NAME = "sr_generated.c"
PREFIX = "sr_gen_"


@dataclasses.dataclass(frozen=True)
class Output:
    name: str
    exprs: tuple
    doc: str


@dataclasses.dataclass(frozen=True)
class Kernel:
    name: str
    doc: str
    inputs: tuple          # subset of ("p", "c", "x", "u"), in argument order
    outputs: tuple         # Output instances, written in this order
    solve: bool = False    # outputs are (M upper triangle, f); write ν̇ = M⁻¹ f instead


INPUT_DOCS = {
    "p": ("const sr_real p[SR_GEN_NPARAM]", "parameters (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g), SI"),
    "c": ("const sr_real c[SR_GEN_NCONST]", "constants from sr_gen_constants"),
    "x": ("const sr_real x[SR_GEN_NX]", "state [R_S | R_Y | R_P | q | w_S | w_Y | w_P]"),
    "u": ("const sr_real u[SR_GEN_NU]", "motor torques (yoke, pendulum) [N m]"),
}


ARRAY_LAYOUTS = {
    "p": {s: i for i, s in enumerate(P.PARAMETERS)},
    "c": {s: i for i, s in enumerate(P.CONSTANTS)},
    "x": S.STATE_LAYOUT,
    "u": S.INPUT_LAYOUT,
}


def input_symbols(arrays):
    """Symbol -> (array, index) for the arrays a kernel reads."""
    return {s: (a, i) for a in arrays for s, i in ARRAY_LAYOUTS[a].items()}


def nested_in_speeds(expr):
    """expr as Σ_j ν_j (Σ_k c_jk(config) ν_k) + (linear and constant terms).

    The right-hand side is quadratic in ν; grouping its 15 monomials this way
    lets CSE share the configuration-dependent coefficients (about half the
    flops of the expanded polynomial).
    """
    speeds, inputs = list(S.nu), list(S.u)
    poly = sp.Poly(expr, *speeds, *inputs)
    rows, rest = {}, []
    for powers, coeff in poly.terms():
        coeff = sp.factor_terms(coeff)
        factors = [v for v, k in zip(speeds, powers[:len(speeds)]) for _ in range(k)]
        if len(factors) == 2:
            rows.setdefault(factors[0], []).append(coeff * factors[1])
        else:
            rest.append(coeff * sp.Mul(*[v**k for v, k in zip(speeds + inputs, powers)]))
    return sp.Add(*rest) + sp.Add(*[v * sp.Add(*terms) for v, terms in rows.items()])


def upper_triangle(M):
    return tuple(M[i, j] for i in range(M.rows) for j in range(i, M.cols))


def kernels():
    """The functions to emit."""
    M, f = D.inertia(), D.rhs().applyfunc(nested_in_speeds)
    return (
        Kernel("constants", "Derived constants of Section 2.3 from the twelve parameters.",
               ("p",), (Output("c", tuple(P.constant_expressions()), "constants (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P)"),)),
        Kernel("inertia", "Generalized inertia M(γ, R_Y, R_P), row-major 5x5, kinetic energy ½νᵀMν.",
               ("c", "x"), (Output("M", tuple(M), "M, row-major 5x5"),)),
        Kernel("rhs", "Right-hand side f of M ν̇ = f: gyroscopic, non-holonomic, gravity, motor and friction terms.",
               ("c", "x", "u"), (Output("f", tuple(f), "f"),)),
        Kernel("energy", "Total energy: ½νᵀMν + m_P g e_zᵀ(q + R_S R_Y R_P c̄_P) [J].",
               ("c", "x"), (Output("E", (D.energy(),), "energy"),)),
        Kernel("equilibrium_residual", "f at ν = 0, u = 0 (eq. 106); zero iff R_S R_Y R_P e_z = ±e_z (eq. 108).",
               ("c", "x"), (Output("res", tuple(D.equilibrium_residual()), "residual"),)),
        Kernel("accel", "ν̇ = (ω̇_S, ω̇_Y, ω̇_P) solving M ν̇ = f by LDLᵀ; SR_GEN_SINGULAR if a pivot is not positive.",
               ("c", "x", "u"), (Output("M", upper_triangle(M), "M"), Output("f", tuple(f), "f")), solve=True),
    )


class Printer(C99CodePrinter):
    """C99 with sr_real literals and integer powers as products."""

    def _print_Rational(self, expr):
        return f"SR_C({float(expr)!r})"

    def _print_Float(self, expr):
        return f"SR_C({float(expr)!r})"

    def _print_Integer(self, expr):
        return f"SR_C({int(expr)}.0)" if abs(int(expr)) > 1 else str(int(expr))

    def _print_Pow(self, expr):
        base, exp = expr.as_base_exp()
        if exp.is_Integer and 1 < exp <= 6:
            factor = self.parenthesize(base, 100)
            return "(" + "*".join([factor] * int(exp)) + ")"
        if exp == -1:
            return f"SR_C(1.0)/{self.parenthesize(base, 100)}"
        raise ValueError(f"unsupported power in generated code: {expr}")


def emit_assignments(printer, assignments, declare):
    lines = []
    for name, expr in assignments:
        prefix = "const sr_real " if declare else ""
        lines.append(f"    {prefix}{name} = {printer.doprint(expr)};")
    return lines


def emit_inputs(kernel, used):
    table = input_symbols(kernel.inputs)
    missing = [s for s in used if s not in table]
    if missing:
        raise ValueError(f"kernel {kernel.name} uses symbols outside its inputs: {missing}")
    lines = []
    for sym in sorted(used, key=lambda s: (kernel.inputs.index(table[s][0]), table[s][1])):
        array, index = table[sym]
        lines.append(f"    const sr_real {sym.name} = {array}[{index}];")
    return lines


def emit_ldlt_solve(n, M_name, f_name, out_name):
    """Unrolled LDLᵀ of a symmetric n×n matrix given as M_i_j (i ≤ j), then forward/back substitution.

    Only the n pivots are divided (1/d_j); every other division becomes a multiplication.
    """
    def m(i, j):
        i, j = min(i, j), max(i, j)
        return f"{M_name}_{i}_{j}"

    lines = ["    /* LDL^T factorization, unrolled: M = L D L^T with unit lower-triangular L. */"]
    for j in range(n):
        terms = "".join(f" - L_{j}_{k}*L_{j}_{k}*d_{k}" for k in range(j))
        lines.append(f"    const sr_real d_{j} = {m(j, j)}{terms};")
        lines.append(f"    if (!(d_{j} > SR_GEN_PIVOT_TOL*{m(j, j)})) return SR_GEN_SINGULAR;")
        lines.append(f"    const sr_real inv_d_{j} = SR_C(1.0)/d_{j};")
        for i in range(j + 1, n):
            terms = "".join(f" - L_{i}_{k}*L_{j}_{k}*d_{k}" for k in range(j))
            lines.append(f"    const sr_real L_{i}_{j} = ({m(i, j)}{terms})*inv_d_{j};")
    lines.append("    /* Solve L y = f, then L^T a = D^-1 y. */")
    for i in range(n):
        terms = "".join(f" - L_{i}_{k}*y_{k}" for k in range(i))
        lines.append(f"    const sr_real y_{i} = {f_name}_{i}{terms};")
    for i in reversed(range(n)):
        terms = "".join(f" - L_{k}_{i}*a_{k}" for k in range(i + 1, n))
        lines.append(f"    const sr_real a_{i} = y_{i}*inv_d_{i}{terms};")
    for i in range(n):
        lines.append(f"    {out_name}[{i}] = a_{i};")
    return lines


def signature(kernel):
    args = [INPUT_DOCS[a][0] for a in kernel.inputs]
    if kernel.solve:
        args.append("sr_real a[SR_GEN_NV]")
    else:
        args += [f"sr_real {o.name}[{len(o.exprs)}]" for o in kernel.outputs]
    return f"int {PREFIX}{kernel.name}({', '.join(args)})"


_TOKEN = re.compile(r"[A-Za-z_][A-Za-z_0-9]*(?:\[[0-9]+\])?|[0-9.]+(?:e[-+]?[0-9]+)?|[-+*/()<>!,]")


def count_flops(lines):
    """Binary + − × ÷ in the right-hand sides of C statements (unary minus is free: it folds into a subtraction)."""
    flops = 0
    for line in lines:
        if "=" not in line or line.lstrip().startswith("/*"):
            continue
        previous = None
        for token in _TOKEN.findall(line.split("=", 1)[1].replace("SR_C", "")):
            if token in "+-*/" and previous is not None and (previous[0].isalnum() or previous[0] in "_.)"):
                flops += 1
            previous = token
    return flops


def emit_kernel(kernel):
    """C text of one kernel and its flop count."""
    printer = Printer()
    exprs = [e for o in kernel.outputs for e in o.exprs]
    temporaries, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), order="canonical")
    used = set().union(*(e.free_symbols for e in exprs)) if exprs else set()
    body = emit_inputs(kernel, used)
    body += emit_assignments(printer, temporaries, declare=True)
    k = 0
    for out in kernel.outputs:
        values = reduced[k:k + len(out.exprs)]
        k += len(out.exprs)
        if kernel.solve:
            if out.name == "M":
                n = S.NV
                names = [f"M_{i}_{j}" for i in range(n) for j in range(i, n)]
            else:
                names = [f"f_{i}" for i in range(len(values))]
            body += emit_assignments(printer, zip(names, values), declare=True)
        else:
            body += [f"    {out.name}[{i}] = {printer.doprint(v)};" for i, v in enumerate(values)]
    if kernel.solve:
        body += emit_ldlt_solve(S.NV, "M", "f", "a")
    body.append("    return SR_GEN_OK;")
    doc = f"/* {kernel.doc} */"
    return "\n".join([doc, signature(kernel), "{", *body, "}", ""]), count_flops(body)


def provenance():
    """Digest of the derivation sources, so a generated file names exactly what it came from."""
    digest = hashlib.sha256()
    for path in sorted((ROOT / "derive").glob("*.py")):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def banner():
    return (f"/* GENERATED FILE, DO NOT EDIT: written by `make generate` (python -m derive) from the derive/ package "
            f"[sha256 of its sources {provenance()}], SymPy {sp.__version__}. */\n")


def header_text(ks, flops):
    guard = "SR_GENERATED_H"
    protos = "\n".join(f"/* {k.doc} */\n{signature(k)};" for k in ks)
    flop_macros = "\n".join(f"#define SR_GEN_{k.name.upper()}_FLOPS {flops[k.name]}" for k in ks)
    float_names = "\n".join(f"#define {PREFIX}{k.name} {PREFIX}{k.name}_f" for k in ks)
    return f"""{banner()}/*
 * Symbolic kernels of the spherical-robot model (Fiori 2024), derived in derive/.
 * Internal to the library: use the checked API of c/spherical_robot.h.
 * Every function returns SR_GEN_OK or SR_GEN_SINGULAR; outputs are caller-provided.
 */
#ifndef {guard}
#define {guard}

#ifdef SR_USE_FLOAT
typedef float sr_real;
#define SR_C(v) ((sr_real)(v##f))
#define SR_GEN_PIVOT_TOL SR_C(1e-6)
#else
typedef double sr_real;
#define SR_C(v) ((sr_real)(v))
#define SR_GEN_PIVOT_TOL SR_C(1e-13)
#endif

#define SR_GEN_OK 0
#define SR_GEN_SINGULAR 4
#define SR_GEN_NPARAM {len(P.PARAMETERS)}
#define SR_GEN_NCONST {len(P.CONSTANTS)}
#define SR_GEN_NX {S.NX}
#define SR_GEN_NU {S.NU}
#define SR_GEN_NV {S.NV}

/* Arithmetic operations (+ - * /) per call, counted in the emitted code after CSE. */
{flop_macros}

/* The float build's symbols carry _f, so a float/double mismatch fails at link time. */
#ifdef SR_USE_FLOAT
{float_names}
#endif

{protos}

#endif /* {guard} */
"""


def source_text(emitted):
    return banner() + f'#include "{HEADER_NAME}"\n\n' + "\n".join(text for text, _ in emitted)


def write(out_dir):
    """The one place that writes files: generated/sr_generated.{{h,c}}."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ks = kernels()
    emitted = [emit_kernel(k) for k in ks]
    flops = {k.name: n for k, (_, n) in zip(ks, emitted)}
    files = {HEADER_NAME: header_text(ks, flops), SOURCE_NAME: source_text(emitted)}
    for name, text in files.items():
        tmp = out_dir / (name + ".tmp")
        tmp.write_text(text)
        tmp.replace(out_dir / name)
    return [out_dir / n for n in files]
