"""The ``optimal_control`` kind: states, controls, parameters, dynamics, objective, time, constraints.

Three sections as in rockit: ``problem`` (what), ``method`` (transcription) and ``solver`` (which
backend, with per-backend options), plus an optional ``guess``. Every expression is a string in the
safe language of :mod:`gamespec.symbolic.grammar`; this module checks that each one parses over the
names it may use, so a typo stops at load time with the field that holds it (the whitelist walk in
floats: no SymPy at load).
"""

from __future__ import annotations

import ast
import dataclasses
import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
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
from gamespec.registry import Kind
from gamespec.specs.base import Number, ProblemParameters, SpecBase, StrictModel, Value
from gamespec.specs.events import EventSpec, MeasurementsSpec
from gamespec.specs.plot import PlotHint
from gamespec.specs.tables import TableSpec
from gamespec.specs.uncertainty import UncertainParameter
from gamespec.specs.vectors import Lowering, lower_problem
from gamespec.symbolic.canonical import check
from gamespec.symbolic.grammar import (
    FLOATS,
    RESERVED,
    at_time,
    at_time_name,
    dependencies,
    expression,
    numeric_value,
    relation,
    syntax_tree,
    unknowns,
)
from gamespec.symbolic.tables import Table

INF = math.inf
INITIAL_TIME = "t_0"
"""The name of a free initial time: a decision variable, usable in Mayer and boundary terms."""
OPTIONAL_SECTIONS = ("tables", "at", "measurements")
"""The sections of ``problem`` left out of its data when empty (:meth:`OcpProblem.model_dump`)."""
NORMALIZED_TIME = "tau"
"""The name of normalized time ``(t - t0) / (t_f - t0)`` in guess and input-default expressions."""


class StateSpec(StrictModel):
    """One state: its bounds and its initial/final values (``None`` means free). A vector state
    (``size: N``, values as lists of N or one value for all) is lowered at load to its components
    ``NAME__0 ...`` (:mod:`gamespec.specs.vectors`)."""

    initial: Value | None = Field(
        None, description="The initial value (a number or an expression of the parameters); omitted: free."
    )
    final: Value | None = Field(
        None, description="The final value (a number or an expression of the parameters); omitted: free."
    )
    lower: Value | None = Field(None, description="Lower bound; omitted: none.")
    upper: Value | None = Field(None, description="Upper bound; omitted: none.")
    scale: Number | Literal["auto", "none"] | None = Field(
        None,
        description="The NLP sees this variable divided by scale; auto: a power of ten from the guess and"
        " the fixed end values, else the bounds (gamespec.ocp.scaling); none: 1; unset: method.scale.",
    )


class ControlSpec(StrictModel):
    """One control: its bounds. A vector control (``size: N``, bounds as lists of N or one value for
    all) is lowered at load to its components ``NAME__0 ...`` (:mod:`gamespec.specs.vectors`)."""

    lower: Value | None = Field(
        None, description="Lower bound (a number or an expression of the parameters); omitted: none."
    )
    upper: Value | None = Field(
        None, description="Upper bound (a number or an expression of the parameters); omitted: none."
    )
    scale: Number | Literal["auto", "none"] | None = Field(
        None,
        description="The NLP sees this variable divided by scale; auto: a power of ten from the guess and"
        " the fixed end values, else the bounds (gamespec.ocp.scaling); none: 1; unset: method.scale.",
    )


class InputSpec(StrictModel):
    """One grid input: a signal tabulated at the transcription's evaluation points (the Result's
    ``control_time``), used in the dynamics, the Lagrange integrand and path constraints like a
    parameter that varies along the horizon. ``default`` is a number or an expression of normalized
    time ``tau`` (in [0, 1]) and the parameters; ``CompiledModel.solve(inputs=...)`` replaces it."""

    default: Value = Field(
        0.0,
        description="The signal when none is given: a number or an expression of tau and the parameters.",
    )


class DesignSpec(StrictModel):
    """A free static parameter (design variable): one number optimized with the trajectory, used
    wherever a parameter may be used in dynamics, costs and constraints; bounds are numbers or
    expressions of the parameters, the guess defaults to the middle of finite bounds."""

    lower: Value | None = Field(None, description="Lower bound; omitted: none.")
    upper: Value | None = Field(None, description="Upper bound; omitted: none.")
    guess: Number | None = Field(
        None, description="The starting value; omitted: the middle of finite bounds."
    )


class IntegralConstraintSpec(StrictModel):
    """An isoperimetric constraint ``lower <= integral of integrand dt <= upper`` over the horizon
    (the integrand is a running expression; the bounds are numbers or expressions of the parameters,
    re-evaluated when a compiled model is solved with new parameter values; an omitted bound is
    infinite)."""

    integrand: Value = Field(description="The running expression integrated over the horizon.")
    lower: Value | None = Field(None, description="Lower bound of the integral; omitted: none.")
    upper: Value | None = Field(None, description="Upper bound of the integral; omitted: none.")

    @model_validator(mode="after")
    def _some_bound(self) -> IntegralConstraintSpec:
        if self.lower is None and self.upper is None:
            raise ValueError("an integral constraint needs lower, upper or both")
        return self


