"""Table 2.1: the suboptimal heading of eq. 2.27 against the optimal evasion of Prop. 1 (§2.4.4).

For each evader speed v, r1(0) = r1 and u1 = u2 = u, a grid of non-degenerate initial conditions
(r2(0), ψ(0)) (eq. 2.21's reduced state; P1 at (0, 0), E at (r1, 0), P2 = E + r2 (cos ψ, sin ψ)):

- ψ(0) at ``grid.angles`` angles −π + (j + ½) 2π/angles, j = 0 … angles − 1;
- r2(0) at ``grid.fractions`` points (k + ½)/fractions of the way from the curve F (eq. 2.6) to the
  ellipse E (§2.3.2) along the ray from E at angle ψ(0): the region N of that ray.

Each point: t_c of the suboptimal heading (true dynamics eq. 2.1 in closed form: the pursuit curve
of :mod:`~gamespec.pursuit.pursuit_curve`), and the optimal t_c of
the generated eq. 2.21 OCP, compiled once per speed and re-solved with the point's r2(0), ψ(0) and
the simulated suboptimal path as initial guess. A solution whose re-integrated defect exceeds
``DEFECT_TOL`` (the grid too coarse near capture, or the solver exploiting it, which happens for a
few starts) is solved again with each of the file's ``refinements`` in turn; a point that still
fails is kept but left out of the averages. Reported per v: average and maximum of the percentage
variation 100 (t_opt − t_sub)/t_opt. Points are saved as they finish (a rerun resumes).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.pursuit.regions import classify
from gamespec.specs.engagement import EngagementSpec
from gamespec.suboptimal_study.spec import SuboptimalStudySpec

DEFECT_TOL = 1e-3
"""Largest re-integrated defect (``checks.max_defect``) of an accepted optimal solution."""


@dataclass(frozen=True)
class StudyPoint:
    """One initial condition at one speed, with what a worker needs (picklable)."""

    v: float
    r2: float
    psi: float
    r1: float
    u: float
    eps: float
    methods: tuple[str, ...]
    backend: str

    @property
    def key(self) -> str:
        """The point's name in the result store; the hash of everything else it is solved with
        (r1, u, capture radius, methods, backend) keeps an edited file from reusing stale points."""
        setup = json.dumps([self.r1, self.u, self.eps, self.methods, self.backend])
        digest = hashlib.sha256(setup.encode()).hexdigest()[:12]
        return f"v={self.v:.6g},r2={self.r2:.9g},psi={self.psi:.9g},setup={digest}"


def ray_bounds(d: float, u: float, v: float, psi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distances from E along angle ψ to F (eqs. 2.5–2.6) and to E (the isochrone u r − v r cos ψ =
    (u² − v²) t_f, §2.3.2), for identical pursuers: the region N of that ray lies between them."""
    inner = (u - v) * d * (u - v * np.cos(psi)) / (u**2 - v**2)
    outer = (u**2 - v**2) * d / ((u - v) * (u - v * np.cos(psi)))
    return inner, outer


def study_points(spec: SuboptimalStudySpec) -> dict[str, StudyPoint]:
    """Every (v, r2(0), ψ(0)) of the study, keyed for the result store."""
    g = spec.grid
    psis = -np.pi + (np.arange(g.angles) + 0.5) * 2 * np.pi / g.angles
    fractions = (np.arange(g.fractions) + 0.5) / g.fractions
    methods = spec.methods()
    points = {}
    for v in spec.speeds:
        inner, outer = ray_bounds(spec.r1, spec.u, v, psis)
        for psi, lo, hi in zip(psis, inner, outer, strict=True):
            for r2 in lo + fractions * (hi - lo):
                p2 = np.array([spec.r1 + r2 * np.cos(psi), r2 * np.sin(psi)])
                if classify("pp", [0.0, 0.0], p2, [spec.r1, 0.0], spec.u, spec.u, v) != "N":
                    continue
                point = StudyPoint(
                    v, float(r2), float(psi), spec.r1, spec.u, spec.capture_radius, methods, spec.ocp_backend
                )
                points[point.key] = point
    return points


def point_engagement(point: StudyPoint) -> EngagementSpec:
    """The engagement of one study point: P1 at (0, 0), E at (r1, 0), P2 = E + r2 (cos ψ, sin ψ)."""
    e = np.array([point.r1, 0.0])
    p2 = e + point.r2 * np.array([np.cos(point.psi), np.sin(point.psi)])
    return EngagementSpec.model_validate(
        {
            "name": "table_2_1_point",
            "pursuers": [
                {"name": "P1", "position": [0.0, 0.0], "speed": point.u, "strategy": "pp"},
                {"name": "P2", "position": p2.tolist(), "speed": point.u, "strategy": "pp"},
            ],
            "evader": {"position": e.tolist(), "speed": point.v},
            "capture_radius": point.eps,
            "frame": "line_of_sight",
            "method": json.loads(point.methods[0]),
        }
    )


def summarize(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per speed: points, points solved, average and maximum percentage variation (Table 2.1)."""
    table = []
    for v in sorted({r["v"] for r in rows}):
        at_v = [r for r in rows if r["v"] == v]
        solved = np.array([r["variation_percent"] for r in at_v if "variation_percent" in r])
        table.append(
            {
                "v": v,
                "points": len(at_v),
                "solved": int(solved.size),
                "average_variation_percent": float(solved.mean()) if solved.size else None,
                "maximum_variation_percent": float(solved.max()) if solved.size else None,
                "suboptimal_better": int(np.sum(solved < 0)),
            }
        )
    return table
