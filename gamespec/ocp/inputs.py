"""Grid inputs as a caller gives them: one value per evaluation point of the transcription, or
``(times, values)`` samples (another player's Result, say) resampled onto those points.

An input is tabulated where the controls are: at the evaluation points of
:class:`~gamespec.ocp.collocation.Grid` (``Grid.eval_tau``; the Result's ``control_time``). The
transcription uses each value where it uses the controls, so between the points an input is what a
control is: the interval's interpolating polynomial through its collocation points (Radau), or linear
between nodes (trapezoidal).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gamespec.errors import SpecError

InputValue = np.ndarray | Sequence[float] | tuple[np.ndarray | Sequence[float], np.ndarray | Sequence[float]]
"""Values at the evaluation points, or a ``(times, values)`` pair of samples."""


@dataclass(frozen=True)
class InputGrid:
    """The points where grid inputs are tabulated: normalized time ``tau`` in [0, 1] and, for a fixed
    horizon, the times ``t0 + tau * (t_f - t0)`` (None when the final time is free)."""

    tau: np.ndarray
    time: np.ndarray | None

    def __len__(self) -> int:
        return len(self.tau)


def is_samples(raw: InputValue) -> bool:
    """Whether ``raw`` is a ``(times, values)`` pair rather than values on the grid."""
    return isinstance(raw, tuple) and len(raw) == 2 and all(np.ndim(part) == 1 for part in raw)


def on_grid(name: str, raw: InputValue, grid: InputGrid, source: str = "") -> np.ndarray:
    """The values of input ``name`` at the grid's points; a SpecError naming it when they are the
    wrong length, not finite, or samples that cannot be placed on the grid."""
    field = f"inputs.{name}"
    if is_samples(raw):
        if grid.time is None:
            raise SpecError(
                "the final time is free, so samples in time cannot be placed on the grid: give one "
                f"value per evaluation point (normalized times in input_grid().tau, {len(grid)} of them)",
                field=field,
                source=source,
            )
        values = resample(*raw, grid.time, field, source)
    else:
        values = np.asarray(raw, dtype=float)
        if values.shape != (len(grid),):
            raise SpecError(
                f"needs one value per evaluation point ({len(grid)}, see input_grid()), got shape "
                f"{values.shape}",
                field=field,
                source=source,
            )
    if not np.all(np.isfinite(values)):
        raise SpecError("values must be finite", field=field, source=source)
    return values


def resample(
    times: Sequence[float] | np.ndarray,
    values: Sequence[float] | np.ndarray,
    grid_times: np.ndarray,
    field: str,
    source: str = "",
) -> np.ndarray:
    """Samples ``(times, values)`` linearly interpolated at ``grid_times``. Before the first and
    after the last sample the end value is held, by at most the samples' largest spacing (a Radau
    Result has no control at its initial time); a grid reaching further is an error."""
    t = np.asarray(times, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.shape != v.shape or t.size < 2:
        raise SpecError(
            f"samples need times and values of one length (at least 2), got {t.shape} and {v.shape}",
            field=field,
            source=source,
        )
    if not (np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)):
        raise SpecError("sample times must be finite and increasing", field=field, source=source)
    reach = float(np.max(np.diff(t)))
    if grid_times[0] < t[0] - reach or grid_times[-1] > t[-1] + reach:
        raise SpecError(
            f"samples cover [{t[0]:g}, {t[-1]:g}] but the grid needs [{grid_times[0]:g}, {grid_times[-1]:g}]",
            field=field,
            source=source,
        )
    return np.interp(grid_times, t, v)
