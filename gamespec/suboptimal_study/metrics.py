"""Metrics of ``pursuit_suboptimal_study`` Results (Table 2.1): what
:mod:`gamespec.suboptimal_study.plotting` and ``gamespec pursuit study`` read."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field

from gamespec.metrics import Finite, Metrics, array

if TYPE_CHECKING:
    from gamespec.result import Result


class TableRow(BaseModel):
    """One row of a ``pursuit_suboptimal_study``'s ``metrics.table`` (Table 2.1)."""

    model_config = ConfigDict(extra="allow")

    v: Finite = Field(description="Evader speed.")
    points: int | None = None
    solved: int | None = None
    average_variation_percent: float | None
    maximum_variation_percent: float | None


class SuboptimalStudyMetrics(Metrics):
    """Metrics of a ``pursuit_suboptimal_study`` Result."""

    table: list[TableRow] = Field(description="One row per speed.")
    points: int | None = None
    solved: int | None = None
    computed: int | None = None
    store: str | None = None

    def check(self, result: Result) -> None:
        v = array(result, "v", 1)
        array(result, "variation_percent", 1, rows=len(v))
        if len(result.arrays["variation_percent"]) != len(v):
            raise ValueError("arrays.v and arrays.variation_percent differ in length")
