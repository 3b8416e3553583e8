"""Active and redundant pursuers against one evader (thesis §3.3.1, Algorithm 1, Conjecture 1).

A pursuer is *active* when its Apollonius circle (CB) or refined Apollonius curve (PP) contributes
an arc to the Apollonius boundary (Definition 4): the first of the curves met along each ray from
the evader. Every curve encloses a convex region holding the evader, so the Apollonius boundary is
the boundary of the *intersection* of those regions, and the active pursuers are the regions that
contribute an arc to it.

Two methods for each strategy:

* CB, ``reference``: :func:`aapc`, Algorithm 1 as printed, ``O(n**2)`` per pursuer.
* CB, ``fast``: :func:`active_cb_lifted`, ``O(n log n)``. Lifting ``X -> (X, |X|**2)`` turns disk
  ``i`` into the half-space below a plane, and the boundary of the disk intersection is where the
  paraboloid meets the lower envelope of those planes. The lower envelope is the lower convex hull
  of the dual points ``q_i = (2 c_i, R_i**2 - |c_i|**2)`` (evader at the origin); projected, it is
  the farthest-power diagram of the disks. A vertex of the boundary, where circles ``i`` and ``k``
  meet inside all other disks, lies on the diagram edge between cells ``i`` and ``k``; so ``i`` and
  ``k`` are active when their common circle crosses that edge. With no vertex at all the boundary
  is one whole circle, that of the pursuer with the least ``|p_i - e| / (u_i + v)`` (Lemma 2), which
  is always active. Pursuers of one speed on one circle (the natural encirclement) or on one line,
  and teams of fewer than four, have dual points spanning no volume; their envelope is read from a
  2-D hull, still ``O(n log n)``. Coincident pursuers share one dual point, hence one status.
* PP, ``reference``: :func:`active_polygons_clipped` clips every edge of every refined curve
  (polygons from :func:`~gamespec_geometric.apollonius.refined_pp_polygons`) against all other
  curves, ``O(n**2 K**2)``.
* PP, ``fast``: :func:`active_polygons_dual`, ``O(nK log nK)``: the intersection of the polygons is
  an intersection of half-planes ``a . X <= h`` with ``h > 0`` (evader at the origin); a half-plane
  bounds it exactly when its dual point ``a / h`` is a vertex of the 2-D convex hull of all dual
  points, and its pursuer is then active.

The public entry is :func:`active_pursuers`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from gamespec.errors import SpecError
from gamespec.pursuit.apollonius import ApolloniusCircles, apollonius_circles
from gamespec_geometric.apollonius import (
    cb_reach,
    circle_polygons,
    refined_pp_polygons,
    refined_pp_reach,
)

Strategy = Literal["cb", "pp"]
TeamStrategy = Strategy | Sequence[Strategy] | np.ndarray
"""One strategy for every pursuer, or one each (a mixed team)."""
Method = Literal["fast", "reference"]
ROUND_OFF = 1e-12
_FLAT = 1e-12


def _segments_meet_circles(ends: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Whether the segment from the evader to ``ends[a]`` meets circle ``b``: ``(A, B)`` bools.

    The evader is inside every Apollonius disk, so the segment meets circle ``b`` exactly when its
    far end is not inside disk ``b``.
    """
    gap = np.sum(ends**2, axis=1)[:, None] - 2 * ends @ centers.T + np.sum(centers**2, axis=1)[None, :]
    return gap >= radii[None, :] ** 2