class ObjectiveSpec(StrictModel):
    """Mayer term (over ``<state>_0``, ``<state>_f``, ``<control>_0``, ``<control>_f``, ``t_f``,
    parameters and design variables) plus Lagrange integrand."""

    sense: Literal["minimize", "maximize"] = Field("minimize", description="`minimize` or `maximize`.")
    mayer: Value = Field(
        0.0, description="The terminal cost over end values, t_f, parameters and design variables."
    )
    lagrange: Value = Field(0.0, description="The running cost integrated over the horizon.")


class FreeOrFixed(StrictModel):
    """A value that is either fixed or ``free`` within ``bounds`` (numbers or expressions of the
    parameters) from ``guess``: a final time, a phase's duration. A subclass names the field of the
    value (``fixed_field``, free when it reads ``free``) and what it is (``what``)."""

    bounds: tuple[Value, Value] | None = Field(
        None, description="[lower, upper] when free (numbers or expressions of the parameters)."
    )
    guess: Number | None = Field(None, description="The starting value when free.")

    fixed_field: ClassVar[str] = ""
    what: ClassVar[str] = ""

    @property
    def free(self) -> bool:
        return getattr(self, self.fixed_field) == "free"

    @model_validator(mode="after")
    def _free_needs_bounds(self) -> FreeOrFixed:
        if self.free and self.bounds is None:
            raise ValueError(f"a free {self.what} needs bounds: [lower, upper]")
        if not self.free and self.bounds is not None:
            raise ValueError(f"bounds are only for a free {self.what} ({self.fixed_field}: free)")
        return self


