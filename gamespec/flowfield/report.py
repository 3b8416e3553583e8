"""The rows that lead a ``flow_field_game``'s solve summary: the capture time ``T̂`` and point
``x_f`` (Theorem 6), the capture probabilities at ``T̂`` (eq. 5.39) in open loop, closed loop and
with the pursuer's feedback against a passive evader, their Monte Carlo estimates, and whether the
game's iteration converged."""

from __future__ import annotations

from gamespec.result import Result

LOOPS = (
    ("open_loop", "open loop"),
    ("closed_loop", "closed loop"),
    ("pursuer_feedback", "pursuer's feedback, evader open loop"),
)


def flow_game_summary(result: Result) -> list[tuple[str, object]]:
    """``T̂``, ``x_f``, the capture probabilities (eq. 5.39 and Monte Carlo), converged."""
    m = result.metrics
    if "capture_time" not in m:
        return []
    rows: list[tuple[str, object]] = [
        ("capture time T̂", m["capture_time"]),
        ("capture point x_f", "[" + ", ".join(f"{v:.4g}" for v in m["capture_point"]) + "]"),
    ]
    carlo = m.get("monte_carlo_capture_probability", {})
    for key, label in LOOPS:
        if f"capture_probability_{key}" not in m:
            continue
        rows.append((f"P(capture at T̂), {label}", m[f"capture_probability_{key}"]))
        if key in carlo:
            c = carlo[key]
            rows.append(
                (
                    f"  Monte Carlo ({c['samples']} paths)",
                    f"{c['estimate']:.4g} [{c['low']:.4g}, {c['high']:.4g}]",
                )
            )
    rows.append(("game converged", f"{m['game_converged']} ({m.get('game_scheme', 'gauss_seidel')})"))
    return rows
