"""Metrics of ``pursuit_scenario`` Results (chapter 3): what :mod:`gamespec_geometric.plot` and
:mod:`gamespec_geometric.report` read."""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import Field

from gamespec.metrics import Finite, Metrics, array, state

if TYPE_CHECKING:
    from gamespec.result import Result


class ScenarioMetrics(Metrics):
    """Metrics of a ``pursuit_scenario`` Result."""

    capture_times: list[Finite | None] = Field(description="Each evader's capture time (None: escaped).")
    capturers: list[int | None] = Field(description="Each evader's capturer (a pursuer's index).")
    algorithm: str = Field(description="The allocation algorithm.")
    pursuit_strategy: str = Field(description="The team's pursuit strategy.")
    pursuer_strategies: list[Literal["cb", "pp"]] | None = None
    pursuer_speeds: list[Finite] = Field(description="Each pursuer's speed.")
    evader_speeds: list[Finite] = Field(description="Each evader's speed.")

    def check(self, result: Result) -> None:
        pursuers = state(result, "pursuers", 3, last=2)
        evaders = state(result, "evaders", 3, last=2)
        if not (np.all(np.isfinite(pursuers)) and np.all(np.isfinite(evaders))):
            raise ValueError("states.pursuers or states.evaders is not finite")
        p, e = pursuers.shape[1], evaders.shape[1]
        allocation = array(result, "allocation", 2, rows=len(pursuers), last=p)
        if allocation.dtype.kind not in "iu" or np.any(allocation < -1) or np.any(allocation >= e):
            raise ValueError(f"arrays.allocation holds values other than -1 … {e - 1}")
        for name, n in (("capture_times", e), ("capturers", e), ("evader_speeds", e), ("pursuer_speeds", p)):
            if len(getattr(self, name)) != n:
                raise ValueError(f"metrics.{name} has {len(getattr(self, name))} entries, not {n}")
        if self.pursuer_strategies is not None and len(self.pursuer_strategies) != p:
            raise ValueError(f"metrics.pursuer_strategies has not {p} entries")
        if self.pursuer_strategies is None and self.pursuit_strategy not in ("cb", "pp"):
            raise ValueError("metrics.pursuit_strategy is not cb or pp")
        for t, i in zip(self.capture_times, self.capturers, strict=True):
            if t is not None and (i is None or not 0 <= i < p):
                raise ValueError("metrics.capturers names no pursuer for a captured evader")
