"""An OCP solution of an engagement's reduced problem, reported as the engagement's Result.

:func:`ocp_report` adds the engagement metrics read from the solution
(:func:`gamespec.pursuit.report.terminal_metrics`): capture time, capturing set,
simultaneous-capture gap, region of P2, and for relay pursuit the three arcs and the switching
condition (eqs. 2.41, 2.46). :func:`resimulation` (the ``resimulation`` analysis of the
``engagement_to_ocp`` transform) turns the OCP's heading into a law (:func:`heading_law`),
re-simulates the true dynamics (eq. 2.1) under it and reports what
:func:`gamespec.pursuit.verification.verify` judges the solution by
(:func:`gamespec.pursuit.report.simulation_report`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gamespec.ocp.control_signal import transcribed_signal
from gamespec.pursuit.reduced import Reduction
from gamespec.pursuit.relay import detect_arcs
from gamespec.pursuit.report import simulation_report, terminal_metrics
from gamespec.pursuit.simulation import Players, ScheduledHeading, simulate_to_capture
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec

ARC_TOL = 1e-5
"""|S| below this counts as on the Voronoi boundary when splitting a relay path into arcs."""


def heading_law(red: Reduction, result: Result) -> ScheduledHeading:
    """The OCP's evader heading as a law for re-simulation, as the transcription holds it
    (:mod:`gamespec.ocp.control_signal`): θ_E(t) in the fixed frame; θ(t) + φ_1 in the
    line-of-sight frame, φ_1 read from the simulated positions."""
    return ScheduledHeading(transcribed_signal(result, [red.control]), line_of_sight=red.frame != "fixed")


def relay_arcs(red: Reduction, players: Players, result: Result) -> dict[str, float]:
    """Arcs and switching condition (eq. 2.41 fixed frame / R-CB, eq. 2.46 line of sight / R-PP)."""
    active = int(np.flatnonzero(players.active)[0])
    guard = int(np.flatnonzero(~players.active)[0])
    s = result.states
    r_a, r_s = s[red.distance[active]], s[red.distance[guard]]
    u, v = players.speeds[active], players.v
    t = np.asarray(result.time)
    control = transcribed_signal(result, [red.control])(t)[0]
    if red.frame == "fixed":
        name = red.angle[active]
        phi_a = s[name] if name in s else np.full_like(t, red.parameters[name])
        switching = (v - u) * r_a - v * r_s * np.cos(phi_a - s[red.angle[guard]])
        off_los = control - phi_a
    else:
        switching = (v - u) * r_a + v * r_s * np.cos(s[red.angle[guard]])
        off_los = control
    arcs = detect_arcs(t, 0.5 * (r_a**2 - r_s**2), switching, off_los, ARC_TOL)
    return arcs.as_metrics()


def ocp_report(result: Result, spec: EngagementSpec, red: Reduction, players: Players) -> Result:
    """``result`` (of the reduced OCP) with the engagement metrics read from it (no simulation)."""
    terminal = np.array([result.states[red.distance[i]][-1] for i in range(len(players.names))])
    metrics = terminal_metrics(spec, players, terminal, result.t_final)
    if spec.is_relay and int(np.sum(~players.active)) == 1:
        metrics["arcs"] = relay_arcs(red, players, result)
    metrics["frame"] = red.frame
    return result.model_copy(update={"metrics": {**result.metrics, **metrics}})


def resimulation(
    result: Result, spec: EngagementSpec, red: Reduction, players: Players
) -> tuple[dict[str, Any], dict[str, float | None], dict[str, np.ndarray]]:
    """The metrics, checks and paths of the re-simulation of ``result`` under its heading."""
    traj = simulate_to_capture(players, heading_law(red, result))
    return simulation_report(spec, players, result.t_final, traj)
