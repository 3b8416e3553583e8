"""gamespec: declarative optimal control and differential games on interchangeable backends.

``load`` reads a problem file into a spec, ``solve`` runs it on a backend and returns a
:class:`Result`. Backends, problem kinds and transforms are plugins found by entry point and
imported only when used.
"""

from gamespec.errors import (
    BackendError,
    ExpressionError,
    GamespecError,
    SpecError,
    UnsupportedFeature,
)
from gamespec.loader import load, spec_from_dict
from gamespec.result import Result, Status
from gamespec.solving import compile_spec, solve

__version__ = "0.1.0"

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
