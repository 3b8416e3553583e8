"""Monte Carlo check of a desensitized solution (§6.3.1, §6.5.2): draw the uncertain parameters,
re-simulate the solution's open-loop control (:func:`monte_carlo`) or the LQR-tracking closed loop
of eqs. 6.27-6.29 (:func:`tracking`, the same draws) for every sample at once, and summarize final
states, costs and path-constraint violations. It only re-simulates; it never solves. The two are
the ``monte_carlo`` and ``lqr_tracking`` analyses of the desensitize and rcs transforms.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

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

DRAWS_KEPT = 200
"""How many of the drawn parameter values (the first ones) are kept, with each one's verdict, for
plots of where the uncertainty is (e.g. the sampled obstacles of the rcs figure)."""

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
    for i, (name, expr) in enumerate(zip(ocp.states, ocp.initial_values, strict=True)):
        x0[i] = result.states[name][0] if expr is None else evaluate([expr], params, (samples,))[0]
    return x0


@dataclass(frozen=True)
class Draws:
    """The sampled parameters of a Monte Carlo run and what every re-simulation of it starts from."""

    drawn: dict[str, np.ndarray]
    nominal: dict[str, float]
    params: dict[Any, Any]
    x0: np.ndarray
    controls: TranscribedSignal
    inputs: TranscribedSignal | None
    t0: float
    tf: float


def draws(
    ocp: SymbolicOcp, result: Result, uncertain: Mapping[str, UncertainParameter], options: MonteCarloOptions
) -> Draws:
    """``options.samples`` draws (seed ``options.seed``) of the uncertain parameters about the
    Result's values, the initial states and the Result's control (and grid inputs) as signals."""
    nominal = {k: float(v) for k, v in result.parameters.items()}
    drawn = sample(distributions(uncertain, nominal), options.samples, options.seed)
    params = {symbol(k): drawn.get(k, v) for k, v in nominal.items()}
    return Draws(
        drawn,
        nominal,
        params,
        initial_state(ocp, result, params, options.samples),
        transcribed_signal(result, ocp.controls),
        transcribed_signal(result, ocp.inputs) if ocp.inputs else None,
        float(result.time[0]),
        float(result.t_final),
    )


def monte_carlo(
    ocp: SymbolicOcp, result: Result, uncertain: Mapping[str, UncertainParameter], options: MonteCarloOptions
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """``metrics.monte_carlo`` for the open-loop control of ``result``, and the trajectories of the
    first :data:`BUNDLE` samples (``monte_carlo_<state>``, (steps+1, samples) each, on
    ``monte_carlo_time``) and the first :data:`DRAWS_KEPT` draws of each uncertain parameter
    (``monte_carlo_draw_<name>``) for plots; with path constraints, the fraction of all samples that
    have violated one by each time (``monte_carlo_violated``, on ``monte_carlo_time``: its last
    value is ``violation_probability``), whether each kept draw violated one
    (``monte_carlo_draw_violated``, 1 or 0), and the largest violation of the same open-loop
    re-simulation at the nominal parameters (``metrics.nominal_violation``, with
    ``nominal_violated``: the deterministic nominal's own verdict on the same grid)."""
    d = draws(ocp, result, uncertain, options)
    run = rk4(
        ocp,
        d.x0,
        d.controls,
        d.params,
        d.t0,
        d.tf,
        options.steps,
        keep=BUNDLE,
        inputs=d.inputs,
        tolerance=VIOLATION_TOL,
    )
    spread = summarize(d.drawn)
    metrics = {
        "samples": options.samples,
        "seed": options.seed,
        "parameters": {
            k: {"mean": v.mean, "std": v.std, "min": v.min, "max": v.max} for k, v in spread.items()
        },
    }
    metrics.update(_outcome(ocp, d.x0, run, d.params))
    metrics["control_energy_mean"] = float(run.energy.mean())
    arrays = {"monte_carlo_time": run.t} | _bundle("monte_carlo", ocp, run)
    arrays |= {f"monte_carlo_draw_{k}": v[:DRAWS_KEPT] for k, v in d.drawn.items()}
    if ocp.path:
        arrays["monte_carlo_violated"] = run.violated
        arrays["monte_carlo_draw_violated"] = (run.violation[:DRAWS_KEPT] > VIOLATION_TOL).astype(float)
        nominal = _nominal_violation(ocp, result, d, options.steps)
        metrics["nominal_violation"] = nominal
        metrics["nominal_violated"] = nominal > VIOLATION_TOL
    return metrics, arrays


def _nominal_violation(ocp: SymbolicOcp, result: Result, d: Draws, steps: int) -> float:
    """The largest path-constraint violation of the open-loop re-simulation at the nominal
    parameters (one sample, the grid of the Monte Carlo's)."""
    params = {symbol(k): v for k, v in d.nominal.items()}
    x0 = initial_state(ocp, result, params, 1)
    run = rk4(ocp, x0, d.controls, params, d.t0, d.tf, steps, keep=0, inputs=d.inputs)
    return float(run.violation[0])


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


def tracking(
    ocp: SymbolicOcp, result: Result, uncertain: Mapping[str, UncertainParameter], options: MonteCarloOptions
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """``metrics.monte_carlo.tracking``: the closed loop ``u = u* - K(t)(x - x*(t))`` of eqs.
    6.27-6.29 for the draws of :func:`monte_carlo` (the same seed), and its first :data:`BUNDLE`
    trajectories (``tracking_<state>``)."""
    d = draws(ocp, result, uncertain, options)
    nominal_params = {symbol(k): v for k, v in d.nominal.items()}
    x0_nominal = initial_state(ocp, result, nominal_params, 1)
    reference = rk4(ocp, x0_nominal, d.controls, nominal_params, d.t0, d.tf, options.steps, inputs=d.inputs)
    A, B = linearization(ocp, reference, nominal_params, d.inputs)
    K = riccati_gains(reference.t, A, B)
    x_ref = reference.x[:, :, 0]

    def law(k: int, x: np.ndarray) -> np.ndarray:
        return -K[k] @ (x - x_ref[k][:, None])

    run = rk4(
        ocp, d.x0, d.controls, d.params, d.t0, d.tf, options.steps, keep=BUNDLE, inputs=d.inputs, feedback=law
    )
    out = _outcome(ocp, d.x0, run, d.params)
    energy = summarize({"energy": run.energy})["energy"]
    out["control_energy_mean"], out["control_energy_std"] = energy.mean, energy.std
    return out, _bundle("tracking", ocp, run)
