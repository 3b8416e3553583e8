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
  constraints of the one problem;
- measurements of phase ``k`` (its ``measurements:``): at time ``t`` the phase's normalized time
  ``s = (t - S_k) / D_k``, a number when every duration up to and with phase ``k`` is one (a free
  or parameter duration moves ``s`` with the solve or the parameters, and is refused); each
  measured key becomes the same expression over the copies of the piece that holds ``s``, and all
  phases' data one ``measurements:`` block of the one problem (times in ``s``; a key's entries at
  another key's times weighted 0), so that its misfit is the sum of the phases' least-squares terms.

The copies share the collocation grid of the one problem in their own normalized time. When the
phases set their own numbers of intervals ``N_k``, the grid has ``g = gcd(N_k)`` uniform intervals
and phase ``k`` is ``N_k / g`` consecutive *pieces* (copies ``x__k__j`` on ``t = S_k + D_k (j + s) /
m_k``, linked by continuity), so that each phase has exactly its ``N_k`` intervals and the NLP the
size of the sum (interval counts with a large common divisor keep the number of copies small).
Everything is built in SymPy over the names the file gives and printed with
:func:`~gamespec.symbolic.printer.to_text`; a bad expression is a SpecError naming the field of the
multi-phase file that holds it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import sympy as sp
from pydantic import ValidationError

from gamespec.errors import ExpressionError, SpecError
from gamespec.specs.ocp import NORMALIZED_TIME, OptimalControlSpec, is_time_varying, parameter_values
from gamespec.symbolic.language import TIME, parse, parse_relation, symbol
from gamespec.symbolic.printer import relation_texts, to_text
from gamespec.symbolic.translate import numeric

if TYPE_CHECKING:
    from gamespec.multiphase.spec import MultiPhaseSpec, PhaseSpec

SEPARATOR = "__"
"""Joins a name and a phase name in the lowered problem (``x__boost``); refused in user names."""


def copy_name(name: str, phase: str) -> str:
    """The lowered name of state or control ``name`` in ``phase``."""
    return f"{name}{SEPARATOR}{phase}"


def duration_name(phase: str) -> str:
    """The lowered name of ``phase``'s duration (a design variable or a parameter)."""
    return copy_name("duration", phase)


@dataclass(frozen=True)
class Piece:
    """One copy of a phase's states and controls on the common grid: user name → lowered name."""

    states: dict[str, str]
    controls: dict[str, str]


@dataclass(frozen=True)
class LoweredPhase:
    """One phase in the lowered problem: its pieces in order (one, or ``intervals / g`` when the
    phases set their own numbers of intervals, g their greatest common divisor), the lowered name of
    its duration, whether that is free, and the phase alone as a fixed-time ``optimal_control``
    spec in the file's names (``check_spec``, for the per-phase checks)."""

    name: str
    pieces: list[Piece]
    duration: str
    free: bool
    check_spec: OptimalControlSpec


@dataclass
class _Parts:
    """The lowered problem's sections as they are gathered, piece by piece."""

    states: dict[str, dict] = dataclasses.field(default_factory=dict)
    controls: dict[str, dict] = dataclasses.field(default_factory=dict)
    dynamics: dict[str, str] = dataclasses.field(default_factory=dict)
    path: list[str] = dataclasses.field(default_factory=list)
    boundary: list[str] = dataclasses.field(default_factory=list)
    guess: dict[str, dict[str, Any]] = dataclasses.field(
        default_factory=lambda: {"states": {}, "controls": {}}
    )
    lagrange: sp.Expr = dataclasses.field(default_factory=lambda: sp.Integer(0))
    integrands: list[sp.Expr] = dataclasses.field(default_factory=list)


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


