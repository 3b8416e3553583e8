"""The ``hji`` backend (capture regions as HJI value functions) against closed forms.

- A game whose pursuer steers (ẋ, ẏ) in the unit box against an evader that cancels up to half of
  its x-speed, with a disk target: the set captured within T is the disk's Minkowski sum with the
  box [−T/2, T/2] × [−T, T] (both ways the evader can act: separable and not); every node farther
  than one grid spacing from that set's edge is classified as the exact set says.
- The homicidal chauffeur in Isaacs' reduced coordinates (``problems/ch7/homicidal_chauffeur_reduced
  .yaml``) at γ = 0.7: Isaacs' barrier closes around the capture circle iff
  ℓ/R < √(1−γ²) + γ·asin γ − 1, so below that the captured set stops growing (all of it is captured
  within a bounded time and the rest escapes), and above it the car captures from everywhere (the
  set keeps growing with the horizon). Checked at ℓ = 0.15 and 0.4 in the default suite, and the
  threshold bracketed by a study over ℓ (``metrics.capture_region.converged`` switches): a few ℓ
  on a coarse grid by default; in slow tests, bisected on two grids
  (``benchmarks/chauffeur_threshold.py``). Just above the threshold the two barrier arcs (traced
  below) leave a gap 2(ℓ − ℓ*) wide on the car's axis at y = γR, and the set leaks through it. The
  numerical switch lies above ℓ* by an error that does not depend on the box (the value at the gap
  is the same to 3e-4 on [−1, 1]², [−1.5, 1.5]² and [−3, 3]² at one spacing) and falls under
  refinement as the spacing by the default upwind flux (as h^0.6 by Lax–Friedrichs, whose
  dissipation fills in the narrow neck). The upwind flux is checked against its definition written
  out for the chauffeur, for monotonicity, and for dissipating less than Lax–Friedrichs. Convergence
  counts only the captured set's part connected to the target: on [−3, 3]² the far corners are
  captured late by the ghost nodes' guess, which made an earlier study switch below the others.
- Below the threshold the captured set is the region Isaacs' barrier closes off: the two
  semipermeable arcs traced back from the ends of the usable part of the capture circle (where
  the pedestrian's radial run is tangent to it, y = γℓ; the car turning fully, the pedestrian running
  along the arc's normal, which turns with the car; SciPy's DOP853 at 1e-11) until they meet on the
  car's axis, and the circle's non-usable part. Every node farther than one grid spacing from that
  curve is classified as the curve says.
- Reach–avoid with a disturbance: the box game with ẏ = b/2 and a wall ``|x − 0.45| ≤ 0.05`` across
  the grid that the pursuer must not enter: the set captured within T is the Minkowski sum
  (``[−T/2, T/2]²``) on the near side of the wall only, though without the wall it reaches past it.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest
from gamespec_levelset.hji import ReachRun, attached, converged, parsed_game, sampled_hamiltonian
from matplotlib.path import Path
from scipy.integrate import solve_ivp
from scipy.spatial import cKDTree

from benchmarks.chauffeur_threshold import chauffeur_model, switch_bracket
from gamespec.flowfield.grid import Grid
from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

CHAUFFEUR = PROBLEMS / "ch7" / "homicidal_chauffeur_reduced.yaml"
GAMMA = 0.7
BARRIER = math.sqrt(1 - GAMMA**2) + GAMMA * math.asin(GAMMA) - 1
"""Isaacs' threshold on ℓ/R at γ = 0.7 (about 0.2569)."""

BOX_GAME = """
kind: differential_game
name: box_pursuit
problem:
  parameters: {{r: 0.3}}
  states:
    x: {{lower: -1.0, upper: 1.0}}
    y: {{lower: -1.0, upper: 1.0}}
  dynamics: {{x: "{x}", y: b}}
  players:
    pursuer: {{objective: minimize, controls: {{a: {{lower: -1, upper: 1}}, b: {{lower: -1, upper: 1}}}}}}
    evader: {{objective: maximize, controls: {{c: {{lower: {c_lower}, upper: 0.5}}}}}}
  capture: x**2 + y**2 <= r**2
  time: {{final: 0.5}}
solver: {{backend: hji, options: {{hji: {{nodes: 41}}}}}}
"""


