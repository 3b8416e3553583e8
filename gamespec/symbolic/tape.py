"""Expressions translated once into a tape of NumPy operations, then evaluated many times.

Walking an expression (a SymPy tree with :func:`~gamespec.symbolic.translate.translate`, a file's
text with :class:`~gamespec.symbolic.library.LibraryAlgebra`) on every call dominates when the same
expressions are evaluated over and over (an RK4 re-integration calls the dynamics
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

from gamespec.symbolic.library import NUMPY, Library


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

    def __sub__(self, other: Any) -> Slot:
        return self.tape.push(operator.sub, self, other)

    def __rsub__(self, other: Any) -> Slot:
        return self.tape.push(operator.sub, other, self)

    def __pow__(self, other: Any) -> Slot:
        return self.tape.push(operator.pow, self, other)

    def __rpow__(self, other: Any) -> Slot:
        return self.tape.push(operator.pow, other, self)

    def __neg__(self) -> Slot:
        return self.tape.push(operator.neg, self)


def _recording(library: Library, tape: Tape) -> Library:
    """``library`` with each function (and the power) recording its call on ``tape``."""

    def recorder(func: Callable[..., Any]) -> Callable[..., Slot]:
        return lambda *args: tape.push(func, *args)

    functions = {name: recorder(func) for name, func in library.functions.items()}
    tables = library.tables
    recorded = None if tables is None else (lambda table: recorder(tables(table)))
    return Library(functions, power=recorder(library.power), tables=recorded)


Build = Callable[[list[Slot], Library], Sequence[Any]]
"""Builds the outputs from one value per argument with a library's functions."""


def record(build: Build, n_args: int, library: Library = NUMPY) -> Callable[[Sequence[Any]], list[Any]]:
    """A function of the argument values returning the value of each output of ``build`` (a
    number for an output that depends on no argument), with ``build`` run once, here, on slots."""
    tape = Tape(n_args)
    outputs = list(build([Slot(tape, i) for i in range(n_args)], _recording(library, tape)))

    def evaluate(values: Sequence[Any]) -> list[Any]:
        registers = tape.run(values)
        return [registers[o.index] if isinstance(o, Slot) else o for o in outputs]

    return evaluate


def vectorized(build: Build, n_args: int, library: Library = NUMPY) -> Callable[..., np.ndarray]:
    """The outputs of ``build`` as a vectorized function: called with one array (or number) per
    argument, broadcast together to a shape ``s``, it returns an array ``(outputs, *s)``."""
    tape = record(build, n_args, library)

    def evaluate(*values: np.ndarray | float) -> np.ndarray:
        if len(values) != n_args:
            raise TypeError(f"expected {n_args} arrays, got {len(values)}")
        arrays = [np.asarray(v, dtype=float) for v in values]
        return as_array(tape(arrays), np.broadcast_shapes(*(a.shape for a in arrays)))

    return evaluate


def as_array(values: list[Any], shape: tuple[int, ...]) -> np.ndarray:
    """Recorded outputs broadcast to ``shape`` and stacked: ``(len(values), *shape)``."""
    rows = [np.broadcast_to(np.asarray(v, dtype=float), shape) for v in values]
    return np.stack(rows) if rows else np.empty((0, *shape))
