"""The rectangle of nodes a local level-set update keeps exact (the "tube" of a narrow-band method,
Peng, Merriman, Osher, Zhao & Kang 1999, as one box per agent).

Each level of φ moves with the characteristics of eq. 5.22 and never takes values from a higher
level (a viscosity solution of a control problem: φ(x, t) is the least initial value over the points
that reach x in time t), so the levels read by the capture search depend only on the nodes at or below
them. The box holds every node below the band level, grown by a margin of nodes (a front moves less
than one node per CFL-limited step); it is solved as a grid of its own, with ghost nodes
extrapolated linearly from it as at the grid's edges, and the nodes beyond keep values above the
band. What remains is the numerical coupling across levels (the stencils, Lax–Friedrichs
dissipation), which decays with the distance in cells from the box's edge to the levels read.
"""

from __future__ import annotations

import numpy as np

Window = tuple[slice, slice]


def band_window(values: np.ndarray, level: float, margin: int) -> Window | None:
    """The smallest rectangle of nodes of ``values`` (nx, ny) holding every node with a value
    below ``level``, grown by ``margin`` nodes on each side and clipped to the grid; None when no
    node is that low."""
    below = values < level
    rows = np.flatnonzero(below.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(below.any(axis=0))
    nx, ny = values.shape
    return (
        slice(max(int(rows[0]) - margin, 0), min(int(rows[-1]) + margin + 1, nx)),
        slice(max(int(cols[0]) - margin, 0), min(int(cols[-1]) + margin + 1, ny)),
    )
