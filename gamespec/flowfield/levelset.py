"""Forward reachable sets of both agents by the level-set equation 5.22, and the capture time.

``φ_t + v̂|∇φ| + ∇φ·f = 0`` from ``φ(x, 0) = |x − x₀|`` (eq. 5.22), upwind in space
(:mod:`~gamespec.flowfield.upwind`), local Lax–Friedrichs (:mod:`~gamespec.flowfield.hamiltonian`),
TVD-RK3 in time with CFL-limited steps (:mod:`~gamespec.flowfield.tvd_rk`); φ of both agents is one
array (2, nx, ny), each advanced in place on its own rectangle of nodes (the whole grid, or in the
capture search the box of :mod:`~gamespec.flowfield.band` around the levels read).

The initial zero level set is a single point, and the viscosity solution from the cone is flat
inside the set: in still air ``φ(x, t) = max(|x − x₀| − v̂t, 0)`` (Hopf–Lax), so the zero level set
is the whole reachable set, not a curve, and its contour is numerical noise: the edge of the flat
region is smeared over a few cells, and a level read a fixed number of cells above it keeps an
error of fixed size under refinement (read at 4 cells, ``T̂`` stayed about 1e-3 off in uniform,
rotating and spiral flows for dx = 0.2, 0.1, 0.05). The capture search therefore reads two positive
levels ``c₁ < c₂`` fixed as *lengths* (the sets reached from the disks of radius ``c`` about the
starting points, where φ is smooth and the scheme keeps its order), so a refined grid puts more
cells between the smeared edge and the levels, and finds the capture time ``T(c)`` and point
``x_f(c)`` of each. Both are extrapolated linearly to ``c = 0``: in a uniform or linear flow
``A = σI + ωJ`` both sets grow by the same ``c e^{σt}``, so ``T(c) = T(0)`` and ``x_f(c)`` is affine
in ``c``, and the extrapolation is exact; in a general flow it leaves ``O(c₁c₂)``. The
extrapolation weighs the lower level's error twice (``c₂ = 2c₁``), so ``c₁`` should be several
cells out (6 on the shipped files: at 4 cells it was 5e-4 off on ``linear_flow.yaml``). Measured in
a uniform flow with ``c = (0.4, 0.8)``: errors 5.6e-3, 6.4e-4, 6.0e-5 in ``T̂`` for dx = 0.2, 0.1,
0.05 (orders 3.1, 3.4; ``tests/flowfield/test_levelset.py``); in rotating and spiral flows with
``c = (0.8, 1.6)`` orders 3.3 and 2.8 over dx = 0.2 → 0.05, with a step-to-step scatter of about
1e-4 from reading the fronts (contour and bilinear interpolation), which is also the floor on the
chapter-5 fields (about 6e-5 against extremal shooting at twice the files' resolution).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gamespec.errors import SpecError
from gamespec.flowfield.band import Window, band_window
from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.capture import first_zero, margin
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.scratch import Scratch
from gamespec.flowfield.tvd_rk import tvd_rk3_step
from gamespec.flowfield.upwind import GHOSTS, extrapolate_ghosts, upwind_pair
from gamespec.limits import MAX_GRID_CELL_STEPS

BAND_CELLS = 15.0
"""How far above the highest level read the band of exact values reaches, in cells: with the
margin, far enough that T̂ and x_f move by less than 1e-3 of their grid error on the chapter-5 fields
(on the Hugo field at 101² and 201² nodes, by at most 6e-8 in T̂ and 1e-5 in x_f)."""
BAND_MARGIN = GHOSTS + 2
"""Nodes added on each side of the band's bounding box (the stencil and a front's move in a step)."""


COMPILED_NODES = 150 * 150
"""From this many nodes on, ``engine: auto`` compiles the step in a process that has not yet: loading
Numba and its cached machine code costs about 0.65 s of CPU once per process, which the compiled
step (3–4× faster than NumPy's) earns back from about 150² nodes (the Hugo file's capture search
in a fresh process: 0.75 s compiled against 0.55 s NumPy at 101², 0.85 against 0.78 at 151²,
1.2 against 1.3 at 201²)."""


def choose_engine(engine: str, grid: Grid) -> str:
    """``compiled`` or ``numpy`` for an engine option: ``auto`` is ``compiled`` where the grid has
    at least :data:`COMPILED_NODES` nodes or the compiled step is already loaded in this process
    (later solves, studies), ``numpy`` otherwise."""
    if engine != "auto":
        return engine
    loaded = "gamespec.flowfield.compiled" in sys.modules
    return "compiled" if loaded or grid.shape[0] * grid.shape[1] >= COMPILED_NODES else "numpy"


def initial_cones(grid: Grid, origins: np.ndarray) -> np.ndarray:
    """``φ(x, 0) = |x − x₀ⁱ|`` for each origin (agents, 2) → (agents, nx, ny)."""
    return np.linalg.norm(grid.points[None] - np.asarray(origins)[:, None, None, :], axis=-1)


class _Buffers:
    """The padded state and stage arrays (nx + 6, ny + 6) of one agent at a time, and the scratch
    of the spatial operator."""

    def __init__(self, shape: tuple[int, int]) -> None:
        padded = (shape[0] + 2 * GHOSTS, shape[1] + 2 * GHOSTS)
        self.stages = tuple(np.zeros(padded) for _ in range(3))
        self.scratch = Scratch(padded[0] * padded[1])


@dataclass(frozen=True)
class LevelSetSolver:
    """The spatial operator ``−Ĥ(x, D⁻φ, D⁺φ)`` and its TVD-RK3 step on one grid.

    A step advances each agent's φ on one rectangle of nodes, in place in padded buffers, with
    ghost nodes extrapolated linearly from the rectangle: the whole grid, or with ``band`` the box
    of :func:`~gamespec.flowfield.band.band_window` around the nodes below ``band``; the ring of
    ghosts is written back (the nodes next to the box start from it when the box grows) and the
    values further out are left as they were, above the band."""

    grid: Grid
    hamiltonian: FlowHamiltonian
    scheme: str = "weno5"
    cfl: float = 0.5
    engine: str = "compiled"
    """``compiled``: WENO5 by the Numba loop of :mod:`~gamespec.flowfield.compiled` (the other
    schemes always by NumPy); ``numpy``: the NumPy operator of :mod:`~gamespec.flowfield.upwind`."""

    @property
    def compiled(self) -> bool:
        """Whether the rate is the compiled WENO5 loop."""
        return self.engine == "compiled" and self.scheme == "weno5"

    @property
    def max_step(self) -> float:
        """The CFL-limited step."""
        return self.hamiltonian.max_step(self.grid.spacing, self.cfl)

    @cached_property
    def _buffers(self) -> _Buffers:
        return _Buffers(self.grid.shape)

    def _rate(self, agent: int, padded: np.ndarray, window: Window) -> np.ndarray:
        """``φ_t = −Ĥ`` of ``agent`` on the nodes ``window`` of a padded array (a scratch array)."""
        g, (dx, dy), scratch = GHOSTS, self.grid.spacing, self._buffers.scratch
        rows, cols = window
        size = (rows.stop - rows.start, cols.stop - cols.start)
        if self.compiled:
            from gamespec.flowfield.compiled import weno5_rate

            out = scratch.take("hamiltonian", *size)
            h = self.hamiltonian
            speed = float(np.asarray(h.speeds, dtype=float)[agent])
            bounds = ((rows.start, rows.stop), (cols.start, cols.stop))
            weno5_rate(padded, *bounds, (float(dx), float(dy)), speed, h.flow, h.jump_weights[agent], out)
            return out
        mx, px = upwind_pair(
            padded[rows.start : rows.stop + 2 * g, cols.start + g : cols.stop + g],
            0,
            dx,
            self.scheme,
            scratch,
        )
        my, py = upwind_pair(
            padded[rows.start + g : rows.stop + g, cols.start : cols.stop + 2 * g],
            1,
            dy,
            self.scheme,
            scratch,
        )
        out = (scratch.take("hamiltonian", *size), scratch.take("work", *size))
        h = self.hamiltonian.numerical(agent, window, (mx, my), (px, py), out)
        return np.negative(h, out=h)

    def _advance(self, agent: int, values: np.ndarray, dt: float, band: float | None) -> np.ndarray:
        g = GHOSTS
        window = (slice(0, values.shape[0]), slice(0, values.shape[1]))
        if band is not None:
            window = band_window(values, band, BAND_MARGIN)
            if window is None:
                return values
        rows, cols = window
        halo = (slice(rows.start, rows.stop + 2 * g), slice(cols.start, cols.stop + 2 * g))
        nodes = (slice(rows.start + g, rows.stop + g), slice(cols.start + g, cols.stop + g))
        stages = self._buffers.stages
        stages[0][g:-g, g:-g] = values

        def rate(stage: int) -> np.ndarray:
            extrapolate_ghosts(stages[stage][halo])
            return self._rate(agent, stages[stage], window)

        tvd_rk3_step(stages[0][nodes], stages[1][nodes], stages[2][nodes], dt, rate)
        extrapolate_ghosts(stages[0][halo])
        return stages[0][g:-g, g:-g]

    def step(self, phi: np.ndarray, dt: float, band: float | None = None) -> np.ndarray:
        """φ (agents, nx, ny) after one step ``dt``; with ``band``, exact only at and below it."""
        out = np.empty(np.shape(phi))
        for agent, values in enumerate(np.asarray(phi, dtype=float)):
            out[agent] = self._advance(agent, values, dt, band)
        return out

    def propagate(self, phi: np.ndarray, duration: float, band: float | None = None) -> np.ndarray:
        """φ after ``duration``, in equal CFL-limited steps."""
        count = max(1, int(np.ceil(duration / self.max_step)))
        for _ in range(count):
            phi = self.step(phi, duration / count, band)
        return phi


@dataclass
class LevelSetReach:
    """What the level-set capture search found: ``capture_time`` (None if none before ``t_max`` or
    the front left the grid) and ``capture_point``, both extrapolated to level 0, the
    capture time and point of each level read (``level_times``, ``level_points``), the margin
    history ``m(t)`` of the upper level (section 5.2), the snapshots of φ (``snapshot_times``,
    (S, 2, nx, ny), capped at the ``band`` level above which φ was not kept exact) ending with φ at
    the capture time, and a ``message`` saying why no capture was found (``timed_out``: the
    budget's time limit stopped the search)."""

    grid: Grid
    levels: np.ndarray
    times: np.ndarray
    margins: np.ndarray
    snapshot_times: np.ndarray
    snapshots: np.ndarray
    capture_time: float | None = None
    capture_point: np.ndarray | None = None
    level_times: np.ndarray | None = None
    level_points: np.ndarray | None = None
    message: str = ""
    steps: int = 0
    band: float = np.inf
    timed_out: bool = False


def _touches_boundary(phi: np.ndarray, level: float) -> bool:
    edges = np.concatenate(
        [phi[:, 0].ravel(), phi[:, -1].ravel(), phi[:, :, 0].ravel(), phi[:, :, -1].ravel()]
    )
    return bool(edges.min() <= level)


def extrapolate_to_zero(levels: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The straight line through ``(levels[0], values[0])`` and ``(levels[1], values[1])`` at 0."""
    w = levels[0] / (levels[1] - levels[0])
    return values[0] - w * (values[1] - values[0])


class _LevelWatch:
    """The margin history of one level and its first zero."""

    def __init__(self, level: float) -> None:
        self.level = level
        self.times: list[float] = []
        self.margins: list[float] = []
        self.points: list[np.ndarray] = []
        self.crossing: tuple[float, np.ndarray] | None = None

    def observe(self, grid: Grid, phi: np.ndarray, t: float) -> None:
        found = margin(grid, phi[0], phi[1], self.level)
        if found is None or self.crossing is not None:
            return
        self.times.append(t)
        self.margins.append(found.value)
        self.points.append(found.point)
        if len(self.times) < 2:
            return
        zero = first_zero(np.array(self.times[-2:]), np.array(self.margins[-2:]))
        if zero is not None:
            w = (zero[1] - self.times[-2]) / (self.times[-1] - self.times[-2])
            self.crossing = zero[1], (1 - w) * self.points[-2] + w * self.points[-1]


GRID_ERROR_ORDER = 2
"""The order the grid-error estimate assumes: the least the tests observe for ``T̂`` (about 3 in
uniform flows, ``tests/flowfield/test_levelset.py``), so the estimate errs on the large side."""


def coarser_grid(grid: Grid) -> Grid:
    """The same box with every other node (about twice the spacing)."""
    return Grid(grid.lower, grid.upper, tuple((n - 1) // 2 + 1 for n in grid.shape))


def grid_error_estimate(fine: LevelSetReach, coarse: LevelSetReach) -> dict[str, float] | None:
    """Richardson's estimate of the error of ``T̂`` and ``x_f`` on the fine grid from the same levels
    read on a coarser one: ``|q_h − q_H| / (r^p − 1)`` with ``r = H/h`` and ``p`` =
    :data:`GRID_ERROR_ORDER`; None when either search found no capture."""
    if fine.capture_time is None or coarse.capture_time is None:
        return None
    ratio = float(coarse.grid.spacing.max() / fine.grid.spacing.max())
    scale = ratio**GRID_ERROR_ORDER - 1
    return {
        "capture_time": abs(fine.capture_time - coarse.capture_time) / scale,
        "capture_point": float(np.linalg.norm(fine.capture_point - coarse.capture_point)) / scale,
        "coarse_nodes": list(coarse.grid.shape),
        "order": GRID_ERROR_ORDER,
    }


def check_steps(grid: Grid, dt: float, t_max: float) -> None:
    """The load-time bound on the work (:meth:`~gamespec.flowfield.spec.FlowGameMethod.check_work`,
    which knows the agents' speeds only) again with the flow's speed on the grid in the CFL step
    ``dt``: the cells times the steps to ``t_max`` within
    :data:`~gamespec.limits.MAX_GRID_CELL_STEPS`; a SpecError naming ``problem.flow`` otherwise."""
    cells = grid.shape[0] * grid.shape[1]
    steps = t_max / dt if dt > 0 else math.inf
    if not cells * steps <= MAX_GRID_CELL_STEPS:
        raise SpecError(
            f"the flow's speed on the grid makes the CFL step {dt:.3g}: {cells} cells times "
            f"{steps:.3g} steps to max_time exceed the limit of {MAX_GRID_CELL_STEPS:g} cell steps",
            field="problem.flow",
        )


def capture_by_level_sets(
    solver: LevelSetSolver,
    origins: np.ndarray,
    t_max: float,
    *,
    levels: tuple[float, float],
    snapshot_interval: float = 0.02,
    banded: bool = True,
    budget: Budget = UNLIMITED,
) -> LevelSetReach:
    """Advance both sets until the margins of both levels have vanished (capture, Theorem 6), a
    set reaches the box's edge or ``t_max`` passes; then re-advance from the last snapshot to land
    exactly on ``T̂``. ``levels``: the two levels read, as lengths ``c₁ < c₂``. ``banded``: update
    only the box around the nodes below :data:`BAND_CELLS` cells above the upper level
    (:mod:`~gamespec.flowfield.band`), else the whole grid. ``budget``: the time limit, checked
    after every step, and the progress line."""
    grid = solver.grid
    levels = np.asarray(levels, dtype=float)
    band = float(levels.max() + BAND_CELLS * grid.spacing.max()) if banded else np.inf
    step_band = band if banded else None
    watches = [_LevelWatch(c) for c in levels]
    phi = initial_cones(grid, origins)
    dt = solver.max_step
    check_steps(grid, dt, t_max)
    snap_t, snaps = [0.0], [np.minimum(phi, band, dtype=np.float32)]
    t, steps = 0.0, 0
    message, timed_out = f"no capture before t_max = {t_max:g}", False
    while t < t_max and any(w.crossing is None for w in watches):
        phi = solver.step(phi, dt, step_band)
        t, steps = t + dt, steps + 1
        budget.advance(f"level sets, t = {t:.3g} of at most {t_max:g}")
        if budget.expired():
            message, timed_out = budget.message(f"level sets at t = {t:.4g}, no capture yet"), True
            break
        if _touches_boundary(phi, levels.max()):
            message = f"a reachable set reached the grid's edge at t = {t:.4g}: enlarge the domain"
            break
        exact = np.minimum(phi, band)
        if t - snap_t[-1] >= snapshot_interval - 1e-12:
            snap_t.append(t)
            snaps.append(exact.astype(np.float32))
        for watch in watches:
            watch.observe(grid, exact, t)
    upper = watches[1]
    history = {"times": np.array(upper.times), "margins": np.array(upper.margins)}
    if any(w.crossing is None for w in watches):
        return LevelSetReach(
            grid,
            levels,
            **history,
            snapshot_times=np.array(snap_t),
            snapshots=np.stack(snaps),
            message=message,
            steps=steps,
            band=band,
            timed_out=timed_out,
        )
    level_times = np.array([w.crossing[0] for w in watches])
    level_points = np.array([w.crossing[1] for w in watches])
    capture_time = float(extrapolate_to_zero(levels, level_times))
    keep = int(np.searchsorted(snap_t, capture_time, side="right"))
    snap_t, snaps = snap_t[:keep], snaps[:keep]
    final = np.minimum(solver.propagate(snaps[-1].astype(float), capture_time - snap_t[-1], step_band), band)
    return LevelSetReach(
        grid,
        levels,
        **history,
        snapshot_times=np.array([*snap_t, capture_time]),
        snapshots=np.stack([*snaps, final.astype(np.float32)]),
        capture_time=capture_time,
        capture_point=extrapolate_to_zero(levels, level_points),
        level_times=level_times,
        level_points=level_points,
        steps=steps,
        band=band,
    )
