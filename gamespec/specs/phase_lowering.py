"""A ``multiphase_optimal_control`` spec as one ``optimal_control`` spec (the ``phases`` transform).

Each phase ``k`` gets its own copy of the states and of its controls (``x__k``, ``u__k``) on a
common normalized time ``s`` in [0, 1], and its duration ``D_k`` (``duration__k``: a design
variable when free, a parameter when fixed). With ``S_k = t0 + D_1 + ... + D_{k-1}`` its start,
phase ``k`` runs on ``t = S_k + D_k s`` (GPOPS-II's time of each phase, and the free-final-time
scaling of one phase, ``dx/ds = D_k f_k``), so that

- dynamics: ``dx__k/ds = D_k f_k(x__k, u__k, S_k + D_k s)``;
- cost: the Mayer term over the first phase's start and the last phase's end, with
  ``t_f = t0 + sum D_k``, plus ``integral_0^1 sum_k D_k L_k ds``; an integral constraint over the
  whole horizon likewise integrates ``sum_k D_k g_k``;
- path constraints and bounds that use ``t``: imposed on each phase's copy at its own time;
- links: ``x__{k+1}(0) = x__k(1)`` (continuity) or ``x__{k+1}(0) = jump(x__k(1), ...)``, boundary
  constraints of the one problem.

The phases share the collocation grid of ``method`` in their own normalized time: a phase of any
duration is resolved by the same number of intervals. Everything is built in SymPy over the names the
file gives and printed with :func:`~gamespec.symbolic.printer.to_text`; a bad expression is a
SpecError naming the field of the multi-phase file that holds it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import sympy as sp
from pydantic import ValidationError

from gamespec.errors import ExpressionError, SpecError
from gamespec.specs.ocp import NORMALIZED_TIME, OptimalControlSpec, is_time_varying, parameter_values
from gamespec.symbolic.language import TIME, Relation, parse, parse_relation, symbol
from gamespec.symbolic.printer import to_text
from gamespec.symbolic.translate import numeric

if TYPE_CHECKING:
    from gamespec.specs.multiphase import MultiPhaseSpec, PhaseSpec

SEPARATOR = "__"
"""Joins a name and a phase name in the lowered problem (``x__boost``); refused in user names."""


def copy_name(name: str, phase: str) -> str:
    """The lowered name of state or control ``name`` in ``phase``."""
    return f"{name}{SEPARATOR}{phase}"


def duration_name(phase: str) -> str:
    """The lowered name of ``phase``'s duration (a design variable or a parameter)."""
    return copy_name("duration", phase)


@dataclass(frozen=True)
class LoweredPhase:
    """One phase in the lowered problem: the lowered names of its states and controls (user name →
    lowered name), of its duration, whether that is free, and the phase alone as a fixed-time
    ``optimal_control`` spec in the file's names (``check_spec``, for the per-phase checks)."""

    name: str
    states: dict[str, str]
    controls: dict[str, str]
    duration: str
    free: bool
    check_spec: OptimalControlSpec


@dataclass(frozen=True)
class Lowering:
    """The lowered spec, its phases in order, and the initial time."""

    target: OptimalControlSpec
    phases: list[LoweredPhase]
    t0: float
    timed_links: bool
    """Whether a jump or a boundary constraint uses a phase's start or end time."""


def _read(
    text: Any,
    symbols: Mapping[str, sp.Expr],
    field: str,
    source: str,
    relation: bool = False,
    phase: str | None = None,
) -> Any:
    """Parse ``text`` over ``symbols``; a SpecError naming ``problem.<field>`` (and ``phase``, where
    a shared field is read in one phase) when it does not parse."""
    try:
        return (parse_relation if relation else parse)(text, symbols)
    except ExpressionError as err:
        shared = phase is not None and not field.startswith("phases.")
        where = f" (in phase {phase!r})" if shared else ""
        raise SpecError(f"{err}{where}", field=f"problem.{field}", source=source) from None


def relation_texts(rel: Relation) -> list[str]:
    """``rel`` as constraints of the file language: one equation, or one or two inequalities."""
    if rel.is_equality:
        return [to_text(sp.Eq(rel.expr - rel.lower, 0, evaluate=False))]
    found = []
    if math.isfinite(rel.lower):
        found.append(to_text(sp.Ge(rel.expr, rel.lower, evaluate=False)))
    if math.isfinite(rel.upper):
        found.append(to_text(sp.Le(rel.expr, rel.upper, evaluate=False)))
    return found


def _merged(shared: Any, own: Any) -> dict[str, Any]:
    """A state's or control's fields: the phase's where it sets them, else the shared ones."""
    data = shared.model_dump()
    if own is not None:
        data |= {k: v for k, v in own.model_dump().items() if v is not None}
    return data


