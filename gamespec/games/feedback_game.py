"""A linear-quadratic ``differential_game`` solved for its feedback equilibrium (``game.information:
feedback``): the coupled Riccati equations of :mod:`gamespec.games.feedback` on the matrices that
:mod:`gamespec.games.lq_structure` reads from the file, and the closed loop from the initial state.

The Result holds the equilibrium's closed-loop trajectory (states on a uniform grid, the controls
``u_i = −K_i(t) x`` on the same grid), each player's payoff in the file's own terms
(``metrics.payoffs``; ``objective`` is the first listed player's, as for best responses), the
solution concept (``feedback_saddle`` for a zero-sum game, ``feedback_nash`` otherwise) and the Nash
gap: each player's improvement by its own optimal feedback reply (an LQR problem along the others'
laws), a check against ``game.tolerance`` relative to the payoffs' scale. A conjugate point of the
coupled equations (no feedback equilibrium on the horizon) is ``unbounded`` with its time.
"""

from __future__ import annotations

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.games.feedback import LQGame, best_response_improvements, feedback_nash
from gamespec.games.lq_structure import LQForm, lq_game
from gamespec.games.nash_gap import nash_gap
from gamespec.result import Result, Status
from gamespec.specs.differential_game import DifferentialGameSpec

POINTS_PER_INTERVAL = 10
"""Points of the returned trajectory per interval of the file's ``method`` grid."""


def _lq(form: LQForm, parameters: dict[str, float], name: str) -> LQGame:
    data = lq_game(form, parameters)
    if isinstance(data, str):
        raise UnsupportedFeature(
            f"game.information: feedback needs a linear-quadratic game: {name!r}: {data}"
        )
    return data


def feedback_equilibrium(game: DifferentialGameSpec, form: LQForm, parameters: dict[str, float]) -> Result:
    """The feedback equilibrium of the LQ ``game`` at ``parameters`` as a Result (module doc)."""
    data = _lq(form, parameters, game.name)
    concept = "feedback_saddle" if form.zero_sum else "feedback_nash"
    solution = feedback_nash(data, POINTS_PER_INTERVAL * game.method.intervals + 1)
    base = {"information": "feedback", "sought_concept": concept}
    if not solution.exists:
        message = f"no feedback equilibrium on the horizon: {solution.reason}"
        return Result(status=Status.UNBOUNDED, message=message, metrics=base | {"solution_concept": "none"})
    signs = [1.0 if sense == "minimize" else -1.0 for sense in form.senses]
    payoffs = {p: s * v for p, s, v in zip(form.players, signs, solution.values, strict=True)}
    improvements = dict(zip(form.players, best_response_improvements(data, solution.gain), strict=True))
    gap = nash_gap(improvements, payoffs, game.game.tolerance)
    n = len(form.states)
    controls = [c for player in game.problem.players.values() for c in player.controls]
    message = gap.message("the feedback equilibrium of the coupled Riccati equations")
    return Result(
        status=Status.OPTIMAL,
        message=message,
        objective=payoffs[form.players[0]],
        t_final=float(solution.times[-1]),
        time=solution.times,
        states={s: solution.x[:, i] for i, s in enumerate(form.states)},
        controls={c: solution.u[:, j] for j, c in enumerate(controls)},
        checks={"saddle_gap": gap.gap},
        metrics=base
        | gap.metrics(concept, payoffs)
        | {"gains": {c: np.asarray(solution.K[:, j, :n]).tolist() for j, c in enumerate(controls)}},
    )
