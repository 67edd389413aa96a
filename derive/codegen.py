"""Emit the derived model as C99: a declarative list of kernels and one writer.

Each kernel is (name, inputs, outputs): inputs are the arrays it reads
(`p` parameters, `c` constants, `x` state, `u` input), outputs are named
arrays of SymPy expressions.  All kernels of a file share nothing at run
time; within a kernel common subexpressions are eliminated by SymPy's CSE.
`rhs` and `accel` evaluate f in the body-by-body form of
`derive.newton_euler`, after proving it equal to `dynamics.rhs`; `accel`
additionally solves M ν̇ = f, joint accelerations first (see
`emit_joint_first_solve`: M is symmetric positive definite, so no pivoting
is needed and no square root is taken).

The scalar type is `sr_real` (double, or float with -DSR_USE_FLOAT), and
numeric literals go through SR_C() so both builds are clean under -Wall
-Wextra -Wpedantic -Werror.
"""
import collections
import dataclasses
import hashlib
import heapq
import pathlib
import re

import sympy as sp
from sympy.printing.c import C99CodePrinter

from . import dynamics as D
from . import newton_euler as NE
from . import parameters as P
from . import state as S
from . import yoke_frame as YF

ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADER_NAME = "sr_generated.h"
SOURCE_NAME = "sr_generated.c"
PREFIX = "sr_gen_"


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


INPUT_DOCS = {
    "p": ("const sr_real p[SR_GEN_NPARAM]", "parameters (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g), SI"),
    "c": ("const sr_real c[SR_GEN_NCONST]", "constants from sr_gen_constants"),
    "x": ("const sr_real x[SR_GEN_NX]", "state [R_S | R_Y | R_P | q | w_S | w_Y | w_P]"),
    "u": ("const sr_real u[SR_GEN_NU]", "motor torques (yoke, pendulum) [N m]"),
}


def array_layouts(constants):
    """Symbol -> index for each input array; `constants` is the full constants array (named, then pooled)."""
    return {
        "p": {s: i for i, s in enumerate(P.PARAMETERS)},
        "c": {s: i for i, s in enumerate(constants)},
        "x": S.STATE_LAYOUT,
        "u": S.INPUT_LAYOUT,
    }


def input_symbols(arrays, layouts):
    """Symbol -> (array, index) for the arrays a kernel reads."""
    return {s: (a, i) for a in arrays for s, i in layouts[a].items()}


class ConstantPool:
    """Parameter-only subexpressions of the kernels, moved into sr_gen_constants.

    A product like l·m_P·r/2 or a sum like j_P + j_S + j_xx depends on the
    parameters alone, so it is computed once per model (in the constants array
    after the twelve named constants) instead of once per call.  Names k_0,
    k_1, ... are given in order of first appearance, so generation stays
    deterministic.
    """

    def __init__(self, base):
        self.base = frozenset(base)
        self.table = {}            # expression -> symbol, in insertion order

    def _name(self, expr):
        if expr.is_Atom:
            return expr
        if expr.could_extract_minus_sign():
            return -self._name(-expr)
        if expr not in self.table:
            self.table[expr] = sp.Symbol(f"k_{len(self.table)}", real=True)
        return self.table[expr]

    def hoist(self, expr):
        """expr with its maximal parameter-only subexpressions replaced by pool symbols."""
        if expr.is_Atom:
            return expr
        if expr.free_symbols <= self.base:
            return self._name(expr)
        if expr.is_Add:
            expr = self._collect(expr)
            if not expr.is_Add:
                return self.hoist(expr)
        if expr.is_Add or expr.is_Mul:
            const = [a for a in expr.args if a.free_symbols <= self.base]
            rest = [self.hoist(a) for a in expr.args if not a.free_symbols <= self.base]
            return expr.func(self._name(expr.func(*const)), *rest) if const else expr.func(*rest)
        return expr.func(*[self.hoist(a) for a in expr.args])

    def _collect(self, add):
        """c₁ m + c₂ m -> (c₁ + c₂) m for terms with the same non-constant factor m (one product instead of two)."""
        groups = {}
        for term in add.args:
            const, var = term.as_independent(*(term.free_symbols - self.base), as_Add=False)
            groups.setdefault(var, []).append(const)
        if all(len(c) == 1 for c in groups.values()):
            return add
        return sp.Add(*[sp.Add(*consts) * var for var, consts in groups.items()])

    def symbols(self):
        return tuple(self.table.values())

    def expressions(self):
        return tuple(self.table)


