"""The default initial guess of the evader's optimal-control problem: a good constant heading.

Constant bearing: the best constant heading (§2.4.1; the optimum whenever one heading suffices).
Pure pursuit: the suboptimal heading of eq. 2.27. Anything else (mixed strategies, relay
pursuit): the best constant heading found by simulating the true dynamics over a grid of headings,
discarding those that enter a stationary pursuer's Voronoi cell (eq. 2.28). The guess trajectory is
that heading simulated to capture.
"""

from __future__ import annotations

import numpy as np

from gamespec.pursuit import constant_bearing, pure_pursuit
from gamespec.pursuit.relay import voronoi_margin
from gamespec.pursuit.simulation import Players, simulate_to_capture


def ranked_simulated_headings(players: Players, samples: int = 48) -> list[float]:
    """Constant headings on a grid of ``samples``, latest simulated capture first, keeping those that
    respect eq. 2.28 (pure evasion from the first active pursuer when none does); a coarse
    integration is enough to rank them."""
    scored = []
    for heading in np.linspace(-np.pi, np.pi, samples, endpoint=False):
        traj = simulate_to_capture(players, float(heading), rtol=1e-6)
        if voronoi_margin(traj, players).max(initial=-np.inf) <= 0:
            scored.append((traj.capture_time, float(heading)))
    ranked = [h for _, h in sorted(scored, reverse=True)]
    return ranked or [float(players.los_angles()[players.active][0])]


def default_heading(players: Players) -> float:
    """The guess heading (see module doc)."""
    strategies = set(players.strategies)
    if strategies == {"cb"}:
        return constant_bearing.best_constant_heading(players).heading
    if strategies == {"pp"}:
        return pure_pursuit.suboptimal_heading(players).heading
    return ranked_simulated_headings(players)[0]
