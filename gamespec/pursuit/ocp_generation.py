"""The evader's reduced-state time-optimal problem of an engagement, as an ``optimal_control`` spec.

:func:`to_ocp` writes the OCP of :mod:`gamespec.pursuit.reduced` (dynamics generated from the
engagement; maximize t_f; r_i ≥ ε; the Voronoi constraint of eq. 2.36 for relay pursuit; t_f
within ``[0, t_max]``, ``t_max`` a parameter like every other value taken from the engagement). Its
starting point is a constant heading simulated to capture — by default the one of
:func:`gamespec.pursuit.guess.default_heading` (eq. 2.27 for pure pursuit) — fitted by polynomials
in normalized time, carried twice: as the spec's ``guess`` section (for the OCP solved on its own)
and sampled as the :func:`fitted_guess` Result the solving layer starts the compiled model from.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import sympy as sp

from gamespec.pursuit.constant_heading import constant_heading_chase
from gamespec.pursuit.guess import default_heading, fit_polynomial, polynomial
from gamespec.pursuit.reduced import Reduction, final_time_bound, observe, parameter_values, reduce
from gamespec.pursuit.simulation import Players, Trajectory
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


@dataclass(frozen=True)
class EngagementInverse:
    """What maps a Result of the OCP back to the engagement: the reduction, the players, the guess
    heading, its simulated capture time (a lower bound on the optimum) and the guess trajectory as
    a Result of the OCP."""

    reduction: Reduction
    players: Players
    guess_heading: float
    guess_capture_time: float
    guess: Result


def trajectory_guess(red: Reduction, traj: Trajectory) -> Result:
    """A simulated trajectory in the reduced states and control of ``red``: a guess Result."""
    observed = observe(red, traj)
    control = observed.pop(red.control)
    return Result(status=Status.FEASIBLE, time=traj.time, states=observed, controls={red.control: control})


def fitted_guess(red: Reduction, traj: Trajectory) -> Result:
    """The starting point the spec's ``guess`` section writes — polynomials in τ fitted to a simulated
    trajectory — sampled at the trajectory's times, as a guess Result (the smooth fit, not the
    trajectory itself, is what the NLP starts well from)."""
    tau = traj.time / traj.time[-1]
    observed = observe(red, traj)
    coefficients = fit_polynomial(tau, np.column_stack(list(observed.values())))
    fitted = dict(zip(observed, np.polynomial.polynomial.polyval(tau, coefficients), strict=True))
    control = fitted.pop(red.control)
    return Result(status=Status.FEASIBLE, time=traj.time, states=fitted, controls={red.control: control})


def heading_guess(red: Reduction, players: Players, heading: float) -> Result:
    """The constant ``heading`` simulated to capture (:func:`constant_heading_chase`), as the fitted
    guess Result of the reduced OCP."""
    return fitted_guess(red, constant_heading_chase(players, heading))


def _control_bounds(red: Reduction) -> ControlSpec:
    """θ ∈ [−π, π] in the line-of-sight frame; θ_E within π of pursuer 1's initial line of sight."""
    if red.frame == "line_of_sight":
        return ControlSpec(lower="-pi", upper="pi")
    ref = symbol(red.angle[0] if red.angle[0] in red.parameters else red.initial[red.angle[0]])
    return ControlSpec(lower=to_text(ref - sp.pi), upper=to_text(ref + sp.pi))


def ocp_parameters(red: Reduction) -> dict[str, float]:
    """The runtime parameters of the OCP :func:`to_ocp` writes for ``red``."""
    return {**red.parameters, "t_max": red.t_max}


def _guess_trajectory(spec: EngagementSpec, players: Players) -> tuple[float, Trajectory]:
    """The guess heading (the file's, else :func:`default_heading`) and its simulation to capture."""
    heading = default_heading(players) if spec.guess_heading is None else spec.guess_heading
    return heading, constant_heading_chase(players, heading)


def remapped(spec: EngagementSpec, inverse: EngagementInverse) -> tuple[dict[str, float], EngagementInverse]:
    """The OCP's runtime parameters and the inverse data for ``spec``, an engagement of the same
    structure as the one ``inverse`` was made for (the same pursuers, strategies and frame): what
    :func:`to_ocp` gives, without writing the OCP again: the reduction's numbers
    (:func:`~gamespec.pursuit.reduced.parameter_values`) and the guess heading simulated to capture."""
    players = Players.from_spec(spec)
    red = replace(
        inverse.reduction,
        parameters=parameter_values(players, inverse.reduction.frame),
        t_max=final_time_bound(players),
    )
    heading, traj = _guess_trajectory(spec, players)
    return ocp_parameters(red), EngagementInverse(
        red, players, heading, traj.capture_time, fitted_guess(red, traj)
    )


def to_ocp(spec: EngagementSpec) -> tuple[OptimalControlSpec, EngagementInverse]:
    """The reduced-state OCP of ``spec`` and the data to map its Result back (see module doc)."""
    red = reduce(spec)
    players = Players.from_spec(spec)
    heading, traj = _guess_trajectory(spec, players)
    tau = traj.time / traj.time[-1]
    observed = observe(red, traj)
    capture = set(red.capture_states)
    states = {
        name: StateSpec(initial=red.initial[name], lower="eps" if name in capture else None)
        for name in red.dynamics
    }
    problem = OcpProblem(
        parameters=ocp_parameters(red),
        states=states,
        controls={red.control: _control_bounds(red)},
        dynamics=red.dynamics,
        objective=ObjectiveSpec(sense="maximize", mayer="t_f"),
        time=TimeSpec(final="free", bounds=(0.0, "t_max"), guess=min(traj.capture_time, red.t_max)),
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
    inverse = EngagementInverse(red, players, heading, traj.capture_time, fitted_guess(red, traj))
    return ocp, inverse