@pytest.mark.parametrize(("x", "c_lower"), [("a + c", -0.5), ("a*(1 - c)", 0.0)], ids=["separable", "mixed"])
def test_box_game_is_the_minkowski_sum(tmp_path, x, c_lower):
    file = tmp_path / "box.yaml"
    file.write_text(textwrap.dedent(BOX_GAME.format(x=x, c_lower=c_lower)))
    result = compile_spec(load(file)).solve()
    r, horizon = 0.3, 0.5
    gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
    outside = np.hypot(np.maximum(abs(gx) - horizon / 2, 0), np.maximum(abs(gy) - horizon, 0))
    spacing = gx[1, 0] - gx[0, 0]
    clear = abs(outside - r) > spacing * (1 + 1e-9)  # farther than one spacing from the exact edge
    captured = result.arrays["value"] <= 0
    assert np.array_equal(captured[clear], (outside <= r)[clear])
    assert result.status is Status.OPTIMAL, result.message


def chauffeur_fluxes(nodes=9):
    """The chauffeur's sampled Hamiltonian on a small grid by both fluxes, and the grid."""
    spec = load(CHAUFFEUR)
    grid = Grid((-1.5, -1.5), (1.5, 1.5), (nodes, nodes))
    game, parameters = parsed_game(spec), dict(spec.problem.parameters)
    return grid, {f: sampled_hamiltonian(game, grid, 33, parameters, f) for f in ("upwind", "lax_friedrichs")}


def test_the_upwind_flux_upwinds_every_control_sample():
    """The upwind numerical Hamiltonian against its definition written out for the chauffeur
    (f = (−yφ + γ sin ψ, xφ − 1 + γ cos ψ), φ = ±1, ψ at 33 samples of [−π, π]):
    ``min_φ max_ψ Σ_i max(f_i, 0) p⁺_i + min(f_i, 0) p⁻_i``; with p⁻ = p⁺ both fluxes are H."""
    grid, fluxes = chauffeur_fluxes()
    rng = np.random.default_rng(3)
    minus, plus = rng.normal(size=(2, 2, *grid.shape))
    x, y = grid.points[..., 0], grid.points[..., 1]
    best = np.full(grid.shape, np.inf)
    for phi in (-1.0, 1.0):
        worst = np.full(grid.shape, -np.inf)
        for psi in np.linspace(-math.pi, math.pi, 33):
            f = (-y * phi + GAMMA * math.sin(psi), x * phi - 1 + GAMMA * math.cos(psi))
            flux = sum(np.maximum(fi, 0) * plus[i] + np.minimum(fi, 0) * minus[i] for i, fi in enumerate(f))
            worst = np.maximum(worst, flux)
        best = np.minimum(best, worst)
    assert np.allclose(fluxes["upwind"].numerical(minus, plus), best, rtol=0, atol=1e-12)
    for ham in fluxes.values():
        assert np.allclose(ham.numerical(plus, plus), ham(plus), rtol=0, atol=1e-12)


@pytest.mark.parametrize("flux", ["upwind", "lax_friedrichs"])
def test_the_fluxes_are_monotone(flux):
    """Raising p⁺ (a larger value ahead) never lowers the rate; raising p⁻ never raises it."""
    grid, fluxes = chauffeur_fluxes()
    ham = fluxes[flux]
    rng = np.random.default_rng(5)
    minus, plus = rng.normal(size=(2, 2, *grid.shape))
    for axis in (0, 1):
        step = np.zeros_like(plus)
        step[axis] = rng.uniform(0, 1, grid.shape)
        assert np.all(ham.numerical(minus, plus + step) >= ham.numerical(minus, plus) - 1e-12)
        assert np.all(ham.numerical(minus + step, plus) <= ham.numerical(minus, plus) + 1e-12)