def upper_triangle(M):
    return tuple(M[i, j] for i in range(M.rows) for j in range(i, M.cols))


def proven(name, residuals):
    if any(r != 0 for r in residuals):
        raise ValueError(f"{name}: the evaluated form differs from the derivation: {residuals}")


def rhs_program():
    """f body by body in the shell frame: (definitions, f), after the proof of `newton_euler`."""
    proven("newton_euler", NE.check_equal_to_rhs())
    p, f = NE.program()
    return tuple(p.definitions), f


def accel_program():
    """(definitions, outputs of joint_first_system) in the yoke frame, at the shell-frame state.

    After the proofs of `newton_euler` and `yoke_frame`.
    """
    proven("newton_euler", NE.check_equal_to_rhs())
    proven("yoke_frame", YF.check_equivalence())
    sub = YF.from_shell_frame()
    p, f = YF.program()
    definitions = tuple((symbol, value.xreplace(sub)) for symbol, value in p.definitions)
    solve_definitions, outputs = joint_first_system(YF.inertia().xreplace(sub), f.xreplace(sub))
    return definitions + solve_definitions, outputs


def kernels():
    """The functions to emit."""
    M = D.inertia()
    rhs_definitions, f = rhs_program()
    accel_definitions, accel_outputs = accel_program()
    return (
        Kernel("constants", "Derived constants of Section 2.3 from the twelve parameters, c[0..11] ="
               " (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P), then the parameter-only"
               " subexpressions of the kernels, computed once per model:",
               ("p",), (Output("c", tuple(P.constant_expressions()), "constants (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P)"),), finite_or_untouched=False),
        Kernel("inertia", "Generalized inertia M(γ, R_Y, R_P), row-major 5x5, kinetic energy ½νᵀMν.",
               ("c", "x"), (Output("M", tuple(M), "M, row-major 5x5"),)),
        Kernel("rhs", "Right-hand side f of M ν̇ = f: gyroscopic, non-holonomic, gravity, motor and friction terms.",
               ("c", "x", "u"), (Output("f", tuple(f), "f"),), definitions=rhs_definitions),
        Kernel("energy", "Total energy: ½νᵀMν + m_P g e_zᵀ(q + R_S R_Y R_P c̄_P) [J].",
               ("c", "x"), (Output("E", (D.energy(),), "energy"),)),
        Kernel("equilibrium_residual", "f at ν = 0, u = 0 (eq. 106); zero iff R_S R_Y R_P e_z = ±e_z (eq. 108).",
               ("c", "x"), (Output("res", tuple(D.equilibrium_residual()), "residual"),)),
        Kernel("accel", "ν̇ = (ω̇_S, ω̇_Y, ω̇_P) solving M ν̇ = f, joints first; SR_GEN_SINGULAR if M is not positive definite.",
               ("c", "x", "u"), accel_outputs, solve=True, definitions=accel_definitions),
    )


class Printer(C99CodePrinter):
    """C99 numeric literals as sr_real: SR_C(0.5), SR_C(2.0) (the Scheduler prints everything else)."""

    def _print_Rational(self, expr):
        return f"SR_C({float(expr)!r})"

    def _print_Float(self, expr):
        return f"SR_C({float(expr)!r})"

    def _print_Integer(self, expr):
        return f"SR_C({int(expr)}.0)" if abs(int(expr)) > 1 else str(int(expr))


def _product_factors(term):
    """The non-numeric factors of a product, with multiplicity (x**2 counts x twice)."""
    factors = collections.Counter()
    for factor in sp.Mul.make_args(term.as_coeff_Mul()[1]):
        base, exp = factor.as_base_exp()
        if exp.is_Integer and exp > 0:
            factors[base] += int(exp)
        else:
            factors[factor] += 1
    return factors


def factor_common(expr):
    """expr with factors shared by several terms of a sum taken out: a·x + a·y -> a·(x + y).

    One multiplication instead of several.  `accel` has half again as many
    products as sums, and AMD's Zen cores (the benchmark machine) multiply
    on two pipes and add on two others, so the multiply pipes fill first
    (llvm-mca's Zen 3 model of `accel`: 100 of ~130 cycles busy on each).  Greedy: the factor shared
    by the most terms first (ties in SymPy's canonical order, so the output
    is deterministic), then the same inside and outside the parentheses.
    """
    if expr.is_Atom:
        return expr
    expr = expr.func(*[factor_common(a) for a in expr.args])
    if not expr.is_Add:
        return expr
    tally = collections.Counter(f for term in expr.args for f in _product_factors(term))
    best = min(tally, key=lambda f: (-tally[f], sp.default_sort_key(f)), default=None)
    if best is None or tally[best] < 2:
        return expr
    inside = [t for t in expr.args if best in _product_factors(t)]
    outside = [t for t in expr.args if best not in _product_factors(t)]
    return best * factor_common(sp.Add(*[t / best for t in inside])) + factor_common(sp.Add(*outside))


