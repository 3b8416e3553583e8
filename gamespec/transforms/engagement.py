"""``engagement`` → ``optimal_control``: the evader's reduced-state time-optimal problem.

:meth:`EngagementToOcp.apply` writes the OCP of :mod:`gamespec.pursuit.reduced` (dynamics as
expression strings generated from the engagement; maximize t_f; r_i ≥ ε; the Voronoi constraint of
eq. 2.36 for relay pursuit) with, as initial guess, the default constant heading of
:mod:`gamespec.pursuit.guess` (eq. 2.27 for pure pursuit) simulated to capture and fitted by
polynomials in normalized time. :meth:`EngagementToOcp.invert` re-simulates the true dynamics under
the OCP's heading and adds the engagement metrics: capture time, capturing set, simultaneous-capture
gap, region of P2, and for relay pursuit the three arcs and the switching condition (eqs. 2.41, 2.46).

An ``optimal`` status from the NLP only says that a KKT point of the discretized problem was found;
:func:`verify` keeps it only when the solution is also right for the engagement: the re-simulated
capture time is no earlier than the guess heading's (which the evader can always achieve), agrees
with the solution's t_f within :data:`RESIM_RTOL`, and the Hamiltonian (eq. 2.23: constant along an
optimal path) varies by at most :data:`HAMILTONIAN_TOL`. When a check fails and the file gives no
``guess_heading`` (an explicit one is the user's choice of starting point, kept as it is),
:meth:`invert` re-solves the OCP from the :data:`RETRIES` best simulated constant headings (eq. 2.28
respected) on the file's backend when it solves ``optimal_control`` (else the kind's default), keeps
the verified solution with the latest capture, and otherwise reports the first solution as
``feasible`` with the failed check in its message.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from gamespec import registry
from gamespec.pursuit.guess import default_heading, polynomial, ranked_simulated_headings
from gamespec.pursuit.reduced import Reduction, observe, reduce
from gamespec.pursuit.relay import detect_arcs
from gamespec.pursuit.report import engagement_report
from gamespec.pursuit.simulation import HeadingLaw, Players, simulate_to_capture
from gamespec.result import Result, Status
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
from gamespec.symbolic.language import symbol
from gamespec.symbolic.printer import to_text
from gamespec.transforms.base import Transform

ARC_TOL = 1e-5
"""|S| below this counts as on the Voronoi boundary when splitting a relay path into arcs."""

HAMILTONIAN_TOL = 1e-2
"""Largest variation of H along a solution (eq. 2.23) that :func:`verify` accepts as optimal."""

RESIM_RTOL = 1e-3
"""Largest |re-simulated capture time − t_f| / t_f that :func:`verify` accepts as optimal; also the
relative margin by which the re-simulated capture may fall short of the guess heading's."""

RETRIES = 4
"""Constant headings :meth:`EngagementToOcp.invert` re-solves from when a solution fails :func:`verify`."""


@dataclass(frozen=True)
class EngagementInverse:
    """What :meth:`EngagementToOcp.invert` needs: the reduction, the players, the guess heading and
    its simulated capture time (a lower bound on the optimum)."""

    reduction: Reduction
    players: Players
    guess_heading: float
    guess_capture_time: float


def _control_bounds(red: Reduction) -> ControlSpec:
    """θ ∈ [−π, π] in the line-of-sight frame; θ_E within π of pursuer 1's initial line of sight."""
    if red.frame == "line_of_sight":
        return ControlSpec(lower="-pi", upper="pi")
    ref = symbol(red.angle[0] if red.angle[0] in red.parameters else red.initial[red.angle[0]])
    return ControlSpec(lower=to_text(ref - sp.pi), upper=to_text(ref + sp.pi))


def to_ocp(spec: EngagementSpec) -> tuple[OptimalControlSpec, EngagementInverse]:
    """The reduced-state OCP of ``spec`` and the data to map its Result back."""
    red = reduce(spec)
    players = Players.from_spec(spec)
    heading = default_heading(players) if spec.guess_heading is None else spec.guess_heading
    traj = simulate_to_capture(players, heading)
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
    return ocp, EngagementInverse(red, players, heading, traj.capture_time)


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


def verify(result: Result, inverse: EngagementInverse) -> str | None:
    """The first engagement check a mapped-back ``result`` fails (see module doc), None if it passes."""
    checks, t_f = result.checks, result.t_final
    resimulated = checks.get("resimulated_capture_time")
    if resimulated is None:
        return "the re-simulated evader is not captured"
    if resimulated < inverse.guess_capture_time * (1 - RESIM_RTOL):
        return (
            f"re-simulated capture time {resimulated:.6g} is earlier than the guess heading's "
            f"{inverse.guess_capture_time:.6g}"
        )
    if abs(resimulated - t_f) > RESIM_RTOL * t_f:
        return f"re-simulated capture time {resimulated:.6g} is not within {RESIM_RTOL:g} of t_f = {t_f:.6g}"
    variation = checks.get("hamiltonian_variation")
    if variation is not None and variation > HAMILTONIAN_TOL:
        return f"hamiltonian_variation {variation:.3g} exceeds {HAMILTONIAN_TOL:g} (eq. 2.23)"
    return None


def report(result: Result, spec: EngagementSpec, inverse: EngagementInverse) -> Result:
    """``result`` with the engagement metrics, checks and paths of its re-simulation."""
    red, players = inverse.reduction, inverse.players
    terminal = np.array([result.states[red.distance[i]][-1] for i in range(len(players.names))])
    traj = simulate_to_capture(players, heading_law(red, result))
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


def resolve_from_headings(spec: EngagementSpec, inverse: EngagementInverse) -> Result | None:
    """The verified solution with the latest capture among re-solves of the OCP from the
    :data:`RETRIES` best simulated constant headings other than the guess; None if none verifies."""
    from gamespec.solving import solve

    backend = spec.solver.backend
    if backend is None or "optimal_control" not in registry.backend_class(backend).kinds:
        backend = OptimalControlSpec.default_backend
    best = None
    for heading in ranked_simulated_headings(inverse.players)[: RETRIES + 1]:
        if np.isclose(np.angle(np.exp(1j * (heading - inverse.guess_heading))), 0.0):
            continue
        retry = spec.model_copy(update={"guess_heading": heading})
        ocp, retry_inverse = to_ocp(retry)
        result = solve(ocp, backend)
        if not result.ok or result.t_final is None:
            continue
        result = report(result, spec, retry_inverse)
        if verify(result, inverse) is None and (best is None or result.t_final > best.t_final):
            best = result.model_copy(
                update={"message": f"{result.message}; re-solved from heading {heading:.6g}"}
            )
    return best


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
        result = report(result, spec, inverse_data)
        failed = verify(result, inverse_data)
        if failed is None or result.status != Status.OPTIMAL:
            return result
        retried = None if spec.guess_heading is not None else resolve_from_headings(spec, inverse_data)
        if retried is not None:
            return super().invert(retried, spec, inverse_data)
        return result.model_copy(
            update={"status": Status.FEASIBLE, "message": f"not verified optimal: {failed}"}
        )
