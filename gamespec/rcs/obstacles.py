"""Avoidance constraints ``g <= 0`` of moving obstacles (§6.4.1-6.4.3), built in SymPy.

An obstacle sits at ``p(t) = center + velocity·(t - t0)`` (eq. 6.38 in closed form: ``z = d + ρt``).
With ``D² = (x - p_x)² + (y - p_y)²`` between the agent and the obstacle:

- eq. 6.39 / 6.41: ``g_β = r_o^β - (D²)^{β/2}`` (β = 1 is eq. 6.39);
- eq. 6.43 with the super-Gaussian of eq. 6.44: ``g = exp(-((x - c)/w_o)^γ) · (r_o² - (y - p_y)²)``,
  for an obstacle moving along a track parallel to y through x = c (its centre's x).
"""

from __future__ import annotations

from collections.abc import Mapping

import sympy as sp

from gamespec.rcs.spec import Obstacle
from gamespec.symbolic.language import TIME


def position(obstacle: Obstacle, parse, t0: float) -> tuple[sp.Expr, sp.Expr]:
    """The obstacle's centre at time ``t`` (eq. 6.38 integrated)."""
    return tuple(
        parse(c) + parse(v) * (TIME - t0) for c, v in zip(obstacle.center, obstacle.velocity, strict=True)
    )


def avoidance(
    obstacle: Obstacle, agent: tuple[sp.Expr, sp.Expr], power: sp.Expr, parse, t0: float
) -> sp.Expr:
    """``g`` of eq. 6.41 (eq. 6.39 for β = 1), or of eqs. 6.43-6.44 for an obstacle on a track."""
    px, py = position(obstacle, parse, t0)
    r = parse(obstacle.radius)
    if obstacle.track is not None:
        across = (agent[0] - parse(obstacle.center[0])) / parse(obstacle.track.half_width)
        boxcar = sp.exp(-(across**obstacle.track.gamma))
        return boxcar * (r**2 - (agent[1] - py) ** 2)
    squared = (agent[0] - px) ** 2 + (agent[1] - py) ** 2
    power = sp.nsimplify(power) if power.is_number else power  # 1.0 → 1, 0.5 → 1/2
    if power == 1:
        return r - sp.sqrt(squared)
    return r**power - squared ** (power / 2)


def constraints(
    obstacles: Mapping[str, Obstacle], agent: tuple[sp.Expr, sp.Expr], power: sp.Expr, parse, t0: float
) -> dict[str, sp.Expr]:
    """Obstacle name → its ``g``."""
    return {name: avoidance(o, agent, power, parse, t0) for name, o in obstacles.items()}
