"""SymPy → a backend's own expressions, by walking the tree (no code generation, no ``eval``).

A :class:`Library` names the functions of the target (NumPy, CasADi, Pyomo, ...). The walk is
memoised per node, so shared sub-expressions are translated once.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property, reduce
from typing import Any

import sympy as sp

from gamespec.errors import ExpressionError


@dataclass(frozen=True)
class Library:
    """The target's elementary functions, by the names of :data:`gamespec.symbolic.language.FUNCTIONS`."""

    functions: Mapping[str, Callable[..., Any]]
    power: Callable[[Any, Any], Any] = field(default=lambda a, b: a**b)

    @classmethod
    def from_namespace(
        cls, namespace: Any, *, power: Callable[[Any, Any], Any] | None = None, **renamed: Callable[..., Any]
    ) -> Library:
        """The functions of :data:`gamespec.symbolic.language.FUNCTIONS` taken from ``namespace`` by
        the same name (``namespace.sin`` ...), except those given in ``renamed``."""
        from gamespec.symbolic.language import FUNCTIONS

        functions = {name: renamed.get(name) or getattr(namespace, name) for name in FUNCTIONS}
        return cls(functions) if power is None else cls(functions, power=power)


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


def _numpy_heaviside(x: Any) -> Any:
    """The unit step with SymPy's value ``heaviside(0) = 1/2``."""
    import numpy as np

    return np.heaviside(x, 0.5)


def _numpy_power(base: Any, exponent: Any) -> Any:
    import numpy as np

    return np.power(base, exponent)


class _NumpyFunctions(Mapping[str, Callable[..., Any]]):
    """NumPy's functions by gamespec's names, looked up in NumPy at the first use: a bound or
    parameter without functions (``-pi``, ``2*xf``) is evaluated at load without importing NumPy."""

    @cached_property
    def _table(self) -> Mapping[str, Callable[..., Any]]:
        import numpy as np

        renamed = {"asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "atan2": np.arctan2}
        renamed |= {"min": np.minimum, "max": np.maximum, "heaviside": _numpy_heaviside}
        return Library.from_namespace(np, **renamed).functions

    def __getitem__(self, name: str) -> Callable[..., Any]:
        return self._table[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._table)

    def __len__(self) -> int:
        return len(self._table)


NUMPY = Library(_NumpyFunctions(), power=_numpy_power)


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
        elif type(node) in _SYMPY_NAMES:
            func = library.functions[_SYMPY_NAMES[type(node)]]
            args = [walk(a) for a in node.args]
            out = reduce(func, args) if len(args) > 2 else func(*args)
        else:
            raise ExpressionError(str(expr), f"cannot translate {type(node).__name__}")
        memo[node] = out
        return out

    return walk(sp.sympify(expr))


def numeric(expr: sp.Expr, values: Mapping[sp.Symbol, float]) -> float:
    """A parameter-only expression evaluated to a float (bounds, fixed times, initial values)."""
    value = float(translate(expr, values, NUMPY))
    if math.isnan(value):
        raise ExpressionError(str(expr), "evaluates to NaN")
    return value