class _Lowerer:
    """Builds the lowered spec phase by phase (see the module doc)."""

    def __init__(self, spec: MultiPhaseSpec) -> None:
        self.spec = spec
        self.p = spec.problem
        self.source = spec.source
        self.params = {n: symbol(n) for n in self.p.parameters}
        self.design = {n: symbol(n) for n in self.p.design}
        self.durations = [symbol(duration_name(ph.name)) for ph in self.p.phases]
        t0 = sp.Float(self.p.time.initial)
        self.starts = [t0 + sum(self.durations[:k], sp.Integer(0)) for k in range(len(self.p.phases) + 1)]
        self.constants = self.params | self.design
        self.values = parameter_values(self.p.parameters)

    def phase_controls(self, ph: PhaseSpec, k: int) -> dict[str, dict[str, Any]]:
        if ph.controls is None:
            return {n: c.model_dump() for n, c in self.p.controls.items()}
        unknown = sorted(set(ph.controls) - set(self.p.controls))
        if unknown:
            raise SpecError(
                f"undeclared controls {unknown} (declare them in problem.controls)",
                field=f"problem.phases.{k}.controls",
                source=self.source,
            )
        return {n: _merged(self.p.controls[n], c) for n, c in ph.controls.items()}

    def running(self, ph: PhaseSpec, k: int, controls: Mapping[str, Any], renamed: bool) -> dict[str, Any]:
        """The symbols of phase ``k``'s running expressions: lowered copies at ``t = S_k + D_k s``
        (``renamed``), else the file's names at the real time; definitions expanded."""
        names = [*self.p.states, *controls]
        if renamed:
            symbols = self.constants | {n: symbol(copy_name(n, ph.name)) for n in names}
            symbols["t"] = self.starts[k] + self.durations[k] * TIME
        else:
            symbols = self.params | self.design | {n: symbol(n) for n in names} | {"t": TIME}
        for name, raw in (self.p.definitions | ph.definitions).items():
            where = f"phases.{k}.definitions.{name}" if name in ph.definitions else f"definitions.{name}"
            symbols[name] = _read(raw, symbols, where, self.source, phase=ph.name)
        return symbols

    def ends(self, phases: Mapping[str, tuple[str, Any]], t_first: sp.Expr, t_last: sp.Expr) -> dict:
        """End symbols ``<name>_0``, ``<name>_f`` (lowered ``<copy>_0`` of the phase that starts and
        ``<copy>_f`` of the one that ends, per name in ``phases``) and ``t_0``, ``t_f``."""
        found = dict(self.constants)
        for name, (first, last) in phases.items():
            if first is not None:
                found[f"{name}_0"] = symbol(f"{first}_0")
            if last is not None:
                found[f"{name}_f"] = symbol(f"{last}_f")
        return found | {"t_0": t_first, "t_f": t_last}

    def lower(self) -> Lowering:
        p, spec = self.p, self.spec
        last = len(p.phases) - 1
        parameters: dict[str, Any] = dict(p.parameters)
        design = {n: d.model_dump() for n, d in p.design.items()}
        states: dict[str, dict] = {}
        controls: dict[str, dict] = {}
        dynamics: dict[str, str] = {}
        path: list[str] = []
        boundary: list[str] = []
        guess: dict[str, dict[str, Any]] = {"states": {}, "controls": {}}
        lagrange = sp.Integer(0)
        integrands = [sp.Integer(0) for _ in p.integral_constraints]
        lowered: list[LoweredPhase] = []
        timed = False
        spans = self.duration_guesses()
        for k, ph in enumerate(p.phases):
            field = f"phases.{k}"
            name = duration_name(ph.name)
            D = self.durations[k]
            if ph.duration.free:
                lo, hi = ph.duration.bounds
                design[name] = {"lower": lo, "upper": hi, "guess": ph.duration.guess}
            else:
                parameters[name] = ph.duration.value
            own = self.phase_controls(ph, k)
            undeclared = sorted((set(ph.dynamics) | set(ph.states) | set(ph.jump)) - set(p.states))
            if undeclared:
                raise SpecError(
                    f"undeclared states {undeclared}", field=f"problem.{field}", source=self.source
                )
            if k == 0 and ph.jump:
                raise SpecError("the first phase has no phase before it", field=f"problem.{field}.jump")
            running = self.running(ph, k, own, renamed=True)
            x_names = {n: copy_name(n, ph.name) for n in p.states}
            u_names = {n: copy_name(n, ph.name) for n in own}
            check_states: dict[str, dict] = {}
            for x, shared in p.states.items():
                entry = _merged(shared, ph.states.get(x))
                mine = ph.states.get(x)
                entry["initial"] = mine.initial if mine and mine.initial is not None else None
                entry["final"] = mine.final if mine and mine.final is not None else None
                if k == 0 and entry["initial"] is None:
                    entry["initial"] = shared.initial
                if k == last and entry["final"] is None:
                    entry["final"] = shared.final
                check_states[x] = dict(entry)
                path += self.time_bounds(entry, running[x], running, f"{field}.states.{x}")
                states[x_names[x]] = entry
                raw = ph.dynamics.get(x, p.dynamics.get(x))
                if raw is None:
                    raise SpecError(
                        f"no dynamics for state {x!r} (neither the phase nor problem.dynamics gives them)",
                        field=f"problem.{field}.dynamics",
                        source=self.source,
                    )
                where = f"{field}.dynamics.{x}" if x in ph.dynamics else f"dynamics.{x}"
                dynamics[x_names[x]] = to_text(D * _read(raw, running, where, self.source, phase=ph.name))
            for u, entry in own.items():
                path += self.time_bounds(entry, running[u], running, f"{field}.controls.{u}")
                controls[u_names[u]] = entry
            cost = ph.lagrange if ph.lagrange is not None else p.objective.lagrange
            where = f"{field}.lagrange" if ph.lagrange is not None else "objective.lagrange"
            lagrange += D * _read(cost, running, where, self.source, phase=ph.name)
            for i, c in enumerate(p.integral_constraints):
                where = f"integral_constraints.{i}.integrand"
                integrands[i] += D * _read(c.integrand, running, where, self.source, phase=ph.name)
            texts = [(f"path_constraints.{i}", c) for i, c in enumerate(p.path_constraints)]
            texts += [(f"{field}.path_constraints.{i}", c) for i, c in enumerate(ph.path_constraints)]
            for where, text in texts:
                path += relation_texts(_read(text, running, where, self.source, True, ph.name))
            names = {n: (c, c) for n, c in (x_names | u_names).items()}
            ends = self.ends(names, self.starts[k], self.starts[k + 1])
            for i, text in enumerate(ph.boundary_constraints):
                rel = _read(text, ends, f"{field}.boundary_constraints.{i}", self.source, relation=True)
                timed |= self.timed(rel.expr)
                boundary += relation_texts(rel)
            if k > 0:
                before = lowered[-1]
                prior = {n: (None, c) for n, c in (before.states | before.controls).items()}
                previous = self.ends(prior, self.starts[k - 1], self.starts[k])
                for x in p.states:
                    end = symbol(f"{before.states[x]}_f")
                    if x in ph.jump:
                        end = _read(ph.jump[x], previous, f"{field}.jump.{x}", self.source)
                        timed |= self.timed(end)
                    boundary.append(to_text(sp.Eq(symbol(f"{x_names[x]}_0") - end, 0, evaluate=False)))
            for group, given, renames in (
                ("states", ph.guess.states, x_names),
                ("controls", ph.guess.controls, u_names),
            ):
                unknown = sorted(set(given) - set(renames))
                if unknown:
                    raise SpecError(
                        f"names no {group[:-1]} of this phase: {unknown}",
                        field=f"problem.{field}.guess.{group}",
                        source=self.source,
                    )
                guess[group] |= {renames[n]: v for n, v in given.items()}
            guess["states"] |= self.spread_guess(ph, k, spans, x_names)
            check = self.check_spec(ph, k, own, check_states)
            lowered.append(LoweredPhase(ph.name, x_names, u_names, name, ph.duration.free, check))
        first, final = lowered[0], lowered[-1]
        names = {
            n: (first.states.get(n, first.controls.get(n)), final.states.get(n, final.controls.get(n)))
            for n in [*p.states, *p.controls]
        }
        ends = self.ends(names, self.starts[0], self.starts[-1])
        ends.pop("t_0")
        mayer = _read(p.objective.mayer, ends, "objective.mayer", self.source)
        for i, text in enumerate(p.boundary_constraints):
            rel = _read(text, ends, f"boundary_constraints.{i}", self.source, relation=True)
            timed |= self.timed(rel.expr)
            boundary += relation_texts(rel)
        data = {
            "kind": "optimal_control",
            "name": spec.name,
            "description": spec.description,
            "solver": spec.solver.model_dump(),
            "problem": {
                "parameters": parameters,
                "states": states,
                "controls": controls,
                "design": design,
                "dynamics": dynamics,
                "objective": {
                    "sense": p.objective.sense,
                    "mayer": to_text(mayer),
                    "lagrange": to_text(lagrange),
                },
                "time": {"initial": 0.0, "final": 1.0},
                "path_constraints": path,
                "boundary_constraints": boundary,
                "integral_constraints": [
                    c.model_dump() | {"integrand": to_text(g)}
                    for c, g in zip(p.integral_constraints, integrands, strict=True)
                ],
            },
            "method": spec.method.model_dump(),
            "guess": guess,
        }
        try:
            target = OptimalControlSpec.model_validate(data)
        except (ValidationError, SpecError) as err:
            reason = err.reason if isinstance(err, SpecError) else str(err.errors()[0]["msg"])
            raise SpecError(f"the lowered problem is invalid: {reason}", field="problem.phases") from None
        target.with_source(spec.source, spec.file_hash)
        return Lowering(target, lowered, float(p.time.initial), timed)

    def timed(self, expr: sp.Expr) -> bool:
        """Whether ``expr`` depends on a duration (uses ``t_0`` or ``t_f``)."""
        return bool(set(self.durations) & expr.free_symbols)

    def time_bounds(self, entry: dict[str, Any], var: sp.Expr, running: dict, field: str) -> list[str]:
        """Bounds of ``entry`` that use ``t``, taken out of it as path constraints at the phase's time."""
        found = []
        for key, sense in (("lower", sp.Ge), ("upper", sp.Le)):
            if is_time_varying(entry.get(key)):
                bound = _read(entry.pop(key), running, f"{field}.{key}", self.source)
                found.append(to_text(sense(var - bound, 0, evaluate=False)))
        return found

    def duration_guesses(self) -> list[sp.Expr]:
        """Each phase's duration guess over the lowered parameters: a fixed duration's parameter, a
        free one's guess, else the middle of its bounds (a SpecError unless each is positive for the
        file's parameter values)."""
        values = {symbol(n): v for n, v in self.values.items()}
        found = []
        for k, ph in enumerate(self.p.phases):
            d = ph.duration
            raws = [d.value] if not d.free else [d.guess] if d.guess is not None else list(d.bounds)
            exprs = [_read(r, self.params, f"phases.{k}.duration", self.source) for r in raws]
            if not all(math.isfinite(v := numeric(e, values)) and v > 0 for e in exprs):
                raise SpecError("a duration must be positive", field=f"problem.phases.{k}.duration")
            found.append(self.durations[k] if not d.free else sum(exprs) / len(exprs))
        return found

    def spread_guess(
        self, ph: PhaseSpec, k: int, spans: list[sp.Expr], names: dict[str, str]
    ) -> dict[str, str]:
        """For each state the phase gives no guess for whose value is fixed at the start of the
        first phase and at the end of the last: the straight line between them over the whole
        horizon (duration guesses), as an expression of the phase's normalized time."""
        tau = symbol(NORMALIZED_TIME)
        start, total = sum(spans[:k], sp.Integer(0)), sum(spans, sp.Integer(0))
        found = {}
        for x, st in self.p.states.items():
            if x in ph.guess.states or st.initial is None or st.final is None:
                continue
            a = _read(st.initial, self.params, f"states.{x}.initial", self.source)
            b = _read(st.final, self.params, f"states.{x}.final", self.source)
            fraction = (start + spans[k] * tau) / total
            found[names[x]] = to_text(a + (b - a) * fraction)
        return found

    def check_spec(
        self, ph: PhaseSpec, k: int, own: dict[str, dict], states: dict[str, dict]
    ) -> OptimalControlSpec:
        """Phase ``k`` alone in the file's names, on a placeholder horizon [0, 1] (the checks set the
        phase's solved start and end times)."""
        p = self.p
        data = {
            "kind": "optimal_control",
            "name": f"{self.spec.name}/{ph.name}",
            "problem": {
                "parameters": dict(p.parameters),
                "definitions": p.definitions | ph.definitions,
                "states": states,
                "controls": own,
                "design": {n: d.model_dump() for n, d in p.design.items()},
                "dynamics": p.dynamics | ph.dynamics,
                "objective": {
                    "sense": p.objective.sense,
                    "lagrange": ph.lagrange if ph.lagrange is not None else p.objective.lagrange,
                },
                "path_constraints": [*p.path_constraints, *ph.path_constraints],
            },
            "method": self.spec.method.model_dump(),
        }
        try:
            return OptimalControlSpec.model_validate(data)
        except SpecError as err:
            field = f"problem.phases.{k}.{(err.field or '').removeprefix('problem.')}".rstrip(".")
            raise SpecError(err.reason, field=field, source=self.source) from None
        except ValidationError as err:
            reason = err.errors()[0]["msg"]
            raise SpecError(reason, field=f"problem.phases.{k}", source=self.source) from None


def lower(spec: MultiPhaseSpec) -> Lowering:
    """``spec`` as one ``optimal_control`` spec (see the module doc), with what maps its Result back."""
    return _Lowerer(spec).lower()
