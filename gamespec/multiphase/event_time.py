"""``free_event``: constraints at a free time inside the horizon of an ``optimal_control`` problem
(issue 25, item 2), a requested rewrite.

A file asks for it under ``transforms:``::

    transforms:
      - free_event: {bounds: [1, 3], guess: 2, constraints: ["x == a", "t <= 2.5"]}

meaning: some time ``t_e`` in ``bounds`` exists at which every constraint holds, each a relation
over the states (their values at ``t_e``), the parameters, the design variables and ``t`` (the
event time itself). The optimizer chooses ``t_e``. The rewrite splits the horizon there, as
GPOPS-II and dymos do with phases: the problem becomes a ``multiphase_optimal_control`` problem of
two phases, ``before`` (from ``t_0``, its duration free in ``bounds - t_0``) and ``after`` (the
rest, its duration free with ``t_f`` held at the file's final time), the states continuous across
``t_e`` and the constraints at the end of ``before``; that problem is lowered to one
``optimal_control`` problem by :func:`gamespec.multiphase.lowering.lower` (each phase its own copy
of the states and controls, the split a design variable): the transform
:class:`gamespec.multiphase.transform.FreeEventTime`. The Result is mapped back by the
``phases`` transform's inverse (:meth:`gamespec.multiphase.transform.PhasesToOcp.invert`: the
trajectories end to end on the real time, ``metrics.phases``, checks per phase) and carries the
event time as ``metrics.event_time``.

The file's final time must be fixed (a number or an expression of the parameters, held at its
value: ``t_f == T`` over the phases' durations) and the initial time a number; ``at:``,
``measurements:``, ``x(t=...)`` points, uncertain parameters and inputs are refused with it (a
fixed-time interior point of the whole horizon would have to be placed in one phase). The guess,
an expression of the whole horizon's normalized time ``tau``, is carried into each phase's own
``tau`` through the event time's guess. Every runtime parameter re-applies the rewrite (nothing
is mapped without it: always correct).
"""

from __future__ import annotations

from typing import Any

import sympy as sp
from pydantic import Field, ValidationError, model_validator

from gamespec.errors import ExpressionError, SpecError
from gamespec.multiphase.spec import MultiPhaseSpec
from gamespec.specs.base import Number, StrictModel
from gamespec.specs.ocp import NORMALIZED_TIME, OptimalControlSpec
from gamespec.symbolic.language import parse, parse_relation, symbol
from gamespec.symbolic.printer import relation_texts, to_text

FIELD = "transforms.free_event"
PHASES = ("before", "after")
"""The names of the two phases the split makes (in ``metrics.phases``)."""


class FreeEventOptions(StrictModel):
    """Constraints at one free time ``t_e`` inside the horizon (see the module doc)."""

    bounds: tuple[Number, Number] = Field(
        description="[lower, upper] of the event time, strictly inside the horizon."
    )
    guess: Number | None = Field(None, description="The event time's starting value (the bounds' middle).")
    constraints: list[str] = Field(
        min_length=1,
        description="Relations over the states at the event time, t (the event time), the parameters "
        "and the design variables.",
    )

    @model_validator(mode="after")
    def _ordered(self) -> FreeEventOptions:
        lo, hi = self.bounds
        if not lo < hi:
            raise ValueError(f"bounds must be increasing, got [{lo}, {hi}]")
        if self.guess is not None and not lo <= self.guess <= hi:
            raise ValueError(f"guess {self.guess} lies outside the bounds [{lo}, {hi}]")
        return self

    @property
    def start(self) -> float:
        """The event time's starting value."""
        return float(self.guess) if self.guess is not None else 0.5 * (self.bounds[0] + self.bounds[1])


def _refuse_other_points(spec: OptimalControlSpec) -> None:
    problem = spec.problem
    for present, name in (
        (problem.at, "at"),
        (problem.measurements is not None, "measurements"),
        (problem.inline_points(), "boundary_constraints"),
        (problem.uncertain, "uncertain"),
        (problem.inputs, "inputs"),
    ):
        if present:
            raise SpecError(
                f"free_event splits the horizon in two phases and cannot place problem.{name} in one",
                field=FIELD,
                source=spec.source,
            )
    if problem.time.free or problem.time.initial == "free":
        raise SpecError("free_event needs a fixed initial and final time", field=FIELD, source=spec.source)


