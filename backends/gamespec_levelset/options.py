"""The options block of the ``levelset``, ``extremals`` and ``hj_reachability`` backends, one for
both of chapter 5's stages (``solver.options.<backend>`` in a file, or ``options=``)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from gamespec.specs.base import StrictModel


class FlowGameOptions(StrictModel):
    """The conic solver of the players' steps and its keyword arguments (the covariance game);
    ``cross_check`` also runs the other reachability method and reports the difference of ``T̂``,
    ``max_wall_time`` (both stages, the game taking what the reachability stage left) and ``engine``
    (the reachability stage)."""

    solver: str = Field("CLARABEL", description="The CVXPY conic solver of the players' steps.")
    solver_options: dict[str, Any] = Field(
        default_factory=dict, description="Keyword arguments passed to that solver."
    )
    cross_check: bool = Field(
        True, description="Also run the other reachability method and report the difference of T̂."
    )
    max_wall_time: float | None = Field(
        300.0,
        gt=0,
        description="Seconds of wall time the run may take: the reachability stage (level sets, the "
        "coarser grid of the grid-error estimate, the cross-check, checked after every step), then what "
        "is left of it for the covariance game (best responses, the lower value, the Monte Carlo): past "
        "it the run stops with the status time_limit (null: no limit).",
    )
    engine: Literal["auto", "compiled", "numpy"] = Field(
        "auto",
        description="The levelset backend's WENO5 step: compiled (one Numba loop over the nodes, "
        "gamespec/flowfield/compiled.py; 3-4x less CPU a step, benchmarks/test_bench_reach.py, "
        "after about 0.65 s to load Numba once per process), numpy (the array operator of "
        "gamespec/flowfield/upwind.py) or auto (compiled from 150x150 nodes or once loaded, numpy "
        "below: the faster for one solve, gamespec.flowfield.levelset.COMPILED_NODES). ENO2 and first "
        "order are always NumPy.",
    )