def _circle_intersections(circles: ApolloniusCircles, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Intersection points of circle ``i`` with every other circle, and the other circle of each point."""
    centers, radii = circles.centers, circles.radii
    delta = centers - centers[i]
    dist = np.linalg.norm(delta, axis=1)
    meets = (dist > 0) & (dist <= radii[i] + radii) & (dist >= np.abs(radii[i] - radii))
    meets[i] = False
    others = np.flatnonzero(meets)
    d, r = dist[others], radii[others]
    along = (d**2 + radii[i] ** 2 - r**2) / (2 * d)
    height = np.sqrt(np.maximum(radii[i] ** 2 - along**2, 0.0))
    unit = delta[others] / d[:, None]
    normal = np.stack([-unit[:, 1], unit[:, 0]], axis=1)
    base = centers[i] + along[:, None] * unit
    points = np.concatenate([base + height[:, None] * normal, base - height[:, None] * normal])
    return points, np.concatenate([others, others])


def aapc(circles: ApolloniusCircles) -> np.ndarray:
    """Apollonius circle based Active Pursuer Check, Algorithm 1 (Lemmas 3 and 4), for every pursuer.

    Pursuer ``i`` is active if an intersection point ``X`` of its circle with another circle ``j``
    can be seen from the evader: the segment ``M(e, X)`` meets no third circle (eq. 3.28). When its
    circle meets no other, it is active unless ``M(e, T_i)`` meets another circle (eq. 3.25–3.26).
    The loops over ``j``, ``X`` and ``k`` are vectorized; the loop over ``i`` is kept.
    """
    n = len(circles.radii)
    status = np.zeros(n, dtype=bool)
    everyone = np.arange(n)
    for i in range(n):
        points, partner = _circle_intersections(circles, i)
        if len(points):
            hits = _segments_meet_circles(points, circles.centers, circles.radii)
            third = (everyone[None, :] != i) & (everyone[None, :] != partner[:, None])
            status[i] = bool(np.any(~np.any(hits & third, axis=1)))
        else:
            closest = circles.closest_points[i : i + 1]
            hits = _segments_meet_circles(closest, circles.centers, circles.radii)
            status[i] = not bool(np.any(hits[0] & (everyone != i)))
    return status


def _nearest_capture(circles: ApolloniusCircles, evader: np.ndarray) -> int:
    """The pursuer whose circle comes closest to the evader (Lemmas 2 and 7): always active."""
    return int(np.argmin(np.linalg.norm(circles.closest_points - evader, axis=1)))


def active_cb_lifted(circles: ApolloniusCircles, evader: np.ndarray) -> np.ndarray:
    """Active pursuers (CB) from the lower envelope of the lifted disks, ``O(n log n)``.

    See the module docstring. Coincident circles share one dual point and one status. When the dual
    points span no volume (fewer than four circles; co-circular or collinear pursuers of one speed)
    the envelope is read from a 2-D hull instead (:func:`_flat_envelope_edges`).
    """
    centers = circles.centers - evader
    radii = circles.radii
    scale = float(np.max(np.abs(centers)) + np.max(radii))
    centers, radii = centers / scale, radii / scale
    lifted = np.column_stack([2 * centers, radii**2 - np.sum(centers**2, axis=1)])
    dual, first, inverse = np.unique(lifted, axis=0, return_index=True, return_inverse=True)
    a, b, start, step, end = _envelope_edges(dual)
    crosses = _circle_crosses_edge(centers[first[a]], radii[first[a]], start, step, end)
    status = np.zeros(len(dual), dtype=bool)
    status[a[crosses]] = True
    status[b[crosses]] = True
    status[inverse.ravel()[_nearest_capture(circles, evader)]] = True
    return status[inverse.ravel()]


def _circle_crosses_edge(
    centers: np.ndarray, radii: np.ndarray, start: np.ndarray, step: np.ndarray, end: np.ndarray
) -> np.ndarray:
    """Whether each circle meets its diagram edge ``start + s step``, ``0 <= s <= end``.

    The power ``|X - c|**2 - R**2`` is a quadratic in ``s``; the circle meets the edge when its least
    value on the edge is not positive and its largest (at an end) not negative.
    """
    offset = start - centers
    power0 = np.sum(offset**2, axis=1) - radii**2
    slope = np.sum(offset * step, axis=1)
    curvature = np.sum(step**2, axis=1)
    s = np.clip(-slope / np.maximum(curvature, np.finfo(float).tiny), 0.0, end)
    lowest = power0 + 2 * s * slope + s**2 * curvature
    power1 = np.where(np.isfinite(end), power0 + 2 * slope + curvature, np.inf)
    return (lowest <= ROUND_OFF) & (np.maximum(power0, power1) >= -ROUND_OFF)


_Edges = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _envelope_edges(dual: np.ndarray) -> _Edges:
    """Edges ``(a, b, start, step, end)`` of the farthest-power diagram of distinct dual points.

    The lower convex hull in 3-D when the points span a volume; otherwise the flat case.
    """
    if len(dual) >= 4:
        spread = np.linalg.svd(dual - dual.mean(axis=0), compute_uv=False)
        if spread[2] > _FLAT * spread[0]:
            try:
                return _farthest_power_edges(ConvexHull(dual), dual[:, :2] / 2)
            except QhullError:
                pass  # numerically flat after all: the 2-D envelope below is exact for it
    return _flat_envelope_edges(dual)


def _flat_envelope_edges(dual: np.ndarray) -> _Edges:
    """Diagram edges when the dual points ``q_i = (x_i, z_i)`` (``x_i = 2 c_i``) span no volume.

    The envelope is ``min_i x_i . X + z_i``. If the ``x_i`` span the plane, the points lie on a
    plane ``z = alpha . x + beta``, so the envelope is ``beta + min_i x_i . (X + alpha)``: its cells
    are wedges from the apex ``-alpha``, one per vertex of the 2-D hull of the ``x_i``, split by
    rays along the inward normals of the hull edges. If the ``x_i`` are collinear along ``d``, the
    envelope depends on ``d . X`` only: the lower hull of the points ``(d . x_i, z_i)`` orders its
    cells, slabs split by whole lines (two rays each). On the edge between cells ``a`` and ``b``,
    ``(x_a - x_b) . X = z_b - z_a``; each edge starts at the point of that line nearest the apex.
    """
    x, z = dual[:, :2], dual[:, 2]
    if len(dual) < 2:
        return _no_edges()
    spread, axes = np.linalg.svd(x - x.mean(axis=0), full_matrices=False)[1:]
    if spread[0] == 0:
        return _no_edges()
    if len(dual) == 2 or spread[1] <= _FLAT * spread[0]:
        t = x @ axes[0]
        order = np.lexsort((z, t))
        order = order[np.r_[True, t[order][1:] != t[order][:-1]]]
        chain = order[_lower_chain(t[order], z[order])]
        a, b = np.repeat(chain[:-1], 2), np.repeat(chain[1:], 2)
        apex = np.zeros(2)
        normal = x[a] - x[b]
        side = np.tile([1.0, -1.0], len(chain) - 1)[:, None]
        inward = side * np.column_stack([-normal[:, 1], normal[:, 0]])
    else:
        alpha = np.linalg.lstsq(np.column_stack([x, np.ones(len(x))]), z, rcond=None)[0][:2]
        apex = -alpha
        ring = _convex_hull_ccw(x)
        a, b = ring, np.roll(ring, -1)
        normal = x[a] - x[b]
        inward = np.column_stack([normal[:, 1], -normal[:, 0]])
    length2 = np.sum(normal**2, axis=1)
    start = apex + normal * ((z[b] - z[a] - normal @ apex) / length2)[:, None]
    step = inward / np.sqrt(length2)[:, None]
    return a, b, start, step, np.full(len(a), np.inf)


def _no_edges() -> _Edges:
    """One cell covers the plane: the diagram has no edge."""
    empty = np.zeros(0, dtype=int)
    return empty, empty, np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)


def _lower_chain(t: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Strict vertices of the lower convex hull of points sorted by ``t`` (Andrew's monotone chain)."""
    chain: list[int] = []
    ts, zs = t.tolist(), z.tolist()
    for k in range(len(ts)):
        while len(chain) >= 2:
            i, j = chain[-2], chain[-1]
            if (ts[j] - ts[i]) * (zs[k] - zs[i]) - (zs[j] - zs[i]) * (ts[k] - ts[i]) > 0:
                break
            chain.pop()
        chain.append(k)
    return np.array(chain, dtype=int)


def _convex_hull_ccw(points: np.ndarray) -> np.ndarray:
    """Strict vertices of the 2-D convex hull, counter-clockwise (lower chain, then upper chain)."""
    order = np.lexsort((points[:, 1], points[:, 0]))
    sorted_points = points[order]
    lower = _lower_chain(sorted_points[:, 0], sorted_points[:, 1])
    upper = _lower_chain(-sorted_points[::-1, 0], -sorted_points[::-1, 1])
    return np.concatenate([order[lower[:-1]], order[::-1][upper[:-1]]])


def _farthest_power_edges(
    hull: ConvexHull, centers: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Edges of the farthest-power diagram from the lower hull of the lifted disks.

    A lower facet (outward normal ``n`` with ``n_z < 0``) is the diagram vertex ``n_xy / n_z``; the
    hull edge between disks ``a`` and ``b`` is the diagram edge ``start + s step``, ``0 <= s <= end``:
    a segment (``end = 1``) to the neighbouring facet's vertex when that facet is lower too, else a
    ray (``end = inf``) along the bisector, away from the facet's third disk ``c``. Each edge is
    listed once per lower facet that holds it.
    """
    normals = hull.equations[:, :3]
    lower = normals[:, 2] < -ROUND_OFF
    vertex = np.zeros((len(normals), 2))
    vertex[lower] = normals[lower, :2] / normals[lower, 2:3]
    facets = np.flatnonzero(lower)
    simplices = hull.simplices[facets]
    a = simplices[:, [1, 2, 0]].ravel()
    b = simplices[:, [2, 0, 1]].ravel()
    c = simplices.ravel()
    across = hull.neighbors[facets].ravel()
    start = np.repeat(vertex[facets], 3, axis=0)
    bounded = lower[across]
    along = centers[b] - centers[a]
    ray = np.stack([-along[:, 1], along[:, 0]], axis=1)
    ray *= np.sign(np.sum(ray * (centers[c] - centers[a]), axis=1))[:, None]
    ray /= np.maximum(np.linalg.norm(ray, axis=1), np.finfo(float).tiny)[:, None]
    step = np.where(bounded[:, None], vertex[across] - start, ray)
    return a, b, start, step, np.where(bounded, 1.0, np.inf)


def _polygon_halfplanes(polygons: np.ndarray, evader: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward normals ``a`` ``(n, K, 2)`` and offsets ``h`` ``(n, K)`` of the edges (evader at origin)."""
    vertices = polygons - evader
    edges = np.roll(vertices, -1, axis=1) - vertices
    normals = np.stack([edges[..., 1], -edges[..., 0]], axis=-1)
    return normals, np.sum(normals * vertices, axis=-1)


def active_polygons_dual(polygons: np.ndarray, evader: np.ndarray) -> np.ndarray:
    """Active pursuers for convex polygons around the evader, by the dual 2-D convex hull, ``O(N log N)``."""
    normals, offsets = _polygon_halfplanes(polygons, evader)
    hull = ConvexHull((normals / offsets[..., None]).reshape(-1, 2))
    status = np.zeros(len(polygons), dtype=bool)
    status[hull.vertices // polygons.shape[1]] = True
    return status


def active_polygons_clipped(polygons: np.ndarray, evader: np.ndarray) -> np.ndarray:
    """Active pursuers for convex polygons: an edge of ``i`` clipped by all other polygons keeps a piece.

    Liang–Barsky clipping of every edge against every other polygon's half-planes, ``O(n**2 K**2)``;
    the reference for :func:`active_polygons_dual`.
    """
    normals, offsets = _polygon_halfplanes(polygons, evader)
    vertices = polygons - evader
    n = len(offsets)
    status = np.zeros(n, dtype=bool)
    for i in range(n):
        others = np.arange(n) != i
        a = normals[others].reshape(-1, 2)
        h = offsets[others].ravel()
        start = vertices[i]
        edge = np.roll(vertices[i], -1, axis=0) - start
        rate = edge @ a.T
        room = h[None, :] - start @ a.T
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = room / rate
        upper = np.min(np.where(rate > 0, bound, np.inf), axis=1, initial=1.0)
        lower = np.max(np.where(rate < 0, bound, -np.inf), axis=1, initial=0.0)
        parallel_out = np.any((rate == 0) & (room < 0), axis=1)
        status[i] = bool(np.any((upper - lower > 1e-9) & ~parallel_out))
    return status


def _as_team(
    pursuers, evader, pursuer_speeds, evader_speed
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Validated arrays; a :class:`SpecError` naming the argument otherwise."""
    p = np.asarray(pursuers, dtype=float)
    e = np.asarray(evader, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2:
        raise SpecError(f"expected an (n, 2) array of positions, got shape {p.shape}", field="pursuers")
    if len(p) == 0:
        raise SpecError("the pursuer team is empty", field="pursuers")
    if e.shape != (2,):
        raise SpecError(f"expected a position of shape (2,), got {e.shape}", field="evader")
    u = np.broadcast_to(np.asarray(pursuer_speeds, dtype=float), (len(p),)).copy()
    v = float(evader_speed)
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(e)) and np.all(np.isfinite(u)) and np.isfinite(v)):
        raise SpecError("positions and speeds must be finite", field="pursuers")
    if v <= 0 or np.any(u <= 0):
        raise SpecError("speeds must be positive", field="pursuer_speeds")
    if u.min() <= v:
        raise SpecError(
            f"speeds violate eq. 3.29: slowest pursuer {u.min():g} is not faster than the evader {v:g}",
            field="pursuer_speeds",
        )
    coincident = np.flatnonzero(np.linalg.norm(p - e, axis=1) == 0)
    if len(coincident):
        raise SpecError(f"pursuer {coincident[0]} coincides with the evader", field="pursuers")
    return p, e, u, v


def active_pursuers(
    pursuers,
    evader,
    pursuer_speeds,
    evader_speed: float,
    strategy: Strategy = "cb",
    *,
    method: Method = "fast",
    samples: int = 64,
) -> np.ndarray:
    """Which pursuers are active against the evader (Definition 3, Conjecture 1): bool array ``(n,)``.

    ``pursuers`` is ``(n, 2)``, ``evader`` ``(2,)``; ``pursuer_speeds`` a scalar or ``(n,)``. For
    ``strategy="pp"`` the refined Apollonius curves are approximated by ``samples``-gons inscribed in
    them. ``method`` picks the fast check or the reference one (AAPC for CB).
    """
    p, e, u, v = _as_team(pursuers, evader, pursuer_speeds, evader_speed)
    if strategy not in ("cb", "pp"):
        raise SpecError(f"unknown pursuit strategy {strategy!r} (use 'cb' or 'pp')", field="strategy")
    return active_set(p, e, u, v, strategy, method=method, samples=samples)


@dataclass(frozen=True)
class CaptureRegions:
    """The Apollonius regions of ``n`` pursuers around one evader: circles (CB) or polygons (PP).
    ``strategy`` is ``mixed`` for a team with both, whose regions are all polygons (the circles'
    inscribed in them, :func:`~gamespec_geometric.apollonius.circle_polygons`); ``kinds`` holds
    each pursuer's own strategy.

    ``inner[i]`` is the radius of a disk around the evader inside region ``i`` and ``outer[i]`` that
    of one holding it (closed forms, :func:`~gamespec_geometric.apollonius.cb_reach` and
    :func:`~gamespec_geometric.apollonius.refined_pp_reach`), so that regions which cannot touch the
    boundary are dropped before any circle or polygon is built.
    """

    pursuers: np.ndarray
    evader: np.ndarray
    pursuer_speeds: np.ndarray
    evader_speed: float
    strategy: Strategy | Literal["mixed"]
    samples: int
    inner: np.ndarray
    outer: np.ndarray
    kinds: np.ndarray

    def take(self, index: np.ndarray) -> CaptureRegions:
        """The regions of the pursuers ``index`` only."""
        return replace(
            self,
            pursuers=self.pursuers[index],
            pursuer_speeds=self.pursuer_speeds[index],
            inner=self.inner[index],
            outer=self.outer[index],
            kinds=self.kinds[index],
        )

    def may_touch(self) -> np.ndarray:
        """Indices of the regions that can reach the boundary of the intersection of all of them.

        The intersection lies within ``min(outer)`` of the evader; a region whose ``inner`` radius
        exceeds that contains it strictly and is redundant.
        """
        return np.flatnonzero(self.inner <= self.outer.min())

    def circles(self) -> ApolloniusCircles:
        """The Apollonius circles (CB)."""
        return apollonius_circles(self.pursuers, self.evader, self.pursuer_speeds, self.evader_speed)

    def polygons(self) -> np.ndarray:
        """The polygons inscribed in the refined Apollonius curves (PP) and, in a mixed team, in the
        Apollonius circles (CB): ``(n, samples, 2)``."""
        out = np.empty((len(self.pursuers), self.samples, 2))
        pp = self.kinds == "pp"
        if pp.any():
            out[pp] = refined_pp_polygons(
                self.pursuers[pp], self.evader, self.pursuer_speeds[pp], self.evader_speed, self.samples
            )
        if not pp.all():
            cb = self.take(np.flatnonzero(~pp)).circles()
            out[~pp] = circle_polygons(cb.centers, cb.radii, self.evader, self.samples)
        return out


def capture_regions(
    pursuers: np.ndarray,
    evader: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speed: float,
    strategy: TeamStrategy,
    samples: int = 64,
) -> CaptureRegions:
    """The CB or PP regions of the pursuers around the evader (one strategy each in a mixed team),
    with their reach bounds.

    A ``samples``-gon inscribed in a refined curve (or, in a mixed team, in a circle) has its
    vertices on the curve at polar steps of at most ``2 pi / samples`` seen from the evader, so its
    edges stay ``cos(pi / samples)`` times the curve's nearest distance away.
    """
    distance = np.linalg.norm(pursuers - evader, axis=1)
    kinds = np.broadcast_to(np.asarray(strategy), distance.shape)
    team = str(kinds[0]) if np.all(kinds == kinds[0]) else "mixed"
    inner, outer = cb_reach(distance, pursuer_speeds, evader_speed)
    pp = kinds == "pp"
    if team != "cb":
        inner = inner * np.cos(np.pi / samples)
    if pp.any():
        nearest, far = refined_pp_reach(
            distance[pp], np.broadcast_to(pursuer_speeds, distance.shape)[pp], evader_speed
        )
        inner, outer = inner.copy(), outer.copy()
        inner[pp], outer[pp] = nearest * np.cos(np.pi / samples), far
    return CaptureRegions(pursuers, evader, pursuer_speeds, evader_speed, team, samples, inner, outer, kinds)


def active_in(regions: CaptureRegions, method: Method = "fast") -> np.ndarray:
    """Active pursuers among ``regions``: the fast check after dropping far regions, or the reference."""
    if method == "reference":
        if regions.strategy == "cb":
            return aapc(regions.circles())
        return active_polygons_clipped(regions.polygons(), regions.evader)
    status = np.zeros(len(regions.inner), dtype=bool)
    keep = regions.may_touch()
    near = regions.take(keep)
    if near.strategy == "cb":
        status[keep] = active_cb_lifted(near.circles(), near.evader)
    else:
        status[keep] = active_polygons_dual(near.polygons(), near.evader)
    return status


def active_set(
    pursuers: np.ndarray,
    evader: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speed: float,
    strategy: TeamStrategy,
    *,
    method: Method = "fast",
    samples: int = 64,
) -> np.ndarray:
    """:func:`active_pursuers` on arrays already checked (positions distinct, eq. 3.29 holds)."""
    regions = capture_regions(pursuers, evader, pursuer_speeds, evader_speed, strategy, samples)
    return active_in(regions, method)
