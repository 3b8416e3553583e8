"""The points of the §6.4.4 trade-off study and what each one keeps (see
:mod:`gamespec.rcs.study_spec` for the layout and the reading of σ).

Each point (N, α) is an ``optimal_control`` problem with the ``moving_obstacles`` and ``rcs``
transforms, solved from every initial guess of ``guesses`` (a homotopy class each); the best
successful solution (lowest augmented cost, eq. 6.36) is kept with its Monte Carlo collision
probability.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.rcs.study_spec import RcsStudySpec


@dataclass(frozen=True)
class StudyPoint:
    """One (N, α) of the study with everything its solve needs (picklable, for worker processes)."""

    obstacles: int
    alpha: float
    study: str
    """The study spec as JSON."""


def study_points(spec: RcsStudySpec) -> dict[str, StudyPoint]:
    """Every (N, α), keyed for the result store by the values that change its answer."""
    data = spec.model_dump_json(exclude={"store", "obstacles", "alphas", "name", "description"})
    return {
        f"N={n},alpha={a:g},{hash_of(data)}": StudyPoint(n, float(a), data)
        for n in spec.obstacles
        for a in spec.alphas
    }


def hash_of(text: str) -> str:
    import hashlib

    return hashlib.sha256(text.encode()).hexdigest()[:12]


def layout(spec: RcsStudySpec, n: int) -> list[tuple[float, float, float]]:
    """(x_i, y_i(0), direction) of each obstacle: crossing y = 0 at t = x_i (module doc)."""
    out = []
    for i in range(1, n + 1):
        x = spec.goal * i / (n + 1)
        direction = 1.0 if i % 2 else -1.0
        out.append((x, -direction * spec.rho * x / spec.v_max, direction))
    return out


def point_problem(spec: RcsStudySpec, n: int, alpha: float, amplitude: float) -> dict[str, Any]:
    """The ``optimal_control`` file of one point and one initial guess."""
    rhos = {f"rho_{i}": spec.rho for i in range(1, n + 1)}
    obstacles = {
        f"o{i}": {"center": [x, y0], "velocity": [0, f"{d:g}*rho_{i}"], "radius": "r_o"}
        for i, (x, y0, d) in enumerate(layout(spec, n), start=1)
    }
    straight = spec.goal / spec.v_max
    return {
        "kind": "optimal_control",
        "name": f"rcs_multi_obstacle_N{n}",
        "problem": {
            "parameters": {**rhos, "alpha": alpha, "r_o": spec.radius, "v_max": spec.v_max},
            "uncertain": {k: {"normal": {"std": spec.std}} for k in rhos},
            "states": {"x": {"initial": 0.0, "final": spec.goal}, "y": {"initial": 0.0, "final": 0.0}},
            "controls": {"theta": {"lower": "-pi", "upper": "pi"}, "v": {"lower": 0.0, "upper": "v_max"}},
            "dynamics": {"x": "v*cos(theta)", "y": "v*sin(theta)"},
            "objective": {"mayer": "t_f"},
            "time": {"final": "free", "bounds": [straight, 10 * straight], "guess": 1.2 * straight},
        },
        "transforms": [
            {"moving_obstacles": {"agent": ["x", "y"], "obstacles": obstacles}},
            {
                "rcs": {
                    "weight": "alpha",
                    "monte_carlo": {"samples": spec.samples, "seed": spec.seed, "steps": spec.steps},
                }
            },
        ],
        "method": spec.method.model_dump(),
        "guess": {
            "states": {"x": f"{spec.goal:g}*tau", "y": f"{amplitude:g}*sin(pi*tau)"},
            "controls": {"v": spec.v_max, "theta": 0.0},
        },
    }


PARAMETERS = ("obstacles", "alpha", "sigma")
"""What a point's row is a function of (N, α and the σ of the Monte Carlo): the columns its table
and ``gamespec results`` lead with."""

HEADLINE = ("collision_probability", "collision_probability_ci")
"""The headline a point's row adds to the status, objective and final time: P_c and its interval."""


def summarize(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Fig. 6.11's table: per (N, α, σ) the status, objective, travel time and collision
    probability with its interval, and their change against α = 0 of the same N
    (``t_final_increase`` and ``collision_reduction`` in percent)."""
    table = []
    for row in rows:
        base = next((r for r in rows if r["obstacles"] == row["obstacles"] and r["alpha"] == 0), None)
        entry = {k: row.get(k) for k in (*PARAMETERS, "status", "objective", "t_final", *HEADLINE)}
        entry["t_final_increase"] = _percent(row.get("t_final"), base and base.get("t_final"), +1)
        entry["collision_reduction"] = _percent(
            row.get("collision_probability"), base and base.get("collision_probability"), -1
        )
        table.append(entry)
    return table


def _percent(value: float | None, base: float | None, sign: int) -> float | None:
    if value is None or not base:
        return None
    return float(sign * 100.0 * (value - base) / base) + 0.0  # no -0.0


def arrays(rows: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """The kept paths ``path_N<n>_alpha<α>_x``/``_y`` (for the trajectory plot)."""
    out = {}
    for row in rows:
        if "path" in row:
            tag = f"N{row['obstacles']}_alpha{row['alpha']:g}"
            out[f"path_{tag}_x"] = np.array(row["path"]["x"])
            out[f"path_{tag}_y"] = np.array(row["path"]["y"])
    return out