class TimeSpec(FreeOrFixed):
    """Initial time, and the final time: a value, or ``free`` within ``bounds`` (numbers or
    expressions of the parameters) from ``guess``."""

    initial: Number | Literal["free"] = Field(
        0.0,
        description="The initial time, or free within initial_bounds (then t_0 in Mayer and boundary terms).",
    )
    initial_bounds: tuple[Value, Value] | None = Field(
        None, description="Bounds of a free initial time (numbers or expressions of the parameters)."
    )
    initial_guess: Number | None = Field(None, description="Starting guess of a free initial time.")
    final: Value | Literal["free"] = Field(
        1.0, description="The final time: a number, an expression of the parameters, or `free`."
    )

    fixed_field: ClassVar[str] = "final"
    what: ClassVar[str] = "final time"

    @model_serializer(mode="wrap")
    def _without_unused_initial(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The time as data, leaving out a fixed initial time's unused bounds and guess (content
        hashes as before they existed)."""
        data: dict[str, Any] = handler(self)
        return {
            k: v for k, v in data.items() if k not in ("initial_bounds", "initial_guess") or v is not None
        }

    @property
    def free_initial(self) -> bool:
        return self.initial == "free"

    @property
    def origin(self) -> float:
        """The initial time when fixed; 0 when free (the transcription's time is then shifted by the
        free initial time, :data:`INITIAL_TIME`)."""
        return 0.0 if self.initial == "free" else float(self.initial)

    @model_validator(mode="after")
    def _free_initial_needs_bounds(self) -> TimeSpec:
        if self.free_initial and self.initial_bounds is None:
            raise ValueError("a free initial time needs initial_bounds: [lower, upper]")
        if not self.free_initial and (self.initial_bounds is not None or self.initial_guess is not None):
            raise ValueError(
                "initial_bounds and initial_guess are only for a free initial time (initial: free)"
            )
        return self


class OcpProblem(StrictModel):
    """The mathematics of an optimal-control problem.

    ``parameters`` are numbers, or expressions of the parameters declared before them (*derived*
    parameters such as ``Dc: 0.5*620``, recomputed whenever a parameter they use changes; the
    runtime parameters of a compiled model are the numeric ones). ``definitions`` are named
    expressions, in order, over the parameters, states, controls, inputs, ``t`` and the earlier
    definitions, substituted symbolically wherever a running expression (dynamics, the Lagrange
    integrand, path constraints) names them.
    """

    parameters: dict[str, Value] = Field(
        default_factory=dict,
        description="Numbers, or expressions of earlier parameters (derived, recomputed from them).",
    )
    definitions: dict[str, Value] = Field(
        default_factory=dict,
        description="Named expressions used in dynamics, the Lagrange integrand and path constraints.",
    )
    tables: dict[str, TableSpec] = Field(
        default_factory=dict,
        description="Gridded data, each a function of the expressions by its name (CL(mach, alpha)).",
    )
    states: dict[str, StateSpec] = Field(
        description="The states, with their bounds and initial and final values."
    )
    controls: dict[str, ControlSpec] = Field(
        default_factory=dict, description="The controls, with their bounds."
    )
    inputs: dict[str, InputSpec] = Field(
        default_factory=dict, description="Grid inputs: signals along the horizon, by name."
    )
    design: dict[str, DesignSpec] = Field(
        default_factory=dict, description="Free static parameters optimized with the trajectory."
    )
    dynamics: dict[str, Value] = Field(description="The right-hand side of each state's ODE.")
    objective: ObjectiveSpec = Field(
        default_factory=ObjectiveSpec, description="The objective: Mayer term plus Lagrange integrand."
    )
    time: TimeSpec = Field(default_factory=TimeSpec, description="The initial and final times.")
    path_constraints: list[str] = Field(
        default_factory=list, description="Relations that hold along the horizon."
    )
    boundary_constraints: list[str] = Field(
        default_factory=list,
        description="Relations over the end values (`<state>_0`, `<state>_f`, t_f, parameters).",
    )
    integral_constraints: list[IntegralConstraintSpec] = Field(
        default_factory=list, description="Isoperimetric constraints on integrals over the horizon."
    )
    at: list[EventSpec] = Field(
        default_factory=list,
        description="Interior-point constraints: [{time: ..., constraints: [...]}] over the states then.",
    )
    measurements: MeasurementsSpec | None = Field(
        None, description="Measured data (times, values, weights): a least-squares term in the objective."
    )
    uncertain: dict[str, UncertainParameter] = Field(
        default_factory=dict, description="Uncertain parameters (chapter 6) and their distributions."
    )

    @model_serializer(mode="wrap")
    def _without_unused_sections(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The problem as data, leaving out the interior-point and table sections a file does not
        use: a spec's content hash (its Results' provenance) is the same as before they existed."""
        data: dict[str, Any] = handler(self)
        return {k: v for k, v in data.items() if k not in OPTIONAL_SECTIONS or v}

    @field_validator("states")
    @classmethod
    def _some_states(cls, v: dict[str, StateSpec]) -> dict[str, StateSpec]:
        if not v:
            raise ValueError("at least one state is needed")
        return v

    @model_validator(mode="after")
    def _consistent(self) -> OcpProblem:
        names = [
            *self.parameters,
            *self.states,
            *self.controls,
            *self.inputs,
            *self.definitions,
            *self.design,
            *self.tables,
        ]
        boundary = [f"{s}_{e}" for s in [*self.states, *self.controls] for e in "0f"] + ["t_f", INITIAL_TIME]
        for name in names:
            if name == NORMALIZED_TIME:
                raise ValueError(
                    f"{name!r} cannot be a symbol name (reserved: the normalized time of guesses and inputs)"
                )
            if not name.isidentifier() or name in RESERVED:
                raise ValueError(f"{name!r} cannot be a symbol name (reserved or not an identifier)")
        clashes = {n for n in names if names.count(n) > 1} | (set(names) & set(boundary))
        if clashes:
            raise ValueError(f"names used twice: {', '.join(sorted(clashes))}")
        missing = set(self.states) - set(self.dynamics)
        extra = set(self.dynamics) - set(self.states)
        if missing or extra:
            what = (f"no dynamics for {sorted(missing)}" if missing else "") + (
                f" dynamics for undeclared states {sorted(extra)}" if extra else ""
            )
            raise ValueError(f"dynamics must give one equation per state: {what.strip()}")
        unknown = set(self.uncertain) - set(self.parameters)
        if unknown:
            raise ValueError(f"uncertain names undeclared parameters: {sorted(unknown)}")
        derived = set(self.uncertain) & self.derived_parameters
        if derived:
            raise ValueError(f"uncertain names derived parameters (give a number instead): {sorted(derived)}")
        self._check_expressions()
        self.evaluate(self.parameter_values())
        self._check_interior_points()
        return self

    def interior_times(self, params: Mapping[str, float]) -> tuple[list[float], list[float]]:
        """The times of the ``at:`` entries and of the measurements for these parameter values."""
        values = {n: float(params[n]) for n in self.parameters if n in params}
        events = [
            _evaluated(e.time, values, f"problem.at.{i}.time") if isinstance(e.time, str) else float(e.time)
            for i, e in enumerate(self.at)
        ]
        inline = sorted({t for pairs in self.inline_points().values() for _, t in pairs})
        measured = [float(t) for t in (self.measurements.times if self.measurements else [])]
        return events + inline, measured

    def inline_points(self) -> dict[int, list[tuple[str, float]]]:
        """Per boundary constraint that names a state at a fixed time (``x(t=5) == 1``), by its
        index, the (state, time) pairs it names (a time that is not a number is left to the check,
        which refuses it)."""
        found: dict[int, list[tuple[str, float]]] = {}
        for i, text in enumerate(self.boundary_constraints):
            try:
                calls = at_time(syntax_tree(text))
            except ExpressionError:
                continue
            pairs = []
            for name, node in calls:
                try:
                    time = numeric_value(ast.unparse(node), {})
                except ExpressionError:
                    continue
                if name in self.states:
                    pairs.append((name, time))
            if pairs:
                found[i] = pairs
        return found

    def _check_interior_points(self) -> None:
        """Interior points need a fixed horizon that holds their times; their expressions parse
        over the states (at that time), the parameters and the design variables."""
        inline = self.inline_points()
        if not self.at and self.measurements is None and not inline:
            return
        field = (
            "problem.at"
            if self.at
            else "problem.measurements"
            if self.measurements
            else "problem.boundary_constraints"
        )
        if self.time.free or self.time.free_initial:
            raise SpecError(
                "interior points (at, measurements) need a fixed initial and final time", field=field
            )
        if self.measurements is not None and self.objective.sense == "maximize":
            reason = "a least-squares fit minimizes: measurements need objective.sense minimize"
            raise SpecError(reason, field="problem.measurements")
        numbers = self.parameter_values()
        t_final = self.evaluate(numbers).t_final
        events, measured = self.interior_times(numbers)
        for where, times in (("at.{i}.time", events), ("measurements.times.{i}", measured)):
            for i, t in enumerate(times):
                if not self.time.origin <= t <= t_final:
                    reason = f"time {t:g} lies outside the horizon [{self.time.origin:g}, {t_final:g}]"
                    raise SpecError(reason, field="problem." + where.format(i=i))
        names = dict.fromkeys([*self.parameters, *self.design, *self.states])
        functions = self.functions
        checks = [
            (f"at.{i}.constraints.{j}", c, True)
            for i, e in enumerate(self.at)
            for j, c in enumerate(e.constraints)
        ]
        measured_keys = self.measurements.values if self.measurements else {}
        checks += [(f"measurements.values.{key}", key, False) for key in measured_keys]
        for field_name, text, constraint in checks:
            try:
                _check_at(text, names, numbers, constraint, {}, functions)
            except ExpressionError as err:
                raise SpecError(str(err), field=f"problem.{field_name}") from None

    @property
    def functions(self) -> dict[str, Table]:
        """The tables as functions of the expressions, by name (each built once)."""
        return {name: spec.named(name) for name, spec in self.tables.items()}

    def time_varying_bounds(self) -> list[tuple[str, str, str]]:
        """``(name, "lower" | "upper", expression)`` of each state or control bound that uses ``t``."""
        found = []
        for items in (self.states, self.controls):
            for name, spec in items.items():
                for key in ("lower", "upper"):
                    raw = getattr(spec, key)
                    if is_time_varying(raw):
                        found.append((name, key, raw))
        return found

    @property
    def derived_parameters(self) -> set[str]:
        """The parameters given as expressions of earlier ones."""
        return {n for n, v in self.parameters.items() if isinstance(v, str)}

    def parameter_values(self, base: Mapping[str, float] | None = None) -> dict[str, float]:
        """Every parameter's value, in declaration order: the numeric ones from ``base`` (else the
        file), each derived one evaluated over the values before it."""
        return parameter_values(self.parameters, base)

    def evaluate(self, params: Mapping[str, float]) -> EvaluatedValues:
        """Bounds, fixed end values and a fixed final time as floats for these parameter values;
        a SpecError naming the field when one is not finite, a lower bound exceeds its upper
        bound, or a fixed value lies outside its bounds."""
        values = {n: float(params[n]) for n in self.parameters if n in params}

        def number(raw: float | str | None, default: float, field: str) -> float:
            if raw is None or (default in (-INF, INF) and is_time_varying(raw)):
                return default
            if isinstance(raw, str):
                raw = _evaluated(raw, values, f"problem.{field}")
            if not math.isfinite(raw):
                raise SpecError(f"evaluates to {raw} (a finite number is needed)", field=f"problem.{field}")
            return float(raw)

        states = []
        for name, st in self.states.items():
            lo = number(st.lower, -INF, f"states.{name}.lower")
            hi = number(st.upper, INF, f"states.{name}.upper")
            ends = [
                None if v is None else number(v, 0.0, f"states.{name}.{k}")
                for k, v in (("initial", st.initial), ("final", st.final))
            ]
            _ordered(lo, hi, f"states.{name}")
            for key, value in zip(("initial", "final"), ends, strict=True):
                if value is not None and not lo <= value <= hi:
                    raise SpecError(
                        f"{value:g} lies outside [{lo:g}, {hi:g}]", field=f"problem.states.{name}.{key}"
                    )
            states.append((lo, hi, *ends))

        def interval(group: str, name: str, spec: ControlSpec | DesignSpec) -> tuple[float, float]:
            lo = number(spec.lower, -INF, f"{group}.{name}.lower")
            hi = number(spec.upper, INF, f"{group}.{name}.upper")
            _ordered(lo, hi, f"{group}.{name}")
            return lo, hi

        controls = [interval("controls", name, c) for name, c in self.controls.items()]
        design = []
        for name, d in self.design.items():
            lo, hi = interval("design", name, d)
            guess = d.guess if d.guess is not None else bounds_midpoint(lo, hi)
            if not lo <= guess <= hi:
                raise SpecError(
                    f"{guess:g} lies outside [{lo:g}, {hi:g}]", field=f"problem.design.{name}.guess"
                )
            design.append((lo, hi, guess))
        integrals = []
        for i, c in enumerate(self.integral_constraints):
            lo = number(c.lower, -INF, f"integral_constraints.{i}.lower")
            hi = number(c.upper, INF, f"integral_constraints.{i}.upper")
            _ordered(lo, hi, f"integral_constraints.{i}")
            integrals.append((lo, hi))
        t_final = t_bounds = t0_bounds = None
        earliest = self.time.origin
        if self.time.free_initial:
            a, b = (
                number(v, 0.0, f"time.initial_bounds.{i}") for i, v in enumerate(self.time.initial_bounds)
            )
            guess = self.time.initial_guess if self.time.initial_guess is not None else 0.5 * (a + b)
            if not a <= guess <= b:
                raise SpecError(
                    "initial_bounds must hold the initial_guess", field="problem.time.initial_bounds"
                )
            t0_bounds, earliest = (a, b, guess), a
        if self.time.free:
            lo, hi = (number(b, 0.0, f"time.bounds.{i}") for i, b in enumerate(self.time.bounds))
            if not earliest <= lo < hi:
                raise SpecError("bounds must satisfy initial <= lower < upper", field="problem.time.bounds")
            t_bounds = (lo, hi)
        else:
            t_final = number(self.time.final, 1.0, "time.final")
            if t_final <= earliest:
                raise SpecError("final time must be after the initial time", field="problem.time.final")
        return EvaluatedValues(states, controls, t_final, t_bounds, design, integrals, t0_bounds)

    def _check_expressions(self) -> None:
        """Parse every expression over the symbols its field may use; an input where it may not
        appear (bounds, end values, Mayer and boundary terms, the final time) is named as such."""
        params = dict.fromkeys(self.parameters)
        inputs = dict.fromkeys(self.inputs)
        design = dict.fromkeys(self.design)
        running = {**params, **design, **inputs}
        running |= dict.fromkeys([*self.states, *self.controls, "t"])
        checks: list[tuple[str, object, dict, bool]] = []
        earlier: dict = {}
        for name, raw in self.parameters.items():
            if isinstance(raw, str):
                checks.append((f"parameters.{name}", raw, dict(earlier), False))
            earlier[name] = params[name]
        for name, raw in self.definitions.items():
            checks.append((f"definitions.{name}", raw, dict(running), False))
            running[name] = None
        ends = {
            **params,
            **design,
            **dict.fromkeys(f"{s}_{e}" for s in [*self.states, *self.controls] for e in "0f"),
            "t_f": None,
            **({INITIAL_TIME: None} if self.time.free_initial else {}),
        }
        timed = params | {"t": None}
        for group, items in (("states", self.states), ("controls", self.controls), ("design", self.design)):
            for name, spec in items.items():
                for key, value in spec.model_dump(exclude={"scale"}).items():
                    if isinstance(value, str):
                        along = group != "design" and key in ("lower", "upper")
                        if along:
                            _bound_over_time(
                                value,
                                timed,
                                {k: v for k, v in running.items() if k not in inputs},
                                f"problem.{group}.{name}.{key}",
                            )
                        checks.append((f"{group}.{name}.{key}", value, timed if along else params, False))
        checks += [
            (f"inputs.{n}.default", i.default, params | {NORMALIZED_TIME: None}, False)
            for n, i in self.inputs.items()
            if isinstance(i.default, str)
        ]
        checks += [(f"dynamics.{k}", v, running, False) for k, v in self.dynamics.items()]
        checks += [
            ("objective.mayer", self.objective.mayer, ends, False),
            ("objective.lagrange", self.objective.lagrange, running, False),
        ]
        if isinstance(self.time.final, str) and self.time.final != "free":
            checks.append(("time.final", self.time.final, params, False))
        for i, bound in enumerate(self.time.bounds or ()):
            if isinstance(bound, str):
                checks.append((f"time.bounds.{i}", bound, params, False))
        for i, bound in enumerate(self.time.initial_bounds or ()):
            if isinstance(bound, str):
                checks.append((f"time.initial_bounds.{i}", bound, params, False))
        checks += [(f"path_constraints.{i}", c, running, True) for i, c in enumerate(self.path_constraints)]
        for i, c in enumerate(self.integral_constraints):
            checks.append((f"integral_constraints.{i}.integrand", c.integrand, running, False))
            checks += [
                (f"integral_constraints.{i}.{key}", bound, params, False)
                for key, bound in (("lower", c.lower), ("upper", c.upper))
                if isinstance(bound, str)
            ]
        inline = self.inline_points()
        control_ends = {f"{c}_{e}" for c in self.controls for e in "0f"}
        for i, c in enumerate(self.boundary_constraints):
            names = ends
            if i in inline:
                at_times = dict.fromkeys(at_time_name(x, time) for x, time in inline[i])
                names = {k: v for k, v in ends.items() if k not in control_ends} | at_times
            checks.append((f"boundary_constraints.{i}", c, names, True))
        numbers = self.parameter_values()
        functions = self.functions
        for field, text, symbols, constraint in checks:
            try:
                _check_at(text, symbols, numbers, constraint, self.definitions, functions)
            except ExpressionError as err:
                used = _inputs_in(constraint, text, symbols, inputs)
                reason = (
                    f"uses grid input(s) {', '.join(used)}: inputs are signals along the horizon and "
                    "may appear only in dynamics, the Lagrange integrand and path constraints"
                    if used
                    else str(err)
                )
                raise SpecError(reason, field=f"problem.{field}") from None


