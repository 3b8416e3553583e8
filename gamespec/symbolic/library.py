"""A backend's elementary functions (:class:`Library`) and the walk of
:mod:`gamespec.symbolic.grammar` building that backend's expressions (:class:`LibraryAlgebra`)
straight from a file's text, without SymPy; :data:`NUMPY` is NumPy's library and
:func:`casadi_library` CasADi's (for the casadi backend's NLP and the compiled checks).
"""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any

from gamespec.symbolic.grammar import BINARY, FLOATS, FUNCTION_ARITY, FileFunction, Refused

TableBuilder = Callable[[FileFunction], Callable[..., Any]]
"""How a target evaluates a file's table: the table → a function of the target's values."""


@dataclass(frozen=True)
class Library:
    """A target's elementary functions, by the names of :data:`FUNCTION_ARITY`, and how it evaluates
    a file's tables (``tables``; None for a target that has no interpolant, which refuses them)."""

    functions: Mapping[str, Callable[..., Any]]
    power: Callable[[Any, Any], Any] = operator.pow
    tables: TableBuilder | None = None

    @classmethod
    def from_namespace(
        cls, namespace: Any, *, power: Callable[[Any, Any], Any] | None = None, **renamed: Callable[..., Any]
    ) -> Library:
        """The functions of :data:`FUNCTION_ARITY` taken from ``namespace`` by the same name
        (``namespace.sin`` ...), except those given in ``renamed``."""
        functions = {name: renamed.get(name) or getattr(namespace, name) for name in FUNCTION_ARITY}
        return cls(functions) if power is None else cls(functions, power=power)


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


def _numpy_table(table: FileFunction) -> Callable[..., Any]:
    return table.numpy  # type: ignore[attr-defined, no-any-return]


def _casadi_table(table: FileFunction) -> Callable[..., Any]:
    return table.casadi  # type: ignore[attr-defined, no-any-return]


NUMPY = Library(_NumpyFunctions(), power=_numpy_power, tables=_numpy_table)


@lru_cache(maxsize=1)
def casadi_library(ca: Any) -> Library:
    """CasADi's functions by gamespec's names; ``heaviside(x) = (1 + sign(x))/2``, which is 1/2 at 0
    as SymPy's ``Heaviside`` (CasADi's ``sign(0) = 0``); a table is a ``casadi.interpolant``
    (:class:`gamespec.symbolic.tables.Table`). One library per process: the algebras over it are
    one algebra (:class:`LibraryAlgebra`), whose kept walks every CasADi model takes again."""
    library = Library.from_namespace(
        ca, abs=ca.fabs, min=ca.fmin, max=ca.fmax, heaviside=lambda x: 0.5 * (1 + ca.sign(x))
    )
    return Library(library.functions, library.power, tables=_casadi_table)


class LibraryAlgebra:
    """A backend's own expressions (CasADi, NumPy arrays, a tape), built with ``library`` over the
    values given for the names; a part made of the text's numbers alone is computed in floats
    (:data:`~gamespec.symbolic.grammar.FLOATS`, which refuses ``1/0`` as the check at load did)."""

    def __init__(self, library: Library) -> None:
        self.library = library

    def __eq__(self, other: object) -> bool:
        """The algebras over one library are one algebra: what
        :class:`~gamespec.ocp.symbolic.SymbolicOcp` keeps walked in one is taken in another."""
        return isinstance(other, LibraryAlgebra) and other.library is self.library

    def __hash__(self) -> int:
        return id(self.library)

    @staticmethod
    def _numbers(*args: Any) -> bool:
        """Whether every argument is a Python number (the text's own constants): a NumPy number
        (``np.float64`` is a ``float``) is the backend's value and is computed by the backend."""
        return all(type(a) in (int, float) for a in args)

    def number(self, value: int | float) -> float:
        return FLOATS.number(value)

    def constant(self, name: str) -> float:
        return FLOATS.constant(name)

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> Any:
        return FLOATS.binary(op, left, right) if self._numbers(left, right) else BINARY[op](left, right)

    def negate(self, value: Any) -> Any:
        return -value

    def power(self, base: Any, exponent: Any) -> Any:
        if self._numbers(base, exponent):
            return FLOATS.power(base, exponent)
        return self.library.power(base, exponent)

    def call(self, name: str, args: list[Any]) -> Any:
        if self._numbers(*args):
            return FLOATS.call(name, args)
        return self.library.functions[name](*args)

    def tabulated(self, function: FileFunction, args: list[Any]) -> Any:
        if self._numbers(*args):
            return FLOATS.tabulated(function, args)
        if self.library.tables is None:
            raise Refused(f"table {function.name!r} has no interpolant on this backend")
        return self.library.tables(function)(*args)

    def scalar(self, value: Any) -> float | None:
        return float(value) if self._numbers(value) else None
