"""Both players' steps of Algorithm 3 as CVXPY problems, built once on ``cp.Parameter``s.

The pursuer minimizes the payoff ``J`` (convex in its gains): with the ``trace`` payoff (eq. 5.34) a
sum of squares, with the ``frobenius`` payoff (eq. 5.17) ``min ‖S‖²_F`` s.t. ``[[S, G], [Gᵀ, I]] ⪰ 0``
(``S ⪰ G Gᵀ = Σʳ``; ``‖·‖_F`` is monotone on the PSD cone), an SDP. The evader *maximizes* the convex
``J``, which is not a convex program: it is solved by the convex–concave procedure — maximize the
linearization of ``J`` at the current gains over the evader's (convex) constraint set, repeat; each
step cannot lower ``J`` (``J`` lies above its tangent), and the procedure stops at a stationary
point when ``J`` rises by less than the tolerance. Its history is reported.

Both feasible sets are eqs. 5.35a–b and the chance constraint eq. 5.36, all second-order cones; in
eq. 5.36 the matrix norm ``‖Σ^{y1/2} K_kⁱᵀ‖`` is bounded by its Frobenius norm (a conservative SOC
form of Theorem 5's ``σ_max``). ``V`` does not enter ``J`` (eq. 5.34 depends on ``K`` only): with
``feedforward: nominal`` it is ``Û``; with ``free`` a small proximal term ``ρ ‖V − Û‖²`` breaks
ties toward the nominal control (a player still moves ``V`` where that frees speed for its gains).
Problems are scaled so that the open-loop payoff is 1.

Algorithm 3 pairs :class:`PursuerStep` with :class:`EvaderStep`; the mixed minimax pairs
:class:`MinimaxPursuerStep` (the pursuer's security strategy over the evader strategies seen) with
:class:`MinimaxEvader` (the evader's step, kept only when it beats the restricted value);
:func:`lower_value` lets the evader commit and the pursuer answer (the thesis' reading,
:mod:`gamespec.flowfield.concepts`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from gamespec_cvxpy.backend import STATUS_MAP

from gamespec.best_response import StepReport
from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.concepts import copy_room, lower_value_bound
from gamespec.flowfield.covariance_game import PLAYERS, CovarianceGame, Strategy
from gamespec.result import Status

PROXIMAL = 1e-6


def _root(M: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh((M + M.T) / 2)
    return (v * np.sqrt(np.clip(w, 0.0, None))) @ v.T


class _PlayerProblem:
    """Variables ``V`` (2N) and the gains of steps 1 … N−1 (8(N−1)) of one player, and its
    constraints (eqs. 5.35–5.36)."""

    def __init__(
        self, game: CovarianceGame, player: int, solver: str, solver_options: dict[str, Any]
    ) -> None:
        import cvxpy as cp

        self.game, self.player = game, player
        self.solver, self.solver_options = solver, solver_options
        N, b = game.N, game.bounds[player]
        self.V = cp.Variable(2 * N)
        self.kappa = cp.Variable(8 * (N - 1)) if N > 1 else None
        self.U_hat = game.U_hat[:, 2 * player : 2 * player + 2].reshape(-1)
        c, B = game.mean_map(player)
        X_hat = game.X_hat[:, 2 * player : 2 * player + 2].reshape(-1)
        V2 = cp.reshape(self.V, (N, 2), order="C")
        mean = cp.reshape(c + B @ self.V - X_hat, (N, 2), order="C")
        self.constraints = [
            cp.norm(mean, 2, axis=1) <= b.delta_x,
            cp.norm(V2 - self.U_hat.reshape(N, 2), 2, axis=1) <= b.delta_u,
            cp.norm(V2[0]) <= b.max_speed,
        ]
        if game.feedforward == "nominal":
            self.constraints.append(self.V - self.U_hat == 0)
        self.spread_maps = np.array(
            [np.kron(np.eye(2), _root(game.noise_rows[k] @ game.noise_rows[k].T).T) for k in range(1, N)]
        ).reshape(-1, 8, 8)
        for k in range(1, N):
            spread = cp.norm(self.spread_maps[k - 1] @ self.kappa[8 * (k - 1) : 8 * k])
            self.constraints.append(cp.norm(V2[k]) + b.chance_factor * spread <= b.max_speed)
        self.proximal = (
            PROXIMAL * cp.sum_squares(self.V - self.U_hat) / max(1.0, float(self.U_hat @ self.U_hat))
        )
        # with V = Û the gains' set of eq. 5.36 is ‖S_k κ_k‖ ≤ ρ_k (S_k = spread_maps[k − 1], k ≥ 1)
        speeds = np.linalg.norm(self.U_hat.reshape(N, 2)[1:], axis=1)
        self.radii = (b.max_speed - speeds) / b.chance_factor

    def strategy(self) -> Strategy:
        kappa = np.zeros((self.game.N, 2, 4))
        if self.kappa is not None:
            kappa[1:] = np.asarray(self.kappa.value).reshape(-1, 2, 4)
        return Strategy(np.asarray(self.V.value).reshape(-1, 2), kappa)

    def gains_map(self) -> np.ndarray:
        """``Tⁱ`` restricted to steps 1 … N−1."""
        return self.game.gain_maps[self.player][:, 8:]

    def run(self, problem: Any) -> Status:
        import cvxpy as cp

        try:
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Solution may be inaccurate")
                problem.solve(solver=self.solver, **self.solver_options)
        except cp.SolverError:
            return Status.NUMERICAL_ERROR
        return STATUS_MAP.get(problem.status, Status.ERROR)


class PursuerStep(_PlayerProblem):
    """``argmin J`` over the pursuer's ``(V, K)`` with the evader's fixed (Algorithm 3, line 3)."""

    def __init__(
        self, game: CovarianceGame, solver: str, solver_options: dict[str, Any], scale: float
    ) -> None:
        import cvxpy as cp

        super().__init__(game, 0, solver, solver_options)
        self.scale = scale
        T = self.gains_map()
        if game.payoff == "trace":
            # ‖c + Tκ‖² = ‖Rκ‖² + 2 (Tᵀc)ᵀκ + ‖c‖², R = (TᵀT)^{1/2}: the small form of the same QP
            self.offset = cp.Parameter(T.shape[1])
            objective = (cp.sum_squares(_root(T.T @ T) @ self.kappa) + 2 * self.offset @ self.kappa) / scale
            constraints = self.constraints
        else:
            N = game.N
            self.offset = cp.Parameter(game.g0.size)
            G = cp.reshape(self.offset + T @ self.kappa, (2 * N, 4 * N), order="C") / np.sqrt(np.sqrt(scale))
            S = cp.Variable((2 * N, 2 * N), symmetric=True)
            objective = cp.sum_squares(S)
            constraints = [*self.constraints, cp.bmat([[S, G], [G.T, np.eye(4 * N)]]) >> 0]
        self.problem = cp.Problem(cp.Minimize(objective + self.proximal), constraints)

    def respond(self, evader: Strategy) -> tuple[Strategy | None, StepReport]:
        offset = self.game.g0 + self.game.gain_maps[1] @ evader.kappa.reshape(-1)
        self.offset.value = self.gains_map().T @ offset if self.game.payoff == "trace" else offset
        status = self.run(self.problem)
        if not status.ok:
            return None, StepReport(status, f"pursuer step: solver reported {self.problem.status}")
        return self.strategy(), StepReport(status)


class MinimaxPursuerStep(_PlayerProblem):
    """The pursuer's security strategy ``min_p max_e J`` by outer approximation: it keeps every
    evader strategy it has been shown (the support ``𝒮``) and answers ``argmin_p max_{e ∈ 𝒮} J(p, e)``,
    a convex program (``min t`` s.t. ``J(p, e_j) ≤ t``). Why: ``J`` is convex in the evader's gains
    too, so a pure saddle point need not exist (then Gauss–Seidel cannot converge); since ``J`` is
    convex in the pursuer's gains, the pursuer has a pure optimal strategy in the mixed extension
    and the game's value is ``min_p max_e J`` (Bohnenblust, Karlin and Shapley 1950, games with
    convex payoff). The restricted value ``t`` is a lower bound of that value; the multipliers of
    the constraints ``J(p, e_j) ≤ t`` sum to one and are the evader's mixed strategy over ``𝒮``
    (``weights``); an evader strategy within ``distinct`` of a support point is not added again.
    When the evader's best response to the answer is already in ``𝒮``, no response
    it finds raises ``J`` above ``t``: the iteration has stopped at the value, up to the evader's
    search being local (the convex–concave procedure)."""

    def __init__(
        self, game: CovarianceGame, solver: str, solver_options: dict[str, Any], scale: float, distinct: float
    ) -> None:
        super().__init__(game, 0, solver, solver_options)
        self.scale, self.distinct = scale, distinct
        self.support: list[Strategy] = []
        self.weights = np.zeros(0)
        self.bound = float("nan")
        T = self.gains_map()
        self.root = _root(T.T @ T)

    def _payoff_constraints(self, t: Any) -> list[Any]:
        """``J(p, e_j)/scale ≤ t`` for every ``e_j`` of the support, in the forms of :class:`PursuerStep`."""
        import cvxpy as cp

        T, N = self.gains_map(), self.game.N
        out = []
        for e in self.support:
            c = self.game.g0 + self.game.gain_maps[1] @ e.kappa.reshape(-1)
            if self.game.payoff == "trace":
                value = cp.sum_squares(self.root @ self.kappa) + 2 * (T.T @ c) @ self.kappa + float(c @ c)
                out.append(value / self.scale <= t)
            else:
                G = cp.reshape(c + T @ self.kappa, (2 * N, 4 * N), order="C") / np.sqrt(np.sqrt(self.scale))
                S = cp.Variable((2 * N, 2 * N), symmetric=True)
                out += [cp.sum_squares(S) <= t, cp.bmat([[S, G], [G.T, np.eye(4 * N)]]) >> 0]
        return out

    def respond(self, evader: Strategy) -> tuple[Strategy | None, StepReport]:
        import cvxpy as cp

        added = all(_distance(evader, e) > self.distinct for e in self.support)
        if added:
            self.support.append(evader)
        t = cp.Variable()
        bounds = self._payoff_constraints(t)
        problem = cp.Problem(cp.Minimize(t + self.proximal), [*self.constraints, *bounds])
        status = self.run(problem)
        if not status.ok:
            if added:  # the support stays the one its weights belong to
                self.support.pop()
            return None, StepReport(status, f"pursuer step: solver reported {problem.status}")
        step = 1 if self.game.payoff == "trace" else 2
        duals = np.array([float(np.sum(c.dual_value)) for c in bounds[::step]])
        self.weights = np.clip(duals, 0.0, None) / max(float(np.clip(duals, 0.0, None).sum()), 1e-300)
        self.bound = float(t.value)
        return self.strategy(), StepReport(status)


@dataclass
class ConvexConcaveLog:
    """Payoffs ``J`` along each evader step's convex–concave iterations."""

    steps: list[list[float]] = field(default_factory=list)
    converged: list[bool] = field(default_factory=list)
    responses: list[Strategy] = field(default_factory=list)

    def alternation(self) -> dict[str, float] | None:
        """How far the last response lies from the one before and from the one two before
        (``max(‖ΔV‖, ‖ΔK‖)``): a period-two cycle of Gauss–Seidel shows as the second far smaller."""
        if len(self.responses) < 3:
            return None
        last, previous, before = self.responses[-1], self.responses[-2], self.responses[-3]
        return {"to_previous": _distance(last, previous), "to_one_before": _distance(last, before)}


