"""The rows a risk-constrained (RCS) solve adds to its summary: the collision probability; and the
summary of the §6.4.4 study, one row per point.

Chapter 6's headline for the RCS regularizer (§6.4) is the probability that the uncertain
obstacles hit the solved path, estimated by Monte Carlo over the uncertain parameters with its
confidence interval, next to the regularizer's weight and power. The ``rcs``
transform names it as its ``summary``; it reads the Result alone. :func:`point_line` is one point
of the §6.4.4 study in its summary (:func:`gamespec.rcs.multi_obstacle_study.rcs_study_summary`).
"""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


def rcs_summary(result: Result) -> Rows:
    """P_c with its interval and sample count, the nominal's verdict, and which constraints the
    regularizer weighted.

    "The nominal's" (issue 28) is read as the deterministic nominal's own verdict, not as P_c of an
    undesensitized (Q = 0) solve, which a single solve does not compute: the same open-loop
    re-simulation at the nominal parameters collides or not (its largest path-constraint violation
    on the Monte Carlo's grid, ``metrics.monte_carlo.nominal_violation``), and, for each obstacle
    off a track, the clearance (centre distance less r_o) at the agent's closest approach
    (``metrics.obstacle_samples``)."""
    m = result.metrics
    mc = m.get("monte_carlo", {})
    rows: Rows = []
    if "collision_probability" in mc:
        low, high = mc.get("collision_probability_ci", [None, None])
        interval = f" [{low:.3g}, {high:.3g}]" if low is not None and high is not None else ""
        rows.append(("collision probability P_c", f"{mc['collision_probability']:.4g}{interval}"))
        rows.append(("Monte Carlo samples", mc.get("samples")))
    if "nominal_violated" in mc:
        verdict = "collides" if mc["nominal_violated"] else "no collision"
        rows.append(
            (
                "nominal (parameters at their values)",
                f"{verdict}, largest violation {mc['nominal_violation']:.3g}",
            )
        )
    for name, entry in m.get("obstacle_samples", {}).items():
        if entry.get("clearance") is not None:
            rows.append(
                (f"nominal clearance to {name}", f"{entry['clearance']:.4g} at t = {entry['time']:.4g}")
            )
    rcs = m.get("rcs", {})
    if rcs.get("constraints"):
        rows.append(("regularized constraints", ", ".join(rcs["constraints"])))
    if "obstacle_power" in m:
        rows.append(("obstacle power β", m["obstacle_power"]))
    return rows


def point_line(entry: dict[str, object]) -> str:
    """P_c with its interval, the objective, the final time and the status of one table entry."""
    parts = []
    probability, interval = entry.get("collision_probability"), entry.get("collision_probability_ci")
    if isinstance(probability, float | int):
        low, high = interval if isinstance(interval, list | tuple) and len(interval) == 2 else (None, None)
        ci = f" [{low:.3g}, {high:.3g}]" if low is not None and high is not None else ""
        parts.append(f"P_c = {probability:.4g}{ci}")
    for name, label in (("objective", "objective"), ("t_final", "t_f")):
        value = entry.get(name)
        if isinstance(value, float | int):
            parts.append(f"{label} = {value:.6g}")
    parts.append(str(entry.get("status")))
    return ", ".join(parts)
