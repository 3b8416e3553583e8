"""SymPy back to the safe language of :mod:`gamespec.symbolic.language` (DESIGN.md, "Expressions
are data"): generated problems (the engagement reduction, sensitivity equations) are built in SymPy
and written out with :func:`to_text`, never assembled from f-strings.

The printer is SymPy's :class:`~sympy.printing.str.StrPrinter` (precedence and parentheses) over a
whitelist of node types: symbols (a state at a fixed time, ``x(t=5.0)``, as the grammar spells it),
a file's tables (by name), exact integers and rationals (``a/b``), floats (``repr``, so they
round-trip exactly), ``pi`` and ``E`` (as ``exp(1)``), ``+ * **`` and the functions of
:data:`~gamespec.symbolic.language.FUNCTIONS` by the language's names (``abs``, binary ``min``/``max``,
``sign``, ``heaviside`` with SymPy's value 1/2 at 0) — everything SymPy's derivatives of the language
produce except ``DiracDelta``. Relations ``<=``, ``>=``, ``==`` print for constraints. Anything else
(``Piecewise``, ``DiracDelta``, ``re``, infinities, unknown functions) is an
:class:`~gamespec.errors.ExpressionError`, so ``parse(to_text(e), symbols) == e`` whenever
``to_text`` returns.
"""

from __future__ import annotations

import keyword
import math
import sys
from typing import Any

import sympy as sp
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.str import StrPrinter

from gamespec.errors import ExpressionError
from gamespec.symbolic.grammar import Relation, at_time_parts
from gamespec.symbolic.language import CONSTANTS, FUNCTIONS

_FUNCTION_NAMES: dict[type, str] = {
    func: name for name, (_, func) in FUNCTIONS.items() if isinstance(func, type)
}
MAX_NUMBER_BITS = 12_000
"""Longest exact integer, numerator or denominator written out (about 3600 digits; an expression
of the language has at most 10000 characters)."""
_RELATIONS: dict[type, str] = {sp.Le: "<=", sp.Ge: ">=", sp.Lt: "<", sp.Gt: ">", sp.Eq: "=="}
_NODES: tuple[type, ...] = (
    sp.Rational,
    sp.Float,
    sp.Add,
    sp.Mul,
    sp.Pow,
    type(sp.pi),
    type(sp.E),
    *_FUNCTION_NAMES,
)


