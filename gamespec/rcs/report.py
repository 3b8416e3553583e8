"""The rows a risk-constrained (RCS) solve adds to its summary: the collision probability.

Chapter 6's headline for the RCS regularizer (§6.4) is the probability that the uncertain
obstacles hit the solved path, estimated by Monte Carlo over the uncertain parameters with its
confidence interval, next to the regularizer's weight and power. The ``rcs``
transform names it as its ``summary``; it reads the Result alone.
"""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


def rcs_summary(result: Result) -> Rows:
    """P_c with its interval and sample count, and which constraints the regularizer weighted."""
    m = result.metrics
    mc = m.get("monte_carlo", {})
    rows: Rows = []
    if "collision_probability" in mc:
        low, high = mc.get("collision_probability_ci", [None, None])
        interval = f" [{low:.3g}, {high:.3g}]" if low is not None and high is not None else ""
        rows.append(("collision probability P_c", f"{mc['collision_probability']:.4g}{interval}"))
        rows.append(("Monte Carlo samples", mc.get("samples")))
    rcs = m.get("rcs", {})
    if rcs.get("constraints"):
        rows.append(("regularized constraints", ", ".join(rcs["constraints"])))
    if "obstacle_power" in m:
        rows.append(("obstacle power β", m["obstacle_power"]))
    return rows
