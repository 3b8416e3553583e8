"""The ``geometric`` backend: simulates ``pursuit_scenario`` specs with AVAA / A2 allocation.

Only NumPy and SciPy are needed, so it is always available. Options (``solver.options.geometric``):
``active_check`` (``fast`` or ``reference``: AAPC for CB, edge clipping for PP) and ``pp_samples``
(vertices of the polygons inscribed in the refined Apollonius curves).
"""

from __future__ import annotations

import time
from typing import ClassVar, Literal

from pydantic import Field

from gamespec.compiling import Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.loader import with_values
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec_geometric.simulation import Trajectories, simulate
from gamespec_geometric.spec import PursuitScenarioSpec


class GeometricOptions(StrictModel):
    """Options of the geometric backend."""

    active_check: Literal["fast", "reference"] = Field(
        "fast",
        description="The active-pursuer check: `fast` or `reference` (AAPC for CB, edge clipping for PP).",
    )
    pp_samples: int = Field(64, ge=8, description="Vertices of each refined Apollonius polygon (PP).")


class CompiledScenario(CompiledModel):
    """A scenario ready to simulate; ``parameters`` set fields by dotted path (the runtime parameters
    of :class:`PursuitScenarioSpec`: ``capture_radius``, ``time_step`` and ``horizon``)."""

    def __init__(self, spec: PursuitScenarioSpec, options: GeometricOptions) -> None:
        self.spec = spec
        self.options = options

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """Simulate (``guess`` is not used: the simulation has no iterate to warm-start)."""
        refuse_inputs(inputs, self.spec.kind)
        spec = with_values(self.spec, parameters) if parameters else self.spec
        start = time.perf_counter()
        run = simulate(spec, method=self.options.active_check, samples=self.options.pp_samples)
        return scenario_result(spec, run, time.perf_counter() - start)


def allocation_changes(run: Trajectories) -> list[dict[str, object]]:
    """The allocation history, one entry per step where the allocation changed."""
    changes: list[dict[str, object]] = []
    previous = None
    for k in range(len(run.time) - 1):
        row = run.allocation[k].tolist()
        if row != previous:
            changes.append({"step": k, "t": float(run.time[k]), "assignment": row})
            previous = row
    return changes


def scenario_result(spec: PursuitScenarioSpec, run: Trajectories, seconds: float) -> Result:
    """The Result of a simulation: trajectories, capture times and capturers, escapes, allocation
    history. A finished simulation is ``simulated`` whether or not every evader was caught: an evader
    still free at the horizon has escaped, which is an outcome of the game, not a failure."""
    escaped = [j for j, c in enumerate(run.capture_times) if c is None]
    caught = len(run.capture_times) - len(escaped)
    last = max((c for c in run.capture_times if c is not None), default=None)
    if escaped:
        names = ", ".join(f"E{j + 1}" for j in escaped)
        message = (
            f"{caught} of {len(run.capture_times)} evaders captured; {names} escaped to t = {spec.horizon:g}"
        )
    else:
        message = f"all {len(run.capture_times)} evaders captured by t = {last:.4g}"
    return Result(
        status=Status.SIMULATED,
        message=message,
        objective=last if not escaped else None,
        t_final=last if not escaped else float(run.time[-1]),
        solve_time_s=seconds,
        iterations=len(run.time) - 1,
        time=run.time,
        states={"pursuers": run.pursuers, "evaders": run.evaders},
        arrays={"allocation": run.allocation, "allocation_rounds": run.rounds},
        checks={
            "shortest_time_max_increase": run.shortest_time_increase,
            "shortest_pair_unassigned_steps": float(run.shortest_pair_unassigned),
        },
        metrics={
            "capture_times": run.capture_times,
            "capturers": run.capturers,
            "escaped": escaped,
            "allocation_history": allocation_changes(run),
            "algorithm": spec.algorithm,
            "pursuit_strategy": spec.pursuers.team_strategy,
            "pursuer_strategies": spec.pursuers.strategies().tolist(),
            "pursuer_speeds": spec.pursuers.speeds().tolist(),
            "evader_speeds": spec.evaders.speeds().tolist(),
            "capture_radius": spec.capture_radius,
        },
    )


class GeometricBackend(Backend[PursuitScenarioSpec, GeometricOptions]):
    """Multi-agent simulation with Apollonius-based allocation (thesis chapter 3)."""

    name: ClassVar[str] = "geometric"
    kinds: ClassVar[frozenset[str]] = frozenset({"pursuit_scenario"})
    options_model = GeometricOptions

    def _compile(self, spec: PursuitScenarioSpec, options: GeometricOptions) -> CompiledScenario:
        return CompiledScenario(spec, options)