def test_the_upwind_flux_dissipates_less_than_lax_friedrichs():
    """Where p⁺ ≥ p⁻ on both axes, H(p̄) ≤ Ĥ_upwind ≤ Ĥ_LF (each sample's |f_i| is at most the
    fastest sample's); where p⁺ ≤ p⁻, the reverse."""
    grid, fluxes = chauffeur_fluxes()
    rng = np.random.default_rng(7)
    mean, jump = rng.normal(size=(2, *grid.shape)), rng.uniform(0, 1, (2, *grid.shape))
    for sign in (1, -1):
        minus, plus = mean - sign * jump, mean + sign * jump
        upwind, lax = (fluxes[f].numerical(minus, plus) for f in ("upwind", "lax_friedrichs"))
        exact = fluxes["upwind"](mean)
        assert np.all(sign * (upwind - exact) >= -1e-12)
        assert np.all(sign * (lax - upwind) >= -1e-12)
    assert np.any(np.abs(lax - upwind) > 0.1)


@pytest.fixture(scope="module")
def chauffeur():
    model = compile_spec(load(CHAUFFEUR))
    return {ell: model.solve({"l": ell}) for ell in (0.15, 0.4)}


def test_below_the_barrier_the_capture_region_stops_growing(chauffeur):
    region = chauffeur[0.15].metrics["capture_region"]
    assert region["area"] == region["area_at_half_horizon"]
    assert region["fraction"] < 0.05


def test_above_the_barrier_the_capture_region_keeps_growing(chauffeur):
    below, above = (chauffeur[ell].metrics["capture_region"] for ell in (0.15, 0.4))
    cell = ((above["upper"][0] - above["lower"][0]) / (above["nodes"] - 1)) ** 2
    assert above["area"] - above["area_at_half_horizon"] > 20 * cell
    assert above["area"] > 5 * below["area"]


def test_value_function_result(chauffeur, tmp_path):
    from gamespec.games.plotting import plot_game

    result = chauffeur[0.15]
    assert result.metrics["solution_concept"] == "value_function"
    assert result.metrics["information"] == "feedback"
    assert result.arrays["value"].shape == (61, 61)
    assert result.metrics["checks_passed"]["capture_region_refinement"] == (result.status is Status.OPTIMAL)
    paths = plot_game(result, tmp_path)
    assert [p.name for p in paths] == ["capture_region.png"] and paths[0].stat().st_size > 0


def test_capture_field_is_checked(tmp_path):
    file = tmp_path / "bad.yaml"
    file.write_text(CHAUFFEUR.read_text().replace("x**2 + y**2 <= l**2", "x**2 + z <= l"))
    with pytest.raises(Exception, match="capture"):
        load(file)


def threshold_bracket(model, ells):
    """The study over ℓ: ``metrics.capture_region.converged`` per ℓ, and the neighbouring ℓ between
    which it switches from converged (a closed barrier) to growing (capture from everywhere)."""
    converged = {ell: model.solve({"l": ell}).metrics["capture_region"]["converged"] for ell in ells}
    stops = [ell for ell, done in converged.items() if done]
    grows = [ell for ell, done in converged.items() if not done]
    assert stops and grows and max(stops) < min(grows), converged
    return max(stops), min(grows)


def test_a_coarse_study_over_l_brackets_the_threshold():
    """41 nodes on the file's box (spacing 0.075), ℓ from 0.18 in steps of 0.04."""
    model = compile_spec(load(CHAUFFEUR, ["solver.options.hji.nodes=41"]))
    spacing, step = 3.0 / 40, 0.04
    below, above = threshold_bracket(model, [0.18 + step * k for k in range(4)])
    assert below - spacing <= BARRIER <= above
    assert above - below == pytest.approx(step)


def test_a_piece_captured_apart_from_the_target_is_left_out_of_convergence():
    """The set captured within τ is the union of the paths into the target, so connected to it: a
    node captured apart from it (the edge's guess) neither makes the set grow nor touch the edge."""
    value = np.ones((9, 9))
    value[3:6, 3:6] = -1.0  # the target's nodes and what they hold at T/2 and T
    arrival = np.where(value <= 0, 0.0, np.inf)
    half = value.copy()
    value[0, 8] = -1.0  # a corner node captured only after T/2
    run = ReachRun(value, half, arrival, math.inf, 10)
    assert converged(run)
    assert not attached(value <= 0, arrival == 0)[0, 8]
    value[6, 6] = -1.0  # a node joined (diagonally) to the target after T/2: the set grows
    assert not converged(ReachRun(value, half, arrival, math.inf, 10))