class Scheduler:
    """Prints sums and products as trees that combine the earliest-ready operands first.

    Shared factors are taken out of sums first (`factor_common`).  C
    evaluates a + b + c + d as ((a + b) + c) + d, and without -ffast-math
    the compiler may not reassociate, so the shape of each printed expression
    fixes its critical path.  Combining, like a Huffman code, the two
    operands that are ready first, by a simple latency model (3 cycles per
    addition or multiplication, 13 per division), shortens the chains of
    dependent operations.  `ready` maps each local already assigned to the
    modelled cycle at which its value is available; inputs are ready at 0.
    """
    ADD, MUL, DIV = 3, 3, 13

    def __init__(self, printer):
        self.printer = printer
        self.ready = {}

    def assign(self, name, expr):
        """C text of expr, and note when `name` will be ready."""
        text, time, negative = self._operand(factor_common(sp.sympify(expr)))
        self.ready[str(name)] = time
        if _balanced(text):
            text = text[1:-1]
        return f"-({text})" if negative and not text.isidentifier() else f"-{text}" if negative else text

    def _operand(self, expr):
        """(C text, ready time, negated?) for expr."""
        if expr.is_Symbol:
            return expr.name, self.ready.get(expr.name, 0), False
        if expr.is_Number:
            return self.printer.doprint(abs(expr)), 0, bool(expr < 0)
        if expr.is_Add:
            terms = []
            for term in expr.args:
                if term.could_extract_minus_sign():
                    text, time, negative = self._operand(-term)
                    terms.append((text, time, not negative))
                else:
                    terms.append(self._operand(term))
            return self._combine(terms, self.ADD, additive=True)
        if expr.is_Mul or expr.is_Pow:
            coeff, rest = expr.as_coeff_Mul()
            negative = bool(coeff < 0)
            factors = [(self.printer.doprint(abs(coeff)), 0)] if abs(coeff) != 1 else []
            divisors = []
            for factor in sp.Mul.make_args(rest):
                base, exp = factor.as_base_exp()
                if not (exp.is_Integer and 0 < abs(exp) <= 6):
                    base, exp = factor, sp.Integer(1)
                if exp == 1 and not (base.is_Symbol or base.is_Add or base.is_Number):
                    raise ValueError(f"unsupported expression in generated code: {factor}")
                text, time, neg = self._operand(base)
                negative ^= neg and exp % 2 == 1
                (factors if exp > 0 else divisors).extend([(text, time)] * abs(int(exp)))
            text, time, _ = self._combine([(x, t, False) for x, t in factors], self.MUL) if factors else ("SR_C(1.0)", 0, False)
            if divisors:
                den, den_time, _ = self._combine([(x, t, False) for x, t in divisors], self.MUL)
                text, time = f"({text}/{den})", max(time, den_time) + self.DIV
            return text, time, negative
        raise ValueError(f"unsupported expression in generated code: {expr}")

    @staticmethod
    def _combine(operands, latency, additive=False):
        """Combine the two earliest-ready operands until one is left; returns (text, time, negated?)."""
        heap = [(t, i, x, n) for i, (x, t, n) in enumerate(operands)]
        heapq.heapify(heap)
        count = len(heap)
        while len(heap) > 1:
            t1, _, x1, n1 = heapq.heappop(heap)
            t2, _, x2, n2 = heapq.heappop(heap)
            if not additive:
                x, n = f"({x1}*{x2})", False
            elif n1 == n2:
                x, n = f"({x1} + {x2})", n1
            elif n2:
                x, n = f"({x1} - {x2})", False
            else:
                x, n = f"({x2} - {x1})", False
            heapq.heappush(heap, (max(t1, t2) + latency, count, x, n))
            count += 1
        t, _, x, n = heap[0]
        return x, t, n


def _balanced(text):
    """True if text is one parenthesized group."""
    if not (text.startswith("(") and text.endswith(")")):
        return False
    depth = 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0 and i < len(text) - 1:
            return False
    return True


