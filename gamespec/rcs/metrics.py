"""Metrics of ``rcs`` Results and of the ``rcs_multi_obstacle_study`` kind (§6.4): what
:mod:`gamespec.rcs.plotting` and the study summary read."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

from gamespec.metrics import Finite, Metrics, array, state

if TYPE_CHECKING:
    from gamespec.result import Result


class Rcs(BaseModel):
    """``metrics.rcs``: the relevance function of eq. 6.33 the weight was formed with."""

    model_config = ConfigDict(extra="allow")

    relevance: str = Field(description="Name or expression of r̃(w).")


class ObstacleSamples(BaseModel):
    """One entry of ``metrics.obstacle_samples`` (:class:`gamespec.rcs.transform.MovingObstacles`):
    where the figure draws the obstacle's sampled centres (``obstacle_<name>_sampled_x``/``_y``)."""

    model_config = ConfigDict(extra="forbid")

    time: Finite = Field(description="Time of the agent's closest approach to the nominal centre.")
    clearance: Finite | None = Field(
        None, description="Centre distance less r_o there (none for an obstacle on a track)."
    )


def check_obstacles(result: Result, obstacles: dict[str, float]) -> None:
    """The tracks of ``obstacles`` (one point per time point) and the path and S_g/S_r curves that
    :func:`gamespec.rcs.plotting.plot_rcs` draws with them, and the obstacles' sampled centres
    (one per kept Monte Carlo draw, with its verdict) where ``metrics.obstacle_samples`` has them."""
    if result.time is None:
        raise ValueError("an rcs Result without a time grid")
    points = len(result.time)
    for name in [k for k in result.arrays if k.startswith(("S_g", "S_r"))]:
        array(result, name, 1, rows=points)
    if "x" not in result.states or not obstacles:
        return
    state(result, "x")
    if "y" in result.states:
        state(result, "y")
    for name in obstacles:
        array(result, f"obstacle_{name}_x", 1, rows=points)
        array(result, f"obstacle_{name}_y", 1, rows=points)
    samples = result.metrics.get("obstacle_samples", {})
    for name, entry in samples.items():
        ObstacleSamples.model_validate(entry)
        if f"obstacle_{name}_sampled_x" in result.arrays:
            sampled = array(result, f"obstacle_{name}_sampled_x", 1)
            array(result, f"obstacle_{name}_sampled_y", 1, rows=len(sampled))
            array(result, "monte_carlo_draw_violated", 1, rows=len(sampled))
    if result.t_final is None:
        raise ValueError("an rcs Result with obstacles has no t_final")


class StudyRow(BaseModel):
    """One row of ``metrics.table`` of the §6.4.4 study (:func:`gamespec.rcs.study_points.summarize`)."""

    model_config = ConfigDict(extra="allow")

    obstacles: int = Field(description="N, the number of obstacles.")
    alpha: Finite = Field(description="The weight α.")
    sigma: Finite | None = Field(None, description="σ of the Monte Carlo's speed draws.")
    status: str | None = Field(None, description="Status of the kept solution (error: none solved).")
    objective: float | None = Field(None, description="Objective (eq. 6.36) of the kept solution.")
    t_final: Finite | None = Field(None, description="Final time of the kept solution.")
    collision_probability: Finite | None = Field(None, description="Monte Carlo collision probability.")
    collision_probability_ci: tuple[Finite, Finite] | None = Field(
        None, description="Its Wilson interval (gamespec.montecarlo.proportion)."
    )


class RcsStudyMetrics(Metrics):
    """Metrics of an ``rcs_multi_obstacle_study`` Result (Fig. 6.11)."""

    table: list[StudyRow] = Field(description="One row per (N, α).")
    layout: dict[str, list[tuple[Finite, Finite, Finite]]] = Field(
        description="Per N: each obstacle's x_i, y_i(0) and direction."
    )
    radius: PositiveFloat = Field(1.0, allow_inf_nan=False, description="The obstacles' radius.")
    points: int | None = None
    solved: int | None = None
    computed: int | None = None
    store: str | None = None

    def check(self, result: Result) -> None:
        for row in self.table:
            if row.t_final is None:
                continue
            if str(row.obstacles) not in self.layout:
                raise ValueError(f"metrics.layout has no entry for N = {row.obstacles}")
            if row.collision_probability is None:
                raise ValueError(f"metrics.table: N = {row.obstacles} has a t_final and no probability")
            tag = f"path_N{row.obstacles}_alpha{row.alpha:g}"
            if f"{tag}_x" in result.arrays:
                x = array(result, f"{tag}_x", 1)
                array(result, f"{tag}_y", 1, rows=len(x))