def _distance(a: Strategy, b: Strategy) -> float:
    return float(max(np.linalg.norm(a.V - b.V), np.linalg.norm(a.kappa - b.kappa)))


class EvaderStep(_PlayerProblem):
    """``argmax J`` over the evader's ``(V, K)`` with the pursuer's fixed (Algorithm 3, line 5), by
    the convex–concave procedure from the evader's current strategy."""

    def __init__(
        self,
        game: CovarianceGame,
        solver: str,
        solver_options: dict[str, Any],
        scale: float,
        tolerance: float,
        max_iterations: int,
        start: Strategy,
    ) -> None:
        import cvxpy as cp

        super().__init__(game, 1, solver, solver_options)
        self.scale, self.tolerance, self.max_iterations = scale, tolerance, max_iterations
        self.slope = cp.Parameter(8 * (game.N - 1)) if game.N > 1 else None
        linear = self.slope @ self.kappa if self.kappa is not None else 0
        self.problem = cp.Problem(cp.Maximize(linear - self.proximal), self.constraints)
        self.current = start
        self.log = ConvexConcaveLog()
        self.inverse_maps = np.linalg.pinv(self.spread_maps) if game.N > 1 else None

    def tangent_step(self, slope: np.ndarray) -> tuple[Strategy | None, StepReport]:
        """The maximizer of the linearization ``slope · κ`` over the evader's set. With ``V = Û``
        (feedforward nominal) the set is a product over steps of ``‖S_k κ_k‖ ≤ ρ_k`` (eq. 5.36,
        ``ρ_k = (v_max − ‖û_k‖)/√(2 log 1/β)``), and each factor's maximizer is closed-form,
        ``κ_k = ρ_k S_k⁺ h_k/‖h_k‖`` with ``h_k = S_k⁺ᵀ g_k``; otherwise the conic problem is solved."""
        if self.game.feedforward == "nominal":
            h = np.einsum("kij,ki->kj", self.inverse_maps, slope.reshape(-1, 8))
            norms = np.linalg.norm(h, axis=1, keepdims=True)
            direction = np.where(norms > 0, h / np.where(norms > 0, norms, 1.0), 0.0)
            kappa = np.zeros((self.game.N, 2, 4))
            kappa[1:] = (self.radii[:, None] * np.einsum("kij,kj->ki", self.inverse_maps, direction)).reshape(
                -1, 2, 4
            )
            return Strategy(self.U_hat.reshape(-1, 2).copy(), kappa), StepReport(Status.OPTIMAL)
        self.slope.value = slope / max(np.linalg.norm(slope), 1e-300)  # the maximizer is scale-free
        status = self.run(self.problem)
        if not status.ok:
            return None, StepReport(status, f"evader step: solver reported {self.problem.status}")
        return self.strategy(), StepReport(status)

    def respond(self, pursuer: Strategy) -> tuple[Strategy | None, StepReport]:
        """The better of the procedure from the current strategy and from its mirror ``(V, −K)``
        (the evader's set is symmetric in its gains and, for the trace payoff,
        ``J(p, e) + J(p, ẽ) = 2‖c‖² + 2‖Tᵉκᵉ‖²`` for the mirror ``ẽ``: the mirror may lie on the side
        where ``J`` grows). Ties keep the current strategy, so an evader indifferent between two
        responses does not alternate."""
        start = self.current
        best = self._climb(pursuer, start)
        if best[0] is not None and np.any(start.kappa):
            mirror = self._climb(pursuer, Strategy(start.V, -start.kappa))
            if mirror[0] is not None and mirror[2][-1] - best[2][-1] > self.tolerance * abs(best[2][-1]):
                best = mirror
        strategy, report, values, converged = best
        if strategy is None:
            return None, report
        self.current = strategy
        self.log.responses.append(strategy)
        self.log.steps.append(values)
        self.log.converged.append(converged)
        return strategy, report

    def _climb(
        self, pursuer: Strategy, current: Strategy
    ) -> tuple[Strategy | None, StepReport, list[float], bool]:
        """The convex–concave procedure from ``current``: the strategy, report, payoffs, converged."""
        values = [self.game.value((pursuer, current)) / self.scale]
        converged = self.slope is None
        for _ in range(0 if converged else self.max_iterations):
            step, report = self.tangent_step(self.game.gradient((pursuer, current), 1)[1:].reshape(-1))
            if step is None:
                return None, report, values, False
            current = step
            values.append(self.game.value((pursuer, current)) / self.scale)
            if values[-1] - values[-2] <= self.tolerance * max(abs(values[-2]), 1e-12):
                converged = True
                break
        if not converged:
            message = f"evader step: convex-concave procedure stopped after {self.max_iterations} iterations"
            return current, StepReport(Status.FEASIBLE, message), values, False
        return current, StepReport(Status.OPTIMAL), values, True


