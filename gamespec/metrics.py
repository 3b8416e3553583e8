"""Typed metrics per kind (DESIGN.md, stage 4): what a Result's ``metrics`` hold, as pydantic models.

Each kind names its model in its :class:`~gamespec.registry.Kind` (``metrics``; the feature
folder that writes the metrics defines it; a kind without one gets :class:`Metrics`). A model types the
keys that plotters and summaries read, allows the others (``extra="allow"``: keys not typed yet
pass unchanged), and its :meth:`Metrics.check` checks the arrays those readers index by the
metrics (names, dimensions, lengths). :func:`validated` applies the kind's model to a Result, so a
Result read from a folder (untrusted input, README "Security") and every Result a plotter draws
has metrics of its kind: a wrong type or shape is one line naming ``metrics.<field>``, never a
traceback in a plotter. The keys every kind may carry (issue 23: checks' verdicts and tolerances,
a game's solution concept, payoffs and values) are typed here, optional.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from gamespec import registry
from gamespec.errors import BackendError, SpecError

if TYPE_CHECKING:
    from gamespec.result import Result

Finite = Annotated[float, Field(allow_inf_nan=False)]
"""A finite number (JSON may spell NaN and Infinity; a coordinate or a radius may not be one)."""


class Metrics(BaseModel):
    """Metrics every kind may carry (all optional); a kind's model adds its own."""

    model_config = ConfigDict(extra="allow")

    solution_concept: str | None = Field(None, description="A game's solution concept (saddle, nash, ...).")
    payoffs: dict[str, float | None] | None = Field(None, description="Each player's payoff.")
    saddle_gap: float | None = Field(None, description="Saddle (or Nash) gap at the returned point.")
    lower_value: float | None = Field(None, description="A game's lower value, where computable.")
    upper_value: float | None = Field(None, description="A game's upper value, where computable.")
    checks_passed: dict[str, bool] | None = Field(None, description="Each check's verdict.")
    check_tolerances: dict[str, float | None] | None = Field(None, description="Each check's tolerance.")
    grid_error_estimate: float | dict[str, Any] | list[Any] | None = Field(
        None, description="An estimate of the discretization error."
    )

    def check(self, result: Result) -> None:
        """ValueError when an array or trajectory the kind's readers use with these metrics is
        missing or misshapen (nothing to check by default)."""


def metrics_model(kind: str) -> type[Metrics]:
    """The metrics model of ``kind`` (:class:`Metrics` when the kind names none or is not installed)."""
    model: type[Metrics] = registry.kind_part(kind, "metrics") or Metrics
    return model


def validated(result: Result, source: str = "<result>") -> Result:
    """``result`` with its metrics validated by its kind's model (types normalized, keys kept as
    given); a SpecError naming ``source`` and the first wrong field otherwise."""
    try:
        model = metrics_model(result.kind)
        typed = model.model_validate(result.metrics)
        typed.check(result)
    except ValidationError as err:
        first = err.errors()[0]
        where = ".".join(str(p) for p in ("metrics", *first["loc"]))
        message = " ".join(first["msg"].split())
        raise SpecError(f"not a readable Result: {where}: {message}", source=source) from None
    except (ValueError, BackendError) as err:
        message = " ".join(str(err).split())
        raise SpecError(f"not a readable Result: {message}", source=source) from None
    return result.model_copy(update={"metrics": typed.model_dump(exclude_unset=True)})


def array(
    result: Result, name: str, ndim: int, *, rows: int | None = None, last: int | None = None
) -> np.ndarray:
    """``result.arrays[name]``, numeric with ``ndim`` dimensions (``rows`` in the first, ``last`` in
    the last, where given); ValueError naming it otherwise."""
    return shaped(result.arrays.get(name), f"arrays.{name}", ndim, rows=rows, last=last)


def state(result: Result, name: str, ndim: int = 1, *, last: int | None = None) -> np.ndarray:
    """``result.states[name]`` as :func:`array` checks it, one row per point of ``result.time``
    (which must be there: a trajectory without its time grid is refused)."""
    if result.time is None:
        raise ValueError(f"states.{name} has no time grid (time is missing)")
    return shaped(result.states.get(name), f"states.{name}", ndim, rows=len(result.time), last=last)


def shaped(
    values: np.ndarray | None, what: str, ndim: int, *, rows: int | None = None, last: int | None = None
) -> np.ndarray:
    """``values`` checked as :func:`array` says; ValueError naming ``what`` otherwise."""
    if values is None:
        raise ValueError(f"{what} is missing")
    if values.dtype.kind not in "biuf":
        raise ValueError(f"{what} is not numeric")
    if values.ndim != ndim:
        raise ValueError(f"{what} has {values.ndim} dimensions, not {ndim}")
    if values.size == 0:
        raise ValueError(f"{what} is empty")
    if rows is not None and values.shape[0] != rows:
        raise ValueError(f"{what} has {values.shape[0]} rows for {rows} points")
    if last is not None and values.shape[-1] != last:
        raise ValueError(f"{what} has {values.shape[-1]} columns, not {last}")
    return values


def known(names: Iterable[str], among: Iterable[str], what: str) -> None:
    """ValueError unless every one of ``names`` is in ``among`` (the names ``what`` may use)."""
    missing = sorted(set(names) - set(among))
    if missing:
        raise ValueError(f"{what} names {', '.join(map(repr, missing))}, which the Result lacks")
