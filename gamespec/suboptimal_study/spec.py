"""The ``pursuit_suboptimal_study`` kind: Table 2.1 of §2.4.4 as a problem file.

The suboptimal constant heading of eq. 2.27 against the optimal evasion of Proposition 1, two
identical pure-pursuit pursuers, over a grid of initial conditions per evader speed (see
:mod:`gamespec.suboptimal_study.points`). The ``study`` study runs it; every finished point is
saved under ``store`` as it completes, so solving the same file again resumes where it stopped.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

from gamespec.errors import SpecError
from gamespec.limits import MAX_STUDY_POINTS
from gamespec.registry import Kind
from gamespec.specs.base import BackendName, Number, StrictModel, StudySpecBase
from gamespec.specs.ocp import MethodSpec

MethodChange = dict[str, int | float | str]
"""Fields of :class:`MethodSpec` to change (e.g. ``{intervals: 80}``)."""


class StudyGrid(StrictModel):
    """The grid of (r2(0), ψ(0)) per speed (see :mod:`gamespec.suboptimal_study.points`)."""

    angles: int = Field(16, ge=1, description="Values of psi(0), evenly spread, none on P1's ray.")
    fractions: int = Field(9, ge=1, description="Values of r2(0) per angle, between F and E.")


class SuboptimalStudySpec(StudySpecBase):
    """Table 2.1 (kind ``pursuit_suboptimal_study``): P1 at (0, 0), E at (r1, 0), both pursuers at
    speed u on pure pursuit, the evader at each of ``speeds``."""

    kind: Literal["pursuit_suboptimal_study"] = Field(
        "pursuit_suboptimal_study",
        description="The problem kind; selects the schema of the rest of the file.",
    )
    r1: Number = Field(1.0, gt=0, description="Initial distance r1(0) from P1 to the evader.")
    u: Number = Field(1.0, gt=0, description="Speed of both pursuers.")
    speeds: list[Number] = Field(
        default_factory=lambda: [0.3, 0.4, 0.5, 0.6, 0.7],
        min_length=1,
        description="Evader speeds v, each in (0, u).",
    )
    capture_radius: Number = Field(
        0.001, gt=0, description="Distance at which a pursuer captures the evader."
    )
    grid: StudyGrid = Field(
        default_factory=StudyGrid, description="The study's grid of speeds and positions."
    )
    method: MethodSpec = Field(
        default_factory=lambda: MethodSpec(intervals=40, grading=10.0),
        description="The transcription of each point's optimal-control problem.",
    )
    refinements: list[MethodChange] = Field(
        default_factory=lambda: [{"intervals": 80}, {"intervals": 60, "grading": 100}],
        description="Changes to method tried in turn when a solution fails the defect check.",
    )
    ocp_backend: BackendName = Field("casadi", description="Backend that solves each point's eq. 2.21 OCP.")
    store: Path = Field(
        Path("runs/table_2_1/points"),
        description="Folder of the per-point records (relative to the current directory); "
        "solving the file again skips the points it holds.",
    )

    @model_validator(mode="after")
    def _grid_fits(self) -> SuboptimalStudySpec:
        points = self.grid.angles * self.grid.fractions * len(self.speeds)
        if points > MAX_STUDY_POINTS:
            raise ValueError(
                f"{points} grid points (angles × fractions × speeds) exceed the limit of {MAX_STUDY_POINTS}"
            )
        return self

    @model_validator(mode="after")
    def _capture_radius_inside(self) -> SuboptimalStudySpec:
        """Every point's engagement starts outside the capture radius: P2's distance r2(0) lies
        beyond F on its ray (eqs. 2.5–2.6), at least ``r1 (u - v) / (u + v)`` (the ray along P1's
        line of sight), and P1's is r1."""
        nearest = min(self.r1 * (self.u - v) / (self.u + v) for v in self.speeds)
        if not self.capture_radius < nearest:
            raise SpecError(
                f"{self.capture_radius:g} is not below the nearest start of a pursuer, "
                f"r1 (u - v) / (u + v) = {nearest:g} at the fastest speed",
                field="capture_radius",
            )
        return self

    @field_validator("speeds")
    @classmethod
    def _slower_than_pursuers(cls, speeds: list[float], info: ValidationInfo) -> list[float]:
        u = info.data.get("u")
        if u is not None and any(not 0 < v < u for v in speeds):
            raise ValueError(f"every speed must lie in (0, u = {u})")
        return speeds

    @field_validator("refinements")
    @classmethod
    def _refinements_are_methods(
        cls, refinements: list[MethodChange], info: ValidationInfo
    ) -> list[MethodChange]:
        method = info.data.get("method")
        for i, change in enumerate(refinements):
            try:
                MethodSpec.model_validate((method.model_dump() if method else {}) | change)
            except ValidationError as err:
                first = err.errors()[0]
                where = ".".join(str(p) for p in first["loc"])
                raise ValueError(f"refinement {i}: {where}: {first['msg']}") from None
        return refinements

    def methods(self) -> tuple[str, ...]:
        """The method, then each refinement applied to it, as validated JSON (tried in turn)."""
        base = self.method.model_dump()
        steps = [self.method, *(MethodSpec.model_validate(base | r) for r in self.refinements)]
        return tuple(m.model_dump_json() for m in steps)


KIND = Kind(
    SuboptimalStudySpec,
    study="study",
    plot="gamespec.suboptimal_study.plotting:plot_study",
    summary="gamespec.studies.report:study_summary",
    metrics="gamespec.suboptimal_study.metrics:SuboptimalStudyMetrics",
)
"""The ``SuboptimalStudySpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
