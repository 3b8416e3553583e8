"""Apollonius circles (CB) and Apollonius curves (PP) of pursuers against one evader (thesis §3.3).

Everything is vectorized over the pursuers: positions are ``(n, 2)`` arrays, the evader a ``(2,)``
array, pursuer speeds ``(n,)`` (heterogeneous teams, §3.5) and the evader speed a scalar.

*CB.* The Apollonius circle of pursuer ``i`` (:mod:`gamespec.pursuit.apollonius`) is the locus
``|X - e| / v = |X - p_i| / u_i``; its disk holds the evader, and its point closest to the evader,
``T_i``, lies at distance ``v |p_i - e| / (u_i + v)``.

*PP.* Against a non-maneuvering evader with heading ``phi`` measured from the line of sight (pursuer
to evader), pure pursuit captures after ``t_f = r0 (u + v cos phi) / (u**2 - v**2)`` (eq. 3.24), so
the Apollonius curve is the limaçon ``r(phi) = A + B cos phi`` around the evader with
``A = v u r0 / (u**2 - v**2)`` and ``B = v**2 r0 / (u**2 - v**2)``. It is non-convex when ``u < 2 v``;
its convex hull, the *refined* Apollonius curve (§3.3.1), replaces the dimple facing the pursuer by
the bitangent line ``x = -A**2 / (4 B)`` (in line-of-sight coordinates), which touches the limaçon
where ``cos phi = -A / (2 B)``.
"""

from __future__ import annotations

import numpy as np

from gamespec.pursuit.apollonius import ApolloniusCircles
from gamespec.pursuit.bearing import line_of_sight_angles
from gamespec.pursuit.pure_pursuit import pursuit_time

FloatArray = np.ndarray


def circle_radial_distance(
    circles: ApolloniusCircles, evader: FloatArray, directions: FloatArray
) -> FloatArray:
    """Distance from the evader to each circle along each direction angle: shape ``(n, len(directions))``.

    The evader is inside every Apollonius disk, so each ray leaves each disk exactly once.
    """
    unit = np.stack([np.cos(directions), np.sin(directions)], axis=-1)
    offset = evader - circles.centers
    along = offset @ unit.T
    inside = circles.radii[:, None] ** 2 - np.sum(offset**2, axis=1)[:, None]
    return -along + np.sqrt(along**2 + inside)


def _limacon_coefficients(
    initial_distance: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> tuple[FloatArray, FloatArray]:
    """``A`` and ``B`` of the Apollonius curve ``r(phi) = A + B cos phi`` (``v t_f`` from eq. 3.24)."""
    u = np.asarray(pursuer_speed, dtype=float)
    scale = evader_speed * initial_distance / (u**2 - evader_speed**2)
    return scale * u, scale * evader_speed


def pp_curve_radius(
    initial_distance: FloatArray, heading: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> FloatArray:
    """Distance from the evader to its Apollonius curve at line-of-sight heading ``heading`` (eq. 3.24)."""
    return evader_speed * pursuit_time(initial_distance, heading, pursuer_speed, evader_speed)


def tangent_heading(
    initial_distance: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> FloatArray:
    """Line-of-sight heading where the refined curve leaves the limaçon (``pi``: no dimple, ``u >= 2 v``)."""
    a, b = _limacon_coefficients(initial_distance, pursuer_speed, evader_speed)
    return np.arccos(np.clip(-a / (2.0 * b), -1.0, 1.0))


def refined_pp_radius(
    initial_distance: FloatArray, heading: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> FloatArray:
    """Distance from the evader to the refined (convex-hull) Apollonius curve (§3.3.1).

    On the convex part of the limaçon this is eq. 3.24; across the dimple it is the bitangent line
    ``r cos phi = -A**2 / (4 B)``. All arguments broadcast together.
    """
    a, b = _limacon_coefficients(initial_distance, pursuer_speed, evader_speed)
    curve = a + b * np.cos(heading)
    dimpled = a < 2.0 * b
    on_chord = dimpled & (np.cos(heading) < -a / (2.0 * b))
    with np.errstate(divide="ignore", invalid="ignore"):
        chord = -(a**2) / (4.0 * b * np.cos(heading))
    return np.where(on_chord, chord, curve)


def cb_reach(
    initial_distance: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> tuple[FloatArray, FloatArray]:
    """Nearest and farthest distance from the evader to each Apollonius circle.

    ``v r0 / (u + v)`` at ``T_i`` and ``|O_i - e| + d_i = v r0 / (u - v)`` across from it (§3.3).
    """
    u = np.asarray(pursuer_speed, dtype=float)
    return evader_speed * initial_distance / (u + evader_speed), evader_speed * initial_distance / (
        u - evader_speed
    )


def refined_pp_reach(
    initial_distance: FloatArray, pursuer_speed: FloatArray, evader_speed: float
) -> tuple[FloatArray, FloatArray]:
    """Nearest and farthest distance from the evader to each refined Apollonius curve.

    The farthest is ``A + B`` (heading straight away, eq. 3.24); the nearest is the bitangent's
    distance ``A**2 / (4 B)`` when the limaçon has a dimple, else ``A - B`` (heading at the pursuer).
    """
    a, b = _limacon_coefficients(initial_distance, pursuer_speed, evader_speed)
    return np.where(a < 2.0 * b, a**2 / (4.0 * b), a - b), a + b


def refined_pp_polygons(
    pursuers: FloatArray,
    evader: FloatArray,
    pursuer_speeds: FloatArray,
    evader_speed: float,
    samples: int = 64,
) -> FloatArray:
    """Convex polygons inscribed in the refined Apollonius curves: shape ``(n, samples, 2)``, CCW.

    The vertices lie on the convex arc of each limaçon (eq. 3.24), evenly spaced in line-of-sight
    heading; the closing edge is the bitangent chord across the dimple when there is one, else a
    chord of the same angular step. The polygons converge to the refined curves as ``samples`` grows.
    """
    distance = np.linalg.norm(pursuers - evader, axis=1)
    speeds = np.broadcast_to(np.asarray(pursuer_speeds, dtype=float), distance.shape)
    half_width = np.minimum(tangent_heading(distance, speeds, evader_speed), np.pi * (samples - 1) / samples)
    heading = half_width[:, None] * np.linspace(-1.0, 1.0, samples)[None, :]
    radius = pp_curve_radius(distance[:, None], heading, speeds[:, None], evader_speed)
    angle = line_of_sight_angles(pursuers, evader)[:, None] + heading
    return evader + radius[..., None] * np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def circle_polygons(
    centers: FloatArray, radii: FloatArray, evader: FloatArray, samples: int = 64
) -> FloatArray:
    """Polygons inscribed in circles that hold the evader, vertices at ``samples`` evenly spaced
    polar angles seen from the evader: shape ``(n, samples, 2)``, CCW. As for the refined curves,
    the edges stay ``cos(pi / samples)`` times the circle's nearest distance from the evader away."""
    angle = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    direction = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    offset = np.asarray(evader, dtype=float) - np.asarray(centers, dtype=float)
    b = offset @ direction.T
    c = np.sum(offset**2, axis=1)[:, None] - np.asarray(radii, dtype=float)[:, None] ** 2
    reach = -b + np.sqrt(np.maximum(b**2 - c, 0.0))
    return evader + reach[..., None] * direction[None, :, :]
