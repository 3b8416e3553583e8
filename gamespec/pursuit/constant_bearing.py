"""Optimal evasion from constant-bearing pursuers in closed form (§2.4.1, §3.2.1).

With every pursuer on constant bearing the line-of-sight angles stay at their initial values and
each distance closes at a constant rate for a constant evader heading (eqs. 2.8–2.9, 3.2–3.3). The
optimal heading is constant (eq. 2.15), so the optimum is the best constant heading of
:mod:`gamespec.pursuit.headings`; in a non-degenerate two-pursuer case it is the farther
intersection of the two Apollonius circles (Fig. 2.7).
"""

from __future__ import annotations

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.headings import HeadingChoice, best_constant_heading
from gamespec.pursuit.simulation import Players


def closing_rate(theta_E: np.ndarray, phi: np.ndarray, u: np.ndarray, v: float) -> np.ndarray:
    """ṙ_i = v cos(θ_E − φ_i) − √(u_i² − v² sin²(θ_E − φ_i)) (eq. 3.2 with the root of eq. 3.3)."""
    a = theta_E - phi
    return v * np.cos(a) - np.sqrt(u**2 - (v * np.sin(a)) ** 2)


def capture_times(players: Players, headings: np.ndarray) -> np.ndarray:
    """Capture times (k, n) of each CB pursuer against constant headings: (r_i(0) − ε) / −ṙ_i."""
    if any(s != "cb" for s in players.strategies):
        raise UnsupportedFeature("the constant-bearing closed form needs every pursuer on cb")
    rate = closing_rate(np.asarray(headings)[:, None], players.los_angles(), players.speeds, players.v)
    return (players.distances() - players.eps) / -rate


def optimal_evasion(players: Players) -> HeadingChoice:
    """The evader's optimal constant heading against CB pursuers and its capture time.

    Degenerate cases come out as pure evasion (θ_E = φ_i, Theorem 1's proof); non-degenerate ones
    as a heading of simultaneous capture.
    """
    return best_constant_heading(lambda h: capture_times(players, h), players.los_angles())


def apollonius_circle(p: np.ndarray, e: np.ndarray, u: float, v: float) -> tuple[np.ndarray, float]:
    """Centre and radius of the Apollonius circle of pursuer ``p`` and evader ``e``: |x − e| = ρ|x − p|.

    With ρ = v/u the centre is (e − ρ² p)/(1 − ρ²) and the radius ρ‖p − e‖/(1 − ρ²) (§2.3.1 and
    §3.3, where the centre is printed with ρ in place of ρ²).
    """
    rho = v / u
    centre = (np.asarray(e) - rho**2 * np.asarray(p)) / (1 - rho**2)
    return centre, rho * float(np.linalg.norm(np.subtract(p, e))) / (1 - rho**2)


def apollonius_heading(players: Players) -> float | None:
    """Heading toward the farther intersection of the two pursuers' Apollonius circles (Fig. 2.7).

    Point capture (ε = 0); None when the circles do not meet (a degenerate case).
    """
    if len(players.names) != 2:
        raise UnsupportedFeature("the Apollonius construction of Fig. 2.7 is for two pursuers")
    (c1, a), (c2, b) = (
        apollonius_circle(p, players.evader, u, players.v)
        for p, u in zip(players.positions, players.speeds, strict=True)
    )
    d = float(np.linalg.norm(c2 - c1))
    if d > a + b or d < abs(a - b) or d == 0:
        return None
    along = (a**2 - b**2 + d**2) / (2 * d)
    half = np.sqrt(max(a**2 - along**2, 0.0))
    axis = (c2 - c1) / d
    base = c1 + along * axis
    normal = np.array([-axis[1], axis[0]])
    points = [base + half * normal, base - half * normal]
    far = max(points, key=lambda q: float(np.linalg.norm(q - players.evader)))
    return float(np.arctan2(*(far - players.evader)[::-1]))
