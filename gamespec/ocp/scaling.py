"""Scale factors of the states and controls (issue 25, item 4): the NLP sees ``x / s`` for each
state and control, and each state's defect rows divided by the same ``s`` (a defect ``D X - T W f``
has the magnitude of its state), so a problem in feet and seconds reaches the solver with variables
and rows of order one, as GPOPS-II and dymos scale from the bounds and the guess.

``auto`` (the default, ``method.scale``) takes a variable's magnitude from its guess and its fixed
end values (the largest absolute value), else from its finite nonzero bounds (a control's guess is
the middle of its bounds: often 0), and rounds it to a power of ten. Two decisions, stated here
because the issue leaves them open:

- magnitudes within ``10^±2`` of one keep ``s = 1``: a factor of up to 100 hardly changes the KKT
  system's conditioning, and a well-scaled problem then reaches the solver exactly as before (every
  shipped file compared before/after: the report of issue 25);
- the guess comes before the bounds: a loose bound (``upper: 1e6`` as "large") would otherwise set
  the scale of a variable of size 10.

A variable with nothing to infer a magnitude from (no fixed end, zero guess, no finite nonzero
bound) keeps 1; when the magnitudes that are inferred and 1 span more than 10³ the scaling is said
to be uncertain: :attr:`Scaling.warning` names those variables (it goes to the Result's message and to
``metrics["scaling"]``). ``scale: none`` (per variable or ``method.scale``) turns scaling off.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from gamespec.ocp.transcription import Transcription

NEUTRAL = 2.0
"""Magnitudes within ``10^±NEUTRAL`` of one are left unscaled."""

SPAN = 1e3
"""Inferred magnitudes spanning more than this make an unscaled, uninferred variable a warning."""


@dataclass(frozen=True)
class Scaling:
    """The factors per state and per control, and a warning (empty when there is none)."""

    states: np.ndarray
    controls: np.ndarray
    warning: str = ""


def power_of_ten(magnitude: float) -> float:
    """The scale factor for a magnitude: the nearest power of ten, 1 within ``10^±NEUTRAL``."""
    if not (math.isfinite(magnitude) and magnitude > 0):
        return 1.0
    exponent = round(math.log10(magnitude))
    return 1.0 if abs(exponent) <= NEUTRAL else 10.0**exponent


def magnitude(guess: np.ndarray, ends: Iterable[float | None], bounds: Iterable[float]) -> float:
    """A variable's magnitude: the largest of ``|guess|`` and ``|fixed ends|``, else of its finite
    nonzero bounds; 0 when none of them says anything."""
    known = [abs(float(v)) for v in ends if v is not None]
    found = max([float(np.max(np.abs(guess), initial=0.0)), *known])
    if found > 0 and math.isfinite(found):
        return found
    finite = [abs(b) for b in bounds if math.isfinite(b) and b != 0]
    return max(finite, default=0.0)


def variable_scaling(tr: Transcription, params: Mapping[str, float]) -> Scaling:
    """The scale factors of ``tr``'s states and controls for these parameter values (the file's
    ``scale`` of each variable: a number, ``auto`` or ``none``; unset: ``method.scale``)."""
    start = tr.guess(params)
    default = tr.spec.method.scale
    factors: list[list[float]] = []
    uninferred: list[str] = []
    inferred: list[float] = []
    state_limits = [(lo, hi, (x0, xf)) for lo, hi, x0, xf in tr.ocp.state_bounds(params)]
    control_limits = [(lo, hi, ()) for lo, hi in tr.ocp.control_bounds(params)]
    groups = (
        (tr.spec.problem.states, start.X, state_limits),
        (tr.spec.problem.controls, start.U, control_limits),
    )
    for specs, guesses, limits in groups:
        row = []
        for (name, spec), guess, (lo, hi, ends) in zip(specs.items(), guesses, limits, strict=True):
            chosen = default if spec.scale is None else spec.scale
            if chosen == "none":
                row.append(1.0)
            elif chosen != "auto":
                row.append(abs(float(chosen)) or 1.0)
            else:
                size = magnitude(guess, ends, (lo, hi))
                row.append(power_of_ten(size))
                if size > 0:
                    inferred.append(size)
                else:
                    uninferred.append(name)
        factors.append(row)
    warning = ""
    span = [1.0, *inferred]
    if uninferred and max(span) / min(span) > SPAN:
        warning = (
            f"nothing gives {', '.join(uninferred)} a magnitude to scale by (no bound, fixed end or"
            f" nonzero guess), while the others' magnitudes reach {min(span):.3g} to {max(span):.3g}:"
            " give a guess, bounds or scale:"
        )
    return Scaling(np.array(factors[0], dtype=float), np.array(factors[1], dtype=float), warning)