def _check_at(
    text: str | float,
    names: Mapping[str, object],
    numbers: Mapping[str, float],
    constraint: bool,
    definitions: Mapping[str, str],
    functions: Mapping[str, Table],
) -> None:
    """:func:`~gamespec.symbolic.canonical.check` of ``text`` over ``names`` (and the file's tables,
    ``functions``) (those of
    ``definitions`` standing for their expressions), the parameters among them at their ``numbers``
    (the file's values): what is undefined, not real or out of range at those values (``acos(xf)``
    with ``xf = 2``, ``sqrt(-w)``) is refused at load, not met by the solver."""
    defined = {n: definitions[n] for n in names if n in definitions}
    free = [n for n in names if n not in defined]
    values = {n: numbers[n] for n in free if n in numbers}
    check(text, free, values, constraint=constraint, definitions=defined, functions=functions)


def parameter_values(
    parameters: Mapping[str, float | str], base: Mapping[str, float] | None = None
) -> dict[str, float]:
    """Every parameter's value, in declaration order: the numeric ones from ``base`` (else
    ``parameters``), each derived one (an expression) evaluated over the values before it."""
    base = base or {}
    values: dict[str, float] = {}
    for name, raw in parameters.items():
        if isinstance(raw, str):
            values[name] = _evaluated(raw, values, f"problem.parameters.{name}")
        else:
            values[name] = float(base.get(name, raw))
    return values