@dataclass
class MinimaxEvader:
    """The evader of the mixed minimax: its step's answer to the pursuer's security strategy
    when that answer raises ``J`` above the restricted value ``t`` by more than ``gap · t`` (a new
    strategy the pursuer has not guarded against), else its previous answer. At a mixed
    equilibrium the evader is indifferent among its support, so its plain best response may jump
    between support points without any gain; keeping the previous answer then lets the iteration
    stop, and the stop certifies ``t ≤ J(p, BR_e(p)) ≤ (1 + gap) t``."""

    step: EvaderStep
    pursuer: MinimaxPursuerStep
    gap: float
    previous: Strategy

    def respond(self, pursuer: Strategy) -> tuple[Strategy | None, StepReport]:
        answer, report = self.step.respond(pursuer)
        if answer is None:
            return None, report
        value = self.step.game.value((pursuer, answer)) / self.step.scale
        if value > (1 + self.gap) * self.pursuer.bound:
            self.previous = answer
        return self.previous, report


@dataclass(frozen=True)
class GamePlayer:
    """A player of :mod:`gamespec.best_response`: its strategy is a :class:`Strategy`,
    distance ``max(‖ΔV‖, ‖ΔK‖)`` (the stopping rule of section 5.4)."""

    name: str
    step: PursuerStep | MinimaxPursuerStep | EvaderStep | MinimaxEvader

    def respond(self, others: dict[str, Strategy]) -> tuple[Strategy | None, StepReport]:
        (other,) = (others[n] for n in PLAYERS if n != self.name)
        return self.step.respond(other)

    def distance(self, a: Strategy, b: Strategy) -> float:
        return _distance(a, b)


