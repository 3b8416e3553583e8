"""Uncertain parameters of an ``optimal_control`` problem (chapter 6): which parameters vary and how.

``problem.uncertain: {rho: {uniform: {percent: 10}}}`` (§6.3.1's ±10 % about the nominal value),
``{uniform: {low: 0.8, high: 1.2}}`` (§6.5.2's ranges) or ``{normal: {std: 0.5}}``. The nominal
value is always the parameter's value in ``problem.parameters`` (after ``--set``), so a sweep over
the parameter moves the distribution with it when it is given in percent.
"""

from __future__ import annotations

from pydantic import Field, FiniteFloat, model_validator

from gamespec.specs.base import StrictModel


class UniformSpec(StrictModel):
    """Uniform on ``[low, high]``, or on ``nominal · (1 ± percent/100)``."""

    percent: FiniteFloat | None = Field(
        None, gt=0, le=1000, description="The interval's half width in percent of the nominal value."
    )
    low: FiniteFloat | None = Field(None, description="The interval's lower end.")
    high: FiniteFloat | None = Field(None, description="The interval's upper end.")

    @model_validator(mode="after")
    def _one_form(self) -> UniformSpec:
        bounds = (self.low is not None, self.high is not None)
        if self.percent is not None and any(bounds):
            raise ValueError("give either percent or low and high, not both")
        if self.percent is None and not all(bounds):
            raise ValueError("give percent, or both low and high")
        if self.percent is None and not self.low < self.high:
            raise ValueError("low must be below high")
        return self


class NormalSpec(StrictModel):
    """Normal about the nominal value with standard deviation ``std``."""

    std: FiniteFloat = Field(gt=0, description="The standard deviation.")


class UncertainParameter(StrictModel):
    """The distribution of one uncertain parameter: exactly one of ``uniform`` and ``normal``."""

    uniform: UniformSpec | None = Field(None, description="Uniform on an interval.")
    normal: NormalSpec | None = Field(None, description="Normal about the nominal value.")

    @model_validator(mode="after")
    def _exactly_one(self) -> UncertainParameter:
        if (self.uniform is None) == (self.normal is None):
            raise ValueError("give exactly one distribution: uniform or normal")
        return self

    def uniform_bounds(self, nominal: float) -> tuple[float, float]:
        """``(low, high)`` of a uniform distribution about ``nominal``."""
        u = self.uniform
        if u.percent is None:
            return u.low, u.high
        half = abs(nominal) * u.percent / 100.0
        return nominal - half, nominal + half

    def std(self, nominal: float) -> float:
        """The standard deviation (``(high - low)/√12`` for a uniform one)."""
        if self.normal is not None:
            return self.normal.std
        low, high = self.uniform_bounds(nominal)
        return (high - low) / 12**0.5
