"""Time-to-reach maps by fast marching (:mod:`gamespec.flowfield.marching`) against exact
solutions: in a uniform flow the set reached at time t from the disk of radius c about x₀ is the
disk of radius c + v̂t about x₀ + ft, so ``T`` solves ``|x − x₀ − fT| = c + v̂T``; in a rigid
rotation ``f = ω J (x − x_c)`` it is that disk carried along by the rotation (in the rotating frame
the air is still), so ``T`` solves ``|x − x_c − R(ωT)(x₀ − x_c)| = c + v̂T``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gamespec.flowfield.grid import Grid
from gamespec.flowfield.marching import time_to_reach

ORIGIN, RADIUS, SPEED = np.array([-0.5, 0.3]), 0.5, 1.0


def exact_time(points: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """The root of ``|r − fT| = c + v̂T`` with ``r = x − x₀`` (a quadratic in T)."""
    r = points - ORIGIN
    a = SPEED**2 - drift @ drift
    b = r @ drift + RADIUS * SPEED
    return (-b + np.sqrt(b * b + a * ((r * r).sum(-1) - RADIUS**2))) / a


def _errors(drift: np.ndarray, nodes: tuple[int, ...], order: int, **options: float) -> np.ndarray:
    """The largest error of ``T`` over the nodes reached within 0.05 … 1.5."""
    errors = []
    for n in nodes:
        grid = Grid((-2.5, -2.5), (2.5, 2.5), (n, n))
        tabulated = np.broadcast_to(drift, (n, n, 2))
        found = time_to_reach(grid, tabulated, SPEED, ORIGIN, RADIUS, t_max=1.6, order=order, **options)
        exact = exact_time(grid.points, drift)
        mask = (exact > 0.05) & (exact <= 1.5)
        errors.append(np.abs(found - exact)[mask].max())
    return np.array(errors)


@pytest.mark.parametrize("drift", [(0.0, 0.0), (0.4, -0.3)], ids=["still", "uniform"])
def test_second_order_marching_meets_the_exact_disks(drift: tuple[float, float]) -> None:
    """The largest error falls at second order (≥ 1.7 per halving of dx) in still air and in a
    drift of half the agent's speed, and is within 4 dx² (about 4e-3 at 51 nodes, 1e-3 at 101)."""
    errors = _errors(np.array(drift), (51, 101), 2)
    assert np.log2(errors[0] / errors[1]) >= 1.7, errors
    assert errors[-1] < 4 * (5.0 / 100) ** 2, errors


def test_second_order_marching_keeps_its_order_on_finer_grids_in_a_drift() -> None:
    """In a drift of half the agent's speed the order per halving of dx rises towards 2 (1.81 from
    101² to 201², 1.90 to 401² measured): at least 1.75 on each step."""
    errors = _errors(np.array([0.4, -0.3]), (101, 201, 401), 2)
    orders = np.log(errors[:-1] / errors[1:]) / np.log([200 / 100, 400 / 200])
    assert np.all(orders >= 1.75), (errors, orders)


def test_first_order_marching_converges_at_first_order() -> None:
    errors = _errors(np.array([0.4, -0.3]), (51, 101), 1)
    assert np.log2(errors[0] / errors[1]) >= 0.8, errors


@pytest.mark.parametrize("order", [1, 2])
def test_leaving_changes_below_reopen_changes_the_map_by_less_than_its_error(order: int) -> None:
    """Re-opening a node on every change above 1e-12 (the label-correcting march to its end)
    and above the default ``REOPEN`` give maps within 1e-6 of each other at 101² (the errors are
    about 3e-2 and 3e-3) over ``T ≤ 1.5``, marched to 1.6 (the last nodes below ``t_max`` are
    not settled: there the two differ by up to 1e-4)."""
    grid = Grid((-2.5, -2.5), (2.5, 2.5), (101, 101))
    drift = np.broadcast_to(np.array([0.4, -0.3]), (101, 101, 2))
    tight = time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=1.6, order=order, reopen=1e-12)
    default = time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=1.6, order=order)
    compared = exact_time(grid.points, np.array([0.4, -0.3])) <= 1.5
    compared &= np.isfinite(tight)
    assert np.isfinite(default[compared]).all()
    assert np.abs(tight[compared] - default[compared]).max() < 1e-6


