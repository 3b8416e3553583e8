"""One best-response engine for n players (Algorithm 2 of section 4.4 and its Gauss–Seidel form).

Each player answers the others' current strategies with a best response; the engine iterates until
the fixed-point residual is within ``tolerance``: every player's best response lies within
``tolerance`` of the strategy it answered, ``distance(BR_p(view), s_p) ≤ tolerance`` (the undamped
response, so damping does not shrink the test). The residual is only as true as the responses are
exact: a player that solves to a tolerance of its own must solve well below the engine's (the
differential-game drivers tie each player's IPOPT ``tol`` to it), or a response that merely accepts
its warm start reads as a zero residual.

- **Jacobi** (Algorithm 2): every player answers the strategies of the previous iterate,
  ``s_p^{i+1} = BR_p(s_{-p}^i)``;
- **Gauss–Seidel**: players answer in order, each seeing the strategies already updated in this
  sweep, ``s_p^{i+1} = BR_p(s_{<p}^{i+1}, s_{>p}^i)``.

With ``damping`` ``w < 1`` a player that supports it keeps ``(1 − w) s_p^i + w BR_p`` (relaxation, which
turns a Jacobi map whose eigenvalues lie outside the unit disc into a contraction when their real
parts are below 1); a player without ``blend`` takes its plain response. The residual recorded is
the undamped one, ``distance(BR_p, s_p)``, not the step ``w · distance(BR_p, s_p)``.

With ``acceleration="anderson"`` the next point the players answer is not the last sweep's
responses ``g_i = G(x_i)`` but Anderson's extrapolation (type II, Walker & Ni 2011) from the last
``memory`` sweeps: ``x_{i+1} = g_i − ΔG γ`` with ``γ = argmin ‖f_i − ΔF γ‖₂``, ``f = g − x`` the
residuals and ``ΔF``, ``ΔG`` the differences of successive residuals and responses. On a linear
sweep map its iterates are GMRES's, so it converges, in at most as many sweeps as the joint
strategy has entries, where the plain iteration spirals outwards. The stopping rule does not
change: a player's change is still ``distance(G_p(x_i), x_{i,p})``, the distance from the point it
answered to its best response there. A response
that fails at an extrapolated point drops the memory and is asked again at the last responses
(a plain step); only a failure there stops the run. Acceleration needs players whose strategies
are vectors (:class:`VectorSpacePlayer`).

The run returns the **best iterate**: the strategies produced by the sweep whose residual was the
smallest (the last one when it converged), not merely the last.

The engine knows nothing of a strategy beyond the player's ``distance``. It stops with an honest
outcome: ``converged``; ``iteration_limit`` (with the observed rate when the residual was still
falling: slow convergence is not a cycle); ``cycling`` (the joint strategy returns to an earlier
iterate, within tolerance and much closer to it than to the previous one; or a period-k cycle,
``2 ≤ k ≤ window``: each of the last k iterates lies within ``cycle_ratio`` times the smallest change
of the last 2k iterations of the iterate k before it, and the change has not shrunk over the period;
or the largest change over the last ``window`` iterations is no smaller than over the ``window``
before); ``diverged`` (a non-finite change, the largest change grown at least ``growth`` times in
each of the last ``growth_sweeps`` sweeps — so a geometric blow-up stops before a player's solver
fails on huge iterates — or the largest change over the last ``window`` at least ``growth`` times
the one before); ``player_failed`` (a response whose status carries no solution); or ``time_limit``
(the caller's ``stop`` said so). :class:`BestResponseRun` maps the outcome to a
:class:`~gamespec.result.Status` and packs the history for ``Result.metrics["best_response"]``.

It sits in the bottom layer, beside :mod:`gamespec.result` (the only gamespec module it imports):
the numerics of a problem family (chapter 4's ``lqgame``, chapter 5's ``flowfield``) drive it with
players that solve convex steps, and the game drivers above :mod:`gamespec.solving` drive it with
players compiled as ``optimal_control`` problems. DESIGN.md places the engine in ``games/``, above
the solving layer; that would make chapter 4's numerics import a higher layer, so the engine lives
here and ``games/`` keeps only what compiles players through the solving chain.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from itertools import pairwise
from typing import Any, Literal, Protocol, runtime_checkable

import numpy as np

from gamespec.result import Status

Strategies = dict[str, Any]


class Outcome(StrEnum):
    """Why a best-response iteration stopped."""

    CONVERGED = "converged"
    ITERATION_LIMIT = "iteration_limit"
    CYCLING = "cycling"
    DIVERGED = "diverged"
    PLAYER_FAILED = "player_failed"
    TIME_LIMIT = "time_limit"


class Response(Protocol):
    """What a player reports with its strategy: a :class:`~gamespec.result.Result` satisfies it."""

    @property
    def status(self) -> Status: ...

    @property
    def message(self) -> str: ...


@dataclass(frozen=True)
class StepReport:
    """A :class:`Response` for players that solve something smaller than a whole Result."""

    status: Status
    message: str = ""


@runtime_checkable
class Player(Protocol):
    """A player: ``respond`` to the others' strategies (keyed by player name) with a strategy (None
    when the response failed) and a :class:`Response`; ``distance`` between two of its strategies."""

    name: str

    def respond(self, others: Mapping[str, Any]) -> tuple[Any, Response]: ...

    def distance(self, a: Any, b: Any) -> float: ...


@runtime_checkable
class BlendingPlayer(Player, Protocol):
    """A player whose strategies can be relaxed: ``blend(old, new, w) = (1 − w) old + w new``."""

    def blend(self, old: Any, new: Any, weight: float) -> Any: ...


@runtime_checkable
class VectorSpacePlayer(Player, Protocol):
    """A player whose strategies are points of a vector space: ``flatten(s)`` is a 1-D array and
    ``unflatten(v, like)`` its inverse (shaped like the strategy ``like``); Anderson acceleration
    combines strategies through them."""

    def flatten(self, strategy: Any) -> np.ndarray: ...

    def unflatten(self, vector: np.ndarray, like: Any) -> Any: ...


@dataclass(frozen=True)
class VectorPlayer:
    """A player whose strategy is a NumPy array (Euclidean distance, convex blend, flattening);
    ``response`` maps the others' strategies to ``(strategy or None, Response)``."""

    name: str
    response: Callable[[Mapping[str, Any]], tuple[np.ndarray | None, Response]]

    def respond(self, others: Mapping[str, Any]) -> tuple[np.ndarray | None, Response]:
        return self.response(others)

    def distance(self, a: np.ndarray, b: np.ndarray) -> float:
        return float(np.linalg.norm(np.asarray(a) - np.asarray(b)))

    def blend(self, old: np.ndarray, new: np.ndarray, weight: float) -> np.ndarray:
        return (1 - weight) * np.asarray(old) + weight * np.asarray(new)

    def flatten(self, strategy: np.ndarray) -> np.ndarray:
        return np.asarray(strategy, dtype=float).ravel()

    def unflatten(self, vector: np.ndarray, like: np.ndarray) -> np.ndarray:
        return np.reshape(vector, np.shape(like))


