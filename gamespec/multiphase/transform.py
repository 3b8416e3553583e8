"""``multiphase_optimal_control`` → ``optimal_control``: the phases as one NLP; and the requested
``free_event`` rewrite of an ``optimal_control`` problem (constraints at a free time: two phases
meeting there, :mod:`gamespec.multiphase.event_time`), lowered and mapped back the same way.

:meth:`PhasesToOcp.apply` is :func:`gamespec.multiphase.lowering.lower` (each phase's copy of the
states and controls on a common normalized time, each duration a design variable or a parameter,
the links boundary constraints); :meth:`PhasesToOcp.invert` is
:func:`gamespec.multiphase.split.split_by_phase` (the trajectories end to end on the real time, phase
boundaries in ``metrics["phases"]``, checks per phase). Both are pure; the fixed durations are
parameters of the lowered problem, so a compiled model re-solves for new parameter values, which
:meth:`PhasesToOcp.parameter_map` sets without lowering again.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

from gamespec.compiling import NoOptions
from gamespec.multiphase.event_time import FreeEventOptions, split_at_event
from gamespec.multiphase.lowering import Lowering, lower
from gamespec.multiphase.spec import MultiPhaseSpec
from gamespec.multiphase.split import split_by_phase
from gamespec.result import Result
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.transforms.base import OcpRewrite, Transform, with_parameter_values


class PhasesToOcp(Transform[MultiPhaseSpec, OptimalControlSpec, NoOptions, Lowering]):
    """Lower a multi-phase problem to one ``optimal_control`` problem (see module doc)."""

    name: ClassVar[str] = "phases"
    source_kind: ClassVar[str] = "multiphase_optimal_control"
    target_kind: ClassVar[str] = "optimal_control"

    def apply(
        self, spec: MultiPhaseSpec, options: NoOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, Lowering]:
        lowering = lower(spec)
        return lowering.target, lowering

    def unmapped(self, spec: MultiPhaseSpec) -> frozenset[str]:
        """None: the file's parameters are the lowered problem's, under the same names."""
        return frozenset()

    def parameter_map(
        self, spec: MultiPhaseSpec, inverse_data: Lowering
    ) -> tuple[dict[str, float], Lowering]:
        """The file's parameter values, with the fixed durations, on the lowered problem and on each
        phase's own problem (its checks)."""
        values = spec.runtime_parameters()
        phases = [
            replace(ph, check_spec=with_parameter_values(ph.check_spec, values)) for ph in inverse_data.phases
        ]
        target = with_parameter_values(inverse_data.target, values)
        return target.runtime_parameters(), replace(inverse_data, target=target, phases=phases)

    def invert(self, result: Result, spec: MultiPhaseSpec, inverse_data: Lowering) -> Result:
        result = super().invert(result, spec, inverse_data)
        plot = {
            **spec.plot.as_metrics(),
            "path_constraints": [
                *spec.problem.path_constraints,
                *(c for ph in spec.problem.phases for c in ph.path_constraints),
            ],
        }
        split = split_by_phase(result, inverse_data)
        return split.model_copy(update={"metrics": split.metrics | {"plot": plot}})


@dataclass(frozen=True)
class EventSplit:
    """The two-phase problem the rewrite made and its lowering (the ``phases`` inverse data)."""

    phases: MultiPhaseSpec
    lowering: Lowering


class FreeEventTime(OcpRewrite[FreeEventOptions, EventSplit]):
    """Constraints at a free time inside the horizon (:mod:`gamespec.multiphase.event_time`)."""

    name: ClassVar[str] = "free_event"
    options_model = FreeEventOptions

    def apply(
        self, spec: OptimalControlSpec, options: FreeEventOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, EventSplit]:
        phased = split_at_event(spec, options)
        lowering = lower(phased)
        return lowering.target, EventSplit(phased, lowering)

    def invert(self, result: Result, spec: OptimalControlSpec, inverse_data: EventSplit) -> Result:
        split = PhasesToOcp().invert(result, inverse_data.phases, inverse_data.lowering)
        phases = split.metrics.get("phases") or []
        event = phases[0]["end"] if phases else None
        return split.model_copy(
            update={"kind": spec.kind, "problem": spec.name, "metrics": split.metrics | {"event_time": event}}
        )
