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
from gamespec.pursuit.simulation import Players, Trajectory


def voronoi_margin(traj: Trajectory, players: Players) -> np.ndarray:
    """S(t) = ½(r_a² − r_s²) (eq. 2.36) for each stationary pursuer s, shape (k, n_stationary)."""
    dist = traj.distances()
    active = players.active
    return 0.5 * (dist[:, active][:, :1] ** 2 - dist[:, ~active] ** 2)


def best_simulated_heading(players: Players, samples: int = 48) -> float:
    """The constant heading with the latest simulated capture that respects eq. 2.28 (pure evasion
    from the first active pursuer when none does); a coarse integration is enough to rank them."""
    best, latest = float(players.los_angles()[players.active][0]), -np.inf
    for heading in np.linspace(-np.pi, np.pi, samples, endpoint=False):
        traj = pure_pursuit.simulate_heading(players, float(heading), rtol=1e-6)
        if voronoi_margin(traj, players).max(initial=-np.inf) <= 0 and traj.capture_time > latest:
            best, latest = float(heading), traj.capture_time
    return best


def default_heading(players: Players) -> float:
    """The guess heading (see module doc)."""
    strategies = set(players.strategies)
    if strategies == {"cb"}:
        return constant_bearing.best_constant_heading(players).heading
    if strategies == {"pp"}:
        return pure_pursuit.suboptimal_heading(players).heading
    return best_simulated_heading(players)