def _phase_copies(pieces: list[Piece]) -> dict[str, tuple[str | None, str]]:
    """Per state and control of a phase, its copy in the first piece (None for a control the first
    piece lacks) and in the last: where the phase starts and ends."""
    first, last = pieces[0], pieces[-1]
    return {
        n: (first.states.get(n, first.controls.get(n)), c) for n, c in (last.states | last.controls).items()
    }


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
        self.functions = {n: t.named(n) for n, t in self.p.tables.items()}
        self.constants = self.params | self.design | self.functions
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

    def running(self, ph: PhaseSpec, k: int, piece: Piece, j: int, m: int) -> dict[str, Any]:
        """The symbols of piece ``j`` of ``m`` of phase ``k``: its lowered copies, at
        ``t = S_k + D_k (j + s) / m``; definitions expanded."""
        symbols = self.constants | {n: symbol(c) for n, c in (piece.states | piece.controls).items()}
        symbols["t"] = self.starts[k] + self.durations[k] * (j + TIME) / m
        for name, raw in (self.p.definitions | ph.definitions).items():
            where = f"phases.{k}.definitions.{name}" if name in ph.definitions else f"definitions.{name}"
            symbols[name] = _read(raw, symbols, where, self.source, phase=ph.name)
        return symbols

    def ends(self, phases: Mapping[str, tuple[str, Any]], t_first: sp.Expr, t_last: sp.Expr) -> dict:
        """End symbols ``<name>_0``, ``<name>_f`` (lowered ``<copy>_0`` of the piece that starts and
        ``<copy>_f`` of the one that ends, per name in ``phases``) and ``t_0``, ``t_f``."""
        found = dict(self.constants)
        for name, (first, last) in phases.items():
            if first is not None:
                found[f"{name}_0"] = symbol(f"{first}_0")
            if last is not None:
                found[f"{name}_f"] = symbol(f"{last}_f")
        return found | {"t_0": t_first, "t_f": t_last}

    def linked_ends(self, lowered: list[LoweredPhase]) -> dict[str, sp.Expr]:
        """Every phase's end symbols by name (``phases.<phase>.x_f``, ``phases.<phase>.t_0``; the
        module doc), for the problem's Mayer term and boundary constraints that link phases."""
        found = {}
        for k, phase in enumerate(lowered):
            own = self.ends(_phase_copies(phase.pieces), self.starts[k], self.starts[k + 1])
            found |= {f"phases.{phase.name}.{n}": v for n, v in own.items() if n not in self.constants}
        return found

    def grid(self) -> tuple[int, list[int]]:
        """The common number of intervals and each phase's number of pieces: ``method.intervals``
        and one piece each, unless a phase sets its own ``intervals`` (then their greatest common
        divisor g, and ``intervals / g`` pieces of g intervals per phase, on a uniform grid)."""
        method = self.spec.method
        if all(ph.intervals is None for ph in self.p.phases):
            return method.intervals, [1] * len(self.p.phases)
        if method.mesh is not None or method.grading != 1.0:
            raise SpecError(
                "phases that set their own intervals need a uniform method grid (no mesh, grading 1)",
                field="method",
                source=self.source,
            )
        counts = [ph.intervals or method.intervals for ph in self.p.phases]
        common = math.gcd(*counts)
        return common, [n // common for n in counts]

    def check_phase(self, ph: PhaseSpec, k: int) -> None:
        p = self.p
        undeclared = sorted((set(ph.dynamics) | set(ph.states) | set(ph.jump)) - set(p.states))
        if undeclared:
            raise SpecError(
                f"undeclared states {undeclared}", field=f"problem.phases.{k}", source=self.source
            )
        if k == 0 and ph.jump:
            raise SpecError("the first phase has no phase before it", field=f"problem.phases.{k}.jump")
        missing = [x for x in p.states if x not in ph.dynamics and x not in p.dynamics]
        if missing:
            raise SpecError(
                f"no dynamics for state {missing[0]!r} (neither the phase nor problem.dynamics gives them)",
                field=f"problem.phases.{k}.dynamics",
                source=self.source,
            )

    def lower(self) -> Lowering:
        p, spec = self.p, self.spec
        parameters: dict[str, Any] = dict(p.parameters)
        design = {n: d.model_dump() for n, d in p.design.items()}
        parts = _Parts(integrands=[sp.Integer(0) for _ in p.integral_constraints])
        lowered: list[LoweredPhase] = []
        timed = False
        spans = self.duration_guesses()
        common, counts = self.grid()
        for k, ph in enumerate(p.phases):
            self.check_phase(ph, k)
            name = duration_name(ph.name)
            if ph.duration.free:
                lo, hi = ph.duration.bounds
                design[name] = {"lower": lo, "upper": hi, "guess": ph.duration.guess}
            else:
                parameters[name] = ph.duration.value
            own = self.phase_controls(ph, k)
            m = counts[k]
            labels = [ph.name] if m == 1 else [f"{ph.name}{SEPARATOR}{j}" for j in range(m)]
            pieces = [
                Piece({n: copy_name(n, c) for n in p.states}, {n: copy_name(n, c) for n in own})
                for c in labels
            ]
            check_states = {x: self.phase_state(ph, k, x) for x in p.states}
            for j, piece in enumerate(pieces):
                self.piece(parts, ph, k, piece, j, m, check_states, spans)
                if j > 0:
                    for x in p.states:
                        start, end = symbol(f"{piece.states[x]}_0"), symbol(f"{pieces[j - 1].states[x]}_f")
                        parts.boundary.append(to_text(sp.Eq(start - end, 0, evaluate=False)))
            ends = self.ends(_phase_copies(pieces), self.starts[k], self.starts[k + 1])
            for i, text in enumerate(ph.boundary_constraints):
                rel = _read(text, ends, f"phases.{k}.boundary_constraints.{i}", self.source, relation=True)
                timed |= self.timed(rel.expr)
                parts.boundary += relation_texts(rel)
            if k > 0:
                before = lowered[-1].pieces[-1]
                prior = {n: (None, c) for n, c in (before.states | before.controls).items()}
                previous = self.ends(prior, self.starts[k - 1], self.starts[k])
                for x in p.states:
                    end = symbol(f"{before.states[x]}_f")
                    if x in ph.jump:
                        end = _read(ph.jump[x], previous, f"phases.{k}.jump.{x}", self.source)
                        timed |= self.timed(end)
                    start = symbol(f"{pieces[0].states[x]}_0")
                    parts.boundary.append(to_text(sp.Eq(start - end, 0, evaluate=False)))
            check = self.check_spec(ph, k, own, check_states)
            lowered.append(LoweredPhase(ph.name, pieces, name, ph.duration.free, check))
        first, final = lowered[0].pieces[0], lowered[-1].pieces[-1]
        names = {
            n: (first.states.get(n, first.controls.get(n)), final.states.get(n, final.controls.get(n)))
            for n in [*p.states, *p.controls]
        }
        ends = self.ends(names, self.starts[0], self.starts[-1])
        ends.pop("t_0")
        ends |= self.linked_ends(lowered)
        measured = self.measurements(lowered)
        mayer = _read(p.objective.mayer, ends, "objective.mayer", self.source)
        for i, text in enumerate(p.boundary_constraints):
            rel = _read(text, ends, f"boundary_constraints.{i}", self.source, relation=True)
            timed |= self.timed(rel.expr)
            parts.boundary += relation_texts(rel)
        data = {
            "kind": "optimal_control",
            "name": spec.name,
            "description": spec.description,
            "solver": spec.solver.model_dump(),
            "problem": {
                "parameters": parameters,
                "tables": {n: t.model_dump() for n, t in p.tables.items()},
                "states": parts.states,
                "controls": parts.controls,
                "design": design,
                "dynamics": parts.dynamics,
                "objective": {
                    "sense": p.objective.sense,
                    "mayer": to_text(mayer),
                    "lagrange": to_text(parts.lagrange),
                },
                "time": {"initial": 0.0, "final": 1.0},
                "path_constraints": parts.path,
                "boundary_constraints": parts.boundary,
                "integral_constraints": [
                    c.model_dump() | {"integrand": to_text(g)}
                    for c, g in zip(p.integral_constraints, parts.integrands, strict=True)
                ],
            },
            "method": spec.method.model_dump() | {"intervals": common},
            "guess": parts.guess,
        }
        if measured is not None:
            data["problem"]["measurements"] = measured
        try:
            target = OptimalControlSpec.model_validate(data)
        except (ValidationError, SpecError) as err:
            reason = err.reason if isinstance(err, SpecError) else str(err.errors()[0]["msg"])
            raise SpecError(f"the lowered problem is invalid: {reason}", field="problem.phases") from None
        target.with_source(spec.source, spec.file_hash)
        return Lowering(target, lowered, float(p.time.initial), timed)

    def measurements(self, lowered: list[LoweredPhase]) -> dict[str, Any] | None:
        """The phases' ``measurements:`` as one block of the lowered problem (the module doc), None
        when no phase has any; a SpecError naming the phase's field for a time outside the phase or
        a duration up to it that is not a number."""
        rows: list[tuple[float, str, float, float]] = []
        start = float(self.p.time.initial)
        for k, (ph, phase) in enumerate(zip(self.p.phases, lowered, strict=True)):
            value, field = ph.duration.value, f"problem.phases.{k}.measurements"
            if ph.measurements is not None:
                if not all(isinstance(q.duration.value, int | float) for q in self.p.phases[: k + 1]):
                    reason = (
                        "measurements need every duration up to and with their phase a number (a free or "
                        "parameter duration moves the measurement times in the phase's normalized time)"
                    )
                    raise SpecError(reason, field=field, source=self.source)
                rows += self.phase_rows(ph.measurements, k, phase.pieces, start, float(value), field)
            if isinstance(value, int | float):
                start += float(value)
        if not rows:
            return None
        times = [row[0] for row in rows]
        keys = list(dict.fromkeys(row[1] for row in rows))
        values = {key: [0.0] * len(rows) for key in keys}
        weights = {key: [0.0] * len(rows) for key in keys}
        for i, (_, key, measured, weight) in enumerate(rows):
            values[key][i], weights[key][i] = measured, weight
        return {"times": times, "values": values, "weights": weights}

    def phase_rows(
        self, data: Any, k: int, pieces: list[Piece], start: float, duration: float, field: str
    ) -> list[tuple[float, str, float, float]]:
        """Phase ``k``'s data as (lowered time, lowered key, value, weight), one per time and key."""
        m = len(pieces)
        weights = data.weight_rows()
        rows = []
        for i, t in enumerate(data.times):
            s = (float(t) - start) / duration
            if not -1e-12 <= s <= 1 + 1e-12:
                raise SpecError(
                    f"time {t} lies outside the phase [{start}, {start + duration}]",
                    field=f"{field}.times.{i}",
                    source=self.source,
                )
            j = min(int(max(s, 0.0) * m), m - 1)
            symbols = self.constants | {n: symbol(c) for n, c in pieces[j].states.items()}
            for key, measured in data.values.items():
                expr = _read(key, symbols, f"phases.{k}.measurements.values.{key}", self.source)
                local = min(max(s * m - j, 0.0), 1.0)
                rows.append((local, to_text(expr), float(measured[i]), weights[key][i]))
        return rows

    def phase_state(self, ph: PhaseSpec, k: int, x: str) -> dict[str, Any]:
        """State ``x`` in phase ``k``: its bounds there, its value at the phase's start (the shared
        initial value in the first phase) and end (the shared final value in the last)."""
        shared, mine = self.p.states[x], ph.states.get(x)
        entry = _merged(shared, mine)
        entry["initial"] = mine.initial if mine and mine.initial is not None else None
        entry["final"] = mine.final if mine and mine.final is not None else None
        if k == 0 and entry["initial"] is None:
            entry["initial"] = shared.initial
        if k == len(self.p.phases) - 1 and entry["final"] is None:
            entry["final"] = shared.final
        return entry

    def piece(
        self,
        parts: _Parts,
        ph: PhaseSpec,
        k: int,
        piece: Piece,
        j: int,
        m: int,
        phase_states: dict[str, dict],
        spans: list[sp.Expr],
    ) -> None:
        """Add piece ``j`` of ``m`` of phase ``k`` to ``parts``: its states (the phase's start value
        on the first piece, its end value on the last), controls, dynamics, running cost, integrands,
        path constraints and guess."""
        p, field = self.p, f"phases.{k}"
        running = self.running(ph, k, piece, j, m)
        D = self.durations[k] / m
        for x, lowered in piece.states.items():
            entry = dict(phase_states[x])
            entry["initial"] = entry["initial"] if j == 0 else None
            entry["final"] = entry["final"] if j == m - 1 else None
            parts.path += self.time_bounds(entry, running[x], running, f"{field}.states.{x}")
            parts.states[lowered] = entry
            raw = ph.dynamics.get(x, p.dynamics.get(x))
            where = f"{field}.dynamics.{x}" if x in ph.dynamics else f"dynamics.{x}"
            parts.dynamics[lowered] = to_text(D * _read(raw, running, where, self.source, phase=ph.name))
        for u, lowered in piece.controls.items():
            entry = dict(self.phase_controls(ph, k)[u])
            parts.path += self.time_bounds(entry, running[u], running, f"{field}.controls.{u}")
            parts.controls[lowered] = entry
        cost = ph.lagrange if ph.lagrange is not None else p.objective.lagrange
        where = f"{field}.lagrange" if ph.lagrange is not None else "objective.lagrange"
        parts.lagrange += D * _read(cost, running, where, self.source, phase=ph.name)
        for i, c in enumerate(p.integral_constraints):
            where = f"integral_constraints.{i}.integrand"
            parts.integrands[i] += D * _read(c.integrand, running, where, self.source, phase=ph.name)
        texts = [(f"path_constraints.{i}", c) for i, c in enumerate(p.path_constraints)]
        texts += [(f"{field}.path_constraints.{i}", c) for i, c in enumerate(ph.path_constraints)]
        for where, text in texts:
            parts.path += relation_texts(_read(text, running, where, self.source, True, ph.name))
        tau = symbol(NORMALIZED_TIME)
        along = self.params | {NORMALIZED_TIME: tau}
        for group, given, renames in (
            ("states", ph.guess.states, piece.states),
            ("controls", ph.guess.controls, piece.controls),
        ):
            unknown = sorted(set(given) - set(renames))
            if unknown:
                raise SpecError(
                    f"names no {group[:-1]} of this phase: {unknown}",
                    field=f"problem.{field}.guess.{group}",
                    source=self.source,
                )
            for n, raw in given.items():
                expr = _read(raw, along, f"{field}.guess.{group}.{n}", self.source)
                parts.guess[group][renames[n]] = to_text(expr.subs(tau, (j + tau) / m))
        parts.guess["states"] |= self.spread_guess(ph, k, (j, m), spans, piece.states)

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
        self, ph: PhaseSpec, k: int, at: tuple[int, int], spans: list[sp.Expr], names: dict[str, str]
    ) -> dict[str, str]:
        """For each state the phase gives no guess for whose value is fixed at the start of the
        first phase and at the end of the last: the straight line between them over the whole
        horizon (duration guesses), as an expression of the normalized time of piece ``at = (j, m)``."""
        tau = symbol(NORMALIZED_TIME)
        j, m = at
        start, total = sum(spans[:k], sp.Integer(0)), sum(spans, sp.Integer(0))
        found = {}
        for x, st in self.p.states.items():
            if x in ph.guess.states or st.initial is None or st.final is None:
                continue
            a = _read(st.initial, self.params, f"states.{x}.initial", self.source)
            b = _read(st.final, self.params, f"states.{x}.final", self.source)
            fraction = (start + spans[k] * (j + tau) / m) / total
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
                "tables": {n: t.model_dump() for n, t in p.tables.items()},
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
