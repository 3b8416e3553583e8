"""The ``hji`` backend's optional engine on hj_reachability (``solver.options.hji.engine:
hj_reachability``; the ``hj`` extra: ``pip install gamespec[hj]``).

The same value as :func:`gamespec_levelset.hji.reach_value` — ``∂φ/∂τ = min(0, min_u max_d ∇φ·f)``
from the target's level, with ``φ ← max(φ, g)`` for an avoid set (reach–avoid) — solved by
hj_reachability (Bansal & Tomlin's JAX toolbox: its upwind ENO2/WENO5 schemes, TVD-RK3, the
``backwards_reachable_tube`` Hamiltonian postprocessor and the ``static_obstacle`` value
postprocessor, linear extrapolation at the grid's edge as in the project's engine). Its Lax–Friedrichs
dissipation is global (one α per axis over the grid), the project's local. The dynamics are printed
by SymPy's JAX printer (``lambdify(..., modules="jax")``) and the Hamiltonian's min and max are over
the same control samples (:func:`gamespec_levelset.hji.control_samples`). Values are kept at
``outputs`` equally spaced times, so the capture times are linear between those (not between the
solver's own steps). JAX runs in 64-bit here (``jax_enable_x64``, set process-wide on first use).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import sympy as sp

from gamespec.flowfield.grid import Grid
from gamespec.specs.differential_game import DifferentialGameSpec
from gamespec.symbolic.language import symbol
from gamespec_levelset.hji import HJIOptions, ReachRun, at_point, bilinear, control_samples

SCHEMES = {"first_order": "first_order", "eno2": "ENO2", "weno5": "WENO5"}
"""The project's scheme names → hj_reachability's ``upwind_first`` functions."""


def available() -> str | None:
    """None when hj_reachability and JAX import here, else why not."""
    try:
        import hj_reachability  # noqa: F401
        import jax  # noqa: F401
    except ImportError as err:
        return f"the hj_reachability engine needs the hj extra (pip install 'gamespec[hj]'): {err}"
    return None


def reach_value_hj(
    game: DifferentialGameSpec,
    grid: Grid,
    initial: np.ndarray,
    horizon: float,
    options: HJIOptions,
    parameters: dict[str, float],
    avoid: np.ndarray | None = None,
    probe: tuple[float, float] | None = None,
) -> ReachRun:
    """:class:`~gamespec_levelset.hji.ReachRun` of the game on ``grid`` by hj_reachability (module doc)."""
    import jax

    jax.config.update("jax_enable_x64", True)  # type: ignore[no-untyped-call, unused-ignore]
    import hj_reachability as hj
    import jax.numpy as jnp

    sampled = control_samples(game, options.control_samples, parameters)
    names = sampled.controls
    pairs = jnp.array([[[(u | d)[c] for c in names] for d in sampled.ds] for u in sampled.us])
    args = [symbol(s) for s in sampled.states] + [symbol(c) for c in names]
    printed = sp.lambdify(args, sampled.exprs, modules="jax")

    def f(state: Any, control: Any) -> Any:
        return jnp.stack([jnp.asarray(v, dtype=float) for v in printed(state[0], state[1], *control)])

    def every(state: Any) -> Any:
        return jax.vmap(jax.vmap(lambda c: f(state, c)))(pairs)

    class SampledDynamics(hj.Dynamics):  # type: ignore[misc]
        """The game's dynamics with the Hamiltonian's min–max over the control samples."""

        def __call__(self, state: Any, control: Any, disturbance: Any, time: Any) -> Any:
            return f(state, control)

        def optimal_control_and_disturbance(self, state: Any, time: Any, grad_value: Any) -> Any:
            h = every(state) @ grad_value
            best_d = jnp.argmax(h, axis=1)
            k = jnp.argmin(jnp.take_along_axis(h, best_d[:, None], axis=1)[:, 0])
            return pairs[k, best_d[k]], jnp.zeros(1)

        def partial_max_magnitudes(self, state: Any, time: Any, value: Any, grad_value_box: Any) -> Any:
            return jnp.abs(every(state)).max(axis=(0, 1))

    unused = hj.sets.Box(jnp.zeros(1), jnp.ones(1))
    dynamics = SampledDynamics("min", "max", unused, unused)
    edges = (hj.boundary_conditions.extrapolate, hj.boundary_conditions.extrapolate)
    hj_grid = hj.Grid.from_lattice_parameters_and_boundary_conditions(
        hj.sets.Box(jnp.array(grid.lower), jnp.array(grid.upper)), grid.shape, edges
    )
    start = initial if avoid is None else np.maximum(initial, avoid)
    settings = hj.SolverSettings(
        upwind_scheme=getattr(hj.finite_differences.upwind_first, SCHEMES[options.scheme]),
        hamiltonian_postprocessor=hj.solver.backwards_reachable_tube,
        value_postprocessor=hj.solver.identity
        if avoid is None
        else hj.solver.static_obstacle(jnp.array(avoid)),
        CFL_number=options.cfl,
    )
    outputs = 2 * options.hj_outputs
    times = np.linspace(0.0, -horizon, outputs + 1)
    values = np.asarray(hj.solve(settings, dynamics, hj_grid, times, jnp.array(start), progress_bar=False))
    return _run(values, -times, grid, probe)


def _run(values: np.ndarray, taus: np.ndarray, grid: Grid, probe: tuple[float, float] | None) -> ReachRun:
    """The ReachRun of the values ``values[k]`` at the times ``taus[k]`` (first zero crossings,
    linear between the stored times)."""
    arrival = np.where(values[0] <= 0, 0.0, np.inf)
    weights = bilinear(grid, probe)
    along = [at_point(v, weights) for v in values]
    probe_arrival = 0.0 if along[0] <= 0 else math.inf
    for k in range(1, len(values)):
        before, now = values[k - 1], values[k]
        reached = (now <= 0) & np.isinf(arrival)
        share = before[reached] / (before[reached] - now[reached])
        arrival[reached] = taus[k - 1] + share * (taus[k] - taus[k - 1])
        if math.isinf(probe_arrival) and along[k] <= 0:
            probe_arrival = taus[k - 1] + along[k - 1] / (along[k - 1] - along[k]) * (taus[k] - taus[k - 1])
    half = len(values) // 2
    return ReachRun(values[-1].copy(), values[half].copy(), arrival, float(probe_arrival), len(values) - 1)
