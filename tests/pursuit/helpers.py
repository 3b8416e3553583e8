"""Small builders shared by the pursuit tests."""

from __future__ import annotations

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.apollonius import apollonius_circles
from gamespec.pursuit.simulation import Players


def two_pursuers(p2, strategy: str, *, u2: float = 1.0, v: float = 0.5, eps: float = 1e-3) -> Players:
    """The §2.3 setting: P1 at the origin, E at (1, 0), u1 = 1."""
    return Players(
        names=("P1", "P2"),
        positions=np.array([[0.0, 0.0], p2], dtype=float),
        speeds=np.array([1.0, u2]),
        strategies=(strategy, strategy),
        evader=np.array([1.0, 0.0]),
        v=v,
        eps=eps,
    )


def apollonius_heading(players: Players) -> float | None:
    """Heading toward the farther intersection of the two pursuers' Apollonius circles (Fig. 2.7).

    Point capture (ε = 0); None when the circles do not meet (a degenerate case).
    """
    if len(players.names) != 2:
        raise UnsupportedFeature("the Apollonius construction of Fig. 2.7 is for two pursuers")
    circles = apollonius_circles(players.positions, players.evader, players.speeds, players.v)
    (c1, c2), (a, b) = circles.centers, circles.radii
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
