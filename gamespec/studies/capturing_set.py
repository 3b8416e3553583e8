"""Multi-pursuer single-evader optimal evasion (§3.2) and the capturing set P* (Definition 2).

Propositions 5 (CB) and 6 (PP): the optimal evading strategy depends only on the pursuers in P*.
:func:`check_capturing_set` tests this numerically: solve the full engagement, drop every pursuer
outside P*, solve again, and compare capture times and evader paths (the paths re-simulated with the
true dynamics, so the comparison does not depend on the reduced frame either solution used).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from gamespec.result import Result
from gamespec.solving import solve
from gamespec.specs.engagement import EngagementSpec


def keep_pursuers(spec: EngagementSpec, names: list[str]) -> EngagementSpec:
    """The same engagement with only the pursuers named in ``names`` (in their original order), in
    the same reduced frame as ``spec``, so that both are solved in the same formulation."""
    unknown = set(names) - {p.name for p in spec.pursuers}
    if unknown:
        raise SpecError(f"no pursuer named {sorted(unknown)}", field="pursuers", source=spec.source)
    data = spec.model_dump(mode="json")
    data["pursuers"] = [p for p in data["pursuers"] if p["name"] in names]
    data["name"] = f"{spec.name}_capturing_set"
    data["frame"] = spec.resolved_frame
    return spec_from_dict(data, source=spec.source)


def path_difference(a: Result, b: Result) -> float:
    """Largest distance between two evader paths compared at equal fractions of their capture times."""
    tau = np.linspace(0.0, 1.0, 201)

    def at(r: Result) -> np.ndarray:
        t, path = r.arrays["path_time"], r.arrays["path_evader"]
        return np.column_stack([np.interp(tau * r.t_final, t, path[:, k]) for k in range(2)])

    return float(np.max(np.linalg.norm(at(a) - at(b), axis=1)))


@dataclass(frozen=True)
class CapturingSetCheck:
    """The full solution, the solution with P* only, and how far apart they are."""

    full: Result
    reduced: Result
    capturing_set: list[str]

    @property
    def capture_time_difference(self) -> float:
        return abs(self.full.t_final - self.reduced.t_final)

    @property
    def path_difference(self) -> float:
        return path_difference(self.full, self.reduced)

    def as_metrics(self) -> dict[str, object]:
        return {
            "capturing_set": self.capturing_set,
            "capture_time_full": self.full.t_final,
            "capture_time_capturing_set_only": self.reduced.t_final,
            "capture_time_difference": self.capture_time_difference,
            "evader_path_difference": self.path_difference,
        }


def check_capturing_set(spec: EngagementSpec, backend: str | None = None) -> CapturingSetCheck:
    """Solve ``spec``, then only its capturing set P*, and compare (Propositions 5–6)."""
    full = solve(spec, backend)
    if not full.ok:
        return CapturingSetCheck(full, full, [])
    names = list(full.metrics["capturing_set"])
    return CapturingSetCheck(full, solve(keep_pursuers(spec, names), backend), names)