@dataclass(frozen=True)
class Settings:
    """Scheme and stopping rule of the iteration (see the module docstring)."""

    scheme: Literal["jacobi", "gauss_seidel"] = "jacobi"
    tolerance: float = 1e-6
    max_iterations: int = 100
    damping: float = 1.0
    window: int = 10
    growth: float = 2.0
    growth_sweeps: int = 3
    cycle_ratio: float = 1e-2
    acceleration: Literal["none", "anderson"] = "none"
    memory: int = 5

    def __post_init__(self) -> None:
        if not 0 < self.damping <= 1:
            raise ValueError(f"damping must lie in (0, 1], got {self.damping}")
        if self.tolerance <= 0 or self.max_iterations < 1 or self.window < 1 or self.growth <= 1:
            raise ValueError("tolerance > 0, max_iterations ≥ 1, window ≥ 1 and growth > 1 are required")
        if self.growth_sweeps < 1:
            raise ValueError(f"growth_sweeps must be at least 1, got {self.growth_sweeps}")
        if not 0 < self.cycle_ratio < 1:
            raise ValueError(f"cycle_ratio must lie in (0, 1), got {self.cycle_ratio}")
        if self.memory < 1:
            raise ValueError(f"memory must be at least 1, got {self.memory}")


@dataclass
class PlayerRecord:
    """One player's last response: its status and message, and how many responses it gave."""

    status: Status = Status.OPTIMAL
    message: str = ""
    responses: int = 0