class LanguagePrinter(StrPrinter):
    """A :class:`StrPrinter` that writes only the gamespec expression language."""

    def __init__(self, expr: sp.Basic) -> None:
        super().__init__()
        self.expr = expr

    def fail(self, reason: str) -> ExpressionError:
        return ExpressionError(StrPrinter().doprint(self.expr), reason)

    def _print(self, expr: Any, **kwargs: Any) -> str:
        table = getattr(expr, "table", None) if isinstance(expr, sp.Function) else None
        if table is not None:
            if expr.derivative:
                raise self.fail(f"a derivative of table {table.name!r} has no form in the language")
            return f"{table.name}({', '.join(self._print(a) for a in expr.args)})"
        if isinstance(expr, sp.Basic) and not (type(expr) is sp.Symbol or isinstance(expr, _NODES)):
            raise self.fail(f"{type(expr).__name__} has no form in the gamespec expression language")
        return super()._print(expr, **kwargs)

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        """A name, a dotted name (``phases.ascent.x_f``, a multi-phase link), or a state's value at
        a fixed time (``x(t=5.0)``, :func:`~gamespec.symbolic.grammar.at_time_name`)."""
        timed = at_time_parts(expr.name)
        name = expr.name if timed is None else timed[0]
        parts = name.split(".")
        if (
            not all(p.isidentifier() and not keyword.iskeyword(p) for p in parts)
            or parts[0] in FUNCTIONS
            or parts[0] in CONSTANTS
            or (timed is not None and len(parts) > 1)
        ):
            raise self.fail(f"symbol name {name!r} cannot be written in the language")
        return str(expr.name)

    def _print_Float(self, expr: sp.Float) -> str:
        """The nearest double, in full (``repr``): a double-precision Float parses back to itself
        (one of more precision is rounded); one beyond the doubles' range, or among the subnormals
        where a double holds fewer digits, is refused."""
        value = float(expr)
        if not math.isfinite(value) or (abs(value) < sys.float_info.min and sp.Float(value) != expr):
            raise self.fail(f"number {sp.sstr(expr)} is outside the range of a double")
        return repr(value)

    def _print_Rational(self, expr: sp.Rational) -> str:
        if max(abs(expr.p), expr.q).bit_length() > MAX_NUMBER_BITS:
            raise self.fail("an exact number too long for the language")
        return super()._print_Rational(expr)

    def _print_Integer(self, expr: sp.Integer) -> str:
        return self._print_Rational(expr)

    def _print_Mul(self, expr: sp.Mul) -> str:
        """Products whose evaluation order matters when parsed back: a fractional coefficient divides
        last (``115/(a + 1)/9``, not ``115/(9*(a + 1))``, which parses as ``115/(9*a + 9)``), and a
        coefficient multiplies the rest of a product with a sum as a whole (``-(a + 1)*b`` would
        parse as ``(-a - 1)*b``), and so does a minus sign: SymPy distributes a number over a sum it
        multiplies alone."""
        coeff, rest = expr.as_coeff_Mul()
        if coeff is sp.S.One or rest is sp.S.One:
            return super()._print_Mul(expr)
        if coeff.is_Rational and coeff.q != 1:
            if coeff < 0:
                positive = self._print_Mul(-expr)
                return f"-({positive})" if positive.startswith("(") else "-" + positive
            numerator = self.parenthesize(coeff.p * rest, PRECEDENCE["Mul"], strict=True)
            return f"{numerator}/{coeff.q}"
        if isinstance(rest, sp.Mul) and any(factor.is_Add for factor in rest.args):
            lead = "-" if coeff is sp.S.NegativeOne else self._print(coeff) + "*"
            return f"{lead}({self._print(rest)})"
        return super()._print_Mul(expr)

    def _print_Exp1(self, expr: sp.Basic) -> str:
        return "exp(1)"

    def _print_Pi(self, expr: sp.Basic) -> str:
        return "pi"

    def _print_Abs(self, expr: sp.Abs) -> str:
        return f"abs({self._print(expr.args[0])})"

    def _binary(self, name: str, args: tuple[sp.Basic, ...]) -> str:
        """``min(a, min(b, c))``: the language's min/max take two arguments; SymPy flattens them back."""
        first, *rest = args
        inner = self._print(rest[0]) if len(rest) == 1 else self._binary(name, tuple(rest))
        return f"{name}({self._print(first)}, {inner})"

    def _print_Min(self, expr: sp.Min) -> str:
        return self._binary("min", expr.args)

    def _print_Max(self, expr: sp.Max) -> str:
        return self._binary("max", expr.args)

    def _print_Heaviside(self, expr: sp.Heaviside) -> str:
        if expr.args[1] != sp.S.Half:
            raise self.fail(f"heaviside with value {expr.args[1]} at 0 (the language's is 1/2)")
        return f"heaviside({self._print(expr.args[0])})"

    def _print_Function(self, expr: sp.Function) -> str:
        args = ", ".join(self._print(a) for a in expr.args)
        return f"{_FUNCTION_NAMES[type(expr)]}({args})"


def to_text(expr: sp.Basic) -> str:
    """``expr`` in the gamespec expression language, such that ``parse(to_text(expr), symbols) ==
    expr`` (``parse_relation`` for a relation), ``symbols`` mapping each name to its symbol, for
    ``expr`` in SymPy's canonical form (the rare product SymPy leaves nested in a product comes back
    flattened)."""
    expr = sp.sympify(expr)
    printer = LanguagePrinter(expr)
    if type(expr) in _RELATIONS:
        return f"{printer.doprint(expr.lhs)} {_RELATIONS[type(expr)]} {printer.doprint(expr.rhs)}"
    return printer.doprint(expr)


def relation_texts(rel: Relation) -> list[str]:
    """``rel`` as constraints of the file language: one equation, or one or two inequalities."""
    if rel.is_equality:
        return [to_text(sp.Eq(rel.expr - rel.lower, 0, evaluate=False))]
    found = []
    if math.isfinite(rel.lower):
        found.append(to_text(sp.Ge(rel.expr, rel.lower, evaluate=False)))
    if math.isfinite(rel.upper):
        found.append(to_text(sp.Le(rel.expr, rel.upper, evaluate=False)))
    return found
