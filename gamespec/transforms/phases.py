"""``multiphase_optimal_control`` → ``optimal_control``: the phases as one NLP.

:meth:`PhasesToOcp.apply` is :func:`gamespec.specs.phase_lowering.lower` (each phase's copy of the
states and controls on a common normalized time, each duration a design variable or a parameter,
the links boundary constraints); :meth:`PhasesToOcp.invert` is
:func:`gamespec.ocp.phases.split_by_phase` (the trajectories end to end on the real time, phase
boundaries in ``metrics["phases"]``, checks per phase). Both are pure; the fixed durations are
parameters of the lowered problem, so a compiled model re-solves for new parameter values.
"""

from __future__ import annotations

from typing import ClassVar

from gamespec.backend import NoOptions
from gamespec.ocp.phases import split_by_phase
from gamespec.result import Result
from gamespec.specs.multiphase import MultiPhaseSpec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.specs.phase_lowering import Lowering, lower
from gamespec.transforms.base import Transform


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
