"""Parameter-only subexpressions of the kernels, computed once per model in sr_gen_constants."""
import dataclasses

import sympy as sp

from .. import parameters as P


class ConstantPool:
    """Parameter-only subexpressions of the kernels, moved into sr_gen_constants.

    A product like l·m_P·r/2 or a sum like j_P + j_S + j_xx depends on the
    parameters alone, so it is computed once per model (in the constants array
    after the twelve named constants) instead of once per call.  Names k_0,
    k_1, ... are given in order of first appearance, so generation stays
    deterministic.
    """

    def __init__(self, base, prefix="k_"):
        self.base = frozenset(base)
        self.prefix = prefix
        self.table = {}            # expression -> symbol, in insertion order

    def _name(self, expr):
        if expr.is_Atom:
            return expr
        if expr.could_extract_minus_sign():
            return -self._name(-expr)
        if expr not in self.table:
            self.table[expr] = sp.Symbol(f"{self.prefix}{len(self.table)}", real=True)
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


@dataclasses.dataclass(frozen=True)
class ConstantsArray:
    """One per-model constants array: the input name the kernels read it by, the kernel that computes
    it, its named constants (symbol, expression in the parameters) and the pool symbols' prefix."""
    array: str
    kernel: str
    named: tuple
    prefix: str


PAPER_CONSTANTS = ConstantsArray("c", "constants", tuple(zip(P.CONSTANTS, P.constant_expressions())), "k_")


def pool_constants(ks, spec=PAPER_CONSTANTS):
    """The kernels with their parameter-only subexpressions moved into the constants kernel.

    Returns (kernels, constants): `constants` is the layout of the constants
    array `spec.array`, its named constants first (for the paper's kernels the
    twelve of `parameters.CONSTANTS`).
    """
    names = tuple(symbol for symbol, _ in spec.named)
    expressions = tuple(expr for _, expr in spec.named)
    pool = ConstantPool(names, spec.prefix)

    def hoisted(kernel):
        if spec.array not in kernel.inputs:
            return kernel
        outputs = tuple(dataclasses.replace(o, exprs=tuple(pool.hoist(e) for e in o.exprs)) for o in kernel.outputs)
        definitions = tuple((symbol, pool.hoist(value)) for symbol, value in kernel.definitions)
        return dataclasses.replace(kernel, outputs=outputs, definitions=definitions)

    ks = tuple(hoisted(k) for k in ks)
    in_parameters = dict(zip(names, expressions))
    pooled = tuple(e.xreplace(in_parameters) for e in pool.expressions())
    first = len(names)
    listing = "".join(f"\n *   {spec.array}[{first + i}] {k} = {sp.sstr(e)}"
                      for i, (k, e) in enumerate(zip(pool.symbols(), pool.expressions())))
    constants = expressions + pooled
    ks = tuple(dataclasses.replace(k, doc=k.doc + listing, outputs=(dataclasses.replace(k.outputs[0], exprs=constants),))
               if k.name == spec.kernel else k for k in ks)
    return ks, names + pool.symbols()
