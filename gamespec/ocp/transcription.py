"""What every direct-collocation backend shares: the grid, bounds and initial guesses as arrays, and
the assembly of a Result from a solution (with the solver-independent checks).

Variables: ``X`` (n_x × n_nodes), ``U`` (n_u × n_eval), and the horizon ``T = t_f - t0``. Grid
inputs ``Win`` (n_w × n_eval) are data at the evaluation points, where the controls are
(:mod:`gamespec.ocp.inputs`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from gamespec.errors import ExpressionError, SpecError
from gamespec.ocp.checks import (
    ARRAYS,
    Trajectory,
    check_tolerances,
    control_basis,
    solution_checks,
    verdicts,
)
from gamespec.ocp.collocation import Grid
from gamespec.ocp.diagnostics import Point, non_finite_report
from gamespec.ocp.events import InteriorPoints, with_event_breaks
from gamespec.ocp.inputs import InputGrid, InputValue, on_grid
from gamespec.ocp.scaling import Scaling, variable_scaling
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result, Status
from gamespec.specs.ocp import INITIAL_TIME, NORMALIZED_TIME, OptimalControlSpec, bounds_midpoint
from gamespec.symbolic.grammar import Relation, dependencies, expression, taken, unknowns

UNCHECKED = "solution checks not computed (Transcription.checked is off: the caller reads none of them)"
"""Why a Result of :meth:`Transcription.result` has no checks when they are turned off: its
``metrics.checks_skipped`` says so, and it is ``feasible``, not ``optimal`` (nothing verified it)."""


@dataclass(frozen=True)
class Bounds:
    """Variable bounds of one solve (after parameter values are known)."""

    x_lower: np.ndarray
    x_upper: np.ndarray
    u_lower: np.ndarray
    u_upper: np.ndarray
    t_lower: float
    t_upper: float
    d_lower: np.ndarray
    d_upper: np.ndarray


@dataclass(frozen=True)
class Guess:
    """A starting point: X, U, the horizon T and the design variables d."""

    X: np.ndarray
    U: np.ndarray
    T: float
    d: np.ndarray


class Transcription:
    """The discretized form of an ``optimal_control`` spec, independent of any backend."""

    def __init__(self, spec: OptimalControlSpec, parsed: SymbolicOcp | None = None) -> None:
        """The transcription of ``spec`` on its mesh; ``parsed``: its problem as another mesh's
        transcription parsed it (:mod:`gamespec.compiling.refinement`, which changes the method
        only), whose kept walks this one takes again (issue 27, item 3)."""
        shared = parsed is None or (parsed.spec.problem is spec.problem and parsed.spec.guess is spec.guess)
        if not shared:
            raise ValueError("a transcription shares the parsed problem of its own problem only")
        self.spec = spec
        self.ocp = (parsed or SymbolicOcp(spec)).kept_for_solves()
        m = spec.method
        mesh = None if m.mesh is None else tuple(m.mesh)
        degrees = None if m.degrees is None else tuple(m.degrees)
        grid = Grid(m.scheme, m.intervals, m.degree if m.scheme == "radau" else 1, m.grading, mesh, degrees)
        self.grid = with_event_breaks(grid, spec) if mesh is None and degrees is None else grid
        self.t0 = spec.problem.time.origin
        self._last_bounds: tuple[tuple[tuple[str, float], ...], Bounds] | None = None
        self.checked = True
        """Whether :meth:`result` computes the solution checks (a caller that reads none of them,
        a receding horizon's best responses, turns them off: see :data:`UNCHECKED`)."""

    @cached_property
    def interior(self) -> InteriorPoints:
        """The ``at:`` constraints and ``measurements:`` (:mod:`gamespec.ocp.events`)."""
        return InteriorPoints(self)

    @property
    def n_x(self) -> int:
        return len(self.ocp.states)

    @property
    def n_u(self) -> int:
        return len(self.ocp.controls)

    @property
    def n_w(self) -> int:
        return len(self.ocp.inputs)

    @property
    def n_d(self) -> int:
        return len(self.ocp.design)

    @property
    def free_time(self) -> bool:
        """Whether the horizon ``T`` is a decision variable (a free final or initial time)."""
        time = self.spec.problem.time
        return time.free or time.free_initial

    def input_grid(self, params: Mapping[str, float] | None = None) -> InputGrid:
        """Where grid inputs are tabulated: the evaluation points in normalized time and, for a fixed
        horizon, in time (the Result's ``control_time``) for these runtime parameter values."""
        return self._input_grid_at(self.ocp.parameter_values(params))

    def _input_grid_at(self, values: Mapping[str, float]) -> InputGrid:
        """:meth:`input_grid` for every parameter's value (derived ones included)."""
        tau = self.grid.eval_tau
        if self.free_time:
            return InputGrid(tau, None)
        _, tf, _ = self.ocp.final_time(values)
        return InputGrid(tau, self.t0 + (tf - self.t0) * tau)

    def input_values(
        self, params: Mapping[str, float], given: Mapping[str, InputValue] | None = None
    ) -> np.ndarray:
        """The inputs at the evaluation points (n_w × n_eval): ``given`` ones (values per point, or
        ``(times, values)`` samples resampled), the spec's defaults for the rest; a SpecError naming
        an unknown input or a bad value."""
        given = dict(given or {})
        unknown = sorted(set(given) - set(self.ocp.inputs))
        if unknown:
            raise SpecError(
                f"unknown input(s) {', '.join(unknown)} (declared: {', '.join(self.ocp.inputs) or 'none'})",
                field="inputs",
                source=self.spec.source,
            )
        grid = self._input_grid_at(params)
        rows = [
            on_grid(name, given[name], grid, self.spec.source)
            if name in given
            else self._profile(
                spec.default, grid.tau, params, f"problem.inputs.{name}.default", None, None, 0.0, 0.0
            )
            for name, spec in self.spec.problem.inputs.items()
        ]
        return np.array(rows, dtype=float).reshape(self.n_w, len(grid))

    def bounds(self, params: Mapping[str, float]) -> Bounds:
        """Bounds on X, U and T; fixed initial/final states are bounds with lower == upper (those of
        the last parameter values kept: a solve, its checks and a game's evaluation of the point
        ask for them several times)."""
        key = tuple((n, float(v)) for n, v in params.items())
        if self._last_bounds is not None and self._last_bounds[0] == key:
            return self._last_bounds[1]
        found = self._bounds(params)
        self._last_bounds = (key, found)
        return found

    def _bounds(self, params: Mapping[str, float]) -> Bounds:
        n = self.grid.n_nodes
        xl = np.empty((self.n_x, n))
        xu = np.empty((self.n_x, n))
        for i, (lo, hi, x0, xf) in enumerate(self.ocp.state_bounds(params)):
            xl[i], xu[i] = lo, hi
            for col, fixed in ((0, x0), (-1, xf)):
                if fixed is not None:
                    xl[i, col] = xu[i, col] = fixed
        cb = np.array(self.ocp.control_bounds(params)).reshape(self.n_u, 2)
        k = len(self.grid.eval_index)
        ul = np.repeat(cb[:, :1], k, axis=1)
        uu = np.repeat(cb[:, 1:], k, axis=1)
        t_lo, t_hi, _ = self.ocp.horizon(params)
        db = np.array(self.ocp.design_bounds(params)).reshape(self.n_d, 3)
        return Bounds(xl, xu, ul, uu, t_lo, t_hi, db[:, 0], db[:, 1])

    def guess(self, params: Mapping[str, float], previous: Result | None = None) -> Guess:
        """The starting point: from ``previous`` (or the spec's ``guess.result`` file), else from the
        spec's ``guess`` section, else linear between fixed end values and mid-bounds controls."""
        if previous is None and self.spec.guess.result:
            try:
                previous = Result.load(self.spec.guess.result)
            except SpecError as err:
                reason = f"{err.source}: {err.reason}"
                raise SpecError(reason, field="guess.result", source=self.spec.source) from None
        if previous is not None and previous.time is not None and previous.states:
            return self._guess_from_result(previous)
        *_, horizon = self.ocp.horizon(params)
        tau_nodes = self.grid.nodes
        X = np.empty((self.n_x, self.grid.n_nodes))
        for i, (name, (lo, hi, x0, xf)) in enumerate(
            zip(self.ocp.states, self.ocp.state_bounds(params), strict=True)
        ):
            raw = self.spec.guess.states.get(name, "linear")
            X[i] = self._profile(raw, tau_nodes, params, f"guess.states.{name}", x0, xf, lo, hi)
        U = np.empty((self.n_u, len(self.grid.eval_index)))
        for j, (name, (lo, hi)) in enumerate(
            zip(self.ocp.controls, self.ocp.control_bounds(params), strict=True)
        ):
            raw = self.spec.guess.controls.get(name, "linear")
            U[j] = self._profile(
                raw, self.grid.eval_tau, params, f"guess.controls.{name}", None, None, lo, hi
            )
        d = np.array([g for *_, g in self.ocp.design_bounds(params)], dtype=float)
        self._off_flat_boundary(X, U, self.t0 + horizon, params, d)
        return Guess(X, U, horizon, d)

    def _off_flat_boundary(
        self, X: np.ndarray, U: np.ndarray, tf: float, params: Mapping[str, float], d: np.ndarray
    ) -> None:
        """Move the ``linear`` guess of the states free at both ends (the middle of their bounds, 0
        when unbounded) off a point where a boundary constraint over their end values has a zero
        gradient (``x_0**2 + v_0**2 == 1`` at the origin: no Newton step can reach it), by a quarter
        of their bounds' width (1 toward the open side when a bound is infinite)."""
        bounds = self.ocp.state_bounds(params)
        free = [
            i
            for i, (name, (_, _, x0, xf)) in enumerate(zip(self.ocp.states, bounds, strict=True))
            if x0 is None and xf is None and name not in self.spec.guess.states
        ]
        if not free or not self.spec.problem.boundary_constraints:
            return
        values = dict(params) | dict(zip(self.ocp.design, map(float, d), strict=True)) | {"t_f": float(tf)}
        for names, rows in ((self.ocp.states, X), (self.ocp.controls, U)):
            for name, row in zip(names, rows, strict=True):
                values |= {f"{name}_0": float(row[0]), f"{name}_f": float(row[-1])}
        ends = [f"{self.ocp.states[i]}_{e}" for i in free for e in "0f"]
        texts = zip(self.ocp.kept_boundary, self.spec.problem.boundary_constraints, strict=True)
        if any(_flat(kept, text, values, ends) for kept, text in texts):
            for i in free:
                lo, hi = bounds[i][:2]
                X[i] += (
                    0.25 * (hi - lo)
                    if np.isfinite(lo) and np.isfinite(hi)
                    else -1.0
                    if np.isfinite(hi)
                    else 1.0
                )

    def _profile(
        self,
        raw: float | str,
        tau: np.ndarray,
        params: Mapping[str, float],
        field: str,
        start: float | None,
        end: float | None,
        lo: float,
        hi: float,
    ) -> np.ndarray:
        if isinstance(raw, int | float):
            return np.full_like(tau, float(raw))
        if raw == "linear":
            a, b = _linear_ends(start, end, lo, hi)
            return a + (b - a) * tau
        kept = self.ocp.profiles.get(field)
        values = dict(params) | {NORMALIZED_TIME: tau}
        try:
            value = expression(raw, values, ARRAYS) if kept is None else taken(kept, values, raw)
        except ExpressionError as err:
            raise SpecError(str(err), field=field, source=self.spec.source) from None
        return np.broadcast_to(np.asarray(value, dtype=float), tau.shape).copy()

    def _guess_from_result(self, previous: Result) -> Guess:
        t = np.asarray(previous.time)
        span = t[-1] - t[0]
        tau_prev = (t - t[0]) / span
        missing = [n for n in self.ocp.states if n not in previous.states]
        missing += [n for n in self.ocp.controls if n not in previous.controls]
        if missing:
            raise SpecError(
                f"guess result lacks {', '.join(missing)}", field="guess.result", source=self.spec.source
            )
        X = np.array([np.interp(self.grid.nodes, tau_prev, previous.states[n]) for n in self.ocp.states])
        tc = np.asarray(previous.control_time if previous.control_time is not None else t)
        tau_c = (tc - t[0]) / span
        U = np.array([np.interp(self.grid.eval_tau, tau_c, previous.controls[n]) for n in self.ocp.controls])
        design = previous.metrics.get("design", {})
        defaults = [g for *_, g in self.ocp.design_bounds(previous.parameters or self.ocp.parameter_values())]
        d = np.array([design.get(n, g) for n, g in zip(self.ocp.design, defaults, strict=True)], dtype=float)
        k = len(self.grid.eval_index)
        return Guess(X.reshape(self.n_x, self.grid.n_nodes), U.reshape(self.n_u, k), float(span), d)

    @cached_property
    def start_weights(self) -> np.ndarray:
        """Weights on the first interval's controls giving the control at the initial time (the
        interval's interpolating polynomial extrapolated to its start, Radau; the first node's value,
        trapezoidal)."""
        return control_basis(self, np.array([0.0]))[0]

    def end_controls(self, U: Any) -> tuple[list[Any], list[Any]]:
        """The controls at the initial and the final time (``<control>_0``, ``<control>_f``) as linear
        functions of ``U``, anything indexed ``U[j, point]`` (a NumPy array, a CasADi matrix, a Pyomo
        Var)."""
        last_point = len(self.grid.eval_index) - 1
        first = [sum(float(w) * U[j, c] for c, w in enumerate(self.start_weights)) for j in range(self.n_u)]
        last = [U[j, last_point] for j in range(self.n_u)]
        return first, last

    def scales(self, params: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
        """Per state and per control, the factor the NLP divides the variable (and a state's defect
        rows) by: :func:`gamespec.ocp.scaling.variable_scaling`, the same factors on every backend."""
        found = self.scaling(params)
        return found.states, found.controls

    def scaling(self, params: Mapping[str, float]) -> Scaling:
        """The scale factors with the warning :mod:`gamespec.ocp.scaling` gives."""
        return variable_scaling(self, params)

    @cached_property
    def compiled_scaling(self) -> Scaling:
        """The factors a backend compiles with (the file's parameter values): the Result reports
        them (``metrics["scaling"]``, where any is not 1) and their warning."""
        return self.scaling(self.ocp.parameter_values())

    def _with_non_finite(self, message: str, at: Point, params: Mapping[str, float]) -> str:
        """``message`` with the file's expression that is NaN or infinite at ``at``, else at the
        file's starting point for ``params`` (:mod:`gamespec.ocp.diagnostics`), where one is."""
        try:
            report = non_finite_report(self, at)
            if report is None:
                start = self.guess(params)
                values = dict(params) | dict(zip(self.ocp.design, map(float, start.d), strict=True))
                report = non_finite_report(self, Point(start.X, start.U, start.T, at.inputs, values))
                report = None if report is None else f"at the starting point, {report}"
        except (SpecError, ExpressionError, ArithmeticError, ValueError, TypeError):
            return message  # the diagnosis is a courtesy: a failed Result stays a Result
        return message if report is None else f"{message}: {report}"

    def _scaling_metrics(self) -> dict[str, Any]:
        found = self.compiled_scaling
        scaled = {
            group: {n: float(s) for n, s in zip(names, factors, strict=True) if s != 1.0}
            for group, names, factors in (
                ("states", self.ocp.states, found.states),
                ("controls", self.ocp.controls, found.controls),
            )
        }
        entry: dict[str, Any] = {k: v for k, v in scaled.items() if v}
        if found.warning:
            entry["warning"] = found.warning
        return {"scaling": entry} if entry else {}

    def rate_penalty(self, U: Any) -> Any:
        """``w * sum_j sum_k (U[j, k+1] - U[j, k])**2 / (tau_{k+1} - tau_k)`` over consecutive
        evaluation points (``method.control_rate_penalty``; 0 when w is 0), a discrete
        ``w * integral of |du/dtau|**2``, for NumPy, CasADi or Pyomo ``U`` alike."""
        weight = self.spec.method.control_rate_penalty
        if weight == 0.0:
            return 0.0
        inverse = 1.0 / np.diff(self.grid.eval_tau)
        return weight * sum(
            float(c) * (U[j, k + 1] - U[j, k]) ** 2 for j in range(self.n_u) for k, c in enumerate(inverse)
        )

    @cached_property
    def costate_rows(self) -> np.ndarray:
        return self.grid.costate_scale()

    def result(
        self,
        *,
        X: np.ndarray,
        U: np.ndarray,
        T: float,
        objective: float | None,
        params: Mapping[str, float],
        status: Status,
        message: str,
        solve_time_s: float,
        iterations: int | None,
        inputs: np.ndarray,
        design: np.ndarray | None = None,
        defect_multipliers: np.ndarray | None = None,
        integral_multipliers: np.ndarray | None = None,
        solver_stats: dict | None = None,
    ) -> Result:
        """A Result from a solution, with costates from the defect multipliers, the checks, the
        grid inputs used (``arrays["input/<name>"]``, on ``control_time``), the mesh the controls
        are held on (``arrays["control_mesh"]``, :mod:`gamespec.ocp.control_signal`), the optimized
        design variables (``metrics["design"]``), a pass/fail verdict per check against its
        tolerance (``metrics["checks_passed"]`` and ``metrics["check_tolerances"]``, see
        :func:`~gamespec.ocp.checks.verdicts`) and the checks left out with the reason
        (``metrics["checks_skipped"]``; all of them, ``feasible``, when :attr:`checked` is off).
        ``integral_multipliers``: the NLP multipliers of the integral constraints' rows, which enter
        the Hamiltonian check."""
        if objective is not None:
            objective -= self.ocp.sign * float(self.rate_penalty(U))
        values = np.zeros(self.n_d) if design is None else np.asarray(design, dtype=float)
        optimized = {n: float(v) for n, v in zip(self.ocp.design, values, strict=True)}
        origin = self.t0 + optimized.get(INITIAL_TIME, 0.0)
        t_nodes = origin + T * self.grid.nodes
        t_eval = origin + T * self.grid.eval_tau
        costates: dict[str, np.ndarray] = {}
        arrays = {f"input/{n}": inputs[i] for i, n in enumerate(self.ocp.inputs)}
        arrays["control_mesh"] = origin + T * self.grid.breaks
        lam = None
        if defect_multipliers is not None and self.grid.scheme == "radau":
            lam = defect_multipliers * self.costate_rows[None, :]
            costates = {f"lambda_{n}": lam[i] for i, n in enumerate(self.ocp.states)}
        if self.checked:
            checks, skipped = solution_checks(
                self, Trajectory(X, U, inputs, T), {**params, **optimized}, lam, integral_multipliers
            )
        else:
            checks, skipped = {}, {"solution_checks": UNCHECKED}
            if status is Status.OPTIMAL:
                status, message = Status.FEASIBLE, f"{message}; not verified optimal: {UNCHECKED}"
        refine = self.spec.method.refine
        tolerances = check_tolerances(checks, refine.tolerance if refine else None)
        if lam is not None:
            arrays["costate_time"] = t_eval
        if status in (Status.NUMERICAL_ERROR, Status.ERROR):
            message = self._with_non_finite(message, Point(X, U, T, inputs, {**params, **optimized}), params)
        warning = self.compiled_scaling.warning
        return Result(
            status=status,
            message=f"{message}; scaling: {warning}" if warning else message,
            objective=objective,
            t_final=origin + T,
            solve_time_s=solve_time_s,
            iterations=iterations,
            time=t_nodes,
            control_time=t_eval,
            states={n: X[i] for i, n in enumerate(self.ocp.states)},
            controls={n: U[j] for j, n in enumerate(self.ocp.controls)},
            costates=costates,
            arrays=arrays,
            parameters=dict(params),
            checks=checks,
            metrics=({"design": optimized} if optimized else {})
            | {"checks_passed": verdicts(checks, tolerances), "check_tolerances": tolerances}
            | ({"checks_skipped": skipped} if skipped else {})
            | self._scaling_metrics()
            | {
                "plot": {
                    **self.spec.plot.as_metrics(),
                    "path_constraints": list(self.spec.problem.path_constraints),
                }
            },
            solver_stats=solver_stats or {},
        )


def _flat(kept: Relation | None, text: str, values: Mapping[str, float], names: list[str]) -> bool:
    """Whether the constraint ``text`` (``kept``: its walk kept over the end names,
    :attr:`~gamespec.ocp.symbolic.SymbolicOcp.kept_boundary`; None for one the walk refuses there)
    uses some of ``names`` and its gradient in them vanishes at ``values`` (central differences;
    False where it is not defined there)."""
    if kept is None:
        return False
    try:
        used = dependencies(taken(kept.expr, dict(values) | unknowns(names), text)) & set(names)
        slopes = []
        for name in used:
            h = 1e-6 * max(1.0, abs(values[name]))
            up, down = (taken(kept.expr, dict(values) | {name: values[name] + s}, text) for s in (h, -h))
            slopes.append(abs(up - down) / (2 * h))
    except ExpressionError:
        return False
    return bool(slopes) and max(slopes) <= 1e-12


def _linear_ends(start: float | None, end: float | None, lo: float, hi: float) -> tuple[float, float]:
    """The end values of the ``linear`` guess: the fixed end values; from a fixed end toward the
    middle of the bounds when the other end is free and both bounds are finite (held at the fixed
    end when a bound is infinite); the middle of the bounds when both ends are free."""
    mid = bounds_midpoint(lo, hi)
    bounded = bool(np.isfinite(lo) and np.isfinite(hi))
    if start is not None and end is not None:
        return start, end
    if start is not None:
        return start, mid if bounded else start
    if end is not None:
        return mid if bounded else end, end
    return mid, mid
