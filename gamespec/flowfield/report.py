"""The rows that lead a ``flow_field_game``'s solve summary: the capture time ``T̂`` and point
``x_f`` (Theorem 6) with the grid-error estimate, the capture probabilities at ``T̂`` (eq. 5.39) in
open loop and under both closed-loop solutions — the lower value (the evader commits, the
pursuer's feedback answers: the thesis' reading) and the mixed minimax (what a worst-case evader
achieves) — with the Monte Carlo estimates, the saddle gap between them, and which solution concept
the Result reports (:mod:`gamespec.flowfield.concepts`)."""

from __future__ import annotations

from gamespec.result import Result

LOOPS = (
    ("open_loop", "open loop"),
    ("lower_value", "lower value (thesis: the pursuer answers)"),
    ("minimax_mixed", "mixed minimax (worst-case evader)"),
    ("gauss_seidel", "Algorithm 3's last iterate"),
)


def _monte_carlo(m: dict, key: str) -> tuple[str, object] | None:
    """The Monte Carlo row of a loop: open loop, or the closed loop of the concept the file chose."""
    carlo = m.get("monte_carlo_capture_probability", {})
    name = "open_loop" if key == "open_loop" else "closed_loop"
    if name not in carlo or (key != "open_loop" and m.get("game_scheme") != key):
        return None
    c = carlo[name]
    return f"  Monte Carlo ({c['samples']} paths)", f"{c['estimate']:.4g} [{c['low']:.4g}, {c['high']:.4g}]"


def flow_game_summary(result: Result) -> list[tuple[str, object]]:
    """``T̂``, ``x_f``, the capture probabilities (eq. 5.39 and Monte Carlo), the saddle gap, the
    solution concept and whether its computation converged."""
    m = result.metrics
    if "capture_time" not in m:
        return []
    rows: list[tuple[str, object]] = [
        ("capture time T̂", m["capture_time"]),
        ("capture point x_f", "[" + ", ".join(f"{v:.4g}" for v in m["capture_point"]) + "]"),
    ]
    estimate = m.get("grid_error_estimate")
    if estimate:
        rows.append(
            (
                "  grid-error estimate (T̂, x_f)",
                f"{estimate['capture_time']:.2g}, {estimate['capture_point']:.2g}",
            )
        )
    for key, label in LOOPS:
        if f"capture_probability_{key}" not in m:
            continue
        rows.append((f"P(capture at T̂), {label}", m[f"capture_probability_{key}"]))
        carlo = _monte_carlo(m, key)
        if carlo:
            rows.append(carlo)
    if m.get("saddle_gap") is not None:
        relative = m["saddle_gap"] / m["upper_value"] if m["upper_value"] else 0.0
        rows.append(("saddle gap v₊ − v₋ (payoff)", f"{m['saddle_gap']:.4g} ({relative:.1%} of v₊)"))
    concept = m.get("solution_concept", "")
    rows.append(
        ("solution concept (closed loop)", f"{concept} (method.game.scheme = {m.get('game_scheme')})")
    )
    rows.append(("game converged", m.get("game_converged")))
    return rows
