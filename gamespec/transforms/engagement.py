"""``engagement`` → ``optimal_control``: the evader's reduced-state time-optimal problem.

:meth:`EngagementToOcp.apply` is :func:`gamespec.pursuit.ocp_generation.to_ocp`; every value taken
from the engagement (speeds, initial distances and angles, ε, the final-time bound) is a parameter
of the OCP, so the solving layer re-solves one compiled OCP for new positions and speeds; its
:meth:`EngagementToOcp.parameter_map` computes those numbers and the new guess without writing the
OCP again.
:meth:`EngagementToOcp.invert` reports the OCP's solution as the engagement's
(:func:`gamespec.pursuit.ocp_report.ocp_report`); its ``resimulation`` analysis
(:data:`RESIMULATION`: :func:`gamespec.pursuit.ocp_report.resimulation`) re-simulates the true
dynamics under the solution's heading, and :meth:`EngagementToOcp.verify`
(:func:`gamespec.pursuit.verification.verify`) judges the solution by it; with the analysis off,
the solving layer does not claim ``optimal``. When it fails and the file gives no ``guess_heading``
(an explicit one is the user's choice of starting point, kept as it is),
:meth:`EngagementToOcp.restarts` offers the :data:`RETRIES` best simulated constant headings other
than the guess (eq. 2.28 respected), from which the solving layer re-solves the same compiled OCP.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from gamespec.analyses import Analysis, Outputs
from gamespec.compiling import NoOptions
from gamespec.pursuit.guess import ranked_simulated_headings
from gamespec.pursuit.ocp_generation import EngagementInverse, heading_guess, remapped, to_ocp
from gamespec.pursuit.ocp_report import ocp_report, resimulation
from gamespec.pursuit.verification import verify
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.transforms.base import Transform

RETRIES = 4
"""Constant headings :meth:`EngagementToOcp.restarts` offers when a solution fails verification."""


def _resimulated(result: Result, spec: EngagementSpec, inverse_data: EngagementInverse) -> Outputs:
    if result.t_final is None:
        return Outputs()
    metrics, checks, arrays = resimulation(result, spec, inverse_data.reduction, inverse_data.players)
    return Outputs(metrics, checks, arrays)


RESIMULATION = Analysis(
    "resimulation",
    _resimulated,
    "re-simulates the true dynamics (eq. 2.1) under the solution's heading: the capture time verify checks",
    checks=("resimulated_capture_time",),
)
"""The engagement's re-simulation; :meth:`EngagementToOcp.verify` reads its checks."""


class EngagementToOcp(Transform[EngagementSpec, OptimalControlSpec, NoOptions, EngagementInverse]):
    """Generate the reduced-state OCP of an engagement (see module doc)."""

    name: ClassVar[str] = "engagement_to_ocp"
    source_kind: ClassVar[str] = "engagement"
    target_kind: ClassVar[str] = "optimal_control"

    def apply(
        self, spec: EngagementSpec, options: NoOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, EngagementInverse]:
        return to_ocp(spec)

    def unmapped(self, spec: EngagementSpec) -> frozenset[str]:
        """None: every position, speed and the capture radius maps to the OCP's parameters."""
        return frozenset()

    def parameter_map(
        self, spec: EngagementSpec, inverse_data: EngagementInverse
    ) -> tuple[dict[str, float], EngagementInverse]:
        """:func:`~gamespec.pursuit.ocp_generation.remapped`: the reduction's numbers and the guess
        simulated again, the OCP not written again."""
        return remapped(spec, inverse_data)

    def invert(self, result: Result, spec: EngagementSpec, inverse_data: EngagementInverse) -> Result:
        result = super().invert(result, spec, inverse_data)
        if not result.ok or result.t_final is None:
            return result
        return ocp_report(result, spec, inverse_data.reduction, inverse_data.players)

    def analyses(self) -> list[Analysis]:
        return [RESIMULATION]

    def guess(self, inverse_data: EngagementInverse) -> Result:
        return inverse_data.guess

    def verify(self, result: Result, spec: EngagementSpec, inverse_data: EngagementInverse) -> str | None:
        return verify(result, inverse_data.guess_capture_time)

    def restarts(self, spec: EngagementSpec, inverse_data: EngagementInverse) -> list[Result]:
        if spec.guess_heading is not None:
            return []
        headings = [
            h
            for h in ranked_simulated_headings(inverse_data.players)[: RETRIES + 1]
            if not np.isclose(np.angle(np.exp(1j * (h - inverse_data.guess_heading))), 0.0)
        ]
        return [heading_guess(inverse_data.reduction, inverse_data.players, h) for h in headings[:RETRIES]]
