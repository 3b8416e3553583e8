"""The rows that lead a ``differential_game``'s solve summary: how each best-response iteration
ended (Algorithms 4–5: converged, cycling, diverging, or stopped at its limit) and, for a receding
horizon, whether and when capture happened and how close each player came to the obstacle."""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


SCHEMES = {"gauss_seidel": "Gauss–Seidel", "jacobi": "Jacobi"}


def _equilibrium(view: str, run: dict, several: bool) -> tuple[str, object]:
    label = f"equilibrium ({view})" if several else "equilibrium"
    scheme = SCHEMES.get(run["scheme"], run["scheme"])
    return label, f"{run['outcome']} after {run['iterations']} {scheme} iterations"


def game_summary(result: Result) -> Rows:
    """Open-loop game: the equilibrium's outcome per game and the game value. Receding horizon:
    captured or not, the capture time, the number of steps, whether every step's game converged,
    and each avoiding player's smallest distance to the obstacle (negative: it collided)."""
    m = result.metrics
    runs = m.get("best_response")
    if runs is not None:
        rows = [_equilibrium(view, run, len(runs) > 1) for view, run in runs.items()]
        return [*rows, ("game value", result.objective)]
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
    return rows
