"""Transforms that exist only for the tests of the solving chain (registered by a fixture)."""

from __future__ import annotations

from typing import Any, ClassVar

from pydantic import Field

from gamespec.result import Result
from gamespec.specs.base import StrictModel
from gamespec.specs.ocp import OptimalControlSpec, TimeSpec
from gamespec.symbolic.language import parse, symbol
from gamespec.symbolic.printer import to_text
from gamespec.transforms.base import Stage, Transform

WEIGHT = "lagrange_weight"
UPSTREAM_TF = "upstream_t_f"


class WeightedLagrangeOptions(StrictModel):
    term: str = Field(description="A running-cost term over states, controls and parameters.")
    weight: float = Field(ge=0)


class WeightedLagrange(Transform):
    """``optimal_control`` → ``optimal_control``: Lagrange integrand + weight·term, the weight a new
    runtime parameter of the target."""

    name: ClassVar[str] = "weighted_lagrange"
    source_kind: ClassVar[str] = "optimal_control"
    target_kind: ClassVar[str] = "optimal_control"
    requested: ClassVar[bool] = True
    options_model: ClassVar[type[StrictModel]] = WeightedLagrangeOptions

    def apply(
        self, spec: OptimalControlSpec, options: WeightedLagrangeOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, Any]:
        p = spec.problem
        names = [*p.parameters, *p.states, *p.controls, *p.inputs, WEIGHT]
        symbols = {n: symbol(n) for n in names} | {"t": symbol("t")}
        lagrange = parse(str(p.objective.lagrange), symbols) + symbols[WEIGHT] * parse(options.term, symbols)
        problem = p.model_copy(
            update={
                "parameters": {**p.parameters, WEIGHT: options.weight},
                "objective": p.objective.model_copy(update={"lagrange": to_text(lagrange)}),
            }
        )
        return OptimalControlSpec.model_validate({**spec.model_dump(), "problem": problem.model_dump()}), None


class FixUpstreamFinalTime(Transform):
    """``optimal_control`` → ``optimal_control``, staged: solve the free-final-time problem first,
    then fix t_f at the upstream optimum (a new parameter ``upstream_t_f``)."""

    name: ClassVar[str] = "fix_upstream_final_time"
    source_kind: ClassVar[str] = "optimal_control"
    target_kind: ClassVar[str] = "optimal_control"
    requested: ClassVar[bool] = True

    def accepts(self, spec: OptimalControlSpec) -> bool:
        return super().accepts(spec) and spec.problem.time.free

    def stage(self, spec: OptimalControlSpec, options: StrictModel) -> Stage:
        return Stage(spec)

    def apply(
        self, spec: OptimalControlSpec, options: StrictModel, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, Any]:
        p = spec.problem
        time = TimeSpec(initial=p.time.initial, final=UPSTREAM_TF)
        problem = {**p.model_dump(), "parameters": {**p.parameters, UPSTREAM_TF: upstream.t_final}}
        problem["time"] = time.model_dump()
        return OptimalControlSpec.model_validate({**spec.model_dump(), "problem": problem}), upstream
