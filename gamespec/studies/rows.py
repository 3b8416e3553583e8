"""What a study store's values must look like before anything reads them (README, "Security"):
the ``study`` meta record, and each point of a sweep (a Table 2.1 study is one too).

A store is untrusted input: SQLite checks no types, and a folder may come from anyone. A value that
does not validate is reported as damaged (:meth:`~gamespec.studies.store.ResultStore.report_damaged`)
and left out, so a rerun computes it again and ``gamespec results`` and ``gamespec plot`` never
index into something of the wrong shape. A sweep point's ``metrics`` are validated by its kind's
metrics model (:func:`gamespec.metrics.metrics_model`; the arrays a Result would carry are not
stored, so only the model's fields are checked).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from gamespec.metrics import metrics_model
from gamespec.studies.store import ResultStore

ParameterName = Annotated[str, Field(pattern=r"^[^./\\\x00][^/\\\x00]*$", max_length=200)]
"""A swept parameter's dotted name; figures are named after it (``sweep_<name>.png``), so it is one
file-name component."""


class StudyMeta(BaseModel):
    """The ``study`` meta record: what kind of study the store holds."""

    model_config = ConfigDict(extra="allow")

    type: Literal["sweep", "compare"] | None = Field(None, description="sweep or compare.")
    problem: str = Field("", description="The problem's name.")
    parameters: list[ParameterName] = Field(default_factory=list, description="A sweep's swept parameters.")
    headline: list[ParameterName] = Field(
        default_factory=list, description="Columns a study kind shows after its parameters (its headline)."
    )


class PointRow(BaseModel):
    """One point of a sweep or compare: the Result's summary, its metrics and (a sweep) its
    parameter values (checked by :func:`valid_value`)."""

    model_config = ConfigDict(extra="allow")

    status: str
    kind: str = ""
    backend: str | None = None
    objective: float | None = None
    t_final: float | None = None
    solve_time_s: float | None = None
    metrics: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _metrics_of_the_kind(self) -> PointRow:
        if self.kind:
            metrics_model(self.kind).model_validate(self.metrics)
        return self


def study_meta(store: ResultStore) -> StudyMeta:
    """The store's ``study`` record (an empty one when it is missing or damaged: reported)."""
    raw = store.meta("study")
    try:
        return StudyMeta.model_validate(raw if raw is not None else {})
    except ValidationError as err:
        store.report_damaged("meta:study", _first(err))
        return StudyMeta()


def valid_value(value: Any, meta: StudyMeta) -> Any:
    """``value`` as a point of the study ``meta`` describes; ValueError saying what is wrong.
    Points of other studies (a user's own ``run_study``) are any JSON."""
    if meta.type is None:
        return value
    if not isinstance(value, dict):
        raise ValueError(f"a {meta.type} point is {type(value).__name__}, not a mapping")
    try:
        PointRow.model_validate(value)
    except ValidationError as err:
        raise ValueError(_first(err)) from None
    for name in meta.parameters:
        if not _finite_number(value.get(name)):
            raise ValueError(f"its parameter {name} is not a finite number")
    return value


def valid_points(store: ResultStore) -> dict[str, Any]:
    """The store's intact points that are valid for its study (the others reported as damaged)."""
    meta = study_meta(store)
    found = {}
    for key, value in store.items().items():
        try:
            found[key] = valid_value(value, meta)
        except ValueError as err:
            store.report_damaged(key, str(err))
    return found


def _finite_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _first(err: ValidationError) -> str:
    first = err.errors()[0]
    where = ".".join(str(p) for p in first["loc"]) or "value"
    return f"{where}: {' '.join(first['msg'].split())}"
