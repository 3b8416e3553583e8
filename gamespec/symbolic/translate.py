"""SymPy → a backend's own expressions, by walking the tree (no code generation, no ``eval``).

A :class:`~gamespec.symbolic.library.Library` names the functions of the target (NumPy, CasADi,
Pyomo, ...). The walk is memoised per node, so shared sub-expressions are translated once.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import reduce
from typing import Any

import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.symbolic.library import NUMPY, Library

_SYMPY_NAMES: dict[type, str] = {
    sp.sin: "sin",
    sp.cos: "cos",
    sp.tan: "tan",
    sp.asin: "asin",
    sp.acos: "acos",
    sp.atan: "atan",
    sp.atan2: "atan2",
    sp.exp: "exp",
    sp.log: "log",
    sp.Abs: "abs",
    sp.tanh: "tanh",
    sp.Min: "min",
    sp.Max: "max",
    sp.sign: "sign",
    sp.Heaviside: "heaviside",
}


def translate(expr: sp.Expr, values: Mapping[sp.Symbol, Any], library: Library) -> Any:
    """The value of ``expr`` with each symbol replaced by ``values[symbol]``, built with ``library``."""
    memo: dict[sp.Basic, Any] = {}

    def walk(node: sp.Basic) -> Any:
        if node in memo:
            return memo[node]
        if node.is_Symbol:
            if node not in values:
                raise ExpressionError(str(expr), f"symbol {node} has no value here")
            out = values[node]
        elif node.is_Number or node is sp.pi or node is sp.E:
            out = float(node)
        elif node.is_Add:
            out = reduce(lambda a, b: a + b, (walk(a) for a in node.args))
        elif node.is_Mul:
            out = reduce(lambda a, b: a * b, (walk(a) for a in node.args))
        elif node.is_Pow:
            base, exponent = node.args
            if exponent == sp.Rational(1, 2):
                out = library.functions["sqrt"](walk(base))
            elif exponent == -1:
                out = 1.0 / walk(base)
            else:
                out = library.power(walk(base), walk(exponent))
        elif isinstance(node, sp.Heaviside):
            if node.args[1] != sp.S.Half:
                raise ExpressionError(str(expr), f"heaviside with value {node.args[1]} at 0 (only 1/2)")
            out = library.functions["heaviside"](walk(node.args[0]))
        elif getattr(node, "table", None) is not None:
            out = _table(expr, node, library)(*(walk(a) for a in node.args))
        elif type(node) in _SYMPY_NAMES:
            func = library.functions[_SYMPY_NAMES[type(node)]]
            args = [walk(a) for a in node.args]
            out = reduce(func, args) if len(args) > 2 else func(*args)
        else:
            raise ExpressionError(str(expr), f"cannot translate {type(node).__name__}")
        memo[node] = out
        return out

    return walk(sp.sympify(expr))


def _table(expr: sp.Expr, node: sp.Basic, library: Library) -> Any:
    """The target's function of a table's node (:mod:`gamespec.symbolic.tables`); a derivative of
    a table, or a target without interpolants, is refused."""
    table = node.table  # type: ignore[attr-defined]
    if node.derivative:  # type: ignore[attr-defined]
        raise ExpressionError(str(expr), f"a derivative of table {table.name!r} cannot be evaluated here")
    if library.tables is None:
        raise ExpressionError(str(expr), f"table {table.name!r} has no interpolant on this backend")
    return library.tables(table)


def numeric(expr: sp.Expr, values: Mapping[sp.Symbol, float]) -> float:
    """A parameter-only expression evaluated to a float (bounds, fixed times, initial values)."""
    value = float(translate(expr, values, NUMPY))
    if math.isnan(value):
        raise ExpressionError(str(expr), "evaluates to NaN")
    return value
