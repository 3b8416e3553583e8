"""A Result of a lowered multi-phase problem (:mod:`gamespec.multiphase.lowering`) split back by phase.

Each phase's copy of the states, controls and costates goes onto its own time ``t = S_k + D_k s``
and the phases are laid end to end: ``time``, ``states``, ``control_time``, ``controls`` and the
costates run over the whole horizon, every phase boundary appearing twice (the end of one phase and
the start of the next, different across a jump); a control a phase does not have is NaN there.
``arrays["phase"]`` is the phase index of each point of ``time`` (``arrays["control_phase"]`` of
``control_time``), ``metrics["phases"]`` the name, start, end and duration of each phase.

Checks: the lowered problem's ``max_constraint_violation`` (bounds, path constraints, links and jumps,
boundary constraints of every phase), ``max_defect`` and ``max_defect_relative`` (the largest over the
phases) and ``chattering``; and per phase, under ``<check>/<phase>``, the checks of
:func:`gamespec.ocp.checks.solution_checks` on the phase alone (its defects, bounds and path
constraints, its controls' swings and, on autonomous phases, the variation of its Hamiltonian
``H_k = sign L_k + lambda^T f_k``). The costates of a phase are the lowered ones: the defect rows
of ``dx/ds = D_k f_k`` are those of the phase on its own horizon ``D_k``. On a phase whose duration
is free, stationarity of the one NLP in ``D_k`` is the transversality condition of a switching time,
``integral_0^1 H_k ds = -dPhi/dt_f`` (eq. 2.23 per phase) when nothing but the Mayer term depends on
the phase times (no explicit ``t``, no ``t_0``/``t_f`` in jumps or boundary constraints):
``hamiltonian_end_error/<phase>`` is then ``max |H_k + dPhi/dt_f|``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.multiphase.lowering import LoweredPhase, Lowering
from gamespec.ocp.checks import Trajectory, hamiltonian, mayer_slope, solution_checks
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.result import Result
from gamespec.specs.ocp import TimeSpec
from gamespec.symbolic.grammar import dependencies

OVERALL_CHECKS = ("max_constraint_violation", "max_defect", "max_defect_relative", "chattering")
"""Checks of the lowered problem that keep their meaning for the whole multi-phase problem."""


def _phase_transcription(phase: LoweredPhase, start: float, end: float, breaks: np.ndarray) -> Transcription:
    """The phase alone on its solved horizon and the lowered (possibly refined) mesh."""
    spec = phase.check_spec
    problem = spec.problem.model_copy(update={"time": TimeSpec(initial=start, final=end)})
    method = spec.method.model_copy(update={"mesh": breaks.tolist(), "intervals": len(breaks) - 1})
    return Transcription(spec.model_copy(update={"problem": problem, "method": method}))


def _end_value(
    lowering: Lowering, lowered: Transcription, X: np.ndarray, U: np.ndarray, values: dict, t_final: float
) -> float:
    """``-dPhi/dd`` at the solution for the last phase's duration ``d`` (``Phi`` in minimization
    form), from the lowered Mayer term."""
    others = {n: np.float64(v) for n, v in values.items()}
    ends = lowered.ocp.end_values((X[:, 0], X[:, -1]), lowered.end_controls(U), np.float64(t_final), others)
    return -mayer_slope(lowered, ends, lowering.phases[-1].duration)


def _switching_times_free(lowering: Lowering) -> bool:
    """Whether only the Mayer term depends on the phase times: no jump or boundary constraint uses
    them, and no phase uses ``t`` (dynamics, running cost, path constraints, bounds)."""
    if lowering.timed_links:
        return False
    for ph in lowering.phases:
        ocp = SymbolicOcp(ph.check_spec)
        if not ocp.autonomous or any("t" in dependencies(r.expr) for r in ocp.running_structure.path):
            return False
    return True


def _joined(parts: list[np.ndarray], at_nodes: bool) -> np.ndarray:
    """A phase's values from those of its pieces in order: at the nodes the start of each piece
    after the first is the end of the one before (continuity) and is dropped; at the evaluation
    points (none at a piece's start) they are laid end to end."""
    if at_nodes:
        parts = [parts[0], *(p[..., 1:] for p in parts[1:])]
    return np.concatenate(parts, axis=-1)


@dataclass(frozen=True)
class PhaseArrays:
    """One phase's solution on its own normalized time: nodes, evaluation points and interval
    boundaries in [0, 1], states (rows in the file's order), controls (by name) and costates."""

    s_nodes: np.ndarray
    s_eval: np.ndarray
    breaks: np.ndarray
    X: np.ndarray
    controls: dict[str, np.ndarray]
    lam: np.ndarray | None


def phase_arrays(
    result: Result, phase: LoweredPhase, grid: tuple[np.ndarray, np.ndarray, np.ndarray]
) -> PhaseArrays:
    """``phase``'s pieces joined (see :func:`_joined`); ``grid``: the lowered nodes, evaluation
    points and interval boundaries."""
    m = len(phase.pieces)
    s_nodes, s_eval, breaks = ([(j + g) / m for j in range(m)] for g in grid)
    names = list(phase.pieces[0].states)
    X = _joined([np.array([result.states[pc.states[n]] for n in names]) for pc in phase.pieces], True)
    controls = {
        n: _joined([result.controls[pc.controls[n]] for pc in phase.pieces], False)
        for n in phase.pieces[0].controls
    }
    lam = None
    if all(f"lambda_{c}" in result.costates for pc in phase.pieces for c in pc.states.values()):
        lam = _joined(
            [np.array([result.costates[f"lambda_{pc.states[n]}"] for n in names]) for pc in phase.pieces],
            False,
        )
    return PhaseArrays(
        _joined(s_nodes, True), _joined(s_eval, False), _joined(breaks, True), X, controls, lam
    )


def split_by_phase(result: Result, lowering: Lowering) -> Result:
    """``result`` (of ``lowering.target``) as the multi-phase problem's Result (see the module doc)."""
    if result.time is None or not result.states:
        return result
    lowered = Transcription(lowering.target)
    values = dict(result.parameters) | result.metrics.get("design", {})
    durations = np.array([values[ph.duration] for ph in lowering.phases])
    starts = lowering.t0 + np.concatenate([[0.0], np.cumsum(durations)])
    s_nodes = np.asarray(result.time)
    s_eval = np.asarray(result.control_time if result.control_time is not None else result.time)
    grid = (s_nodes, s_eval, s_nodes[:: lowered.grid.points_per_interval])
    X_all = np.array([result.states[n] for n in lowered.ocp.states])
    U_all = np.array([result.controls[n] for n in lowered.ocp.controls]).reshape(lowered.n_u, len(s_eval))
    state_names = list(lowering.phases[0].pieces[0].states)
    control_names = list(dict.fromkeys(n for ph in lowering.phases for n in ph.pieces[0].controls))
    joined: dict[str, list[np.ndarray]] = {"time": [], "control_time": [], "phase": [], "control_phase": []}
    states = {n: [] for n in state_names}
    controls = {n: [] for n in control_names}
    costates: dict[str, list[np.ndarray]] = {f"lambda_{n}": [] for n in state_names}
    checks = {k: result.checks[k] for k in OVERALL_CHECKS if k in result.checks}
    skipped: dict[str, str] = {}
    end_value = None
    if _switching_times_free(lowering):
        end_value = _end_value(lowering, lowered, X_all, U_all, values, float(s_nodes[-1]))
    for k, ph in enumerate(lowering.phases):
        arrays = phase_arrays(result, ph, grid)
        tr = _phase_transcription(ph, starts[k], starts[k + 1], arrays.breaks)
        joined["time"].append(starts[k] + durations[k] * arrays.s_nodes)
        joined["control_time"].append(starts[k] + durations[k] * arrays.s_eval)
        joined["phase"].append(np.full(len(arrays.s_nodes), k))
        joined["control_phase"].append(np.full(len(arrays.s_eval), k))
        for i, n in enumerate(state_names):
            states[n].append(arrays.X[i])
        for n in control_names:
            controls[n].append(arrays.controls.get(n, np.full(len(arrays.s_eval), np.nan)))
        lam = arrays.lam
        for i, n in enumerate(state_names if lam is not None else []):
            costates[f"lambda_{n}"].append(lam[i])
        U = np.array([arrays.controls[n] for n in tr.ocp.controls]).reshape(tr.n_u, len(arrays.s_eval))
        sol = Trajectory(arrays.X, U, np.zeros((0, U.shape[1])), float(durations[k]))
        own, left_out = solution_checks(tr, sol, values, lam)
        if lam is not None and ph.free and end_value is not None and "hamiltonian_variation" in own:
            H = hamiltonian(tr, sol, values, lam)
            own["hamiltonian_end_error"] = float(np.max(np.abs(H - end_value)))
        checks |= {f"{name}/{ph.name}": value for name, value in own.items()}
        skipped |= {f"{name}/{ph.name}": reason for name, reason in left_out.items()}
    has_costates = all(len(v) == len(lowering.phases) for v in costates.values())
    extra = {k: v for k, v in result.arrays.items() if k != "costate_time"}
    extra |= {
        "phase": np.concatenate(joined["phase"]),
        "control_phase": np.concatenate(joined["control_phase"]),
    }
    if has_costates:
        extra["costate_time"] = np.concatenate(joined["control_time"])
    user = lowering.phases[0].check_spec.problem.design
    design = {n: v for n, v in result.metrics.get("design", {}).items() if n in user}
    phases = [
        {
            "name": ph.name,
            "start": float(starts[k]),
            "end": float(starts[k + 1]),
            "duration": float(durations[k]),
            "free": ph.free,
        }
        for k, ph in enumerate(lowering.phases)
    ]
    metrics = {k: v for k, v in result.metrics.items() if k not in ("design", "checks_skipped")}
    metrics |= {"phases": phases} | ({"checks_skipped": skipped} if skipped else {})
    if design:
        metrics["design"] = design
    return result.model_copy(
        update={
            "time": np.concatenate(joined["time"]),
            "control_time": np.concatenate(joined["control_time"]),
            "t_final": float(starts[-1]),
            "states": {n: np.concatenate(v) for n, v in states.items()},
            "controls": {n: np.concatenate(v) for n, v in controls.items()},
            "costates": {n: np.concatenate(v) for n, v in costates.items()} if has_costates else {},
            "arrays": extra,
            "checks": checks,
            "metrics": metrics,
        }
    )
