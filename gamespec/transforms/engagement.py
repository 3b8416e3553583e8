"""``engagement`` → ``optimal_control``: the evader's reduced-state time-optimal problem.

:meth:`EngagementToOcp.apply` is :func:`gamespec.pursuit.ocp_generation.to_ocp`; every value taken
from the engagement (speeds, initial distances and angles, ε, the final-time bound) is a parameter
of the OCP, so the solving layer re-solves one compiled OCP for new positions and speeds.
:meth:`EngagementToOcp.invert` reports the OCP's solution as the engagement's
(:func:`gamespec.pursuit.ocp_report.ocp_report`); :meth:`EngagementToOcp.verify` is
:func:`gamespec.pursuit.verification.verify`. When it fails and the file gives no ``guess_heading``
(an explicit one is the user's choice of starting point, kept as it is),
:meth:`EngagementToOcp.restarts` offers the :data:`RETRIES` best simulated constant headings other
than the guess (eq. 2.28 respected), from which the solving layer re-solves the same compiled OCP.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from gamespec.backend import NoOptions
from gamespec.pursuit.guess import ranked_simulated_headings
from gamespec.pursuit.ocp_generation import EngagementInverse, heading_guess, to_ocp
from gamespec.pursuit.ocp_report import ocp_report
from gamespec.pursuit.verification import verify
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.transforms.base import Transform

RETRIES = 4
"""Constant headings :meth:`EngagementToOcp.restarts` offers when a solution fails verification."""


class EngagementToOcp(Transform[EngagementSpec, OptimalControlSpec, NoOptions, EngagementInverse]):
    """Generate the reduced-state OCP of an engagement (see module doc)."""

    name: ClassVar[str] = "engagement_to_ocp"
    source_kind: ClassVar[str] = "engagement"
    target_kind: ClassVar[str] = "optimal_control"

    def apply(
        self, spec: EngagementSpec, options: NoOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, EngagementInverse]:
        return to_ocp(spec)

    def invert(self, result: Result, spec: EngagementSpec, inverse_data: EngagementInverse) -> Result:
        result = super().invert(result, spec, inverse_data)
        if not result.ok or result.t_final is None:
            return result
        return ocp_report(result, spec, inverse_data.reduction, inverse_data.players)

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