@dataclass
class Iteration:
    """One sweep: each player's change — its fixed-point residual ``distance(BR_p, s_p^i)``, the
    undamped best response's distance from the strategy it answered — and the payoff after it."""

    changes: dict[str, float]
    payoff: float | None = None

    @property
    def largest(self) -> float:
        return max(self.changes.values())


@dataclass
class BestResponseRun:
    """The best iterate (the strategies of the sweep with the smallest residual), why the iteration
    stopped, its history and each player's record; ``best`` is that sweep's index in ``history``."""

    strategies: Strategies
    outcome: Outcome
    status: Status
    message: str
    settings: Settings
    history: list[Iteration] = field(default_factory=list)
    players: dict[str, PlayerRecord] = field(default_factory=dict)
    failed_player: str = ""
    best: int | None = None
    rate: float | None = None
    """The observed factor of the largest change per sweep over the last window (below 1: still
    converging), None with too short a history."""

    @property
    def residual(self) -> float:
        """The largest player's residual of the best sweep (NaN when no sweep finished)."""
        return self.history[self.best].largest if self.best is not None else float("nan")

    @property
    def converged(self) -> bool:
        return self.outcome is Outcome.CONVERGED

    @property
    def iterations(self) -> int:
        return len(self.history)

    def changes(self, name: str) -> list[float]:
        """``name``'s change per iteration."""
        return [it.changes[name] for it in self.history]

    def as_metrics(self) -> dict[str, Any]:
        """The JSON-able ``Result.metrics["best_response"]``."""
        return {
            "converged": self.converged,
            "outcome": self.outcome.value,
            "iterations": self.iterations,
            "scheme": self.settings.scheme,
            "tolerance": self.settings.tolerance,
            "damping": self.settings.damping,
            "acceleration": self.settings.acceleration,
            "failed_player": self.failed_player or None,
            "best_iteration": self.best,
            "residual": self.residual,
            "observed_rate": self.rate,
            "players": {
                name: {"status": r.status.value, "message": r.message, "responses": r.responses}
                for name, r in self.players.items()
            },
            "history": [{"changes": it.changes, "payoff": it.payoff} for it in self.history],
        }


class _Anderson:
    """Anderson's extrapolation (type II) from the last ``memory`` sweeps: the points answered
    ``x_j`` and the responses ``g_j`` as joint vectors (players' :meth:`VectorSpacePlayer.flatten`
    in order), ``x_{i+1} = g_i − ΔG γ`` with ``γ`` the least-squares solution of ``ΔF γ = f_i``
    (numpy's rank cutoff, so nearly dependent differences do not blow ``γ`` up)."""

    def __init__(self, players: Sequence[Player], memory: int) -> None:
        plain = [p.name for p in players if not isinstance(p, VectorSpacePlayer)]
        if plain:
            raise ValueError(f"Anderson acceleration needs vector strategies (flatten/unflatten): {plain}")
        self.players = [p for p in players if isinstance(p, VectorSpacePlayer)]
        self.memory = memory
        self.points: list[np.ndarray] = []
        self.responses: list[np.ndarray] = []

    def reset(self) -> None:
        self.points, self.responses = [], []

    def _joint(self, strategies: Strategies) -> np.ndarray:
        return np.concatenate([p.flatten(strategies[p.name]) for p in self.players])

    def _split(self, vector: np.ndarray, like: Strategies) -> Strategies:
        sizes = [p.flatten(like[p.name]).size for p in self.players]
        parts = np.split(vector, np.cumsum(sizes)[:-1])
        return {p.name: p.unflatten(v, like[p.name]) for p, v in zip(self.players, parts, strict=True)}

    def next(self, point: Strategies, responses: Strategies) -> Strategies | None:
        """The next point after the sweep answered ``point`` with ``responses`` (the responses
        themselves while the memory holds one sweep); None when the extrapolation is not finite."""
        keep = self.memory + 1
        self.points = [*self.points, self._joint(point)][-keep:]
        self.responses = [*self.responses, self._joint(responses)][-keep:]
        if len(self.points) < 2:
            return responses
        G = np.array(self.responses).T
        F = G - np.array(self.points).T
        gamma = np.linalg.lstsq(np.diff(F, axis=1), F[:, -1], rcond=None)[0]
        extrapolated = G[:, -1] - np.diff(G, axis=1) @ gamma
        return self._split(extrapolated, responses) if np.isfinite(extrapolated).all() else None