def _event_constraints(spec: OptimalControlSpec, options: FreeEventOptions) -> list[str]:
    """The constraints over the first phase's end: each state ``x`` as ``x_f``, ``t`` as ``t_f``."""
    problem = spec.problem
    names = [*problem.parameters, *problem.design]
    symbols: dict[str, Any] = {n: symbol(n) for n in names}
    symbols |= {x: symbol(f"{x}_f") for x in problem.states} | {"t": symbol("t_f")}
    texts = []
    for i, text in enumerate(options.constraints):
        try:
            texts += relation_texts(parse_relation(text, symbols | problem.functions))
        except ExpressionError as err:
            raise SpecError(str(err), field=f"{FIELD}.constraints.{i}", source=spec.source) from None
    return texts


def _phase_guess(raw: Any, spec: OptimalControlSpec, start: float, span: float) -> Any:
    """A guess over the horizon's ``tau`` as one over a phase's own ``tau`` (the phase starting at
    ``start`` and lasting ``span``, both fractions of the horizon)."""
    if not isinstance(raw, str) or raw == "linear":
        return raw
    tau = symbol(NORMALIZED_TIME)
    symbols = {n: symbol(n) for n in spec.problem.parameters} | {NORMALIZED_TIME: tau}
    return to_text(parse(raw, symbols).subs(tau, start + span * tau))


def split_at_event(spec: OptimalControlSpec, options: FreeEventOptions) -> MultiPhaseSpec:
    """``spec`` as two phases meeting at the free event time (see the module doc)."""
    _refuse_other_points(spec)
    problem = spec.problem
    t0 = float(problem.time.initial)
    t_final = problem.evaluate(problem.parameter_values()).t_final
    if t_final is None:
        raise SpecError("free_event needs a fixed final time", field=FIELD, source=spec.source)
    lo, hi = (float(b) for b in options.bounds)
    if not t0 < lo or not hi < t_final:
        raise SpecError(
            f"the event's bounds [{lo}, {hi}] must lie strictly inside the horizon [{t0}, {t_final}]",
            field=f"{FIELD}.bounds",
            source=spec.source,
        )
    if "linear" in (*spec.guess.states.values(), *spec.guess.controls.values()):
        raise SpecError("free_event takes no `linear` guess", field="guess", source=spec.source)
    split = (options.start - t0) / (t_final - t0)
    phases = []
    for name, (begin, span) in zip(PHASES, ((0.0, split), (split, 1.0 - split)), strict=True):
        phases.append(
            {
                "name": name,
                "guess": {
                    group: {n: _phase_guess(raw, spec, begin, span) for n, raw in given.items()}
                    for group, given in (("states", spec.guess.states), ("controls", spec.guess.controls))
                },
            }
        )
    phases[0] |= {
        "duration": {"value": "free", "bounds": [lo - t0, hi - t0], "guess": options.start - t0},
        "boundary_constraints": _event_constraints(spec, options),
    }
    phases[1]["duration"] = {
        "value": "free",
        "bounds": [t_final - hi, t_final - lo],
        "guess": t_final - options.start,
    }
    data = spec.model_dump(include={"name", "description", "solver", "method", "plot"})
    shared = problem.model_dump(
        include={
            "parameters",
            "definitions",
            "tables",
            "states",
            "controls",
            "design",
            "dynamics",
            "objective",
            "path_constraints",
            "boundary_constraints",
            "integral_constraints",
        }
    )
    held = sp.Eq(symbol("t_f") - sp.Float(t_final), 0, evaluate=False)
    shared["boundary_constraints"] = [*shared["boundary_constraints"], to_text(held)]
    data |= {
        "kind": "multiphase_optimal_control",
        "problem": shared | {"time": {"initial": t0}, "phases": phases},
    }
    try:
        phased = MultiPhaseSpec.model_validate(data)
    except (ValidationError, SpecError) as err:
        reason = err.reason if isinstance(err, SpecError) else str(err.errors()[0]["msg"])
        raise SpecError(
            f"the split at the event is invalid: {reason}", field=FIELD, source=spec.source
        ) from None
    phased.with_source(spec.source, spec.file_hash)
    return phased
