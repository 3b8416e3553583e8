"""One Result's trajectories as table rows (``gamespec results RESULT_DIR --csv F``).

A row per time point: ``t``, then every state, costate (``lambda_<state>``) and control. States
live on ``Result.time``, costates on ``arrays["costate_time"]`` where the transcription estimates
them elsewhere (the collocation points), controls on ``Result.control_time`` where it holds them
elsewhere (Radau's collocation points, a receding horizon's steps). The rows are the union of
both grids (a time a grid repeats, such as a phase boundary, stays two rows) and a value is written
only where its own grid has it: a control is exported as the
transcription holds it, never interpolated onto the state grid.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gamespec.result import Result


def _series(result: Result) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Every exported series as (column, its time grid, its values)."""
    if result.time is None:
        return []
    control_time = result.control_time if result.control_time is not None else result.time
    costate_time = result.arrays.get("costate_time", result.time)
    found = [(name, result.time, values) for name, values in result.states.items()]
    found += [(name, costate_time, values) for name, values in result.costates.items()]
    found += [(name, control_time, values) for name, values in result.controls.items()]
    return [
        (name, grid, np.ravel(values)) for name, grid, values in found if np.size(values) == np.size(grid)
    ]


def _keys(grid: np.ndarray) -> list[tuple[float, int]]:
    """Each point of ``grid`` as (time, how many earlier points share it): a time a grid repeats (a
    phase boundary) stays two rows."""
    seen: dict[float, int] = {}
    keys = []
    for t in map(float, grid):
        keys.append((t, seen.get(t, 0)))
        seen[t] = seen.get(t, 0) + 1
    return keys


def trajectory_rows(result: Result) -> list[dict[str, Any]]:
    """The rows of ``result``'s trajectories (see the module doc); empty when it has no time grid."""
    rows: dict[tuple[float, int], dict[str, Any]] = {}
    for name, grid, values in _series(result):
        for key, value in zip(_keys(grid), values, strict=True):
            rows.setdefault(key, {"t": key[0]})[name] = float(value)
    return [rows[key] for key in sorted(rows)]