class _Iterator:
    """The state of one run of :func:`iterate`."""

    def __init__(
        self,
        players: Sequence[Player],
        start: Mapping[str, Any],
        settings: Settings,
        payoff: Callable[[Strategies], float] | None,
    ) -> None:
        names = [p.name for p in players]
        if len(set(names)) != len(names):
            raise ValueError(f"player names must be distinct: {names}")
        missing = set(names) - set(start)
        if missing:
            raise ValueError(f"no starting strategy for {sorted(missing)}")
        self.players = list(players)
        self.settings = settings
        self.payoff = payoff
        self.current: Strategies = {name: start[name] for name in names}
        self.point: Strategies = dict(self.current)
        self.extrapolated = False
        accelerated = settings.acceleration == "anderson"
        self.anderson = _Anderson(self.players, settings.memory) if accelerated else None
        self.records = {name: PlayerRecord() for name in names}
        self.history: list[Iteration] = []
        self.recent: list[Strategies] = [dict(self.current)]
        self.failed = ""
        self.best: int | None = None
        self.best_strategies: Strategies = dict(self.current)

    def _respond(self, player: Player, view: Strategies) -> tuple[Any, float]:
        """``player``'s (damped) response to ``view`` (None when it failed) and its residual, the
        undamped response's distance from ``view``'s strategy of the player."""
        others = {k: v for k, v in view.items() if k != player.name}
        strategy, report = player.respond(others)
        record = self.records[player.name]
        record.status, record.message = report.status, report.message
        record.responses += 1
        if strategy is None or not report.status.ok:
            return None, float("nan")
        residual = float(player.distance(strategy, view[player.name]))
        w = self.settings.damping
        if w < 1 and isinstance(player, BlendingPlayer):
            return player.blend(view[player.name], strategy, w), residual
        return strategy, residual

    def sweep(self) -> tuple[Strategies, dict[str, float], str]:
        """One Jacobi or Gauss–Seidel sweep answering ``self.point``: the new strategies, each
        player's residual and the failed player's name ('' when none failed)."""
        gauss_seidel = self.settings.scheme == "gauss_seidel"
        previous = dict(self.point)
        following = dict(self.point)
        residuals: dict[str, float] = {}
        for player in self.players:
            strategy, residuals[player.name] = self._respond(player, following if gauss_seidel else previous)
            if strategy is None:
                return following, residuals, player.name
            following[player.name] = strategy
        return following, residuals, ""

    def _returned_to_earlier(self, strategies: Strategies, change: float) -> bool:
        """The joint strategy is back at an iterate before the previous one: within tolerance of it
        and a thousand times closer to it than to the previous iterate (a converging sequence is
        about as far from its earlier iterates as from its previous one)."""
        bound = min(self.settings.tolerance, 1e-3 * change)
        return any(
            all(p.distance(strategies[p.name], old[p.name]) <= bound for p in self.players)
            for old in self.recent[:-1]
        )

    def _distance(self, a: Strategies, b: Strategies) -> float:
        return max(float(p.distance(a[p.name], b[p.name])) for p in self.players)

    def _repeats_with_period(self, period: int) -> bool:
        """The last ``period`` iterates each repeat the one ``period`` before within ``cycle_ratio``
        times the smallest change of the last ``2·period`` iterations, and the change has not shrunk
        over the period. A converging alternation ``s_i = qⁱ a`` (``−1 < q < 0``) comes back to within
        ``(1 − |q|)/|q|`` times its change, and the change shrinks by ``q²`` per period of two: it
        passes both tests only when ``|q| ≳ 1 − cycle_ratio/2``, a contraction too slow to converge
        in fewer than about ``(2/cycle_ratio) · ln(change/tolerance)`` iterations."""
        recent, ratio = self.recent, self.settings.cycle_ratio
        if len(recent) < 2 * period + 1:
            return False
        changes = [it.largest for it in self.history[-2 * period :]]
        if changes[-1] < (1 - ratio) * changes[-1 - period]:
            return False
        bound = ratio * min(changes)
        return all(self._distance(recent[-1 - j], recent[-1 - j - period]) <= bound for j in range(period))

    def _growing(self) -> bool:
        """The largest change grew at least ``growth`` times in each of the last ``growth_sweeps``
        sweeps: a geometric blow-up, stopped while the players can still answer."""
        k = self.settings.growth_sweeps
        if len(self.history) < k + 1:
            return False
        largest = [it.largest for it in self.history[-k - 1 :]]
        return all(b >= self.settings.growth * a for a, b in pairwise(largest))

    def rate(self) -> float | None:
        """The observed factor by which the largest change shrinks per sweep over the last window
        (geometric mean), or None with fewer than two sweeps or a zero change."""
        largest = [it.largest for it in self.history[-self.settings.window - 1 :]]
        if len(largest) < 2 or largest[0] <= 0 or largest[-1] <= 0:
            return None
        return float((largest[-1] / largest[0]) ** (1 / (len(largest) - 1)))

    def _trend(self) -> Outcome | None:
        """Cycling or divergence from the largest changes of the last two windows."""
        w = self.settings.window
        if len(self.history) < 2 * w:
            return None
        largest = [it.largest for it in self.history[-2 * w :]]
        before, last = max(largest[:w]), max(largest[w:])
        if last >= self.settings.growth * before:
            return Outcome.DIVERGED
        if last >= before:
            return Outcome.CYCLING
        return None

    def step(self) -> Outcome | None:
        """One iteration; the outcome when the iteration stops here."""
        following, changes, failed = self.sweep()
        if failed and self.extrapolated:
            self._plain_point()
            following, changes, failed = self.sweep()
        if failed:
            self.failed = failed
            return Outcome.PLAYER_FAILED
        payoff = float(self.payoff(following)) if self.payoff is not None else None
        self.history.append(Iteration(changes, payoff))
        if not np.isfinite(list(changes.values())).all():
            return Outcome.DIVERGED
        self.current = following
        if self.best is None or max(changes.values()) < self.history[self.best].largest:
            self.best, self.best_strategies = len(self.history) - 1, following
        if max(changes.values()) <= self.settings.tolerance:
            return Outcome.CONVERGED
        if self._growing():
            return Outcome.DIVERGED
        if self._returned_to_earlier(following, max(changes.values())):
            return Outcome.CYCLING
        self.recent = [*self.recent[-2 * self.settings.window :], dict(following)]
        if any(self._repeats_with_period(k) for k in range(2, self.settings.window + 1)):
            return Outcome.CYCLING
        self._next_point(following)
        return self._trend()

    def _plain_point(self) -> None:
        """Answer the last responses next (a plain step), forgetting Anderson's memory."""
        self.point, self.extrapolated = dict(self.current), False
        if self.anderson is not None:
            self.anderson.reset()

    def _next_point(self, following: Strategies) -> None:
        """The point the next sweep answers: the responses, or Anderson's extrapolation from them."""
        if self.anderson is None:
            self.point = following
            return
        extrapolated = self.anderson.next(self.point, following)
        if extrapolated is None:
            self._plain_point()
        else:
            self.point, self.extrapolated = extrapolated, True


