"""Monte Carlo check of a desensitized solution (§6.3.1, §6.5.2): draw the uncertain parameters,
re-simulate the solution's open-loop control (and, when asked, the LQR-tracking closed loop of
eqs. 6.27-6.29) for every sample at once, and summarize final states, costs and path-constraint
violations. It only re-simulates; it never solves.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from gamespec.desensitize.augment import initial_values
from gamespec.desensitize.simulate import Trajectories, cost, evaluate, rk4
from gamespec.desensitize.spec import MonteCarloOptions
from gamespec.desensitize.tracking import linearization, riccati_gains
from gamespec.montecarlo import Distribution, Normal, Uniform, proportion, sample, summarize
from gamespec.ocp.control_signal import TranscribedSignal, transcribed_signal
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.specs.uncertainty import UncertainParameter
from gamespec.symbolic.language import symbol

BUNDLE = 50
"""How many sampled trajectories are kept for plots."""

VIOLATION_TOL = 1e-6
"""A sample violates the path constraints when its largest violation exceeds this."""


def distributions(
    uncertain: Mapping[str, UncertainParameter], nominal: Mapping[str, float]
) -> dict[str, Distribution]:
    """The Monte Carlo engine's distribution of each uncertain parameter about its nominal value."""
    out: dict[str, Distribution] = {}
    for name, dist in uncertain.items():
        if dist.normal is not None:
            out[name] = Normal(nominal[name], dist.normal.std)
        else:
            out[name] = Uniform(*dist.uniform_bounds(nominal[name]))
    return out


def initial_state(ocp: SymbolicOcp, result: Result, params: Mapping[Any, Any], samples: int) -> np.ndarray:
    """The initial state of each sample: the solution's, or the file's expression of the (sampled)
    parameters when the initial value depends on them."""
    x0 = np.empty((len(ocp.states), samples))
    for i, (name, expr) in enumerate(zip(ocp.states, initial_values(ocp), strict=True)):
        x0[i] = result.states[name][0] if expr is None else evaluate([expr], params, (samples,))[0]
    return x0


def monte_carlo(
    ocp: SymbolicOcp, result: Result, uncertain: Mapping[str, UncertainParameter], options: MonteCarloOptions
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """``metrics.monte_carlo`` for the open-loop control of ``result`` (with ``tracking`` when asked),
    and the trajectories of the first :data:`BUNDLE` samples (``monte_carlo_<state>``, and
    ``tracking_<state>``, (steps+1, samples) each, on ``monte_carlo_time``) for plots."""
    nominal = {k: float(v) for k, v in result.parameters.items()}
    n = options.samples
    drawn = sample(distributions(uncertain, nominal), n, options.seed)
    params = {symbol(k): drawn.get(k, v) for k, v in nominal.items()}
    t0, tf = float(result.time[0]), float(result.t_final)
    x0 = initial_state(ocp, result, params, n)
    u_star = transcribed_signal(result, ocp.controls)
    signals = transcribed_signal(result, ocp.inputs) if ocp.inputs else None
    run = rk4(ocp, x0, u_star, params, t0, tf, options.steps, keep=BUNDLE, inputs=signals)
    spread = summarize(drawn)
    metrics = {
        "samples": n,
        "seed": options.seed,
        "parameters": {
            k: {"mean": v.mean, "std": v.std, "min": v.min, "max": v.max} for k, v in spread.items()
        },
    }
    metrics.update(_outcome(ocp, x0, run, params))
    metrics["control_energy_mean"] = float(run.energy.mean())
    arrays = {"monte_carlo_time": run.t} | _bundle("monte_carlo", ocp, run)
    if options.tracking:
        metrics["tracking"], closed = _tracking(ocp, result, params, nominal, (u_star, signals), options, x0)
        arrays |= _bundle("tracking", ocp, closed)
    return metrics, arrays


def _bundle(prefix: str, ocp: SymbolicOcp, run: Trajectories) -> dict[str, np.ndarray]:
    return {f"{prefix}_{s}": run.x[:, i, :] for i, s in enumerate(ocp.states)}


def _outcome(
    ocp: SymbolicOcp, x0: np.ndarray, run: Trajectories, params: Mapping[Any, Any]
) -> dict[str, Any]:
    final = summarize(dict(zip(ocp.states, run.final, strict=True)))
    costs = summarize({"cost": cost(ocp, x0, run, params)})["cost"]
    out = {
        "final_state_mean": {s: v.mean for s, v in final.items()},
        "final_state_std": {s: v.std for s, v in final.items()},
        "cost_mean": costs.mean,
        "cost_std": costs.std,
        "cost_min": costs.min,
        "cost_max": costs.max,
        "cost_mean_ci": [costs.ci_low, costs.ci_high],
    }
    if ocp.path:
        violated = proportion(run.violation > VIOLATION_TOL)
        out["violation_probability"] = violated.estimate
        out["violation_probability_ci"] = [violated.low, violated.high]
    return out


def _tracking(
    ocp: SymbolicOcp,
    result: Result,
    params: Mapping[Any, Any],
    nominal: Mapping[str, float],
    signals: tuple[TranscribedSignal, TranscribedSignal | None],
    options: MonteCarloOptions,
    x0: np.ndarray,
) -> tuple[dict[str, Any], Trajectories]:
    """The closed loop ``u = u* - K(t)(x - x*(t))`` of eqs. 6.27-6.29 for the same samples."""
    t0, tf = float(result.time[0]), float(result.t_final)
    nominal_params = {symbol(k): v for k, v in nominal.items()}
    x0_nominal = initial_state(ocp, result, nominal_params, 1)
    u_star, inputs = signals
    reference = rk4(ocp, x0_nominal, u_star, nominal_params, t0, tf, options.steps, inputs=inputs)
    A, B = linearization(ocp, reference, nominal_params, inputs)
    K = riccati_gains(reference.t, A, B)
    x_ref = reference.x[:, :, 0]

    def law(k: int, x: np.ndarray) -> np.ndarray:
        return -K[k] @ (x - x_ref[k][:, None])

    run = rk4(ocp, x0, u_star, params, t0, tf, options.steps, keep=BUNDLE, inputs=inputs, feedback=law)
    out = _outcome(ocp, x0, run, params)
    energy = summarize({"energy": run.energy})["energy"]
    out["control_energy_mean"], out["control_energy_std"] = energy.mean, energy.std
    return out, run
