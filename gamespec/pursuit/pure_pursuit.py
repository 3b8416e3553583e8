"""Evasion from pure-pursuit pursuers: the suboptimal constant heading of §2.4.3.

Against a non-maneuvering evader a pure-pursuit pursuer captures at t_p = r_0 (u + v cos θ)/(u² − v²)
(eq. 2.5), θ being the evader's heading measured from the pursuer's line of sight. The suboptimal
heading makes two such times equal (eq. 2.27) and, of the solutions, keeps the later capture; with
more pursuers it is the best constant heading against all of them. Its true capture time comes from
simulating eq. 2.1: a constant heading in the inertial frame is not a constant θ in the rotating
frame of eq. 2.21, since that frame turns with the first pursuer's line of sight (eq. 2.20).
"""

from __future__ import annotations

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.headings import HeadingChoice, best_constant_heading
from gamespec.pursuit.simulation import Players


def pursuit_time(r0: np.ndarray, theta: np.ndarray, u: np.ndarray, v: float) -> np.ndarray:
    """t_p = r_0 (u + v cos θ)/(u² − v²): pure-pursuit capture time of a constant heading θ measured
    from the initial line of sight (eq. 2.5; eq. 3.24, whose v t_p is the Apollonius curve)."""
    u = np.asarray(u, dtype=float)
    return r0 * (u + v * np.cos(theta)) / (u**2 - v**2)


def capture_times(players: Players, headings: np.ndarray) -> np.ndarray:
    """Eq. 2.5 capture times (k, n) of each PP pursuer against constant headings ``headings``."""
    if any(s != "pp" for s in players.strategies):
        raise UnsupportedFeature("eq. 2.5 capture times need every pursuer on pp")
    theta = np.asarray(headings)[:, None] - players.los_angles()
    return pursuit_time(players.distances(), theta, players.speeds, players.v)


def suboptimal_heading(players: Players) -> HeadingChoice:
    """The suboptimal constant heading (eq. 2.27): equal eq. 2.5 capture times, the later one kept.

    In a degenerate case eq. 2.27 has no useful solution and the result is pure evasion.
    """
    return best_constant_heading(lambda h: capture_times(players, h), players.los_angles())
