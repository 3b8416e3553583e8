"""The ``rcs_multi_obstacle_study`` kind: the trade-off study of thesis §6.4.4 (Fig. 6.11).

An agent (heading and speed v ∈ [0, v_max] the controls, eq. 6.37) goes from (0, 0) to
(``goal``, 0) in minimum time past N identical obstacles moving parallel to y at uncertain speeds
ρ_i (nominal ``rho``), with the RCS cost ``Q = α I_N`` (eq. 6.36), for every N in ``obstacles`` and α
in ``alphas``. Layout (not given in the thesis): obstacle i of N sits on x_i = goal·i/(N+1), moves
up (i odd) or down (i even) and starts at y_i(0) = ∓ρ̂ x_i, so that it crosses y = 0 at t = x_i,
just when a straight-line agent at full speed gets there: every obstacle blocks the straight path.

The Monte Carlo draws ρ_i = ρ̂ + Δρ_i, Δρ_i ~ N(0, σ²). §6.4.4 writes "σ² = 0.1": ``sigma`` is σ
when ``sigma_is: std`` (the default, so ``--set sigma=0.1`` means σ = 0.1) and σ² when
``sigma_is: variance`` (``--set sigma_is=variance`` reads the thesis literally: σ ≈ 0.316).
The ``rcs_study`` study saves each (N, α) point under ``store`` as it finishes; solving the file
again resumes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, model_validator

from gamespec.errors import SpecError
from gamespec.limits import MAX_RCS_OBSTACLES, MAX_SAMPLE_VALUES, MAX_STUDY_POINTS
from gamespec.registry import Kind
from gamespec.specs.base import BackendName, Number, StudySpecBase
from gamespec.specs.ocp import MethodSpec


class RcsStudySpec(StudySpecBase):
    """Fig. 6.11: travel time against collision probability per number of obstacles and weight."""

    kind: Literal["rcs_multi_obstacle_study"] = Field(
        "rcs_multi_obstacle_study",
        description="The problem kind; selects the schema of the rest of the file.",
    )
    obstacles: list[Annotated[int, Field(ge=1, le=MAX_RCS_OBSTACLES)]] = Field(
        default_factory=lambda: [2, 3, 5, 10], min_length=1, description="Numbers of obstacles N."
    )
    alphas: list[Number] = Field(
        default_factory=lambda: [0.0, 0.1, 0.33, 1.0],
        min_length=1,
        description="The RCS weights α (Q = α I_N, eq. 6.36): every N of `obstacles` is solved with every α.",
    )
    sigma: Number = Field(0.1, gt=0, description="σ (sigma_is: std) or σ² (sigma_is: variance) of Δρ.")
    sigma_is: Literal["std", "variance"] = Field(
        "std", description="Whether the thesis' σ is a standard deviation (`std`) or a variance (`variance`)."
    )
    rho: Number = Field(0.25, gt=0, description="Nominal obstacle speed ρ̂.")
    radius: Number = Field(1.0, gt=0, description="Safe distance r_o of every obstacle.")
    goal: Number = Field(30.0, gt=0, description="The target (goal, 0).")
    v_max: Number = Field(1.0, gt=0, description="The agent's maximum speed.")
    guesses: list[Number] = Field(
        default_factory=lambda: [4.0, -4.0, 0.0],
        min_length=1,
        description="Initial guesses y = a·sin(πτ) (homotopy classes); the best solution is kept.",
    )
    samples: int = Field(
        1000, ge=2, le=100_000, description="Monte Carlo samples of each point's collision probability."
    )
    seed: int = Field(0, ge=0, description="The seed of the obstacles' samples.")
    steps: int = Field(1000, ge=10, le=100_000, description="RK4 steps of the Monte Carlo re-simulation.")
    method: MethodSpec = Field(
        default_factory=lambda: MethodSpec(intervals=40, degree=3),
        description="The transcription of each point's optimal-control problem.",
    )
    ocp_backend: BackendName = Field("casadi", description="The backend that solves each point.")
    store: Path = Field(Path("runs/rcs_multi_obstacle/points"), description="Folder of per-point records.")

    @model_validator(mode="after")
    def _work_bounded(self) -> RcsStudySpec:
        """The solves (points times guesses) within :data:`~gamespec.limits.MAX_STUDY_POINTS` and one
        point's Monte Carlo (samples times steps times obstacles) within
        :data:`~gamespec.limits.MAX_SAMPLE_VALUES`."""
        solves = len(self.obstacles) * len(self.alphas) * len(self.guesses)
        if solves > MAX_STUDY_POINTS:
            raise SpecError(
                f"{solves} solves (obstacles x alphas x guesses) exceed the limit of {MAX_STUDY_POINTS}",
                field="obstacles",
            )
        values = self.samples * self.steps * max(self.obstacles)
        if values > MAX_SAMPLE_VALUES:
            raise SpecError(
                f"{values} simulated values (samples x steps x obstacles) exceed the limit of "
                f"{MAX_SAMPLE_VALUES}",
                field="samples",
            )
        return self

    @property
    def std(self) -> float:
        """σ, whichever way ``sigma`` is given."""
        return float(self.sigma if self.sigma_is == "std" else self.sigma**0.5)


KIND = Kind(
    RcsStudySpec,
    study="rcs_study",
    plot="gamespec.rcs.plotting:plot_study",
    summary="gamespec.rcs.multi_obstacle_study:rcs_study_summary",
    metrics="gamespec.rcs.metrics:RcsStudyMetrics",
)
"""The ``RcsStudySpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
