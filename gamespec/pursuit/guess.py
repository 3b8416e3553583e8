"""The default initial guess of the evader's optimal-control problem: a good constant heading.

Constant bearing: the best constant heading (§2.4.1; the optimum whenever one heading suffices).
Pure pursuit: the suboptimal heading of eq. 2.27. Anything else (mixed strategies, relay
pursuit): the best constant heading found by simulating the true dynamics over a grid of headings,
discarding those that enter a stationary pursuer's Voronoi cell (eq. 2.28). The guess trajectory is
that heading simulated to capture, carried into the optimal-control problem's ``guess`` section as
least-squares polynomials in normalized time τ (:func:`polynomial`, written by the printer).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from gamespec.pursuit import constant_bearing, pure_pursuit
from gamespec.pursuit.constant_heading import constant_heading_chase
from gamespec.pursuit.relay import voronoi_margin
from gamespec.pursuit.simulation import Players
from gamespec.symbolic.language import symbol
from gamespec.symbolic.printer import to_text

GUESS_DEGREE = 5
"""Degree of the polynomials in normalized time τ that carry the simulated guess."""

NEGLIGIBLE = 1e-10
"""Fitted coefficients of smaller magnitude are left out of the guess polynomial."""


def fit_polynomial(tau: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Coefficients (lowest degree first) of the least-squares polynomial of :data:`GUESS_DEGREE`
    (one column per column of ``values`` when it has two dimensions)."""
    return np.polynomial.polynomial.polyfit(tau, values, GUESS_DEGREE)


def polynomial(tau: np.ndarray, values: np.ndarray) -> str:
    """The least-squares polynomial in ``tau`` through ``values``, as an expression of the language."""
    coefficients = enumerate(fit_polynomial(tau, values))
    tau_symbol = symbol("tau")
    return to_text(sp.Add(*(sp.Float(c) * tau_symbol**k for k, c in coefficients if abs(c) > NEGLIGIBLE)))


def ranked_simulated_headings(players: Players, samples: int = 48) -> list[float]:
    """Constant headings on a grid of ``samples``, latest simulated capture first, keeping those that
    respect eq. 2.28 (pure evasion from the first active pursuer when none does); a coarse
    integration is enough to rank them (constant-bearing teams have a closed form,
    :func:`~gamespec.pursuit.constant_heading.constant_heading_chase`)."""
    scored = []
    for heading in np.linspace(-np.pi, np.pi, samples, endpoint=False):
        traj = constant_heading_chase(players, float(heading), rtol=1e-6)
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
