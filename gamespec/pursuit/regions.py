"""Regions of non-degeneracy for two pursuers and one evader (§2.3, Figs. 2.3 and 2.5).

Given P1, the evader E and the speeds, the plane of P2's initial positions splits into
D1 (P2 alone decides: pure evasion from P2), D2 (P1 alone decides: pure evasion from P1) and N
(both matter: simultaneous capture). The boundaries are, for constant bearing, the circles C1
(eq. 2.2 and the t_f-isochrone) and C2 (eqs. 2.3–2.4); for pure pursuit, the ellipse E and the closed
curve F (eqs. 2.5–2.6). The thesis works in a frame with P1 at the origin and E at (d, 0); the
functions here take positions anywhere and rotate into that frame. Point capture (ε = 0), as in the
thesis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.apollonius import apollonius_circles
from gamespec.pursuit.pure_pursuit import pursuit_time

Region = Literal["D1", "D2", "N"]


@dataclass(frozen=True)
class Frame:
    """The thesis frame of §2.3.1: P1 at the origin, E at (d, 0)."""

    origin: np.ndarray
    angle: float
    d: float

    @classmethod
    def of(cls, p1: np.ndarray, e: np.ndarray) -> Frame:
        diff = np.asarray(e, float) - np.asarray(p1, float)
        return cls(np.asarray(p1, float), float(np.arctan2(diff[1], diff[0])), float(np.hypot(*diff)))

    def _rotation(self, sign: float) -> np.ndarray:
        c, s = np.cos(self.angle), np.sin(sign * self.angle)
        return np.array([[c, -s], [s, c]])

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 2) → frame coordinates."""
        return (np.asarray(points, float) - self.origin) @ self._rotation(1.0)

    def to_world(self, points: np.ndarray) -> np.ndarray:
        """Frame coordinates (..., 2) → world points."""
        return np.asarray(points, float) @ self._rotation(-1.0) + self.origin


def pure_evasion_time(d: float, u1: float, v: float) -> float:
    """t_f = d/(u1 − v): capture by P1 under pure evasion (eq. 2.2)."""
    return d / (u1 - v)


def cb_circle_c1(d: float, u1: float, u2: float, v: float) -> tuple[np.ndarray, float]:
    """C1: centre C = (u1 t_f, 0), radius u2 t_f — the boundary between N and D2 for CB (§2.3.1)."""
    tf = pure_evasion_time(d, u1, v)
    return np.array([u1 * tf, 0.0]), u2 * tf


def cb_circle_c2(d: float, u1: float, u2: float, v: float) -> tuple[np.ndarray, float]:
    """C2: centre (d + (u2 − v)(d − x_a)/v, 0), radius r_a (u2 − v)/v — the D1 boundary (eq. 2.4),
    (x_a, 0) and r_a being the centre and radius of P1's Apollonius circle."""
    apollonius = apollonius_circles(np.zeros((1, 2)), np.array([d, 0.0]), np.array([u1]), v)
    xa, ra = apollonius.centers[0, 0], apollonius.radii[0]
    return np.array([d + (u2 - v) * (d - xa) / v, 0.0]), ra * (u2 - v) / v


def pp_ellipse_foci(d: float, u1: float, u2: float, v: float) -> tuple[np.ndarray, np.ndarray, float]:
    """E: foci p_E(0) = (d, 0) and p_E' = ((u1 + v)/(u1 − v) d, 0), focal-distance sum 2 u2 t_f (§2.3.2)."""
    tf = pure_evasion_time(d, u1, v)
    return np.array([d, 0.0]), np.array([(u1 + v) / (u1 - v) * d, 0.0]), 2 * u2 * tf


def pp_curve_f(d: float, u1: float, u2: float, v: float, theta: np.ndarray) -> np.ndarray:
    """F: P2's initial positions (k, 2) for which pure evasion from P2 at heading θ ends in
    simultaneous capture (eq. 2.6)."""
    rho = (u2 - v) * pursuit_time(d, theta, u1, v)
    return np.column_stack([d - rho * np.cos(theta), -rho * np.sin(theta)])


def _inside_d1_and_n(strategy: str, local: np.ndarray, d: float, u1: float, u2: float, v: float):
    """Masks (inside the D1 boundary, inside the N/D2 boundary) for frame points ``local``."""
    x, y = local[..., 0], local[..., 1]
    if strategy == "cb":
        (c1, r1), (c2, r2) = cb_circle_c1(d, u1, u2, v), cb_circle_c2(d, u1, u2, v)
        return np.hypot(x - c2[0], y) < r2, np.hypot(x - c1[0], y) < r1
    focus, other, total = pp_ellipse_foci(d, u1, u2, v)
    in_e = np.hypot(x - focus[0], y) + np.hypot(x - other[0], y) < total
    theta = np.arctan2(-y, d - x)
    in_f = np.hypot(x - d, y) < (u2 - v) * pursuit_time(d, theta, u1, v)
    return in_f, in_e


def classify(
    strategy: str,
    p1: np.ndarray,
    p2: np.ndarray,
    e: np.ndarray,
    u1: float,
    u2: float,
    v: float,
) -> np.ndarray:
    """Region ('D1', 'D2' or 'N') of P2's initial position(s) ``p2`` (..., 2), for ``cb`` or ``pp``.

    D1: inside C2 (CB) or F (PP); N: otherwise inside C1 (CB) or E (PP); D2: the rest.
    """
    if strategy not in ("cb", "pp"):
        raise UnsupportedFeature(f"regions of non-degeneracy are defined for cb or pp, not {strategy!r}")
    frame = Frame.of(p1, e)
    in_d1, in_n = _inside_d1_and_n(strategy, frame.to_local(p2), frame.d, u1, u2, v)
    return np.where(in_d1, "D1", np.where(in_n, "N", "D2"))


def boundary_curves(
    strategy: str, p1: np.ndarray, e: np.ndarray, u1: float, u2: float, v: float, samples: int = 361
) -> dict[str, np.ndarray]:
    """The region boundaries as world-frame polylines: C1, C2 (CB) or E, F (PP)."""
    frame = Frame.of(p1, e)
    d = frame.d
    s = np.linspace(-np.pi, np.pi, samples)
    ring = np.column_stack([np.cos(s), np.sin(s)])
    if strategy == "cb":
        (c1, r1), (c2, r2) = cb_circle_c1(d, u1, u2, v), cb_circle_c2(d, u1, u2, v)
        local = {"C1": c1 + r1 * ring, "C2": c2 + r2 * ring}
    elif strategy == "pp":
        focus, other, total = pp_ellipse_foci(d, u1, u2, v)
        a = total / 2
        c = (other[0] - focus[0]) / 2
        b = np.sqrt(a**2 - c**2)
        centre = (focus + other) / 2
        local = {"E": centre + ring * [a, b], "F": pp_curve_f(d, u1, u2, v, s)}
    else:
        raise UnsupportedFeature(f"regions of non-degeneracy are defined for cb or pp, not {strategy!r}")
    return {name: frame.to_world(points) for name, points in local.items()}