def _evaluated(text: str, values: Mapping[str, float], field: str) -> float:
    """The value of a parameter-only expression; a SpecError naming ``field`` when it is not a
    finite real number (``log(rho - 10)`` at ``rho = 10``)."""
    try:
        return numeric_value(text, values)
    except ExpressionError as err:
        raise SpecError(str(err), field=field) from None


def is_time_varying(raw: float | str | None) -> bool:
    """Whether a bound uses ``t`` (it is then imposed as a path constraint, not a variable bound)."""
    if not isinstance(raw, str):
        return False
    try:
        tree = ast.parse(raw.strip(), mode="eval")
    except SyntaxError:
        return False
    return any(isinstance(n, ast.Name) and n.id == "t" for n in ast.walk(tree))


def _bound_over_time(text: str, timed: dict, running: dict, field: str) -> None:
    """A bound may use the parameters and ``t``; one over states or controls is refused with a
    pointer to ``path_constraints``."""
    try:
        check(text, timed)
    except ExpressionError:
        try:
            check(text, running)
        except ExpressionError:
            return
        raise SpecError(
            f"bound {text!r} uses states or controls: a bound may use the parameters and t; write it "
            "as a path constraint (path_constraints: [...])",
            field=field,
        ) from None


def _inputs_in(constraint: bool, text: str, symbols: dict, inputs: dict) -> list[str]:
    """The grid inputs that ``text`` uses, when it parses once they are allowed (else none)."""
    if not inputs or set(inputs) <= set(symbols):
        return []
    names = unknowns(symbols | inputs)
    try:
        used = relation(text, names, FLOATS).expr if constraint else expression(text, names, FLOATS)
    except ExpressionError:
        return []
    return sorted(dependencies(used) & set(inputs))


