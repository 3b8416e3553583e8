"""gamespec: declarative optimal control and differential games on interchangeable backends.

``load`` reads a problem file into a spec, ``solve`` runs it on a backend and returns a
:class:`Result`. Backends, problem kinds and transforms are plugins found by entry point and
imported only when used.

The errors are imported with the package; ``load``, ``solve`` and the rest are imported on first
use (PEP 562), so that ``import gamespec.errors`` or the command line's ``--help`` does not pay for
NumPy, pydantic and the solving chain.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from gamespec.errors import (
    BackendError,
    ExpressionError,
    GamespecError,
    SpecError,
    UnsupportedFeature,
)

if TYPE_CHECKING:
    from gamespec.loader import load, spec_from_dict
    from gamespec.result import Result, Status
    from gamespec.solving import compile_spec, solve

__version__ = "0.1.0"

_LAZY = {
    "load": "gamespec.loader",
    "spec_from_dict": "gamespec.loader",
    "Result": "gamespec.result",
    "Status": "gamespec.result",
    "compile_spec": "gamespec.solving",
    "solve": "gamespec.solving",
}
"""Public names imported on first use: name → the module that defines it."""

__all__ = [
    "BackendError",
    "ExpressionError",
    "GamespecError",
    "Result",
    "SpecError",
    "Status",
    "UnsupportedFeature",
    "compile_spec",
    "load",
    "solve",
    "spec_from_dict",
]


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module 'gamespec' has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