def emit_assignments(scheduler, assignments, declare):
    lines = []
    for name, expr in assignments:
        prefix = "const sr_real " if declare else ""
        lines.append(f"    {prefix}{name} = {scheduler.assign(name, expr)};")
    return lines


def emit_inputs(kernel, used, layouts):
    table = input_symbols(kernel.inputs, layouts)
    missing = [s for s in used if s not in table]
    if missing:
        raise ValueError(f"kernel {kernel.name} uses symbols outside its inputs: {missing}")
    lines = []
    for sym in sorted(used, key=lambda s: (kernel.inputs.index(table[s][0]), table[s][1])):
        array, index = table[sym]
        lines.append(f"    const sr_real {sym.name} = {array}[{index}];")
    return lines


def joint_first_system(M, f):
    """M ν̇ = f with the joint accelerations eliminated: (definitions, outputs) of the `accel` kernel.

    M = [A B; Bᵀ D] with A the 3×3 shell block and D = diag(M_33, M_44): the
    yoke and pendulum rates do not couple (M_34 = 0 identically, asserted
    here).  The shell accelerations solve S ω̇_S = g with the Schur complement
    S = A − β Bᵀ, g = f_S − β f_J, β = B D⁻¹ (1/M_44 = 1/j_P is a per-model
    constant, and 1/M_33 is ready early, off the critical path); then
    ω̇_J = D⁻¹ f_J − βᵀ ω̇_S.  The entries of β are definitions (named
    `beta_i_k`; those of zero entries of B are left out), so that each term
    of β Bᵀ costs one multiplication, not the two of B_ik B_jk / d_k.  All of
    it is symbolic, so CSE and the constant pool see it together with M and f.
    """
    if sp.simplify(M[3, 4]) != 0:
        raise ValueError("joint-first solve needs M_34 = 0: the yoke and pendulum rates couple")
    A, B, d = M[0:3, 0:3], M[0:3, 3:5], (M[3, 3], M[4, 4])
    definitions, beta = [], sp.zeros(3, 2)
    for i in range(3):
        for k in range(2):
            if sp.expand(B[i, k]) != 0:
                beta[i, k] = sp.Symbol(f"beta_{i}_{k + 3}", real=True)
                definitions.append((beta[i, k], B[i, k] / d[k]))
    S_ = A - beta * B.T
    g_ = f[0:3, 0] - beta * f[3:5, 0]
    return tuple(definitions), (
        Output("S", upper_triangle(S_), "Schur complement, upper triangle", ("S_0_0", "S_0_1", "S_0_2", "S_1_1", "S_1_2", "S_2_2")),
        Output("g", tuple(g_), "reduced right-hand side", ("g_0", "g_1", "g_2")),
        Output("fD", (f[3] / d[0], f[4] / d[1]), "D^-1 f_J", ("fD_3", "fD_4")),
        Output("D", d, "joint inertias", ("M_3_3", "M_4_4")),
        Output("Mdiag", (M[0, 0], M[1, 1], M[2, 2]), "diagonal of A, the scale of the pivot tests", ("M_0_0", "M_1_1", "M_2_2")),
    )


