"""``engagement`` → ``optimal_control``: the evader's reduced-state time-optimal problem.

:meth:`EngagementToOcp.apply` writes the OCP of :mod:`gamespec.pursuit.reduced` (dynamics as
expression strings generated from the engagement; maximize t_f; r_i ≥ ε; the Voronoi constraint of
eq. 2.36 for relay pursuit) with, as initial guess, the default constant heading of
:mod:`gamespec.pursuit.guess` (eq. 2.27 for pure pursuit) simulated to capture and fitted by
polynomials in normalized time. :meth:`EngagementToOcp.invert` re-simulates the true dynamics under
the OCP's heading and adds the engagement metrics: capture time, capturing set, simultaneous-capture
gap, region of P2, and for relay pursuit the three arcs and the switching condition (eqs. 2.41, 2.46).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.pursuit.guess import default_heading
from gamespec.pursuit.pure_pursuit import simulate_heading
from gamespec.pursuit.reduced import Reduction, observe, reduce
from gamespec.pursuit.relay import detect_arcs
from gamespec.pursuit.report import engagement_report, resimulate
from gamespec.pursuit.simulation import HeadingLaw, Players
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec
from gamespec.specs.ocp import (
    ControlSpec,
    GuessSpec,
    ObjectiveSpec,
    OcpProblem,
    OptimalControlSpec,
    StateSpec,
    TimeSpec,
)
from gamespec.transforms.base import Transform

GUESS_DEGREE = 5
"""Degree of the polynomials in normalized time τ that carry the simulated guess."""

ARC_TOL = 1e-5
"""|S| below this counts as on the Voronoi boundary when splitting a relay path into arcs."""


@dataclass(frozen=True)
class EngagementInverse:
    """What :meth:`EngagementToOcp.invert` needs: the reduction and the players."""

    reduction: Reduction
    players: Players


def polynomial(tau: np.ndarray, values: np.ndarray) -> str:
    """A least-squares polynomial in ``tau`` through ``values``, as an expression string."""
    coeffs = np.polynomial.polynomial.polyfit(tau, values, GUESS_DEGREE)
    terms = [f"({c:.12g})*tau**{k}" if k else f"({c:.12g})" for k, c in enumerate(coeffs) if abs(c) > 1e-10]
    return " + ".join(terms) or "0"


def _control_bounds(red: Reduction) -> ControlSpec:
    """θ ∈ [−π, π] in the line-of-sight frame; θ_E within π of pursuer 1's initial line of sight."""
    if red.frame == "line_of_sight":
        return ControlSpec(lower="-pi", upper="pi")
    ref = red.angle[0] if red.angle[0] in red.parameters else f"{red.angle[0]}_init"
    return ControlSpec(lower=f"{ref} - pi", upper=f"{ref} + pi")


def to_ocp(spec: EngagementSpec) -> tuple[OptimalControlSpec, EngagementInverse]:
    """The reduced-state OCP of ``spec`` and the data to map its Result back."""
    red = reduce(spec)
    players = Players.from_spec(spec)
    heading = default_heading(players) if spec.guess_heading is None else spec.guess_heading
    traj = simulate_heading(players, heading)
    tau = traj.time / traj.time[-1]
    observed = observe(red, traj)
    capture = set(red.capture_states)
    states = {
        name: StateSpec(initial=red.initial[name], lower="eps" if name in capture else None)
        for name in red.dynamics
    }
    problem = OcpProblem(
        parameters=red.parameters,
        states=states,
        controls={red.control: _control_bounds(red)},
        dynamics=red.dynamics,
        objective=ObjectiveSpec(sense="maximize", mayer="t_f"),
        time=TimeSpec(final="free", bounds=(0.0, red.t_max), guess=min(traj.capture_time, red.t_max)),
        path_constraints=red.path_constraints,
    )
    guess = GuessSpec(
        states={name: polynomial(tau, observed[name]) for name in red.dynamics},
        controls={red.control: polynomial(tau, observed[red.control])},
        t_final=traj.capture_time,
    )
    ocp = OptimalControlSpec(
        name=spec.name,
        description=f"Reduced-state evasion problem generated from engagement {spec.name!r}.",
        solver=spec.solver,
        problem=problem,
        method=spec.method,
        guess=guess,
    )
    return ocp, EngagementInverse(red, players)


def heading_law(red: Reduction, result: Result) -> HeadingLaw:
    """The OCP's evader heading as a law for re-simulation: θ_E(t) interpolated in the fixed frame;
    θ(t) + φ_1 in the line-of-sight frame, φ_1 read from the simulated positions."""
    tc = np.asarray(result.control_time if result.control_time is not None else result.time)
    control = np.asarray(result.controls[red.control])
    if red.frame == "fixed":
        return lambda t, P, E: float(np.interp(t, tc, control))
    return lambda t, P, E: float(np.interp(t, tc, control) + np.arctan2(*(E - P[0])[::-1]))


def relay_arcs(red: Reduction, players: Players, result: Result) -> dict[str, float]:
    """Arcs and switching condition (eq. 2.41 fixed frame / R-CB, eq. 2.46 line of sight / R-PP)."""
    active = int(np.flatnonzero(players.active)[0])
    guard = int(np.flatnonzero(~players.active)[0])
    s = result.states
    r_a, r_s = s[red.distance[active]], s[red.distance[guard]]
    u, v = players.speeds[active], players.v
    t = np.asarray(result.time)
    tc = np.asarray(result.control_time if result.control_time is not None else t)
    control = np.interp(t, tc, result.controls[red.control])
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


class EngagementToOcp(Transform):
    """Generate the reduced-state OCP of an engagement (see module doc)."""

    source_kind = "engagement"
    target_kind = "optimal_control"

    def apply(self, spec: EngagementSpec) -> tuple[OptimalControlSpec, EngagementInverse]:
        return to_ocp(spec)

    def invert(self, result: Result, spec: EngagementSpec, inverse_data: Any) -> Result:
        result = super().invert(result, spec, inverse_data)
        if not result.ok or result.t_final is None:
            return result
        red, players = inverse_data.reduction, inverse_data.players
        terminal = np.array([result.states[red.distance[i]][-1] for i in range(len(players.names))])
        traj = resimulate(players, heading_law(red, result), result.t_final)
        metrics, checks, arrays = engagement_report(spec, players, terminal, result.t_final, traj)
        if spec.is_relay and int(np.sum(~players.active)) == 1:
            metrics["arcs"] = relay_arcs(red, players, result)
        metrics["frame"] = red.frame
        return result.model_copy(
            update={
                "metrics": {**result.metrics, **metrics},
                "checks": {**result.checks, **checks},
                "arrays": {**result.arrays, **arrays},
            }
        )
