"""Active pursuers (CB) against many evaders at once (thesis §3.3.1, Lemmas 2–4), batched over evaders.

An allocation round (§3.4) asks for the active set of every evader among its candidate pursuers.
One evader at a time, :func:`~gamespec_geometric.active.active_cb_lifted` spends most of its time in
per-call overhead, for a handful of candidates each. Here every evader is handled in the same array
operations:

1. the reach bound of :meth:`~gamespec_geometric.active.CaptureRegions.may_touch` drops the disks
   that cannot reach the boundary;
2. a disk that strictly holds another candidate's disk holds the whole intersection, so its circle
   cannot touch the boundary: dropped (exact, ``O(K**2)`` per evader);
3. on the ``K`` survivors, pursuer ``i`` is active when a point where its circle meets circle ``j``
   lies in every other disk (a vertex of the Apollonius boundary, eq. 3.28 with Lemmas 3–4), or when
   its circle is that of the soonest capture (Lemma 2), ``O(K**3)`` per evader.

Step 3 is the vertex test of :func:`~gamespec_geometric.active.active_cb_lifted` (a pair is active
when their common circle crosses the diagram edge between their cells, i.e. at a boundary vertex),
with the same tolerance on the power of a point and the same rule for coincident circles (they
share one status); evaders left with more than :data:`MAX_BATCHED` survivors go to it one by one.
"""

from __future__ import annotations

import numpy as np

from gamespec.pursuit.apollonius import apollonius_circles
from gamespec_geometric.active import ROUND_OFF, active_cb_lifted
from gamespec_geometric.apollonius import cb_reach

MAX_BATCHED = 24
"""Survivors per evader above which the ``O(K**3)`` vertex test hands over to the lifted hull."""
_STRICT = 1e-9


def _compact(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Column indices of the ``True`` entries of each row, left-aligned and padded: ``(index, valid)``."""
    width = max(int(mask.sum(axis=1).max(initial=0)), 1)
    index = np.argsort(~mask, axis=1, kind="stable")[:, :width]
    return index, np.take_along_axis(mask, index, axis=1)


def active_cb_many(
    pursuers: np.ndarray,
    evaders: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speeds: np.ndarray,
    candidates: np.ndarray,
) -> np.ndarray:
    """Active set ``(m, n)`` of each evader among its candidate pursuers ``candidates`` ``(m, n)``.

    Equal, row by row, to :func:`~gamespec_geometric.active.active_in` with ``method="fast"`` on
    the CB regions of the candidates (module docstring).
    """
    status = np.zeros(candidates.shape, dtype=bool)
    rows = np.flatnonzero(candidates.any(axis=1))
    if not len(rows):
        return status
    index, valid = _compact(candidates[rows])
    distance = np.linalg.norm(pursuers[index] - evaders[rows, None, :], axis=2)
    inner, outer = cb_reach(distance, pursuer_speeds[index], evader_speeds[rows, None])
    keep, valid = _compact(valid & (inner <= np.min(np.where(valid, outer, np.inf), axis=1, keepdims=True)))
    index, inner = np.take_along_axis(index, keep, axis=1), np.take_along_axis(inner, keep, axis=1)
    offset = pursuers[index] - evaders[rows, None, :]
    distance = np.take_along_axis(distance, keep, axis=1)
    ratio = evader_speeds[rows, None] / pursuer_speeds[index]
    centers = -(ratio**2 / (1 - ratio**2))[..., None] * offset
    radii = ratio * distance / (1 - ratio**2)
    scale = np.max(np.where(valid, np.max(np.abs(centers), axis=2), 0.0), axis=1) + np.max(
        np.where(valid, radii, 0.0), axis=1
    )
    centers, radii = centers / scale[:, None, None], radii / scale[:, None]

    x, y = centers[..., 0], centers[..., 1]
    gap = np.hypot(x[:, :, None] - x[:, None, :], y[:, :, None] - y[:, None, :])
    holds = gap + radii[:, None, :] < radii[:, :, None] - _STRICT
    valid &= ~np.any(holds & valid[:, None, :], axis=2)

    keep, valid = _compact(valid)
    index, inner = np.take_along_axis(index, keep, axis=1), np.take_along_axis(inner, keep, axis=1)
    centers = np.take_along_axis(centers, keep[..., None], axis=1)
    radii = np.take_along_axis(radii, keep, axis=1)
    few = valid.sum(axis=1) <= MAX_BATCHED
    width = min(valid.shape[1], MAX_BATCHED)
    small = _soonest_or_vertex(
        centers[few, :width], radii[few, :width], inner[few, :width], valid[few, :width]
    )
    status[rows[few, None], index[few, :width]] = small
    for r in np.flatnonzero(~few):
        members = index[r, valid[r]]
        evader = evaders[rows[r]]
        circles = apollonius_circles(
            pursuers[members], evader, pursuer_speeds[members], evader_speeds[rows[r]]
        )
        status[rows[r], members] = active_cb_lifted(circles, evader)
    return status


def _soonest_or_vertex(
    centers: np.ndarray, radii: np.ndarray, inner: np.ndarray, valid: np.ndarray
) -> np.ndarray:
    """Step 3 of the module docstring on padded rows: ``(r, K)`` circles, evader at the origin."""
    first, second = np.triu_indices(centers.shape[1], 1)
    x, y = centers[..., 0], centers[..., 1]
    dx, dy = x[:, second] - x[:, first], y[:, second] - y[:, first]
    d = np.hypot(dx, dy)
    ra, rb = radii[:, first], radii[:, second]
    meets = valid[:, first] & valid[:, second] & (d > 0) & (d <= ra + rb) & (d >= np.abs(ra - rb))
    safe = np.where(meets, d, 1.0)
    along = (safe**2 + ra**2 - rb**2) / (2 * safe**2)
    height = np.sqrt(np.maximum(ra**2 / safe**2 - along**2, 0.0))
    base_x, base_y = x[:, first] + along * dx, y[:, first] + along * dy
    sign = np.array([1.0, -1.0])
    point_x = base_x[..., None] - sign * height[..., None] * dy[..., None]
    point_y = base_y[..., None] + sign * height[..., None] * dx[..., None]
    power = (
        (point_x[..., None] - x[:, None, None, :]) ** 2
        + (point_y[..., None] - y[:, None, None, :]) ** 2
        - radii[:, None, None, :] ** 2
    )
    others = np.ones((len(first), centers.shape[1]), dtype=bool)
    others[np.arange(len(first)), first] = False
    others[np.arange(len(first)), second] = False
    outside = (power > ROUND_OFF) & (valid[:, None, :] & others[None, :, :])[:, :, None, :]
    vertex = meets & np.any(~np.any(outside, axis=3), axis=2)
    pairs = np.zeros((len(centers), centers.shape[1], centers.shape[1]), dtype=bool)
    pairs[:, first, second] = vertex
    status = pairs.any(axis=2) | pairs.any(axis=1)
    pick = np.arange(len(centers))
    nearest = np.argmin(np.where(valid, inner, np.inf), axis=1)
    same = (radii == radii[pick, nearest][:, None]) & np.all(
        centers == centers[pick, nearest][:, None], axis=2
    )
    return (status | same) & valid
