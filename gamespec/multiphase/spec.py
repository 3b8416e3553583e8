"""The ``multiphase_optimal_control`` kind: a sequence of phases, each with its own dynamics,
duration (fixed or free), running cost, path and boundary constraints, controls and guess, linked
by continuity of the states or by jump conditions, solved as one NLP.

The states are declared once (``problem.states``: bounds, the value at the start of the first phase
and at the end of the last); a phase may narrow a state's bounds and fix its value at the phase's
start or end (``phases[k].states``), choose its controls (``phases[k].controls``, all by default),
replace or add to the shared dynamics and definitions, and give the start of its states as
expressions of the previous phase's end (``jump``: ``{m: m_f - m_stage}``, a staged rocket's mass
drop; a state not named there is continuous). The Mayer term and ``boundary_constraints`` use
``<state>_0`` (start of the first phase), ``<state>_f`` (end of the last), ``<control>_0``,
``<control>_f`` and ``t_f``, and link any two phases by name: ``phases.<phase>.<state>_0``,
``phases.<phase>.<state>_f`` (and controls, ``phases.<phase>.t_0``, ``phases.<phase>.t_f``: that
phase's start and end; ``phases.coast.h_f == phases.ascent.h_f + 10``); a phase's own
``boundary_constraints`` use the same names at its own start and end, and ``t_0``, ``t_f`` for its
start and end times. A definition may be given in some phases only (each phase's own).

The kind is lowered to one ``optimal_control`` problem by the ``phases`` transform
(:mod:`gamespec.multiphase.lowering` says how); loading a file lowers it once, so every
expression is checked at load with the field that holds it.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import (
    Field,
    SerializerFunctionWrapHandler,
    ValidationInfo,
    field_validator,
    model_serializer,
    model_validator,
)

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_INTERVALS
from gamespec.multiphase.lowering import SEPARATOR, lower
from gamespec.registry import Kind
from gamespec.specs.base import Number, SpecBase, StrictModel, Value
from gamespec.specs.events import MeasurementsSpec
from gamespec.specs.ocp import (
    NORMALIZED_TIME,
    ControlSpec,
    DesignSpec,
    FreeOrFixed,
    IntegralConstraintSpec,
    MethodSpec,
    ObjectiveSpec,
    OcpFamily,
    StateSpec,
)
from gamespec.specs.plot import PlotHint
from gamespec.specs.tables import TableSpec
from gamespec.specs.vectors import lower_problem
from gamespec.symbolic.language import RESERVED


class DurationSpec(FreeOrFixed):
    """A phase's duration: a value (a number or an expression of the parameters), or ``free``
    within ``bounds`` (numbers or expressions of the parameters) from ``guess`` (the middle of the
    bounds when omitted). A phase may give a number or an expression instead of the mapping."""

    value: Value | Literal["free"] = Field(
        "free",
        description="The duration: a number, an expression of the parameters, or `free` (within `bounds`).",
    )

    fixed_field: ClassVar[str] = "value"
    what: ClassVar[str] = "duration"


class PhaseGuessSpec(StrictModel):
    """A phase's starting point: per state or control a number or an expression of the phase's
    normalized time ``tau`` (0 at its start, 1 at its end) and the parameters."""

    states: dict[str, Value] = Field(
        default_factory=dict,
        description="Per state, a number or an expression of the phase's tau and the parameters.",
    )
    controls: dict[str, Value] = Field(
        default_factory=dict,
        description="Per control, a number or an expression of the phase's tau and the parameters.",
    )


class PhaseSpec(StrictModel):
    """One phase (see the module doc)."""

    name: str = Field(description="The phase's name (figures, summaries, `<phase>.<state>_f`).")
    duration: DurationSpec = Field(description="The phase's duration: fixed, or free within bounds.")
    dynamics: dict[str, Value] = Field(
        default_factory=dict, description="Per state; replaces problem.dynamics for the states it names."
    )
    definitions: dict[str, Value] = Field(
        default_factory=dict, description="Named expressions of this phase; replace shared ones by name."
    )
    states: dict[str, StateSpec] = Field(
        default_factory=dict,
        description="Per state: bounds in this phase, and its value at the phase's start and end.",
    )
    controls: dict[str, ControlSpec] | None = Field(
        None, description="The controls of this phase (all shared ones when omitted), bounds narrowed."
    )
    lagrange: Value | None = Field(None, description="The running cost here (problem.objective.lagrange).")
    path_constraints: list[str] = Field(
        default_factory=list, description="Relations that hold along the phase."
    )
    boundary_constraints: list[str] = Field(
        default_factory=list, description="Over this phase's <state>_0, <state>_f, t_0, t_f."
    )
    jump: dict[str, Value] = Field(
        default_factory=dict,
        description="Per state, its value at this phase's start over the previous phase's end "
        "(<state>_f, <control>_f, t_f); states not named are continuous.",
    )
    guess: PhaseGuessSpec = Field(default_factory=PhaseGuessSpec, description="The phase's starting point.")
    intervals: int | None = Field(
        None, ge=1, le=MAX_INTERVALS, description="Collocation intervals of this phase (method.intervals)."
    )
    measurements: MeasurementsSpec | None = Field(
        None,
        description="Data measured in this phase: times on the horizon's clock inside the phase (every "
        "duration up to and with this phase a number), values of its states or expressions of them, the "
        "parameters and design; adds sum(weight*(model - measured)**2) to the objective.",
    )

    @model_serializer(mode="wrap")
    def _without_unused_measurements(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The phase as data, ``measurements`` left out when absent (content hashes as before it
        existed)."""
        data: dict[str, Any] = handler(self)
        return {k: v for k, v in data.items() if k != "measurements" or v is not None}

    @field_validator("duration", mode="before")
    @classmethod
    def _value_alone(cls, value: object) -> object:
        if isinstance(value, int | float | str):
            return {"value": value}
        return value


