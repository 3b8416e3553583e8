"""What an engagement Result reports, from any solution method (OCP, closed form, suboptimal).

A solution is judged by re-simulating the true dynamics (eq. 2.1) under its evader heading with an
ODE integrator, independently of how it was found: the capture time of the re-simulation, the
Voronoi margin for relay pursuit (eq. 2.28), and the players' paths for plots. The capturing set
(Definition 2) and the simultaneous-capture gap come from the solution's terminal distances.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gamespec.pursuit import regions
from gamespec.pursuit.relay import voronoi_margin
from gamespec.pursuit.simulation import Players, Trajectory
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec

CAPTURE_RTOL = 1e-3
"""A pursuer is in the capturing set when its terminal distance is within ε(1 + CAPTURE_RTOL)."""


def capturing_set(players: Players, terminal: np.ndarray) -> list[str]:
    """Names of the active pursuers within the capture radius at the capture time (Definition 2)."""
    inside = terminal <= players.eps * (1 + CAPTURE_RTOL)
    return [n for n, a, c in zip(players.names, players.active, inside, strict=True) if a and c]


def capture_gap(players: Players, terminal: np.ndarray) -> float | None:
    """Second-smallest minus smallest terminal distance of active pursuers (0: simultaneous capture)."""
    ends = np.sort(terminal[players.active])
    return float(ends[1] - ends[0]) if ends.size > 1 else None


def region_of_p2(spec: EngagementSpec, players: Players) -> str | None:
    """D1, D2 or N (§2.3) for two active pursuers with the same cb or pp strategy, else None."""
    if len(players.names) != 2 or spec.is_relay or len(set(players.strategies)) != 1:
        return None
    p1, p2 = players.positions
    u1, u2 = players.speeds
    return str(regions.classify(players.strategies[0], p1, p2, players.evader, u1, u2, players.v))


def terminal_metrics(
    spec: EngagementSpec, players: Players, terminal: np.ndarray, t_final: float
) -> dict[str, Any]:
    """The metrics of a solution read from its terminal distances ``terminal`` (no simulation)."""
    return {
        "capture_time": t_final,
        "capturing_set": capturing_set(players, terminal),
        "simultaneous_capture_gap": capture_gap(players, terminal),
        "terminal_distances": dict(zip(players.names, map(float, terminal), strict=True)),
        "region": region_of_p2(spec, players),
        "engagement": spec.model_dump(mode="json", include={"pursuers", "evader", "capture_radius"}),
    }


def simulation_report(
    spec: EngagementSpec, players: Players, t_final: float, traj: Trajectory
) -> tuple[dict[str, Any], dict[str, float | None], dict[str, np.ndarray]]:
    """Metrics, checks and path arrays of the re-simulation ``traj`` of a solution ending at
    ``t_final``: its initial heading, re-simulated capture time (and its error), the Voronoi margin
    for relay pursuit (eq. 2.28), the players' paths."""
    metrics: dict[str, Any] = {"initial_heading": float(traj.heading[0])}
    checks: dict[str, float | None] = {
        "resimulated_capture_time": traj.capture_time if traj.captured else None,
        "resimulated_capture_time_error": abs(traj.capture_time - t_final) if traj.captured else None,
    }
    if spec.is_relay:
        checks["resimulated_max_voronoi_margin"] = float(voronoi_margin(traj, players).max())
    arrays = {"path_time": traj.time, "path_evader": traj.evader}
    arrays |= {f"path_{name}": traj.pursuers[:, i] for i, name in enumerate(players.names)}
    return metrics, checks, arrays


def engagement_report(
    spec: EngagementSpec, players: Players, terminal: np.ndarray, t_final: float, traj: Trajectory
) -> tuple[dict[str, Any], dict[str, float | None], dict[str, np.ndarray]]:
    """Metrics, checks and path arrays of a solution with terminal distances ``terminal`` and
    re-simulation ``traj`` (:func:`terminal_metrics` and :func:`simulation_report`)."""
    metrics, checks, arrays = simulation_report(spec, players, t_final, traj)
    return terminal_metrics(spec, players, terminal, t_final) | metrics, checks, arrays


def engagement_summary(result: Result) -> list[tuple[str, object]]:
    """The rows that lead an engagement's solve summary: capture time, capturing set P*, terminal
    distances, the region of P2, relay arcs with the switching residual (eqs. 2.41, 2.46), and a
    hint when another backend answers the engagement better."""
    m = result.metrics
    if "capture_time" not in m:
        return []
    rows: list[tuple[str, object]] = [
        ("capture time t_c", m["capture_time"]),
        ("capturing set P*", ", ".join(m.get("capturing_set", [])) or "—"),
    ]
    rows += [(f"terminal distance to {n}", d) for n, d in m.get("terminal_distances", {}).items()]
    rows += [
        ("simultaneous capture gap", m.get("simultaneous_capture_gap")),
        ("region of P2", m.get("region")),
    ]
    arcs = m.get("arcs") or {}
    if arcs:
        rows += [
            ("arcs: interior, boundary, line of sight", _durations(arcs)),
            ("switching times tau1, tau2", f"{arcs['tau1']:.6g}, {arcs['tau2']:.6g}"),
            ("switching residual (eq. 2.46)", arcs["switching_residual"]),
        ]
    strategies = {p["strategy"] for p in m.get("engagement", {}).get("pursuers", [])}
    if strategies == {"cb"} and result.backend != "analytic":
        rows.append(("hint", "every pursuer is on constant bearing: --backend analytic solves it exactly"))
    if strategies == {"pp"} and result.backend == "analytic" and result.status.value != "optimal":
        rows.append(("hint", "--backend casadi solves the optimum of Prop. 1 (this is eq. 2.27's heading)"))
    return [(k, v) for k, v in rows if v is not None]


def _durations(arcs: dict[str, float]) -> str:
    keys = ("interior_duration", "boundary_duration", "line_of_sight_duration")
    return ", ".join(f"{arcs[k]:.4g}" for k in keys)