@dataclass(frozen=True)
class EvaluatedValues:
    """Per state ``(lower, upper, initial, final)`` (initial/final None when free), per control
    ``(lower, upper)``, the fixed final time (None when free), the bounds of a free one, per
    design variable ``(lower, upper, guess)`` and per integral constraint ``(lower, upper)``."""

    states: list[tuple[float, float, float | None, float | None]]
    controls: list[tuple[float, float]]
    t_final: float | None
    t_bounds: tuple[float, float] | None = None
    design: list[tuple[float, float, float]] = dataclasses.field(default_factory=list)
    integrals: list[tuple[float, float]] = dataclasses.field(default_factory=list)
    t0_bounds: tuple[float, float, float] | None = None


def bounds_midpoint(lo: float, hi: float) -> float:
    """The middle of finite bounds, the finite one (or 0 when inside) of half-bounded ones, else 0."""
    if math.isfinite(lo) and math.isfinite(hi):
        return 0.5 * (lo + hi)
    if math.isfinite(lo):
        return max(lo, 0.0)
    if math.isfinite(hi):
        return min(hi, 0.0)
    return 0.0


def _ordered(lower: float, upper: float, field: str) -> None:
    if lower > upper:
        raise SpecError(f"lower bound {lower:g} exceeds upper bound {upper:g}", field=f"problem.{field}")


