"""Vectors in the expression language: the SymPy algebra of :mod:`gamespec.symbolic.language` with
column vectors beside scalars, for vector states and controls (``r: {size: 3}``).

A vector is an immutable SymPy column matrix. ``+`` and ``-`` act between vectors of one size,
``*`` and ``/`` between a vector and a scalar; ``v[i]`` is a component (negative ``i`` from the
end), ``[a, b, c]`` a vector of scalars; ``dot(a, b)``, ``cross(a, b)`` (size 3) and ``norm(a)``
(``sqrt(dot(a, a))``) are the vector functions; a table of the file (``CL(norm(v), r[2])``) takes
scalars and stays SymPy's opaque function of them. Everything else on a vector (``sin(r)``, ``r**2``,
``r * v``) is refused with the reason, so that a file means one thing. The scalar results are
SymPy expressions of the components, printed back to the language by
:func:`~gamespec.symbolic.printer.to_text` (:mod:`gamespec.specs.vectors` lowers a file this way).
"""

from __future__ import annotations

import ast
from collections.abc import Mapping
from typing import Any

import sympy as sp

from gamespec.symbolic.grammar import FileFunction, Refused, relation
from gamespec.symbolic.grammar import expression as walk
from gamespec.symbolic.language import SYMPY, Relation

Vector = sp.ImmutableMatrix
"""A column vector of SymPy scalars."""


def is_vector(value: Any) -> bool:
    return isinstance(value, sp.MatrixBase)


def _size(value: Any) -> int:
    return int(value.shape[0])


class VectorSympyAlgebra:
    """The grammar's walk building SymPy scalars and :data:`Vector` values (module doc)."""

    functions: Mapping[str, int] = {"dot": 2, "cross": 2, "norm": 1}

    def number(self, value: int | float) -> Any:
        return SYMPY.number(value)

    def constant(self, name: str) -> Any:
        return SYMPY.constant(name)

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> Any:
        if not (is_vector(left) or is_vector(right)):
            return SYMPY.binary(op, left, right)
        if op in (ast.Add, ast.Sub):
            if not (is_vector(left) and is_vector(right)):
                raise Refused("a vector and a scalar cannot be added (index the vector: r[0])")
            if _size(left) != _size(right):
                raise Refused(f"vectors of sizes {_size(left)} and {_size(right)} cannot be added")
            return Vector(left + right if op is ast.Add else left - right)
        if is_vector(left) and is_vector(right):
            raise Refused("a product of two vectors is not defined here: use dot(a, b) or cross(a, b)")
        if op is ast.Div and is_vector(right):
            raise Refused("division by a vector is not defined")
        vector, factor = (left, right) if is_vector(left) else (right, left)
        if op is ast.Div:
            return Vector([SYMPY.binary(ast.Div, c, factor) for c in vector])
        return Vector([SYMPY.binary(ast.Mult, c, factor) for c in vector])

    def negate(self, value: Any) -> Any:
        return Vector(-value) if is_vector(value) else SYMPY.negate(value)

    def power(self, base: Any, exponent: Any) -> Any:
        if is_vector(base) or is_vector(exponent):
            raise Refused("a power of a vector is not defined here: use dot(a, a) or norm(a)**2")
        return SYMPY.power(base, exponent)

    def call(self, name: str, args: list[Any]) -> Any:
        if name in self.functions:
            return self._vector_call(name, args)
        if any(is_vector(a) for a in args):
            raise Refused(f"{name} takes scalars: apply it to each component (r[0])")
        return SYMPY.call(name, args)

    def tabulated(self, function: FileFunction, args: list[Any]) -> Any:
        """A table (:mod:`gamespec.symbolic.tables`) of scalars: SymPy's opaque function of it."""
        if any(is_vector(a) for a in args):
            raise Refused(f"table {function.name} takes scalars: give it components (r[0]) or norm(r)")
        return SYMPY.tabulated(function, args)

    def _vector_call(self, name: str, args: list[Any]) -> Any:
        if not all(is_vector(a) for a in args):
            raise Refused(f"{name} takes vectors")
        if name == "norm":
            return SYMPY.call("sqrt", [SYMPY.finite(args[0].dot(args[0]))])
        a, b = args
        if _size(a) != _size(b):
            raise Refused(f"{name} of vectors of sizes {_size(a)} and {_size(b)}")
        if name == "dot":
            return SYMPY.finite(a.dot(b))
        if _size(a) != 3:
            raise Refused("cross takes vectors of size 3")
        return Vector(a.cross(b))

    def index(self, value: Any, i: int) -> Any:
        if not is_vector(value):
            raise Refused("only a vector can be indexed")
        n = _size(value)
        if not -n <= i < n:
            raise Refused(f"index {i} is out of range for a vector of size {n}")
        return value[i]

    def vector(self, items: list[Any]) -> Any:
        if not items or any(is_vector(v) for v in items):
            raise Refused("a list holds one or more scalars")
        return Vector(items)

    def scalar(self, value: Any) -> float | None:
        return None if is_vector(value) else SYMPY.scalar(value)


VECTORS = VectorSympyAlgebra()


def parse_vector(text: str | float, symbols: Mapping[str, Any]) -> Any:
    """A SymPy scalar or :data:`Vector` of an expression over ``symbols`` (scalars or vectors)."""
    return walk(text, symbols, VECTORS)


def parse_vector_relation(text: str, symbols: Mapping[str, Any]) -> list[Relation]:
    """A constraint over ``symbols`` as scalar relations: one, or one per component of a vector
    relation (``r_f == [1, 0, 0]``, ``-1 <= u <= 1``)."""
    found = relation(text, symbols, VECTORS)
    if not is_vector(found.expr):
        return [found]
    return [Relation(c, found.lower, found.upper) for c in found.expr]
