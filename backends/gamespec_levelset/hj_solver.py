"""The level-set step of eq. 5.22 by hj_reachability (JAX), for the optional ``hj_reachability``
backend: the same WENO5 + TVD-RK3 scheme (with global Lax–Friedrichs dissipation), compiled by XLA.

``HJSolver`` offers what :func:`gamespec.flowfield.levelset.capture_by_level_sets` uses of a
solver (``grid``, ``hamiltonian``, ``max_step``, ``step``, ``propagate``), so the capture search,
the nominal paths and the game are unchanged. The drift is translated to ``jax.numpy`` through
:func:`gamespec.symbolic.translate.translate`. hj_reachability and jax are imported only here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gamespec.flowfield.field import FlowField
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.symbolic.library import NUMPY, Library
from gamespec.symbolic.translate import translate


def jax_library() -> Library:
    """The NumPy translator's functions, each replaced by its ``jax.numpy`` namesake."""
    import jax.numpy as jnp

    def twin(name: str, func: Any) -> Any:
        if name == "heaviside":
            return lambda x: jnp.heaviside(x, 0.5)
        return getattr(jnp, func.__name__)

    return Library({name: twin(name, f) for name, f in NUMPY.functions.items()}, power=jnp.power)


def drift_dynamics(flow: FlowField, speed: float) -> Any:
    """``ẋ = f(x) + u`` with ``|u| ≤ v̂`` as hj_reachability dynamics whose Hamiltonian is
    ``max_u p·(f + u) = p·f + v̂|p|`` (eq. 5.22, forward in time)."""
    import hj_reachability as hj
    import jax.numpy as jnp

    library = jax_library()

    class Drift(hj.ControlAndDisturbanceAffineDynamics):
        def __init__(self) -> None:
            control = hj.sets.Ball(jnp.zeros(2), speed)
            super().__init__("max", "min", control, hj.sets.Box(jnp.zeros(1), jnp.zeros(1)))

        def open_loop_dynamics(self, state: Any, time: Any) -> Any:
            values = dict(zip(flow.position, (state[0], state[1]), strict=True))
            return jnp.stack(
                [translate(e, values, library) * jnp.ones_like(state[0]) for e in flow.drift_exprs]
            )

        def control_jacobian(self, state: Any, time: Any) -> Any:
            return jnp.eye(2)

        def disturbance_jacobian(self, state: Any, time: Any) -> Any:
            return jnp.zeros((2, 1))

    return Drift()


def hj_grid(grid: Grid) -> Any:
    """The same nodes as an hj_reachability grid (linear extrapolation at the edges)."""
    import hj_reachability as hj
    import jax.numpy as jnp

    box = hj.sets.Box(jnp.array(grid.lower, dtype=float), jnp.array(grid.upper, dtype=float))
    return hj.Grid.from_lattice_parameters_and_boundary_conditions(box, grid.shape)


def tvd_rk3(settings: Any, dynamics: Any, grid: Any, values: Any, dt: Any) -> Any:
    """One TVD-RK3 step of exactly ``dt`` from hj_reachability's forward Euler step (its
    ``third_order_total_variation_diminishing_runge_kutta`` with the step given, not re-derived from
    the CFL bound in float32, which can split a step in two)."""
    from hj_reachability.time_integration import euler_step

    def euler(v: Any) -> Any:
        return euler_step(settings, dynamics, grid, 0.0, v, time_step=dt)[1]

    first = euler(values)
    second = 0.75 * values + 0.25 * euler(first)
    return values / 3 + 2 / 3 * euler(second)


_COMPILED: dict[tuple, Any] = {}
"""The compiled step of each (grid, drift, speeds, CFL number) met in this process."""


def compiled_step(grid: Grid, flow: FlowField, speeds: tuple[float, ...], cfl: float) -> Any:
    """``(φ (agents, nx, ny), dt) → φ`` after one step of every agent, traced and compiled by XLA
    on the first call for these values and reused by every later solver for them."""
    key = (grid, tuple(map(str, flow.position)), str(flow.drift_exprs), speeds, cfl)
    if key not in _COMPILED:
        import hj_reachability as hj
        import jax
        import jax.numpy as jnp

        nodes = hj_grid(grid)
        settings = hj.SolverSettings.with_accuracy("very_high", CFL_number=cfl)
        dynamics = [drift_dynamics(flow, s) for s in speeds]

        def advance(values: Any, dt: Any) -> Any:
            return jnp.stack(
                [tvd_rk3(settings, d, nodes, v, dt) for d, v in zip(dynamics, values, strict=True)]
            )

        _COMPILED[key] = jax.jit(advance)
    return _COMPILED[key]


@dataclass
class HJSolver:
    """Both agents' level sets advanced together by one compiled (XLA) TVD-RK3 step of
    hj_reachability's WENO5 / Lax–Friedrichs operator, in JAX's default single precision."""

    grid: Grid
    flow: FlowField
    speeds: np.ndarray
    cfl: float = 0.5
    _advance: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.hamiltonian = FlowHamiltonian(np.asarray(self.speeds, float), self.flow.drift(self.grid.points))
        speeds = tuple(float(s) for s in self.speeds)
        self._advance = compiled_step(self.grid, self.flow, speeds, float(self.cfl))

    @property
    def max_step(self) -> float:
        return self.hamiltonian.max_step(self.grid.spacing, self.cfl)

    def step(self, phi: np.ndarray, dt: float, band: float | None = None) -> np.ndarray:
        """One step ``dt`` of every agent on the whole grid (``band`` is not needed: φ is kept exact
        everywhere)."""
        return np.asarray(self._advance(np.asarray(phi, dtype=np.float32), dt))

    def propagate(self, phi: np.ndarray, duration: float, band: float | None = None) -> np.ndarray:
        """φ after ``duration``, in equal CFL-limited steps."""
        count = max(1, int(np.ceil(duration / self.max_step)))
        for _ in range(count):
            phi = self.step(phi, duration / count)
        return phi