_STATUS = {
    Outcome.ITERATION_LIMIT: Status.ITERATION_LIMIT,
    Outcome.CYCLING: Status.NOT_CONVERGED,
    Outcome.DIVERGED: Status.NOT_CONVERGED,
    Outcome.TIME_LIMIT: Status.TIME_LIMIT,
}


def _slow(it: _Iterator) -> str:
    """How fast a run stopped at its limit was still converging: the observed rate and the sweeps
    it would need at that rate ('' when the residual was not falling)."""
    rate = it.rate()
    if rate is None or rate >= 1:
        return ""
    last = it.history[-1].largest
    more = int(np.ceil(np.log(it.settings.tolerance / last) / np.log(rate)))
    return (
        f"; converging slowly: the residual falls ×{rate:.3g} per sweep, "
        f"about {more} more sweeps to reach {it.settings.tolerance:.3g}"
    )


def _message(outcome: Outcome, it: _Iterator, failed: str) -> str:
    n = len(it.history)
    last = it.history[-1].largest if it.history else float("nan")
    if outcome is Outcome.CONVERGED:
        inexact = [f"{k}: {r.message}" for k, r in it.records.items() if r.status is not Status.OPTIMAL]
        return "; ".join(inexact)
    if outcome is Outcome.PLAYER_FAILED:
        record = it.records[failed]
        reason = f": {record.message}" if record.message else ""
        return f"best responses stopped at iteration {n + 1}: {failed} failed ({record.status.value}){reason}"
    if outcome is Outcome.ITERATION_LIMIT:
        return f"best responses did not converge in {n} iterations (last change {last:.3g}){_slow(it)}"
    if outcome is Outcome.TIME_LIMIT:
        return f"best responses stopped by their time limit after {n} iterations (last change {last:.3g})"
    if outcome is Outcome.CYCLING:
        return f"best responses cycle: no progress after {n} iterations (last change {last:.3g})"
    rate = it.rate()
    speed = f" (diverging: ×{rate:.3g} per sweep)" if rate is not None and rate > 1 else ""
    return f"best responses diverge: the change grew to {last:.3g} after {n} iterations{speed}"


