"""The ``analytic`` backend: engagements answered without an NLP.

- every pursuer on constant bearing: the optimal plan of
  :func:`gamespec.pursuit.constant_bearing.optimal_evasion` (a linear program over headings; one
  constant heading in the cases of §2.4.1, possibly several in §3.2.1), status ``optimal``;
- every pursuer on pure pursuit: the suboptimal constant heading of eq. 2.27, status ``feasible``
  (it is not the optimum of Proposition 1; the ``casadi`` backend solves that), except against one
  pursuer, where the best constant heading is pure evasion along the line of sight, the optimum
  (t_c = (r_0 − ε)/(u − v), Proposition 1 with one pursuer): status ``optimal``.

Either way the capture time is read from the true dynamics (eq. 2.1) simulated under that plan
(RK45, or the compiled RK4 within a study); the ``resimulated_*`` checks come from an independent
integration of the same plan (DOP853), and ``predicted_capture_time_error`` compares the
constant-bearing closed form with the simulation. The Result carries the same metrics as an OCP
solution mapped back by :class:`gamespec.transforms.engagement.EngagementToOcp`. Relay pursuit and
mixed strategies need the OCP.
"""

from __future__ import annotations

import time
from typing import ClassVar

from gamespec.compiling import Backend, CompiledModel, Inputs, NoOptions, refuse_inputs
from gamespec.loader import with_values
from gamespec.pursuit import constant_bearing, pure_pursuit
from gamespec.pursuit.reduced import observe, reduce
from gamespec.pursuit.report import engagement_report
from gamespec.pursuit.simulation import HeadingLaw, Players, simulate_to_capture
from gamespec.result import Result, Status
from gamespec.specs.base import SpecBase
from gamespec.specs.engagement import EngagementSpec


class AnalyticModel(CompiledModel):
    """An engagement ready to be answered by its closed form or suboptimal heading; ``parameters``
    set the engagement's runtime parameters (positions, speeds, capture radius) by dotted path."""

    def __init__(self, spec: EngagementSpec) -> None:
        self.spec = spec

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        tic = time.perf_counter()
        spec = with_values(self.spec, parameters) if parameters else self.spec
        players = Players.from_spec(spec)
        law: HeadingLaw | float
        if set(players.strategies) == {"cb"}:
            plan = constant_bearing.optimal_evasion(players)
            constant = constant_bearing.best_constant_heading(players)
            law, predicted = plan.law(), plan.capture_time
            status, message = Status.OPTIMAL, "optimal heading plan of constant bearing (§2.4.1, §3.2.1)"
            extra = {
                "headings": plan.headings.tolist(),
                "durations": plan.durations.tolist(),
                "best_constant_heading": constant.heading,
                "best_constant_heading_capture_time": constant.capture_time,
            }
        else:
            choice = pure_pursuit.suboptimal_heading(players)
            law, predicted = choice.heading, choice.capture_time
            if int(players.active.sum()) == 1:
                status, message = Status.OPTIMAL, "pure evasion, optimal against one pursuer"
            else:
                status, message = (
                    Status.FEASIBLE,
                    ("suboptimal constant heading of eq. 2.27 (§2.4.3); --backend casadi gives the optimum"),
                )
            extra = {"headings": [choice.heading]}
        traj = simulate_to_capture(players, law)
        check = simulate_to_capture(players, law, method="DOP853")
        red = reduce(spec)
        observed = observe(red, traj)
        control = observed.pop(red.control)
        terminal = traj.distances()[-1]
        metrics, checks, arrays = engagement_report(spec, players, terminal, traj.capture_time, check)
        metrics |= extra | {"predicted_capture_time": predicted}
        if status == Status.OPTIMAL:
            checks["predicted_capture_time_error"] = abs(predicted - traj.capture_time)
        return Result(
            status=status,
            message=message,
            objective=traj.capture_time,
            t_final=traj.capture_time,
            solve_time_s=time.perf_counter() - tic,
            time=traj.time,
            states=observed,
            controls={red.control: control},
            arrays=arrays,
            checks=checks,
            metrics=metrics,
        )


class AnalyticBackend(Backend[EngagementSpec, NoOptions]):
    """Closed forms and suboptimal strategies of :mod:`gamespec.pursuit` (see module doc)."""

    name: ClassVar[str] = "analytic"
    kinds: ClassVar[frozenset[str]] = frozenset({"engagement"})

    def unsupported(self, spec: SpecBase) -> str | None:
        reason = super().unsupported(spec)
        if (
            reason is None
            and isinstance(spec, EngagementSpec)
            and len({p.strategy for p in spec.pursuers}) != 1
        ):
            return "backend 'analytic' needs every pursuer on cb or every pursuer on pp (no relay)"
        return reason

    def _compile(self, spec: EngagementSpec, options: NoOptions) -> AnalyticModel:
        return AnalyticModel(spec)
