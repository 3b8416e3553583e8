"""Expressions translated once into a tape of NumPy operations, then evaluated many times.

:func:`~gamespec.symbolic.translate.translate` walks a SymPy tree on every call, which dominates
when the same expressions are evaluated over and over (an RK4 re-integration calls the dynamics
``4 * RK4_STEPS`` times per check). :func:`record` runs that same walk once over :class:`Slot`
placeholders, so the translation rules stay in one place: every arithmetic operation and library
function applied to a slot appends one step to a :class:`Tape` instead of computing a value. The
tape then evaluates with a flat loop over NumPy calls.
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp

from gamespec.symbolic.library import NUMPY, Library
from gamespec.symbolic.translate import translate


@dataclass
class Tape:
    """Registers ``0 .. n_args-1`` hold the arguments; each step appends one register."""

    n_args: int
    steps: list[tuple[Callable[..., Any], tuple[Any, ...]]] = field(default_factory=list)

    def push(self, func: Callable[..., Any], *inputs: Any) -> Slot:
        self.steps.append((func, tuple(inputs)))
        return Slot(self, self.n_args + len(self.steps) - 1)

    def run(self, args: Sequence[Any]) -> list[Any]:
        """Every register's value for these argument values."""
        registers = list(args)
        for func, inputs in self.steps:
            registers.append(func(*(registers[i.index] if isinstance(i, Slot) else i for i in inputs)))
        return registers


@dataclass(frozen=True)
class Slot:
    """A register of a :class:`Tape`; operations on it are recorded, not computed."""

    tape: Tape
    index: int

    def __add__(self, other: Any) -> Slot:
        return self.tape.push(operator.add, self, other)

    __radd__ = __add__

    def __mul__(self, other: Any) -> Slot:
        return self.tape.push(operator.mul, self, other)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Slot:
        return self.tape.push(operator.truediv, self, other)

    def __rtruediv__(self, other: Any) -> Slot:
        return self.tape.push(operator.truediv, other, self)

    def __neg__(self) -> Slot:
        return self.tape.push(operator.neg, self)


def _recording(library: Library, tape: Tape) -> Library:
    """``library`` with each function (and the power) recording its call on ``tape``."""

    def recorder(func: Callable[..., Any]) -> Callable[..., Slot]:
        return lambda *args: tape.push(func, *args)

    functions = {name: recorder(func) for name, func in library.functions.items()}
    return Library(functions, power=recorder(library.power))


def record(
    exprs: Sequence[sp.Expr], args: Sequence[sp.Symbol], library: Library = NUMPY
) -> Callable[[Sequence[Any]], list[Any]]:
    """A function of the argument values returning the value of each expression (a number for an
    expression that depends on no argument), with the tree walked once, here."""
    tape = Tape(len(args))
    slots = {a: Slot(tape, i) for i, a in enumerate(args)}
    outputs = [translate(e, slots, _recording(library, tape)) for e in exprs]

    def evaluate(values: Sequence[Any]) -> list[Any]:
        registers = tape.run(values)
        return [registers[o.index] if isinstance(o, Slot) else o for o in outputs]

    return evaluate


def as_array(values: list[Any], shape: tuple[int, ...]) -> np.ndarray:
    """Recorded outputs broadcast to ``shape`` and stacked: ``(len(values), *shape)``."""
    rows = [np.broadcast_to(np.asarray(v, dtype=float), shape) for v in values]
    return np.stack(rows) if rows else np.empty((0, *shape))
