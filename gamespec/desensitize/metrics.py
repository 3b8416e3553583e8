"""Metrics of a desensitized Result (chapter 6): what :mod:`gamespec.desensitize.plotting` reads."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field

from gamespec.metrics import array, known, state

if TYPE_CHECKING:
    from gamespec.result import Result


class Desensitization(BaseModel):
    """``metrics.desensitization``: how the sensitivities were formed."""

    model_config = ConfigDict(extra="allow")

    method: str = Field(description="The desensitization method (the sensitivity plot's title).")


class MonteCarlo(BaseModel):
    """``metrics.monte_carlo``: the open-loop (and tracking) Monte Carlo about the nominal path."""

    model_config = ConfigDict(extra="allow")

    samples: int | None = Field(description="Number of samples drawn.")
    final_state_mean: dict[str, float | None] = Field(description="Mean final value of each original state.")

    def check(self, result: Result, planar: list[tuple[str, str]]) -> None:
        """The states and bundles :func:`gamespec.desensitize.plotting.plot_desensitized` draws."""
        names = list(self.final_state_mean)
        if not names:
            return
        known(names, result.states, "metrics.monte_carlo.final_state_mean")
        pair = planar[0] if planar and set(planar[0]) <= set(names) else None
        for prefix in ("monte_carlo", "tracking"):
            if f"{prefix}_{names[0]}" not in result.arrays:
                continue
            drawn = [f"{prefix}_{n}" for n in (pair or (names[0],))]
            bundles = [array(result, name, 2) for name in drawn]
            if pair is None:
                array(result, "monte_carlo_time", 1, rows=len(bundles[0]))
            elif bundles[0].shape != bundles[1].shape:
                raise ValueError(f"arrays.{drawn[0]} and arrays.{drawn[1]} differ in shape")
        for name in pair or (names[0],):
            state(result, name)
        if "monte_carlo_violated" in result.arrays:
            time = array(result, "monte_carlo_time", 1)
            array(result, "monte_carlo_violated", 1, rows=len(time))
