"""The rows that lead a ``differential_game``'s solve summary: how each best-response iteration
ended (Algorithms 4–5: converged, cycling, diverging, or stopped at its limit) and, for a receding
horizon, whether and when capture happened and how close each player came to the obstacle; then
which solution the open-loop game found (its concept, each player's payoff and the saddle/Nash
gap, flagged when it exceeds the tolerance), or why the Riccati test refused it."""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


SCHEMES = {"gauss_seidel": "Gauss–Seidel", "jacobi": "Jacobi", "joint": "joint Newton"}


def _equilibrium(view: str, run: dict, several: bool) -> tuple[str, object]:
    label = f"equilibrium ({view})" if several else "equilibrium"
    scheme = SCHEMES.get(run["scheme"], run["scheme"])
    return label, f"{run['outcome']} after {run['iterations']} {scheme} iterations"


def _solution(m: dict) -> Rows:
    """The concept found, the payoffs and the gap (with its verdict against the tolerance)."""
    concept = m.get("solution_concept")
    if concept is None:
        return []
    sought = m.get("sought_concept")
    rows: Rows = [
        ("solution", concept if concept == sought or sought is None else f"{concept} (sought {sought})")
    ]
    rows += [(f"payoff ({player})", value) for player, value in m.get("payoffs", {}).items()]
    gap = m.get("saddle_gap")
    if "saddle_gap" in m:
        tolerance = m.get("check_tolerances", {}).get("saddle_gap")
        passed = m.get("checks_passed", {}).get("saddle_gap")
        verdict = "not computed" if gap is None else f"{gap:.3g}"
        if passed is False:
            verdict += f" — exceeds the tolerance {tolerance:.3g}"
        rows.append(("saddle gap" if "saddle" in (sought or "") else "Nash gap", verdict))
    bounds = m.get("value_bounds")
    if bounds:
        rows.append(("value bounds (best responses)", f"[{bounds['lower']:.10g}, {bounds['upper']:.10g}]"))
    return rows


def game_summary(result: Result) -> Rows:
    """Open-loop game: the equilibrium's outcome per game, the game value and the solution found
    (refused by the Riccati test: the reason). Feedback game (``game.information: feedback``): the
    method, the value and the solution found. Receding horizon:
    captured or not, the capture time, the number of steps, whether every step's game converged,
    and each avoiding player's smallest distance to the obstacle (negative: it collided)."""
    m = result.metrics
    if m.get("information") == "feedback" and "payoffs" in m:
        label = (
            "game value"
            if m["solution_concept"] == "feedback_saddle"
            else "objective (first player's payoff)"
        )
        return [
            (
                "equilibrium",
                "feedback laws, iterative LQ games"
                if m.get("method") == "iterative_lq"
                else "feedback laws, coupled Riccati equations",
            ),
            (label, result.objective),
            *_solution(m),
        ]
    runs = m.get("best_response")
    if runs is not None:
        rows = [_equilibrium(view, run, len(runs) > 1) for view, run in runs.items()]
        value = (
            "game value"
            if m.get("sought_concept") != "open_loop_nash"
            else "objective (first player's payoff)"
        )
        return [*rows, (value, result.objective), *_solution(m)]
    existence = m.get("existence")
    if existence is not None and existence.get("riccati") is not None:
        return [("existence (Riccati test)", existence["reason"])]
    if "steps" not in m:
        return []
    rows: Rows = [("captured", m["captured"])]
    if m["captured"]:
        rows.append(("capture time", m["capture_time"]))
    rows += [("receding-horizon steps", m["steps"]), ("every step's game converged", m["all_converged"])]
    rows += [
        (f"{key.removesuffix('_min_obstacle_distance')}: closest to the obstacle", value)
        for key, value in m.items()
        if key.endswith("_min_obstacle_distance")
    ]
    return [*rows, *_solution(m)]
