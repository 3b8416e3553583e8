"""One root error and a few subclasses; every user-facing failure is one of these.

The CLI turns a :class:`GamespecError` into exit code 2 and one line (``str(err)``); anything else
is a bug and keeps its traceback.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


class GamespecError(Exception):
    """Root of all errors gamespec raises on purpose."""


class SpecError(GamespecError):
    """A problem file (or spec built in Python) is invalid.

    ``source`` is the file (or ``<spec>``), ``field`` the dotted location, ``reason`` the why.
    """

    def __init__(self, reason: str, *, field: str = "", source: str = "<spec>") -> None:
        self.reason = reason
        self.field = field
        self.source = source
        where = f"{source}: {field}: " if field else f"{source}: "
        super().__init__(where + reason)


class RefusedInput(SpecError):
    """Well-formed input that gamespec refuses to read: beyond a limit of :mod:`gamespec.limits`, a
    recursive alias, a duplicate key."""


@contextmanager
def sourced(source: str) -> Iterator[None]:
    """Name the file ``source`` in a SpecError raised inside that names none (``<spec>``): a
    backend's refusal at compile or solve time knows the field, not the file."""
    try:
        yield
    except SpecError as err:
        if err.source != "<spec>" or source == "<spec>":
            raise
        raise type(err)(err.reason, field=err.field, source=source) from None


class ExpressionError(GamespecError):
    """An expression string uses something outside the whitelisted language."""

    def __init__(self, expression: str, reason: str, column: int | None = None) -> None:
        self.expression = expression
        self.reason = reason
        self.column = column
        at = f" at column {column + 1}" if column is not None else ""
        shown = expression if len(expression) <= 80 else expression[:77] + "..."
        super().__init__(f"expression {shown!r}{at}: {reason}")


class BackendError(GamespecError):
    """A backend is unknown, not installed, or cannot take the problem it was given."""


class UnsupportedFeature(BackendError):
    """The chosen backend lacks a kind or feature the problem needs."""