def emit_shell_solve(scheduler, out_name, rotation, defined):
    """C for the rest of `joint_first_system`: S ω̇' = g by the adjugate of S, then the joints.

    M is positive definite iff M_33, M_44 and the leading minors of S are
    positive; as in an LDLᵀ, each pivot must exceed SR_GEN_PIVOT_TOL times
    M's diagonal entry.  1/M_33 is formed before its test: a zero or
    negative M_33 gives an infinity or a wrong sign that is never used.  The
    shell accelerations come out in the frame of the system (the yoke frame,
    see `derive.yoke_frame`) and are written as `rotation` times them.
    Couplings β_ik not among the `defined` names are identically zero and left out.
    """
    def sym(name):
        return sp.Symbol(name, real=True)

    S_ = sp.Matrix(3, 3, lambda i, j: sym(f"S_{min(i, j)}_{max(i, j)}"))
    C_ = S_.adjugate()
    C = sp.Matrix(3, 3, lambda i, j: sym(f"C_{min(i, j)}_{max(i, j)}"))
    g, a = sp.Matrix([sym(f"g_{i}") for i in range(3)]), [sym(f"a_{i}") for i in range(5)]
    beta = sp.Matrix(3, 2, lambda i, k: sym(f"beta_{i}_{k + 3}") if f"beta_{i}_{k + 3}" in defined else 0)

    def let(name, value):
        return f"    const sr_real {name} = {scheduler.assign(name, value)};"

    lines = ["    /* M positive definite: the joint block, then the leading minors of S; C = adj S (symmetric). */",
             "    if (!(M_3_3 > 0 && M_4_4 > 0)) return SR_GEN_SINGULAR;"]
    lines += [let(f"C_{i}_{j}", C_[i, j]) for i in range(3) for j in range(i, 3)]
    lines += [
        let("det_S", (S_.row(0) * C.col(0))[0]),
        "    if (!(S_0_0 > SR_GEN_PIVOT_TOL*M_0_0)) return SR_GEN_SINGULAR;",
        "    if (!(C_2_2 > SR_GEN_PIVOT_TOL*M_1_1*S_0_0)) return SR_GEN_SINGULAR;",
        "    if (!(det_S > SR_GEN_PIVOT_TOL*M_2_2*C_2_2)) return SR_GEN_SINGULAR;",
        let("inv_det_S", 1 / sym("det_S")),
    ]
    lines += [let(f"a_{i}", (C.row(i) * g)[0] * sym("inv_det_S")) for i in range(3)]
    lines += [let(f"a_{k + 3}", sym(f"fD_{k + 3}") - (beta.col(k).T * sp.Matrix(a[0:3]))[0]) for k in range(2)]
    shell_out = rotation * sp.Matrix(a[0:3])
    return lines, [(f"{out_name}[{i}]", value) for i, value in enumerate(list(shell_out) + a[3:5])]


def emit_results(scheduler, results, finite_or_untouched):
    """Assign the outputs; with `finite_or_untouched`, only after checking that all are finite.

    One test of their sum clears the common case (a NaN or an infinity makes
    it non-finite); a sum that is not finite is decided value by value, so
    finite values whose sum overflows still pass.  The caller's arrays are
    written last, so they may alias the inputs.
    """
    if not finite_or_untouched:
        return [f"    {target} = {scheduler.assign(target, value)};" for target, value in results]
    names = [f"out_{i}" for i in range(len(results))]
    lines = [f"    const sr_real {n} = {scheduler.assign(n, value)};" for n, (_, value) in zip(names, results)]
    each = " && ".join(f"isfinite({n})" for n in names)
    if len(names) == 1:
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
        args += [f"sr_real {o.name}[{'SR_GEN_NCONST' if o.name == 'c' else len(o.exprs)}]" for o in kernel.outputs]
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


def dependency_order(nodes, roots):
    """The (symbol, expression) nodes the roots need, each after the nodes it uses (depth first, roots in order)."""
    definition = dict(nodes)
    rank = {symbol: i for i, (symbol, _) in enumerate(nodes)}
    done, order = set(), []

    def visit(expr):
        for symbol in sorted(expr.free_symbols & definition.keys(), key=rank.get):
            if symbol not in done:
                done.add(symbol)
                visit(definition[symbol])
                order.append((symbol, definition[symbol]))

    for root in roots:
        visit(root)
    return order


def emit_kernel(kernel, layouts):
    """C text of one kernel and its flop count."""
    scheduler = Scheduler(Printer())
    defined = [symbol for symbol, _ in kernel.definitions]
    exprs = [value for _, value in kernel.definitions] + [e for o in kernel.outputs for e in o.exprs]
    temporaries, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), order="canonical")
    definitions, reduced = list(zip(defined, reduced[:len(defined)])), reduced[len(defined):]
    used = set().union(*(e.free_symbols for e in exprs)) - set(defined) if exprs else set()
    body = emit_inputs(kernel, used, layouts)
    nodes = temporaries + definitions
    body += emit_assignments(scheduler, dependency_order(nodes, [s for s, _ in nodes] + reduced), declare=True)
    k, results = 0, []
    for out in kernel.outputs:
        values = reduced[k:k + len(out.exprs)]
        k += len(out.exprs)
        if out.local_names:
            body += emit_assignments(scheduler, list(zip(out.local_names, values)), declare=True)
        else:
            results += [(f"{out.name}[{i}]", v) for i, v in enumerate(values)]
    if kernel.solve:
        lines, results = emit_shell_solve(scheduler, "a", S.R_Y, {s.name for s in defined})
        body += lines
    body += emit_results(scheduler, results, kernel.finite_or_untouched)
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


