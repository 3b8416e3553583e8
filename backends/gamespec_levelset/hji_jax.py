"""The ``hji`` backend's optional engine on hj_reachability (``solver.options.hji.engine:
hj_reachability``; the ``hj`` extra: ``pip install gamespec[hj]``).

The same value as :func:`gamespec_levelset.hji.reach_value` — ``∂φ/∂τ = min(0, min_u max_d ∇φ·f)``
from the target's level, with ``φ ← max(φ, g)`` for an avoid set (reach–avoid) — solved by
hj_reachability (Bansal & Tomlin's JAX toolbox: its upwind ENO2/WENO5 schemes, TVD-RK3, the
``backwards_reachable_tube`` Hamiltonian postprocessor and the ``static_obstacle`` value
postprocessor, linear extrapolation at the grid's edge as in the project's engine). Its Lax–Friedrichs
dissipation is global (one α per axis over the grid), the project's local (``flux: lax_friedrichs``)
or, by default, none beyond each control sample's upwinding (``flux: upwind``), so the two engines
differ by their dissipation near a narrow neck (the chauffeur's threshold). The dynamics are printed
by SymPy's JAX printer (``lambdify(..., modules="jax")``) and the Hamiltonian's min and max are over
the same control samples (:func:`gamespec_levelset.hji.control_samples`). Values are kept at
the times the caller asks for (``hj_outputs`` per half horizon), so the capture times are linear
between those (not between the solver's own steps). It imports nothing of :mod:`gamespec_levelset.hji`
(which calls it). JAX runs in 64-bit here (``jax_enable_x64``, set process-wide on first use).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import sympy as sp

from gamespec.symbolic.language import symbol

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


def reach_values_hj(
    exprs: list[sp.Expr],
    names: list[str],
    pairs: list[list[list[float]]],
    box: tuple[tuple[float, float], tuple[float, float], tuple[int, int]],
    initial: np.ndarray,
    times: np.ndarray,
    scheme: str,
    cfl: float,
    avoid: np.ndarray | None = None,
) -> np.ndarray:
    """φ at each of the (decreasing, from 0) hj_reachability ``times`` (module doc) for the dynamics
    ``exprs`` over ``names`` (the two states, then the controls) with the Hamiltonian's min–max
    over ``pairs[k][m]`` (the controls of the minimizers' k-th and the maximizers' m-th sample), on
    the grid ``box`` (lower corner, upper corner, nodes per axis)."""
    import jax

    jax.config.update("jax_enable_x64", True)  # type: ignore[no-untyped-call, unused-ignore]
    import hj_reachability as hj
    import jax.numpy as jnp

    samples = jnp.array(pairs)
    printed = sp.lambdify([symbol(n) for n in names], exprs, modules="jax")

    def f(state: Any, control: Any) -> Any:
        return jnp.stack([jnp.asarray(v, dtype=float) for v in printed(state[0], state[1], *control)])

    def every(state: Any) -> Any:
        return jax.vmap(jax.vmap(lambda c: f(state, c)))(samples)

    class SampledDynamics(hj.Dynamics):  # type: ignore[misc]
        """The game's dynamics with the Hamiltonian's min–max over the control samples."""

        def __call__(self, state: Any, control: Any, disturbance: Any, time: Any) -> Any:
            return f(state, control)

        def optimal_control_and_disturbance(self, state: Any, time: Any, grad_value: Any) -> Any:
            h = every(state) @ grad_value
            best_d = jnp.argmax(h, axis=1)
            k = jnp.argmin(jnp.take_along_axis(h, best_d[:, None], axis=1)[:, 0])
            return samples[k, best_d[k]], jnp.zeros(1)

        def partial_max_magnitudes(self, state: Any, time: Any, value: Any, grad_value_box: Any) -> Any:
            return jnp.abs(every(state)).max(axis=(0, 1))

    unused = hj.sets.Box(jnp.zeros(1), jnp.ones(1))
    dynamics = SampledDynamics("min", "max", unused, unused)
    edges = (hj.boundary_conditions.extrapolate, hj.boundary_conditions.extrapolate)
    lower, upper, shape = box
    grid = hj.Grid.from_lattice_parameters_and_boundary_conditions(
        hj.sets.Box(jnp.array(lower), jnp.array(upper)), shape, edges
    )
    start = initial if avoid is None else np.maximum(initial, avoid)
    settings = hj.SolverSettings(
        upwind_scheme=getattr(hj.finite_differences.upwind_first, SCHEMES[scheme]),
        hamiltonian_postprocessor=hj.solver.backwards_reachable_tube,
        value_postprocessor=hj.solver.identity
        if avoid is None
        else hj.solver.static_obstacle(jnp.array(avoid)),
        CFL_number=cfl,
    )
    values = hj.solve(settings, dynamics, grid, jnp.array(times), jnp.array(start), progress_bar=False)
    return np.asarray(values)