def test_t_max_leaves_the_far_nodes_unreached_and_a_fast_drift_is_refused() -> None:
    grid = Grid((-2.5, -2.5), (2.5, 2.5), (41, 41))
    drift = np.broadcast_to(np.array([0.4, -0.3]), (41, 41, 2))
    found = time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=0.5)
    exact = exact_time(grid.points, np.array([0.4, -0.3]))
    assert np.isinf(found[exact > 0.6]).all() and np.isfinite(found[(exact > 0) & (exact < 0.4)]).all()
    with pytest.raises(ValueError, match="below the agent's speed"):
        time_to_reach(grid, 3 * drift, SPEED, ORIGIN, RADIUS)
    with pytest.raises(ValueError, match="order must be 1, 2 or 5"):
        time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, order=3)


@pytest.mark.parametrize("drift", [(0.0, 0.0), (0.4, -0.3)], ids=["still", "uniform"])
def test_fifth_order_route_meets_the_exact_disks(drift: tuple[float, float]) -> None:
    """The defect-corrected map (the default) at its default tolerance: the largest error falls
    at order 4.1 (still air) and 4.6 (the drift) from 51² to 101², to 1.5e-6 and 4.0e-6 at 101²,
    a thousandth and a seven-hundredth of the second-order march's."""
    errors = _errors(np.array(drift), (51, 101), 5)
    marched = _errors(np.array(drift), (101,), 2)
    assert np.log2(errors[0] / errors[1]) >= 3.5, errors
    assert errors[-1] < 1e-5 and errors[-1] < marched[0] / 100, (errors, marched)


def test_fifth_order_route_converged_is_of_order_four_and_a_half() -> None:
    """Corrected until a pass changes nothing by more than 1e-11: 9.7e-5 at 51², 3.8e-6 at 101²
    in the drift (order 4.7; 1.6e-7 at 201², 5.5e-9 at 401², 2.4e-10 at 801² measured)."""
    errors = _errors(np.array([0.4, -0.3]), (51, 101), 5, tolerance=1e-11)
    assert np.log2(errors[0] / errors[1]) >= 4.3, errors


def test_fifth_order_route_warns_when_its_passes_run_out() -> None:
    grid = Grid((-2.5, -2.5), (2.5, 2.5), (51, 51))
    drift = np.broadcast_to(np.array([0.4, -0.3]), (51, 51, 2))
    with pytest.warns(RuntimeWarning, match="in its last of 2 passes"):
        time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=1.6, passes=2)
    with pytest.raises(ValueError, match="at least one pass"):
        time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, passes=0)
    with pytest.raises(ValueError, match="positive tolerance"):
        time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, tolerance=float("nan"))


ROTATION, PIVOT = 0.2, np.array([1.0, -1.0])
"""ω and x_c of the rigid rotation: the drift is 0.4 at x₀ and below 0.99 on the grid."""


def rotating_drift(grid: Grid) -> np.ndarray:
    r = grid.points - PIVOT
    return ROTATION * np.stack([-r[..., 1], r[..., 0]], axis=-1)