@pytest.mark.slow
def test_the_far_corners_captured_by_the_edge_do_not_decide_the_study():
    """On [−3, 3]² with 81 nodes up to T = 14 the two far corners behind the car are captured late
    (the ghost nodes' guess), apart from the set around the target, which has stopped growing at
    ℓ = 0.265 (above ℓ*, below this grid's switch: spacing 0.075, the switch about 0.3 of it above ℓ*)."""
    model = chauffeur_model(3.0, 81, 14.0)
    region = model.solve({"l": 0.265}).metrics["capture_region"]
    assert region["detached_nodes"] > 0
    assert region["converged"]


@pytest.mark.slow
def test_the_threshold_study_converges_under_refinement():
    """The study over ℓ bisected (:func:`benchmarks.chauffeur_threshold.switch_bracket`) on [−1, 1]²
    up to T = 8 at spacings 0.05 and 0.025 by the default (upwind) flux: the switch's bracket lies
    within half a spacing of ℓ*, above it (the residual dissipation of each sample's upwinding
    narrows the neck between the barrier's arcs, module doc), and its error at least nearly halves
    with the spacing (first order, to within the brackets' width h/8)."""
    errors = {}
    for nodes in (41, 81):
        spacing = 2.0 / (nodes - 1)
        low, high = switch_bracket(chauffeur_model(1.0, nodes, 8.0), 0.2, 0.4, spacing / 8)
        errors[spacing] = (low + high) / 2 - BARRIER
        assert high >= BARRIER and high - BARRIER <= spacing / 2, (low, high)
    coarse, fine = errors.values()
    assert 0 < fine <= 0.6 * coarse, errors


def isaacs_barrier(ell: float, gamma: float = GAMMA) -> np.ndarray:
    """The closed curve that bounds the captured set below the threshold (w = R = 1): the capture
    circle's non-usable part (y < γℓ) and the two barrier arcs from its ends to where they meet on
    the y axis (module doc), as points in order."""
    end = np.array([ell * math.sqrt(1 - gamma**2), gamma * ell])

    def backward(t, z):
        x, y, nx, ny = z
        norm = math.hypot(nx, ny)
        return [y - gamma * nx / norm, 1 - x - gamma * ny / norm, ny, -nx]

    def on_axis(t, z):
        return z[0]

    on_axis.terminal, on_axis.direction = True, -1
    arc = solve_ivp(
        backward,
        (0, 8),
        [*end, *end / ell],
        "DOP853",
        rtol=1e-11,
        atol=1e-12,
        events=on_axis,
        dense_output=True,
    )
    assert arc.status == 1, "the arcs meet below the threshold"
    right = arc.sol(np.linspace(0, arc.t[-1], 400))[:2].T
    start = math.atan2(end[1], end[0])
    angles = np.linspace(math.pi - start, 2 * math.pi + start, 200)
    circle = np.column_stack([ell * np.cos(angles), ell * np.sin(angles)])
    return np.vstack([circle, right, right[::-1] * [-1, 1]])


@pytest.mark.parametrize(("ell", "nodes"), [(0.2, 41), (0.25, 61)])
def test_below_the_threshold_the_captured_set_is_what_the_barrier_closes_off(ell, nodes):
    sets = [f"solver.options.hji.nodes={nodes}", "problem.time.final=2.0"]
    sets += ["solver.options.hji.lower=[-1,-1]", "solver.options.hji.upper=[1,1]"]
    result = compile_spec(load(CHAUFFEUR, sets)).solve({"l": ell})
    assert result.metrics["capture_region"]["converged"]
    curve = isaacs_barrier(ell)
    gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
    nodes_xy = np.column_stack([gx.ravel(), gy.ravel()])
    inside = Path(curve).contains_points(nodes_xy).reshape(gx.shape)
    dense = np.vstack([np.linspace(a, b, 5) for a, b in zip(curve, np.roll(curve, -1, axis=0), strict=True)])
    distance = cKDTree(dense).query(nodes_xy)[0].reshape(gx.shape)
    clear = distance > (gx[1, 0] - gx[0, 0]) * (1 + 1e-9)
    assert np.array_equal((result.arrays["value"] <= 0)[clear], inside[clear])
    assert inside.sum() > 40