def layout_macros():
    """Index macros of the state blocks, the inputs and the parameters: each layout written once, here."""
    assert sum(n for _, _, n in S.STATE_BLOCKS) == S.NX
    lines = ["/* Layout of x[SR_GEN_NX]: offset of each block (matrices row-major; nu = (w_S, w_Y, w_P) starts at SR_X_w_S). */"]
    lines += [f"#define SR_X_{name} {offset}" for name, offset, _ in S.STATE_BLOCKS]
    lines += ["/* Layout of u[SR_GEN_NU]. */"]
    lines += [f"#define SR_U_{name} {index}" for name, index in S.INPUT_NAMES]
    lines += ["/* Layout of p[SR_GEN_NPARAM], the parameters of derive/parameters.py (SI). */"]
    lines += [f"#define SR_P_{s.name} {i}" for i, s in enumerate(P.PARAMETERS)]
    return "\n".join(lines)


def header_text(ks, flops, n_constants):
    guard = "SR_GENERATED_H"
    protos = "\n".join(f"/* {k.doc} */\n{signature(k)};" for k in ks)
    flop_macros = "\n".join(f"#define SR_GEN_{k.name.upper()}_FLOPS {flops[k.name]}" for k in ks)
    float_names = "\n".join(f"#define {PREFIX}{k.name} {PREFIX}{k.name}_f" for k in ks)
    return f"""{banner()}/*
 * Symbolic kernels of the spherical-robot model (Fiori 2024), derived in derive/.
 * Internal to the library: use the checked API of c/spherical_robot.h.
 * Every function returns SR_GEN_OK, SR_GEN_NONFINITE (a result is not finite) or, for accel,
 * SR_GEN_SINGULAR; outputs are caller-provided and written only on SR_GEN_OK (sr_gen_constants:
 * always, the caller checks them).
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
#define SR_GEN_NONFINITE 2
#define SR_GEN_SINGULAR 4
#define SR_GEN_NPARAM {len(P.PARAMETERS)}
#define SR_GEN_NCONST {n_constants}
#define SR_GEN_NCONST_NAMED {len(P.CONSTANTS)}
#define SR_GEN_NX {S.NX}
#define SR_GEN_NU {S.NU}
#define SR_GEN_NV {S.NV}

{layout_macros()}

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
    return banner() + f'#include "{HEADER_NAME}"\n\n#include <math.h>\n\n' + "\n".join(text for text, _ in emitted)


def pool_constants(ks):
    """The kernels with their parameter-only subexpressions moved into the constants kernel.

    Returns (kernels, constants): `constants` is the layout of the constants
    array, the twelve named constants of `parameters.CONSTANTS` first.
    """
    pool = ConstantPool(P.CONSTANTS)

    def hoisted(kernel):
        if "c" not in kernel.inputs:
            return kernel
        outputs = tuple(dataclasses.replace(o, exprs=tuple(pool.hoist(e) for e in o.exprs)) for o in kernel.outputs)
        definitions = tuple((symbol, pool.hoist(value)) for symbol, value in kernel.definitions)
        return dataclasses.replace(kernel, outputs=outputs, definitions=definitions)

    ks = tuple(hoisted(k) for k in ks)
    in_parameters = dict(zip(P.CONSTANTS, P.constant_expressions()))
    pooled = tuple(e.xreplace(in_parameters) for e in pool.expressions())
    first = len(P.CONSTANTS)
    listing = "".join(f"\n *   c[{first + i}] {k} = {sp.sstr(e)}"
                      for i, (k, e) in enumerate(zip(pool.symbols(), pool.expressions())))
    constants = tuple(P.constant_expressions()) + pooled
    ks = tuple(dataclasses.replace(k, doc=k.doc + listing, outputs=(dataclasses.replace(k.outputs[0], exprs=constants),))
               if k.name == "constants" else k for k in ks)
    return ks, tuple(P.CONSTANTS) + pool.symbols()


def write(out_dir):
    """The one place that writes files: generated/sr_generated.{{h,c}}."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ks, constants = pool_constants(kernels())
    layouts = array_layouts(constants)
    emitted = [emit_kernel(k, layouts) for k in ks]
    flops = {k.name: n for k, (_, n) in zip(ks, emitted)}
    files = {HEADER_NAME: header_text(ks, flops, len(constants)), SOURCE_NAME: source_text(emitted)}
    for name, text in files.items():
        tmp = out_dir / (name + ".tmp")
        tmp.write_text(text)
        tmp.replace(out_dir / name)
    return [out_dir / n for n in files]