@dataclass(frozen=True)
class LowerValue:
    """The lower value's point: the evader's committed strategy and the pursuer's answer, the
    payoffs ``φ(e)/scale`` along the ascent, whether it stopped (one more step gains at most the
    tolerance), the relative gain of that last step, and — when the
    pursuer's first answer can copy every evader gain (``room`` ≤ 1, ``V = Û``) — the certified
    upper ``bound`` of ``v₋/scale`` and the copy ``defect`` ``max_e ‖(Tᵖ + Tᵉ)κᵉ‖`` it uses."""

    evader: Strategy
    pursuer: Strategy
    values: list[float]
    converged: bool
    residual: float
    room: float | None
    defect: float | None
    bound: float | None


def lower_value(
    pursuer: PursuerStep,
    evader: EvaderStep,
    start: Strategy,
    tolerance: float,
    max_iterations: int,
    budget: Budget = UNLIMITED,
) -> LowerValue | StepReport:
    """``v₋ = max_e min_p J(p, e)``: the evader commits, the pursuer's feedback answers (the thesis'
    reading of Algorithm 3 and Fig. 5.2). ``φ(e) = min_p J(p, e)`` is convex in ``e`` (``J`` is jointly
    convex, the pursuer's set does not depend on ``e``), so, as in the evader's step, the
    convex–concave procedure: from the open-loop evader ``start``, step to the maximizer of the
    tangent ``∇φ(e)·e'`` (``∇φ(e) = ∇_e J(p(e), e)``, Danskin; ``p(e)`` the pursuer's answer) over the
    evader's set, and stop when ``φ`` rises by at most ``tolerance · φ``. The first point certifies
    itself when :func:`~gamespec.flowfield.concepts.copy_room` ≤ 1: then ``φ(start) ≤ v₋ ≤ bound``
    (:func:`~gamespec.flowfield.concepts.lower_value_bound`). A failed pursuer or tangent step
    returns its report; past the ``budget``'s time limit the ascent stops, not converged."""
    game, scale = pursuer.game, pursuer.scale
    answer, report = pursuer.respond(start)
    if answer is None:
        return report
    point, values = (answer, start), [game.value((answer, start)) / scale]
    room = defect = bound = None
    if game.feedforward == "nominal" and game.N > 1 and not np.any(start.kappa):
        used = np.linalg.norm(
            np.einsum("kij,kj->ki", pursuer.spread_maps, answer.kappa[1:].reshape(-1, 8)), axis=1
        )
        room = copy_room(used, pursuer.radii, evader.radii)
        if room <= 1:
            T = game.gain_maps[0][:, 8:] + game.gain_maps[1][:, 8:]
            blocks = T.reshape(T.shape[0], -1, 8)
            defect = float(
                sum(
                    r * np.linalg.norm(blocks[:, k] @ inverse, 2)
                    for k, (r, inverse) in enumerate(zip(evader.radii, evader.inverse_maps, strict=True))
                )
            )
            factor = game.factor((answer, start))
            bound = lower_value_bound(factor, defect, game.payoff) / scale
    residual, converged = 0.0, False
    for _ in range(max_iterations):
        slope = game.gradient(point, 1)[1:].reshape(-1)
        committed, report = evader.tangent_step(slope)
        if committed is None:
            return report
        answer, report = pursuer.respond(committed)
        if answer is None:
            return report
        value = game.value((answer, committed)) / scale
        gain = (value - values[-1]) / max(abs(values[-1]), 1e-300)
        if gain <= tolerance:
            residual, converged = max(gain, 0.0), True
            break
        point = (answer, committed)
        values.append(value)
        budget.advance("covariance game, lower value")
        if budget.expired():
            break
    return LowerValue(point[1], point[0], values, converged, residual, room, defect, bound)
