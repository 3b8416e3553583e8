"""An evader on a constant heading, simulated to capture in closed form where the team has one.

Against a constant heading each pursuer moves on its own (eq. 2.1), so a team has a closed form
when every member does: a constant-bearing pursuer keeps its line of sight's direction (eq. 3.3),
so its heading θ_i = φ_i + asin(v sin(θ_E − φ_i)/u_i) is constant and it runs a straight line,
closing at the constant rate ṙ_i of eq. 3.2 (capture at (r_i(0) − ε)/(−ṙ_i)); a stationary one
stays put; a team all on pure pursuit follows the pursuit curves of
:mod:`~gamespec.pursuit.pursuit_curve` (a sixth of the integration's CPU time at 400 points). A
team with pure pursuit beside another strategy is integrated by
:func:`~gamespec.pursuit.simulation.simulate_to_capture`. The closed forms return the integrator's
grid (``samples`` times from 0 to capture) and agree with it to its tolerance (round-off for the
straight lines, about 1e-10 for the pursuit curves).
"""

from __future__ import annotations

import numpy as np

from gamespec.pursuit.bearing import constant_bearing_headings
from gamespec.pursuit.constant_bearing import closing_rate
from gamespec.pursuit.pursuit_curve import constant_heading_pursuit
from gamespec.pursuit.simulation import Players, Trajectory, simulate_to_capture

SAMPLES = 400
"""Time points of the returned trajectory, as :func:`~gamespec.pursuit.simulation.simulate` gives."""


def straight_line_chase(players: Players, heading: float, samples: int = SAMPLES) -> Trajectory:
    """Constant-bearing and stationary pursuers against a constant heading (module doc)."""
    active = players.active
    phi = players.los_angles()
    rates = closing_rate(heading, phi[active], players.speeds[active], players.v)
    t_capture = float(np.min((players.distances()[active] - players.eps) / -rates))
    time = np.linspace(0.0, t_capture, samples)
    headings = constant_bearing_headings(phi, players.speeds, players.v, heading)
    velocity = players.speeds[:, None] * np.column_stack([np.cos(headings), np.sin(headings)])
    pursuers = players.positions[None] + time[:, None, None] * velocity[None]
    evader = players.evader + players.v * time[:, None] * np.array([np.cos(heading), np.sin(heading)])
    return Trajectory(time, pursuers, evader, np.full(samples, float(heading)), captured=True)


def constant_heading_chase(players: Players, heading: float, *, rtol: float = 1e-10) -> Trajectory:
    """The engagement under a constant evader heading until capture (module doc); ``rtol``: the
    integrator's tolerance where there is no closed form."""
    strategies = set(players.strategies)
    if strategies == {"pp"}:
        return constant_heading_pursuit(players, heading, samples=SAMPLES)
    if "pp" in strategies:
        return simulate_to_capture(players, heading, rtol=rtol)
    return straight_line_chase(players, heading)