REACH_AVOID = """
kind: differential_game
name: box_reach_avoid
problem:
  parameters: {{r: 0.3}}
  states:
    x: {{lower: -1.0, upper: 1.0}}
    y: {{lower: -1.0, upper: 1.0}}
  dynamics: {{x: "{x}", y: b/2}}
  players:
    pursuer: {{objective: minimize, controls: {{a: {{lower: -1, upper: 1}}, b: {{lower: -1, upper: 1}}}}}}
    evader: {{objective: maximize, controls: {{c: {{lower: {c_lower}, upper: 0.5}}}}}}
  capture: x**2 + y**2 <= r**2
  avoid: abs(x - 0.45) <= 0.05
  time: {{final: 1.0}}
solver: {{backend: hji, options: {{hji: {{nodes: 41}}}}}}
"""


@pytest.mark.parametrize(("x", "c_lower"), [("a + c", -0.5), ("a*(1 - c)", 0.0)], ids=["separable", "mixed"])
def test_reach_avoid_with_a_disturbance_stops_at_the_wall(tmp_path, x, c_lower):
    file = tmp_path / "wall.yaml"
    file.write_text(textwrap.dedent(REACH_AVOID.format(x=x, c_lower=c_lower)))
    spec = load(file)
    result = compile_spec(spec).solve()
    gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
    outside = np.hypot(np.maximum(abs(gx) - 0.5, 0), np.maximum(abs(gy) - 0.5, 0))
    reached = outside <= 0.3
    spacing = (gx[1, 0] - gx[0, 0]) * (1 + 1e-9)
    clear = (abs(outside - 0.3) > spacing) & ((abs(gx - 0.4) > spacing) | ~reached)
    captured = result.arrays["value"] <= 0
    assert np.array_equal(captured[clear], (reached & (gx < 0.4))[clear])
    assert result.metrics["capture_region"]["avoid"]
    assert result.status is Status.OPTIMAL, result.message
    free = compile_spec(load(file, ["problem.avoid=null"])).solve()
    assert np.any((free.arrays["value"] <= 0) & (gx > 0.5 + spacing))


def test_games_it_cannot_solve_are_refused_with_the_reason(tmp_path):
    from gamespec_levelset.hji import HJIBackend

    five_states = load(PROBLEMS / "ch7" / "homicidal_chauffeur.yaml")
    assert "two states" in HJIBackend().unsupported(five_states)
    file = tmp_path / "timed.yaml"
    file.write_text(CHAUFFEUR.read_text().replace("- w + gamma*w*cos(psi)", "- w*(1 + t) + gamma*w*cos(psi)"))
    assert "autonomous" in HJIBackend().unsupported(load(file))


def test_work_beyond_the_limits_is_refused_before_it_runs():
    """A grid reaching beyond MAX_GAME_STATE is refused at compile; dynamics so fast on the grid
    that the CFL steps times the nodes exceed MAX_HJI_NODE_STEPS are refused before a step is
    taken (issue 27, item 2: the work a file implies is checked before anything runs)."""
    from gamespec.errors import SpecError

    with pytest.raises(SpecError, match="MAX_GAME_STATE"):
        compile_spec(load(CHAUFFEUR, ["problem.states.y.upper=1e300"]))
    fast = compile_spec(load(CHAUFFEUR, ["problem.states.y.upper=1e8"]))
    with pytest.raises(SpecError, match="MAX_HJI_NODE_STEPS"):
        fast.solve()


def test_a_run_past_its_wall_time_stops_with_time_limit():
    """``max_wall_time`` is checked after every step: a run stopped by it says so, with the steps
    it took, and holds no capture region (none was computed)."""
    result = compile_spec(load(CHAUFFEUR, ["solver.options.hji.max_wall_time=1e-6"])).solve()
    assert result.status is Status.TIME_LIMIT, result.message
    assert "max_wall_time" in result.message and result.iterations is not None
    assert "capture_region" not in result.metrics
