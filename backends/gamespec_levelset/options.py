"""The options block of the ``levelset``, ``extremals`` and ``hj_reachability`` backends, one for
both of chapter 5's stages (``solver.options.<backend>`` in a file, or ``options=``)."""

from __future__ import annotations

from typing import Any

from pydantic import Field

from gamespec.specs.base import StrictModel


class FlowGameOptions(StrictModel):
    """The conic solver of the players' steps and its keyword arguments (the covariance game);
    ``cross_check`` also runs the other reachability method and reports the difference of ``T̂``
    (the reachability stage)."""

    solver: str = Field("CLARABEL", description="The CVXPY conic solver of the players' steps.")
    solver_options: dict[str, Any] = Field(
        default_factory=dict, description="Keyword arguments passed to that solver."
    )
    cross_check: bool = Field(
        True, description="Also run the other reachability method and report the difference of T̂."
    )
