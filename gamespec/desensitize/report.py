"""The rows a desensitized solve adds to its summary (``gamespec solve``): what chapter 6 reports.

The nominal objective and the sensitivity cost it was traded against (eq. 6.26's two terms), the
final sensitivities ``S(t_f)`` (eqs. 6.24, 6.50) and the measure ``∫ Sᵀ S dt``, and the Monte Carlo
of the open-loop control about the nominal (§6.3.1): each original state's final mean and standard
deviation, the LQR-tracking closed loop's (eqs. 6.27–6.29) and its control energy, where it ran.
The ``desensitize`` transform names it as its ``summary``; it reads the
Result alone.
"""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


def _spread(mc: dict, states: list[str]) -> Rows:
    """``state(t_f)``: mean ± standard deviation over the samples."""
    means, stds = mc.get("final_state_mean", {}), mc.get("final_state_std", {})
    return [(f"{s}(t_f)", f"{means[s]:.6g} ± {stds[s]:.3g}") for s in states if s in means and s in stds]


def monte_carlo_rows(mc: dict, states: list[str]) -> Rows:
    """The open-loop Monte Carlo's final states (and the tracking closed loop's, where it ran)."""
    samples = mc.get("samples")
    rows: Rows = [("Monte Carlo samples (open loop)", samples)]
    rows += [(f"Monte Carlo {name}", value) for name, value in _spread(mc, states)]
    tracking = mc.get("tracking")
    if tracking:
        rows += [(f"LQR tracking {name}", value) for name, value in _spread(tracking, states)]
        energy, spread = tracking.get("control_energy_mean"), tracking.get("control_energy_std")
        if energy is not None:
            rows.append(("LQR tracking energy ∫Δu²", f"{energy:.6g} ± {spread or 0.0:.3g}"))
    return rows


def desensitization_summary(result: Result) -> Rows:
    """The rows of the module doc (none for a Result without desensitization metrics)."""
    m = result.metrics
    if "desensitization" not in m:
        return []
    rows: Rows = [
        ("nominal objective", m.get("nominal_objective")),
        ("sensitivity cost", m.get("sensitivity_cost")),
        ("sensitivity measure ∫SᵀS dt", m.get("sensitivity_measure")),
    ]
    rows += [(f"S(t_f) {name}", value) for name, value in m.get("final_sensitivity", {}).items()]
    original = list(result.states)[: m["desensitization"].get("original_states", 0)]
    if "monte_carlo" in m:
        rows += monte_carlo_rows(m["monte_carlo"], original)
    return rows
