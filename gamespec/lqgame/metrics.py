"""Metrics of ``lq_stochastic_game`` Results: what :mod:`gamespec.lqgame.plotting` and
:mod:`gamespec.lqgame.report` read (the terminal statistics against the target, eq. 4.62)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from pydantic import Field

from gamespec.metrics import Finite, Metrics, array

if TYPE_CHECKING:
    from gamespec.result import Result


class LqGameMetrics(Metrics):
    """Metrics of an ``lq_stochastic_game`` Result."""

    terminal_mean: list[float | None] | None = Field(None, description="E[x_N].")
    target_mean: list[float | None] | None = Field(None, description="The controller's target mean.")
    terminal_covariance: list[list[Finite]] | None = Field(None, description="Σ_N reached.")
    target_covariance: list[list[Finite]] | None = Field(None, description="Σ_N's target.")
    min_covariance_scaling: float | None = None
    mean_payoff: float | None = None
    covariance_payoff: float | None = None

    def check(self, result: Result) -> None:
        if self.terminal_mean is not None:
            n = len(self.terminal_mean)
            for name in ("target_mean",):
                if getattr(self, name) is not None and len(getattr(self, name)) != n:
                    raise ValueError(f"metrics.{name} has not {n} entries")
            for name in ("terminal_covariance", "target_covariance"):
                matrix = getattr(self, name)
                if matrix is not None and np.shape(matrix) != (n, n):
                    raise ValueError(f"metrics.{name} is not {n} × {n}")
            if self.terminal_covariance is None:
                raise ValueError("metrics.terminal_covariance is missing")
        if "mean" not in result.arrays:
            return
        mean = array(result, "mean", 2)
        steps, n = mean.shape
        if n > len(result.states) or not result.states:
            raise ValueError(f"arrays.mean has {n} states, the Result names {len(result.states)}")
        covariance = array(result, "covariance", 3, rows=steps, last=n)
        if covariance.shape[1] != n:
            raise ValueError(f"arrays.covariance is not {steps} × {n} × {n}")
        if not (np.all(np.isfinite(mean)) and np.all(np.isfinite(covariance))):
            raise ValueError("arrays.mean or arrays.covariance is not finite")
        if "samples" in result.arrays:
            samples = array(result, "samples", 3, last=n)
            if samples.shape[1] != steps:
                raise ValueError(f"arrays.samples has {samples.shape[1]} steps, not {steps}")
        if "target_mean" in result.arrays:
            array(result, "target_mean", 1, rows=n)
        if "target_covariance" in result.arrays:
            array(result, "target_covariance", 2, rows=n, last=n)
        if "convergence_history" in result.arrays and result.arrays["convergence_history"].size:
            array(result, "convergence_history", 2, last=2)