class RefineSpec(StrictModel):
    """Adaptive mesh refinement: solve, refine every interval whose defect relative to the state
    scale (``max_defect_relative``) exceeds ``tolerance``, re-solve from the last solution, until
    none does or ``max_iterations`` refinements were made. ``h`` splits such an interval into two;
    ``hp`` raises its Radau degree instead where the defect predicts that a degree up to
    ``max_degree`` meets the tolerance (a smooth solution), and splits it otherwise."""

    tolerance: Number = Field(
        1e-6, gt=0, description="Refine every interval whose relative defect exceeds this."
    )
    max_iterations: int = Field(8, ge=1, le=30, description="The most refinements made.")
    strategy: Literal["h", "hp"] = Field(
        "h", description="`h` (split intervals) or `hp` (raise the degree where the solution is smooth)."
    )
    max_degree: int = Field(
        8,
        ge=2,
        le=12,
        description="Highest Radau degree hp gives an interval (hang glider from 10 intervals to 1e-6:"
        " 3 refinements with 8, 5 with 10, whose intervals overshoot and are split again).",
    )


class MethodSpec(StrictModel):
    """Transcription: Legendre–Gauss–Radau collocation of ``degree`` on ``intervals``, or trapezoidal.

    ``grading`` > 1 shrinks the intervals geometrically toward the final time (ratio between the
    first and the last interval's length).
    """

    scheme: Literal["radau", "trapezoidal"] = Field(
        "radau", description="The transcription: `radau` collocation or `trapezoidal`."
    )
    intervals: int = Field(40, ge=1, le=MAX_INTERVALS, description="Number of collocation intervals.")
    degree: int = Field(3, ge=1, le=12, description="The Radau collocation degree.")
    grading: Number = Field(
        1.0,
        gt=0,
        le=1e4,
        description="Ratio of the first to the last interval's length (> 1 shrinks them toward t_f).",
    )
    mesh: list[Number] | None = Field(
        None, description="Interval boundaries in normalized time, 0 to 1 increasing (sets intervals)."
    )
    degrees: list[int] | None = Field(
        None, description="Radau degree of each interval (one per interval; from hp refinement)."
    )
    refine: RefineSpec | None = Field(None, description="Adaptive mesh refinement on the defect estimate.")
    scale: Literal["auto", "none"] = Field(
        "auto",
        description="Scaling of the states and controls whose own scale is unset (auto: each by a power of"
        " ten of its magnitude, with its defect rows; none: unscaled).",
    )

    @model_validator(mode="before")
    @classmethod
    def _intervals_of_mesh(cls, data: object) -> object:
        if isinstance(data, dict) and isinstance(data.get("mesh"), list):
            return {**data, "intervals": max(len(data["mesh"]) - 1, 1)}
        return data

    @model_validator(mode="after")
    def _one_degree_per_interval(self) -> MethodSpec:
        if self.degrees is not None:
            if self.scheme != "radau" or len(self.degrees) != self.intervals:
                raise ValueError("degrees needs the radau scheme and one degree per interval")
            if not all(1 <= d <= 12 for d in self.degrees):
                raise ValueError("each degree must lie in [1, 12]")
        return self

    @field_validator("mesh")
    @classmethod
    def _increasing(cls, mesh: list[float] | None) -> list[float] | None:
        if mesh is not None and (
            len(mesh) < 2
            or mesh[0] != 0.0
            or mesh[-1] != 1.0
            or any(b <= a for a, b in itertools.pairwise(mesh))
        ):
            raise ValueError("mesh must increase strictly from 0 to 1")
        return mesh

    control_rate_penalty: Number = Field(
        0.0,
        ge=0,
        description="Weight w of the regularization w * sum_k |u_{k+1} - u_k|**2 / (tau_{k+1} - tau_k) "
        "added to the objective (smooths singular and chattering arcs; not in the Result's objective).",
    )


class GuessSpec(StrictModel):
    """Initial guess: per-variable values (a number, an expression of normalized time ``tau`` and the
    parameters, or ``linear`` between a state's initial and final values), a final-time guess, or a
    previous Result file (``result``) interpolated onto the new grid."""

    states: dict[str, Value] = Field(
        default_factory=dict,
        description="Per state, a number, an expression of tau and the parameters, or `linear`.",
    )
    controls: dict[str, Value] = Field(
        default_factory=dict, description="Per control, a number or an expression of tau and the parameters."
    )
    t_final: Number | None = Field(None, description="The final time's starting value.")
    result: str | None = Field(
        None, description="A saved Result (folder or result.json) interpolated onto the new grid."
    )


