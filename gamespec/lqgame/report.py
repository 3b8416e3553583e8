"""The rows that lead an ``lq_stochastic_game``'s solve summary: the terminal mean and covariance
against the controller's target (eq. 4.62), the payoffs and the solution found."""

from __future__ import annotations

import numpy as np

from gamespec.result import Result


def _vector(values: object) -> str:
    return "[" + ", ".join("free" if v is None else f"{v:.4g}" for v in values) + "]"


def _solution(m: dict) -> list[tuple[str, object]]:
    concept = m.get("solution_concept")
    if concept is None:
        return []
    parts = m.get("solution_concepts", {})
    rows: list[tuple[str, object]] = [
        ("solution", f"{concept} (mean: {parts.get('mean')}, covariance: {parts.get('covariance')})")
    ]
    gap = m.get("saddle_gap")
    rows.append(("saddle gap", "not computed" if gap is None else f"{gap:.3g}"))
    for name, passed in m.get("checks_passed", {}).items():
        if name in ("saddle_gap", "follower_gap") and not passed:
            rows.append((name, f"exceeds the tolerance {m['check_tolerances'][name]:.3g}"))
    return rows


def lq_summary(result: Result) -> list[tuple[str, object]]:
    """Terminal mean and covariance diagonal, each beside its target when the file gives one, the
        largest eigenvalue of Σ_N(reached) − Σ_N(target) (≤ 0 when met), the smallest achievable
        scaling when Σ_N is out of reach, the mean and covariance payoffs, and which solution it is (its
    concept, the gap and its verdict: :mod:`gamespec.lqgame.equilibrium`)."""
    m = result.metrics
    if "terminal_mean" not in m:
        return []
    rows: list[tuple[str, object]] = [("terminal mean", _vector(m["terminal_mean"]))]
    if "target_mean" in m:
        rows.append(("target mean", _vector(m["target_mean"])))
    reached = np.asarray(m["terminal_covariance"])
    rows.append(("terminal covariance (diagonal)", _vector(np.diag(reached))))
    if "target_covariance" in m:
        target = np.asarray(m["target_covariance"])
        rows.append(("target covariance (diagonal)", _vector(np.diag(target))))
        rows.append(("max eig(Σ_N − target)", float(np.linalg.eigvalsh(reached - target).max())))
    if "min_covariance_scaling" in m:
        rows.append(("smallest reachable scaling of the target", m["min_covariance_scaling"]))
    rows += [("mean payoff", m.get("mean_payoff")), ("covariance payoff", m.get("covariance_payoff"))]
    rows += _solution(m)
    return [(k, v) for k, v in rows if v is not None]
