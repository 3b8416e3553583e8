"""Named scratch arrays reused from one call to the next, so the level-set step allocates nothing.

A stencil sweep along one axis of a 2-D block works on arrays whose stencil axis may be the slow
(rows) or the fast (columns) one; :meth:`Scratch.take` hands out an array in the same memory layout
as the block, so NumPy's ufunc loops run over contiguous memory for every operand.
"""

from __future__ import annotations

import numpy as np

MAX_VIEWS = 4096
"""Views kept for reuse before the cache is emptied (a moving band asks for many shapes)."""


class Scratch:
    """Float64 buffers by name, each ``capacity`` values long, and the views handed out so far."""

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self._buffers: dict[str, np.ndarray] = {}
        self._views: dict[tuple[str, int, int, bool], np.ndarray] = {}
        self._sets: dict[tuple[str, int, int, bool], dict[str, np.ndarray]] = {}

    def take(self, name: str, length: int, width: int, transposed: bool = False) -> np.ndarray:
        """A (length, width) array: C-ordered, or the transpose of a C-ordered (width, length) one.
        Its contents are whatever the last user of ``name`` left."""
        key = (name, length, width, transposed)
        view = self._views.get(key)
        if view is None:
            if len(self._views) >= MAX_VIEWS:
                self._views.clear()
            size = length * width
            if size > self.capacity:
                raise ValueError(f"scratch {name!r}: {size} values asked for, capacity {self.capacity}")
            buffer = self._buffers.setdefault(name, np.empty(self.capacity))
            flat = buffer[:size]
            view = self._views[key] = (
                flat.reshape(width, length).T if transposed else flat.reshape(length, width)
            )
        return view

    def arrays(
        self, tag: str, extra_rows: dict[str, int], length: int, width: int, transposed: bool = False
    ) -> dict[str, np.ndarray]:
        """One array per name of ``extra_rows``, of ``length + extra`` rows (as :meth:`take`), found
        by one look-up once this set of shapes has been asked for."""
        key = (tag, length, width, transposed)
        found = self._sets.get(key)
        if found is None:
            if len(self._sets) >= MAX_VIEWS:
                self._sets.clear()
            found = self._sets[key] = {
                name: self.take(f"{tag}{name}", length + extra, width, transposed)
                for name, extra in extra_rows.items()
            }
        return found
