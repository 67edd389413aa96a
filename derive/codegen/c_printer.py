"""Generic C printing of SymPy expressions: literals, common factors, a latency scheduler, flop counts.

Nothing here is specific to the model.  The scalar type is `sr_real`
(double, or float with -DSR_USE_FLOAT; c/include/sr_real.h), and numeric literals
go through SR_C() so both builds are clean under -Wall -Wextra -Wpedantic
-Werror.
"""
import collections
import heapq
import re

import sympy as sp
from sympy.printing.c import C99CodePrinter


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
    ADD, MUL, DIV, CALL = 3, 3, 13, 40
    #: Functions of one argument that a kernel may call (the sine and cosine of the slope, per model).
    FUNCTIONS = {sp.sin: "SR_GEN_SIN", sp.cos: "SR_GEN_COS"}

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
        if expr.func in self.FUNCTIONS:
            text, time, negative = self._operand(expr.args[0])
            return f"{self.FUNCTIONS[expr.func]}({'-' if negative else ''}{text})", time + self.CALL, False
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
                if exp == 1 and not (base.is_Symbol or base.is_Add or base.is_Number or base.func in self.FUNCTIONS):
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
