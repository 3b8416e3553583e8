"""Base pydantic models for everything a user writes, and the sections every problem file shares.

Following SQLMesh's config layer: ``extra="forbid"`` everywhere, and errors reported with their
dotted location and the nearest valid key (see :func:`gamespec.loader.format_validation_error`).
"""

from __future__ import annotations

from typing import Any, ClassVar

from pydantic import BaseModel, ConfigDict, Field, FiniteFloat, PrivateAttr

Number = FiniteFloat
"""A finite number: NaN and ±inf are refused at load, with the field named."""

Value = Number | str
"""A finite number, or an expression over the problem's parameters (each kind checks that the
expression evaluates to a finite number)."""


class StrictModel(BaseModel):
    """A pydantic model that rejects unknown keys and is immutable once built."""

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class SolverSection(StrictModel):
    """Which backend solves the problem, and the knobs of each backend (validated by the backend).

    ``options`` maps a backend name to that backend's own options block, so the same file can be
    solved on several backends without re-typing anything.
    """

    backend: str | None = Field(None, description="Backend name; the kind's default when omitted.")
    options: dict[str, dict[str, Any]] = Field(
        default_factory=dict, description="Per-backend option blocks, keyed by backend name."
    )


class SpecBase(StrictModel):
    """Fields shared by every problem kind; subclasses fix ``kind`` to a literal."""

    kind: str
    name: str = Field("unnamed", description="A short name used in reports and output folders.")
    description: str = ""
    solver: SolverSection = Field(default_factory=SolverSection)

    default_backend: ClassVar[str] = ""
    _source: str = PrivateAttr("<spec>")
    _file_hash: str = PrivateAttr("")

    @property
    def source(self) -> str:
        """The file this spec was loaded from, or ``<spec>``."""
        return self._source

    def with_source(self, source: str, file_hash: str) -> SpecBase:
        """Record the file this spec was read from (and its hash) for reports and provenance."""
        self._source = source
        self._file_hash = file_hash
        return self

    @property
    def file_hash(self) -> str:
        """SHA-256 (first 16 hex digits) of the file this spec was loaded from, or ``""``."""
        return self._file_hash

    def required_features(self) -> frozenset[str]:
        """Features a backend must declare to take this spec (e.g. ``free_final_time``)."""
        return frozenset()

    @property
    def objective_sense(self) -> str:
        """``minimize`` or ``maximize``: which objective is better, for comparisons."""
        return "minimize"
