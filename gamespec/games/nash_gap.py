"""The Nash gap of a feedback equilibrium (issue 23's game convention): each player's improvement
by its own best reply to the others' laws, the largest of them against a tolerance scaled by the
payoffs, and the metrics and message a game Result carries for it (the status policy reads the
``saddle_gap`` verdict)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class NashGap:
    """``improvements`` by player, their largest ``gap``, its ``tolerance`` and whether it passed."""

    improvements: dict[str, float]
    gap: float
    tolerance: float
    passed: bool

    def message(self, head: str) -> str:
        """``head``, with the failed gap and its tolerance when it did not pass."""
        if self.passed:
            return head
        return f"{head}; the Nash gap {self.gap:.3g} exceeds its tolerance {self.tolerance:.3g}"

    def metrics(self, concept: str, payoffs: dict[str, float]) -> dict[str, Any]:
        """The solution concept, the payoffs, the improvements, ``saddle_gap`` and its verdict."""
        return {
            "solution_concept": concept,
            "payoffs": payoffs,
            "improvements": self.improvements,
            "saddle_gap": self.gap,
            "checks_passed": {"saddle_gap": self.passed},
            "check_tolerances": {"saddle_gap": self.tolerance},
        }


def nash_gap(improvements: dict[str, float], payoffs: dict[str, float], relative: float) -> NashGap:
    """The gap of ``improvements`` against ``relative`` times the largest payoff (at least 1)."""
    gap = max(improvements.values())
    tolerance = relative * max(1.0, *(abs(v) for v in payoffs.values()))
    return NashGap(improvements, gap, tolerance, bool(gap <= tolerance))