def rotating_exact_time(grid: Grid) -> np.ndarray:
    """The root of ``g(T) = |x − x_c − R(ωT)(x₀ − x_c)| − c − v̂T`` by bisection (g falls: the
    disk's centre moves at 0.4 < v̂)."""
    arm = ORIGIN - PIVOT

    def gap(t: np.ndarray) -> np.ndarray:
        c, s = np.cos(ROTATION * t), np.sin(ROTATION * t)
        centre = PIVOT + np.stack([c * arm[0] - s * arm[1], s * arm[0] + c * arm[1]], axis=-1)
        return np.linalg.norm(grid.points - centre, axis=-1) - RADIUS - SPEED * t

    low, high = np.full(grid.shape, -1.0), np.full(grid.shape, 6.0)
    for _ in range(60):
        middle = (low + high) / 2
        ahead = gap(middle) > 0
        low, high = np.where(ahead, middle, low), np.where(ahead, high, middle)
    return (low + high) / 2


def test_fifth_order_route_in_a_rotating_flow() -> None:
    """Curved characteristics: four cells or more from the grid's edge (where the stencils are
    one-sided) the error over 0.05 ≤ T ≤ 1.5 is 5.6e-5 at 51² and 3.7e-6 at 101² (order 3.9),
    against 7.8e-3 and 2.3e-3 for the march. The start band, shot along the characteristics, is
    within 4.3e-11 of the exact times at 101², where the uniform-flow closed form it starts from
    is off by 5.2e-4."""
    errors = {}
    for n in (51, 101):
        grid = Grid((-2.5, -2.5), (2.5, 2.5), (n, n))
        exact = rotating_exact_time(grid)
        inside = np.zeros(grid.shape, dtype=bool)
        inside[4:-4, 4:-4] = True
        compared = inside & (exact > 0.05) & (exact <= 1.5)
        for order in (2, 5):
            found = time_to_reach(grid, rotating_drift(grid), SPEED, ORIGIN, RADIUS, t_max=1.6, order=order)
            errors[n, order] = np.abs(found - exact)[compared].max()
    assert np.log2(errors[51, 5] / errors[101, 5]) >= 3.0, errors
    assert errors[101, 5] < errors[101, 2] / 100, errors

    grid = Grid((-2.5, -2.5), (2.5, 2.5), (101, 101))
    exact, drift = rotating_exact_time(grid), rotating_drift(grid)
    distance = np.linalg.norm(grid.points - ORIGIN, axis=-1)
    band = np.abs(distance - RADIUS) <= 1.5 * grid.spacing[0]
    shot = time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=0.3)
    closed_form = time_to_reach(grid, drift, SPEED, ORIGIN, RADIUS, t_max=0.3, order=2)
    assert np.abs(shot - exact)[band].max() < 1e-9
    assert np.abs(closed_form - exact)[band].max() > 1e-4


def jet(grid: Grid) -> np.ndarray:
    """A jet of 0.8 v̂ along x about y = 0.9: the front runs ahead in it, and behind it the two
    fronts meet at a kink of ``T``."""
    y = grid.points[..., 1]
    return np.stack([0.8 * np.exp(-(((y - 0.9) / 0.2) ** 2)), np.zeros_like(y)], axis=-1)


def test_fifth_order_route_converges_across_a_kink() -> None:
    """In the jet the correction converges on a coarse and a fine grid (no warning), and at 101²
    it is nearer the 201² map than the march is (99th percentile of the difference over
    0.05 ≤ T ≤ 1.8: 4.2e-4 against 4.4e-3)."""
    origin, radius = np.array([-1.0, 0.0]), 0.4
    maps = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for n, order in ((51, 5), (101, 5), (101, 2), (201, 5)):
            grid = Grid((-2.5, -2.5), (2.5, 2.5), (n, n))
            maps[n, order] = time_to_reach(grid, jet(grid), SPEED, origin, radius, t_max=1.8, order=order)
    reference = maps[201, 5][::2, ::2]
    compared = (reference > 0.05) & (reference <= 1.7)
    corrected = np.quantile(np.abs(maps[101, 5][compared] - reference[compared]), 0.99)
    marched = np.quantile(np.abs(maps[101, 2][compared] - reference[compared]), 0.99)
    assert corrected < marched / 4, (corrected, marched)