def iterate(
    players: Sequence[Player],
    start: Mapping[str, Any],
    settings: Settings | None = None,
    payoff: Callable[[Strategies], float] | None = None,
    stop: Callable[[], bool] | None = None,
) -> BestResponseRun:
    """Iterate best responses from ``start`` (strategies by player name) until an outcome;
    ``stop``, asked after every iteration, ends the run with the outcome ``time_limit`` when it
    returns True (a caller's time limit).

    A converged run is ``optimal`` when every player's last response was, else ``feasible``; a run
    stopped by a player's failure has that player's status; the others map as in ``_STATUS``. The
    strategies returned are the best iterate (see the module docstring), the start when no sweep
    finished.
    """
    settings = settings or Settings()
    it = _Iterator(players, start, settings, payoff)
    outcome = Outcome.ITERATION_LIMIT
    for _ in range(settings.max_iterations):
        stopped = it.step()
        if stopped is None and stop is not None and stop():
            stopped = Outcome.TIME_LIMIT
        if stopped is not None:
            outcome = stopped
            break
    if outcome is Outcome.CONVERGED:
        exact = all(r.status is Status.OPTIMAL for r in it.records.values())
        status = Status.OPTIMAL if exact else Status.FEASIBLE
    elif outcome is Outcome.PLAYER_FAILED:
        status = it.records[it.failed].status
        status = status if not status.ok else Status.ERROR
    else:
        status = _STATUS[outcome]
    return BestResponseRun(
        strategies=it.best_strategies,
        outcome=outcome,
        status=status,
        message=_message(outcome, it, it.failed),
        settings=settings,
        history=it.history,
        players=it.records,
        failed_player=it.failed,
        best=it.best,
        rate=it.rate(),
    )