class StartSpec(StrictModel):
    """When the first phase starts."""

    initial: Number = Field(0.0, description="The initial time.")


class MultiPhaseProblem(StrictModel):
    """The mathematics of a multi-phase optimal-control problem (see the module doc)."""

    parameters: dict[str, Value] = Field(
        default_factory=dict,
        description="Numbers, or expressions of earlier parameters (derived, recomputed from them).",
    )
    definitions: dict[str, Value] = Field(
        default_factory=dict, description="Named expressions shared by every phase."
    )
    tables: dict[str, TableSpec] = Field(
        default_factory=dict,
        description="Gridded data shared by every phase, each a function of the expressions by its name.",
    )
    states: dict[str, StateSpec] = Field(
        description="The states, with their bounds and initial and final values."
    )
    controls: dict[str, ControlSpec] = Field(
        default_factory=dict, description="The controls of any phase, with their bounds."
    )
    design: dict[str, DesignSpec] = Field(
        default_factory=dict, description="Free static parameters optimized with the trajectory."
    )
    dynamics: dict[str, Value] = Field(
        default_factory=dict, description="Shared dynamics, per state; a phase replaces them by name."
    )
    objective: ObjectiveSpec = Field(
        default_factory=ObjectiveSpec,
        description="The objective: Mayer term plus Lagrange integrand over all phases.",
    )
    time: StartSpec = Field(default_factory=StartSpec, description="When the first phase starts.")
    path_constraints: list[str] = Field(default_factory=list, description="Imposed in every phase.")
    boundary_constraints: list[str] = Field(
        default_factory=list,
        description="Relations over the phases' end values (`<state>_0`, `<phase>.<state>_f` ...).",
    )
    integral_constraints: list[IntegralConstraintSpec] = Field(
        default_factory=list, description="Over the whole horizon: the integrand summed over the phases."
    )
    phases: list[PhaseSpec] = Field(min_length=1, description="The phases, in order.")

    @model_serializer(mode="wrap")
    def _without_unused_tables(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The problem as data, ``tables`` left out when empty (content hashes as before it existed)."""
        data: dict[str, Any] = handler(self)
        return {k: v for k, v in data.items() if k != "tables" or v}

    @model_validator(mode="after")
    def _names(self) -> MultiPhaseProblem:
        """Names are identifiers, not used twice, without the phases' separator ``__`` but before
        a vector component's index (``r__0``, :mod:`gamespec.specs.vectors`; the file's own names
        never have it, :func:`_refuse_separator`)."""
        names = [
            *self.parameters,
            *self.states,
            *self.controls,
            *self.design,
            *self.definitions,
            *self.tables,
        ]
        names += sorted({n for ph in self.phases for n in ph.definitions if n not in self.definitions})
        phases = [ph.name for ph in self.phases]
        for name in names + phases:
            base, _, index = name.rpartition(SEPARATOR)
            plain = base if index.isdigit() and name not in phases else name
            if not name.isidentifier() or name in RESERVED or name == NORMALIZED_TIME or SEPARATOR in plain:
                raise ValueError(
                    f"{name!r} cannot be a name (reserved, not an identifier, or has {SEPARATOR})"
                )
        repeated = sorted({n for n in phases if phases.count(n) > 1})
        if repeated:
            raise ValueError(f"phase names used twice: {', '.join(repeated)}")
        boundary = {f"{s}_{e}" for s in [*self.states, *self.controls] for e in "0f"} | {"t_0", "t_f"}
        clashes = {n for n in names if names.count(n) > 1} | (set(names) & boundary)
        if clashes:
            raise ValueError(f"names used twice: {', '.join(sorted(clashes))}")
        if not self.states:
            raise ValueError("at least one state is needed")
        return self


def _component(name: str) -> bool:
    """Whether ``name`` is a vector's component as the vector lowering writes it (``r__0``,
    :mod:`gamespec.specs.vectors`): what a lowered spec's dump holds, so that it validates again
    (:func:`gamespec.loader.with_values`); no phase copy looks so (a phase's name is an identifier)."""
    base, _, index = name.rpartition(SEPARATOR)
    return index.isdigit() and base.isidentifier() and SEPARATOR not in base


def _refuse_separator(problem: dict[str, Any]) -> None:
    """A name the file gives (a parameter, state, control, design variable, definition, table or
    phase) with the phases' separator ``__`` is refused, naming it (the lowered copies use it),
    but a vector state's, control's or definition's component (:func:`_component`)."""
    groups = ["parameters", "states", "controls", "design", "definitions", "tables"]
    found = [(f"problem.{g}.{n}", n) for g in groups if isinstance(problem.get(g), dict) for n in problem[g]]
    phases = problem.get("phases") if isinstance(problem.get("phases"), list) else []
    for k, phase in enumerate(p for p in phases if isinstance(p, dict)):
        found.append((f"problem.phases.{k}.name", phase.get("name")))
        if isinstance(phase.get("definitions"), dict):
            found += [(f"problem.phases.{k}.definitions.{n}", n) for n in phase["definitions"]]
    for field, name in found:
        vectors = ("problem.states.", "problem.controls.", "problem.definitions.")
        component = isinstance(name, str) and field.startswith(vectors) and _component(name)
        if isinstance(name, str) and SEPARATOR in name and not component:
            raise SpecError(
                f"{name!r} cannot be a name (has {SEPARATOR}, which the phases' copies use)", field=field
            )


class MultiPhaseSpec(OcpFamily, SpecBase):
    """A multi-phase optimal-control problem: phases in sequence, each with its own dynamics
    (``phases[k].dynamics`` replaces ``problem.dynamics`` by state), duration (a value, or ``free``
    within bounds: a switching time), running cost, path and boundary constraints, controls (a
    subset of ``problem.controls``, bounds narrowed), state bounds and end values, and guess;
    consecutive phases are linked by continuity of every state or by a jump
    (``jump: {m: m_f - structure}``, over the previous phase's end). Solved as one NLP: the
    ``phases`` transform lowers it to one ``optimal_control`` problem in which each phase has its
    own copy of the states and controls on a normalized time in [0, 1], its duration a design
    variable (free) or a parameter (fixed), the links boundary constraints (``gamespec show FILE
    --transformed`` prints it). Each phase has ``method.intervals`` collocation intervals in its
    own normalized time, or its own ``intervals`` (then on a uniform grid).

    The Result runs over the whole horizon, phase after phase (each boundary twice: the end of one
    phase and the start of the next); ``metrics.phases`` gives each phase's name, start, end and
    duration, ``arrays.phase`` the phase of each time point, and the plots mark the boundaries.
    Checks: ``max_constraint_violation`` (links included), ``max_defect`` and
    ``max_defect_relative`` overall, and per phase ``<check>/<phase>`` (defects, bounds and path
    constraints, control swings, the Hamiltonian's variation on autonomous phases and, on a phase
    of free duration, ``hamiltonian_end_error/<phase>`` = ``max |H + dPhi/dt_f|``, the switching
    time's transversality condition). Its runtime parameters are ``problem.parameters``."""

    kind: Literal["multiphase_optimal_control"] = Field(
        "multiphase_optimal_control",
        description="The problem kind; selects the schema of the rest of the file.",
    )
    problem: MultiPhaseProblem = Field(description="The mathematics: states, controls, objective and phases.")
    method: MethodSpec = Field(
        default_factory=MethodSpec,
        description="The transcription of each phase (on its own normalized time).",
    )
    plot: PlotHint = Field(
        default_factory=PlotHint, description="What the figures draw: planar pairs, units."
    )

    @model_validator(mode="before")
    @classmethod
    def _lower_vectors(cls, data: object, info: ValidationInfo) -> object:
        """Vector states and controls as their components (:mod:`gamespec.specs.vectors`)."""
        if not isinstance(data, dict) or not isinstance(data.get("problem"), dict):
            return data
        _refuse_separator(data["problem"])
        problem, _ = lower_problem(data["problem"], phases=True, context=info.context)
        return data if problem is data["problem"] else {**data, "problem": problem}

    @model_validator(mode="after")
    def _lowers(self) -> MultiPhaseSpec:
        """The phases lower to one ``optimal_control`` problem; an expression the lowering generates
        from the file's values that has no form in the language (a guess spread over a duration of
        1e308) is a SpecError naming ``problem.phases``."""
        self.check_plot_names()
        try:
            lower(self)
        except ExpressionError as err:
            raise SpecError(
                f"the phases do not lower to one problem: {err}", field="problem.phases"
            ) from None
        return self


KIND = Kind(
    MultiPhaseSpec,
    default_backend="casadi",
    plot="gamespec.plotting:plot_trajectories",
    summary="gamespec.summaries:multiphase_summary",
    metrics="gamespec.ocp.metrics:OcpMetrics",
)
"""The ``MultiPhaseSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