class OcpFamily(ProblemParameters):
    """What the optimal-control kinds share: the objective's sense, the numeric parameters as
    runtime parameters, and a ``plot`` section that names their states and controls."""

    def check_plot_names(self) -> None:
        """A SpecError naming the ``plot`` field that names no state or control
        (:meth:`~gamespec.specs.plot.PlotHint.check_names`)."""
        self.plot.check_names(list(self.problem.states), list(self.problem.controls))

    @property
    def objective_sense(self) -> str:
        return self.problem.objective.sense

    def runtime_parameters(self) -> dict[str, float]:
        """The numeric parameters (derived ones follow them and are not set on their own)."""
        return {n: float(v) for n, v in self.problem.parameters.items() if not isinstance(v, str)}


def _event_lowered(step: Any, i: int, lowering: Lowering) -> Any:
    """One requested transform, a ``free_event``'s constraints read as the vector lowering reads an
    interior point's (:mod:`gamespec.specs.vectors`); any other as written."""
    if not isinstance(step, dict) or not isinstance(step.get("free_event"), dict):
        return step
    options = step["free_event"]
    if "constraints" not in options:
        return step
    constraints = lowering.event(options["constraints"], f"transforms.{i}.free_event")
    return {**step, "free_event": {**options, "constraints": constraints}}


class OptimalControlSpec(OcpFamily, SpecBase):
    """An optimal-control problem (kind ``optimal_control``); its runtime parameters are
    ``problem.parameters``, its starting point ``guess`` and ``problem.time.guess``."""

    kind: Literal["optimal_control"] = Field(
        "optimal_control", description="The problem kind; selects the schema of the rest of the file."
    )
    problem: OcpProblem = Field(
        description="The mathematics: states, controls, dynamics, objective, constraints."
    )
    method: MethodSpec = Field(
        default_factory=MethodSpec,
        description="The transcription: scheme, intervals, degree, mesh refinement.",
    )
    guess: GuessSpec = Field(default_factory=GuessSpec, description="The starting point of the solve.")
    plot: PlotHint = Field(
        default_factory=PlotHint, description="What the figures draw: planar pairs, units."
    )

    guess_fields = ("guess", "problem.time.guess")

    @model_validator(mode="before")
    @classmethod
    def _lower_vectors(cls, data: object, info: ValidationInfo) -> object:
        """Vector states and controls as their components (:mod:`gamespec.specs.vectors`), in the
        problem, the guess and a requested ``free_event``'s constraints."""
        if not isinstance(data, dict) or not isinstance(data.get("problem"), dict):
            return data
        problem, lowering = lower_problem(data["problem"], context=info.context)
        if problem is data["problem"]:
            return data
        lowered = {**data, "problem": problem}
        if isinstance(data.get("guess"), dict):
            lowered["guess"] = lowering.guess(data["guess"], "guess")
        if isinstance(data.get("transforms"), list):
            lowered["transforms"] = [
                _event_lowered(step, i, lowering) for i, step in enumerate(data["transforms"])
            ]
        return lowered

    def analysis_values(self) -> dict[str, Any]:
        """Each uncertain parameter's distribution (``problem.uncertain.<name>``): only the Monte
        Carlo analyses read it (which parameters are uncertain stays structure: a rewrite builds
        their sensitivities)."""
        return {f"problem.uncertain.{n}": d for n, d in self.problem.uncertain.items()}

    @model_validator(mode="after")
    def _guess_names(self) -> OptimalControlSpec:
        for group in ("states", "controls"):
            unknown = set(getattr(self.guess, group)) - set(getattr(self.problem, group))
            if unknown:
                raise ValueError(f"guess.{group} names undeclared {group}: {sorted(unknown)}")
        return self

    @model_validator(mode="after")
    def _plot_names(self) -> OptimalControlSpec:
        self.check_plot_names()
        return self

    def required_features(self) -> frozenset[str]:
        p = self.problem
        needed = {"ode"}
        if p.time.free:
            needed.add("free_final_time")
        if p.time.free_initial:
            needed.add("free_initial_time")
        if p.path_constraints or p.time_varying_bounds():
            needed.add("path_constraints")
        if p.integral_constraints:
            needed.add("integral_constraints")
        if p.boundary_constraints:
            needed.add("boundary_constraints")
        if p.inputs:
            needed.add("grid_inputs")
        if p.design:
            needed.add("design_parameters")
        if p.tables:
            needed.add("tables")
        if p.at or p.inline_points():
            needed.add("interior_points")
        if p.measurements is not None:
            needed.add("measurements")
        return frozenset(needed)


KIND = Kind(
    OptimalControlSpec,
    default_backend="casadi",
    plot="gamespec.plotting:plot_trajectories",
    summary="gamespec.summaries:optimal_control_summary",
    metrics="gamespec.ocp.metrics:OcpMetrics",
    columns=(
        "metrics.nominal_objective",
        "metrics.sensitivity_measure",
        "metrics.monte_carlo.cost_mean",
        "metrics.monte_carlo.cost_std",
        "metrics.monte_carlo.collision_probability",
    ),
)
"""The ``OptimalControlSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
