"""The reduced-state dynamics of an engagement, built in SymPy and written in the expression language.

Fixed frame (eqs. 2.8, 2.34, 3.2, 3.15–3.16), control θ_E (``theta_E``):

- constant bearing ``i``: state r_i, ṙ_i = v cos(θ_E − φ_i) − √(u_i² − v² sin²(θ_E − φ_i)) with the
  line-of-sight angle φ_i a constant parameter (eqs. 2.8–2.9, 3.2–3.3);
- pure pursuit ``i``: states r_i, φ_i, ṙ_i = −u_i + v cos(θ_E − φ_i), φ̇_i = v sin(θ_E − φ_i)/r_i
  (eqs. 3.15–3.16);
- stationary ``i``: the same with u_i = 0 (eqs. 2.34b–c).

Line-of-sight frame (eqs. 2.21, 2.42): the frame turns with pursuer 1's line of sight (pure
pursuit), the control is θ = θ_E − φ_1 (``theta``) and pursuer i ≥ 2 sits at angle ψ_i seen from
the evader: ṙ_1 = −u_1 + v cos θ, ṙ_i = −u_i − v cos(ψ_i − θ), ψ̇_i = v sin(ψ_i − θ)/r_i − v sin θ/r_1
(u_i = 0 when stationary); a constant-bearing pursuer i has ṙ_i = −v cos(ψ_i − θ) −
√(u_i² − v² sin²(ψ_i − θ)) and ψ̇_i = −v sin θ/r_1, its line of sight being fixed in the inertial frame.

Capture is r_i ≥ ε for every active pursuer with the final time maximized: since every r_i of an
active pursuer decreases (u_i > v), the optimum ends with some r_i = ε (eq. 3.5). A relay
engagement adds the Voronoi constraint ½(r_a² − r_s²) ≤ 0 per stationary pursuer s (eq. 2.36).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import sympy as sp

from gamespec.pursuit.simulation import Players, Trajectory
from gamespec.specs.engagement import EngagementSpec
from gamespec.symbolic.language import symbol
from gamespec.symbolic.printer import to_text

T_MAX_FACTOR = 1.25
"""Final-time upper bound relative to the latest possible capture min_i (r_i(0) − ε)/(u_i − v): no
evader outlives it (ṙ_i ≤ v − u_i), and the margin keeps the bound inactive so that the
transversality condition H(t_c) = 0 holds even for pure evasion."""


@dataclass(frozen=True)
class Reduction:
    """An engagement's reduced-state problem: names, parameters and expressions, written in the
    language by :func:`~gamespec.symbolic.printer.to_text` from SymPy."""

    frame: str
    control: str
    parameters: dict[str, float] = field(default_factory=dict)
    dynamics: dict[str, str] = field(default_factory=dict)
    initial: dict[str, str] = field(default_factory=dict)
    distance: dict[int, str] = field(default_factory=dict)
    angle: dict[int, str] = field(default_factory=dict)
    capture_states: list[str] = field(default_factory=list)
    path_constraints: list[str] = field(default_factory=list)
    t_max: float = 0.0


def _angle_name(frame: str, index: int, n: int) -> str:
    if frame == "fixed":
        return f"phi{index + 1}"
    return "psi" if n == 2 else f"psi{index + 1}"


V = symbol("v")


def _initial(red: Reduction, state: str) -> None:
    """``state(0)`` is the parameter ``<state>_init``."""
    red.initial[state] = to_text(symbol(f"{state}_init"))


def parameter_values(players: Players, frame: str) -> dict[str, float]:
    """The values of a reduction's parameters in ``frame`` for ``players``: ``v``, ``eps``, and per
    pursuer k its initial distance ``r<k>_init``, its speed ``u<k>`` (when it moves) and its angle:
    the constant ``phi<k>`` (fixed frame, constant bearing), the initial ``phi<k>_init`` (fixed
    frame, otherwise) or ``psi<k>_init`` (line-of-sight frame, k ≥ 2). Numbers only: what a new
    engagement changes in its reduced problem (:func:`reduce` builds the rest once)."""
    n = len(players.names)
    r0, phi0 = players.distances(), players.los_angles()
    values = {"v": players.v, "eps": players.eps}
    for i, strategy in enumerate(players.strategies):
        k = i + 1
        values[f"r{k}_init"] = float(r0[i])
        if strategy != "stationary":
            values[f"u{k}"] = float(players.speeds[i])
        angle = _angle_name(frame, i, n)
        if frame == "fixed":
            values[angle if strategy == "cb" else f"{angle}_init"] = float(phi0[i])
        elif i > 0:
            values[f"{angle}_init"] = float(np.angle(np.exp(1j * (np.pi - phi0[0] + phi0[i]))))
    return values


def final_time_bound(players: Players) -> float:
    """``t_max``: :data:`T_MAX_FACTOR` times the latest possible capture min_i (r_i(0) − ε)/(u_i − v)."""
    active = players.active
    latest = (players.distances()[active] - players.eps) / (players.speeds[active] - players.v)
    return T_MAX_FACTOR * float(np.min(latest))


def reduce(spec: EngagementSpec) -> Reduction:
    """The reduced-state dynamics, initial values and constraints of ``spec`` (see module doc)."""
    players = Players.from_spec(spec)
    frame = spec.resolved_frame
    n = len(players.names)
    red = Reduction(frame=frame, control="theta_E" if frame == "fixed" else "theta")
    control = symbol(red.control)
    for i, strategy in enumerate(players.strategies):
        k = i + 1
        r, ang = symbol(f"r{k}"), symbol(_angle_name(frame, i, n))
        red.distance[i] = r.name
        if frame == "fixed" or i > 0:
            red.angle[i] = ang.name
        _initial(red, r.name)
        speed = symbol(f"u{k}")
        if strategy != "stationary":
            red.capture_states.append(r.name)
        closing = speed if strategy == "pp" else sp.Integer(0)
        if frame == "fixed":
            dynamics = _fixed_frame(red, strategy, r, ang, speed, closing, control)
        elif i == 0:
            dynamics = {r: -speed + V * sp.cos(control)}
        else:
            _initial(red, ang.name)
            dynamics = _line_of_sight_frame(strategy, r, ang, speed, closing, control)
        red.dynamics.update({state.name: to_text(rate) for state, rate in dynamics.items()})
    active = [i for i, s in enumerate(players.strategies) if s != "stationary"]
    guard = symbol(red.distance[active[0]])
    for i, strategy in enumerate(players.strategies):
        if strategy == "stationary":
            voronoi = sp.Rational(1, 2) * (guard**2 - symbol(red.distance[i]) ** 2)
            red.path_constraints.append(to_text(sp.Le(voronoi, 0)))
    return replace(red, parameters=parameter_values(players, frame), t_max=final_time_bound(players))


def _fixed_frame(
    red: Reduction,
    strategy: str,
    r: sp.Symbol,
    ang: sp.Symbol,
    speed: sp.Symbol,
    closing: sp.Expr,
    control: sp.Symbol,
) -> dict[sp.Symbol, sp.Expr]:
    """Eqs. 2.8 (constant bearing: φ_i a parameter), 3.15–3.16 and 2.34b–c (φ_i a state)."""
    rel = control - ang
    if strategy == "cb":
        return {r: V * sp.cos(rel) - sp.sqrt(speed**2 - V**2 * sp.sin(rel) ** 2)}
    _initial(red, ang.name)
    return {r: -closing + V * sp.cos(rel), ang: V * sp.sin(rel) / r}


def _line_of_sight_frame(
    strategy: str, r: sp.Symbol, ang: sp.Symbol, speed: sp.Symbol, closing: sp.Expr, control: sp.Symbol
) -> dict[sp.Symbol, sp.Expr]:
    """Eqs. 2.21 and 2.42 for pursuer i ≥ 2 at angle ψ_i, with the turn of pursuer 1's line of sight."""
    rel = ang - control
    turn = V * sp.sin(control) / symbol("r1")
    if strategy == "cb":
        return {r: -V * sp.cos(rel) - sp.sqrt(speed**2 - V**2 * sp.sin(rel) ** 2), ang: -turn}
    return {r: -closing - V * sp.cos(rel), ang: V * sp.sin(rel) / r - turn}


def observe(red: Reduction, traj: Trajectory) -> dict[str, np.ndarray]:
    """The reduced states and the control along a simulated trajectory (angles unwrapped)."""
    rel = traj.evader[:, None, :] - traj.pursuers
    dist = np.hypot(rel[..., 0], rel[..., 1])
    los = np.unwrap(np.arctan2(rel[..., 1], rel[..., 0]), axis=0)
    out = {red.distance[i]: dist[:, i] for i in red.distance}
    heading = np.unwrap(traj.heading)
    if red.frame == "fixed":
        out.update({red.angle[i]: los[:, i] for i in red.angle if red.angle[i] in red.dynamics})
        out[red.control] = heading
        return out
    for i, name in red.angle.items():
        out[name] = np.unwrap(np.angle(np.exp(1j * (np.pi - los[:, 0] + los[:, i]))))
    out[red.control] = np.unwrap(heading - los[:, 0])
    return out
