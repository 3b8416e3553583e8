"""Options of the ``desensitize`` transform (chapter 6), as a file requests it:

```yaml
transforms:
  - desensitize:
      method: sensitivity        # eqs. 6.11-6.18 | seywald (eqs. 6.4-6.7) | costate (C-DOC, eqs. 6.46-6.64)
      trajectory: alpha          # eq. 6.16 / 6.7 / 6.62: the weight of the integral term
      final: {S_x1_rho: alpha}   # eq. 6.17: weights of the final-time sensitivity term
      fixed: {S_x1_rho: s1_final}  # eq. 6.18: S(t_f) fixed
      monte_carlo: {samples: 1000, seed: 0, tracking: true}
```

A weight is a number or an expression of the problem's parameters. A single weight applies to every
entry (``S_<state>_<parameter>`` for the sensitivity and Seywald methods, ``mu_<parameter>`` for
C-DOC); a mapping weights the entries it names (the others get zero), i.e. a diagonal ``Q``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from gamespec.specs.base import StrictModel, Value

Weights = Value | dict[str, Value]
"""One weight for every entry, or weights by entry name (a diagonal Q)."""


class MonteCarloOptions(StrictModel):
    """Re-simulation of the solution's open-loop control under sampled uncertain parameters."""

    samples: int = Field(1000, ge=0, le=1_000_000, description="Number of samples (0: off; else at least 2).")
    seed: int = Field(0, ge=0, description="Seed of the sampler: the same seed gives the same samples.")
    steps: int = Field(500, ge=10, le=100_000, description="RK4 steps over the horizon.")
    tracking: bool = Field(False, description="Also run the LQR-tracking closed loop (eqs. 6.27-6.29).")

    @field_validator("samples")
    @classmethod
    def _not_one(cls, v: int) -> int:
        if v == 1:
            raise ValueError("one sample has no spread: use 0 (off) or at least 2")
        return v


class DesensitizeOptions(StrictModel):
    """What to desensitize, with which method, and the Monte Carlo check of the result."""

    method: Literal["sensitivity", "seywald", "costate"] = Field(
        "sensitivity",
        description="`sensitivity` (eqs. 6.11–6.18), `seywald` (6.4–6.7) or `costate` (C-DOC, 6.46–6.64).",
    )
    trajectory: Weights | None = Field(
        None,
        description="Weight(s) of the integral sensitivity term (eq. 6.16; 6.7 Seywald, 6.62 C-DOC).",
    )
    final: Weights | None = Field(
        None,
        description="Weight(s) of the final-time sensitivity term (eq. 6.17).",
    )
    fixed: dict[str, Value] = Field(
        default_factory=dict,
        description="Final-time sensitivities held at given values, by entry name (eq. 6.18).",
    )
    monte_carlo: MonteCarloOptions = Field(
        default_factory=MonteCarloOptions,
        description="The Monte Carlo check of the desensitized solution over the uncertain parameters.",
    )
