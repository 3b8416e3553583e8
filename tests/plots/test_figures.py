"""Every shipped problem's figures, drawn from its saved Result (:mod:`tests.plots.fixtures`: a
solve with fast settings, saved once) and checked for what they show (titles with problem, backend,
status and the headline number; axis labels; legends outside the axes; the artists each kind must
draw), not for their pixels."""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

import numpy as np
import pytest
from matplotlib.patches import Circle

import gamespec
from gamespec.plotting import plot_result
from tests.conftest import PROBLEMS
from tests.plots import fixtures
from tests.plots.recording import legend_texts, recording, titles


@pytest.mark.parametrize("path", fixtures.FILES, ids=lambda p: p.stem)
def test_each_fixture_is_its_problem_file_solved(path: Path) -> None:
    """The saved Result is of the file as shipped under the fixture's settings (its provenance spec
    hash, :func:`tests.plots.fixtures.saved`: a stale one fails with the command that regenerates
    it), of the file's problem and kind."""
    result = fixtures.saved(path)
    spec = fixtures.spec_of(path)
    assert (result.problem, result.kind) == (spec.name, spec.kind)
    assert result.provenance.source == str(path.relative_to(fixtures.ROOT))


def _check_common(result: gamespec.Result, saved) -> None:
    for figure in saved:
        text = titles(figure)
        assert result.problem in text and result.backend in text and result.status.value in text, figure.name
        _check_cannot_mislead(figure)
        for ax, outside in zip(figure.axes, figure.legend_outside, strict=True):
            if outside is None:
                continue
            shared = ax.get_shared_x_axes().get_siblings(ax)
            assert any(a.get_xlabel() for a in shared) and ax.get_ylabel(), (figure.name, ax.get_title())
            assert outside, figure.name


@pytest.mark.parametrize("path", fixtures.FILES, ids=lambda p: p.stem)
def test_shipped_problem_figures(path: Path, tmp_path: Path, caplog) -> None:
    """Drawn without a library warning (a warning is an error here; matplotlib's logged ones are
    read from the log), and showing what :func:`_check_common` and the kind's check say."""
    result = fixtures.saved(path)
    with recording() as saved, warnings.catch_warnings():
        warnings.simplefilter("error")
        written = plot_result(result, tmp_path)
    assert not [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert [s.name for s in saved] == [p.name for p in written]
    _check_common(result, saved)
    check = {
        "engagement": _check_engagement,
        "pursuit_scenario": _check_scenario,
        "lq_stochastic_game": _check_lq,
        "optimal_control": _check_ocp,
        "multiphase_optimal_control": _check_multiphase,
        "flow_field_game": _check_flow,
        "differential_game": _check_differential_game,
    }[result.kind]
    check(result, {s.name: s for s in saved})


def _data_axes(figure):
    """The axes that draw data (a colorbar's are the scale of another's)."""
    return [ax for ax in figure.axes if not hasattr(ax, "_colorbar")]


def _labelled(ax) -> list[str]:
    """The labels of the artists an axes draws that ask for a legend entry."""
    artists = [*ax.lines, *ax.patches, *ax.collections]
    return [a.get_label() for a in artists if a.get_label() and not a.get_label().startswith("_")]


def _check_cannot_mislead(figure) -> None:
    """What every figure must show (issue 28 item 3): every data axes titled (or the figure), no
    axis with an offset or a multiplier ("1e-7+1"), and a legend entry for every labelled series."""
    axes = _data_axes(figure)
    for ax in axes:
        assert ax.get_title() or figure.title, (figure.name, "an untitled axes in an untitled figure")
        for axis in (ax.xaxis, ax.yaxis):
            assert not axis.get_offset_text().get_text(), (figure.name, axis.get_offset_text().get_text())
    legends = [ax.get_legend() for ax in axes if ax.get_legend() is not None] + list(figure.figure.legends)
    entries = {t.get_text() for legend in legends for t in legend.get_texts()}
    labels = {label for ax in axes for label in _labelled(ax)}
    if len(labels) >= 2 or legends:
        assert labels <= entries, (figure.name, "not in a legend:", sorted(labels - entries))


def _check_engagement(result, saved) -> None:
    names = [p["name"] for p in result.metrics["engagement"]["pursuers"]]
    paths = saved["paths.png"]
    assert f"t_c = {result.t_final:.4f}" in titles(paths)
    assert "P* = {" + ", ".join(result.metrics["capturing_set"]) + "}" in titles(paths)
    (ax,) = paths.axes
    labels = legend_texts(ax)
    assert all(any(label.startswith(n) for label in labels) for n in names)
    assert "capture point" in labels
    distances = saved["distances.png"].axes
    assert len(distances) == (2 if len(names) > 1 else 1)
    assert len([line for line in distances[0].lines if line.get_label().startswith("r to")]) == len(names)
    if len(names) > 1:
        assert distances[1].lines, "the second panel is drawn for any number of pursuers"


def _check_scenario(result, saved) -> None:
    n = result.states["pursuers"].shape[1]
    m = result.states["evaders"].shape[1]
    for name in ("trajectories.png", "snapshots.png"):
        figure = saved[name]
        assert "captured" in titles(figure)
        for ax in figure.axes:
            labels = {t.get_text() for t in ax.texts}
            assert {f"P{i + 1}" for i in range(n)} | {f"E{j + 1}" for j in range(m)} <= labels
    first = saved["snapshots.png"].axes[0]
    arrows = [t for t in first.texts if t.arrow_patch is not None]
    assert len(arrows) == int(np.sum(result.arrays["allocation"][0] >= 0))
    assert f"t = {result.time[-1]:.2f}" in titles(saved["trajectories.png"])


def _check_lq(result, saved) -> None:
    if "ellipses.png" not in saved:
        return
    ax = saved["ellipses.png"].axes[0]
    labels = legend_texts(ax)
    assert "initial 3σ" in labels and "terminal 3σ" in labels
    colours = {line.get_label(): line.get_color() for line in ax.lines}
    if "target_covariance" in result.arrays:
        assert "target 3σ" in labels and colours["target 3σ"] != colours["initial 3σ"]
    zoom = ax.child_axes
    assert len(zoom) == 1 and "zoom" in zoom[0].get_title()


def _check_differential_game(result, saved) -> None:
    paths = saved.get(f"{result.problem}_paths.png")
    if paths is not None:
        assert legend_texts(paths.axes[0]), "each player is in the legend"
    elif "value" not in result.arrays:
        _check_ocp(result, saved)


def _check_flow(result, saved) -> None:
    if "reachable_sets.png" in saved:
        assert "capture point" in legend_texts(saved["reachable_sets.png"].axes[0])


def _check_ocp(result, saved) -> None:
    pairs = result.metrics["plot"]["planar"]
    assert (f"{result.problem}_path.png" in saved) == bool(pairs)
    figure = saved[f"{result.problem}_time.png"]
    assert f"J = {result.objective:.6g}" in titles(figure)
    angles = result.metrics["plot"].get("angles", [])
    _check_spans(figure.axes[0], result.time, result.time, result.states, angles)
    if result.controls:
        times = result.control_time if result.control_time is not None else result.time
        _check_spans(figure.axes[1], result.time, times, result.controls, angles)
        _check_controls_per_interval(result, figure.axes[1])


def _drawn(ax, name: str):
    return next(line for line in ax.lines if line.get_label().split(" ")[0] == name)


def _check_spans(ax, span, time, signals, angles) -> None:
    """Each signal (values at ``time``) is drawn over the Result's whole ``span`` and keeps its
    values (angles modulo 2π): one whose values vary by at most the solver's tolerance is drawn
    flat and says "constant"; any other keeps its variation; the axes hold the whole line."""
    for name, values in signals.items():
        line = _drawn(ax, name)
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        assert x.min() == pytest.approx(span[0]) and x.max() == pytest.approx(span[-1]), name
        spread = np.ptp(np.unwrap(values) if name in angles else values)
        if spread <= 1e-6 * max(1.0, np.abs(values).max()):
            assert np.ptp(y) == 0 and "constant" in line.get_label(), name
        else:
            assert np.ptp(y) >= 0.5 * spread and "constant" not in line.get_label(), name
        if name in angles:
            assert np.all(np.abs(np.diff(y)) < np.pi), f"{name} is drawn with a 2π jump"
            assert np.allclose(np.cos(np.interp(time, x, y)), np.cos(values), atol=1e-6), name
        low, high = ax.get_ylim()
        assert low <= y.min() and y.max() <= high, name


def _check_controls_per_interval(result, ax) -> None:
    """Controls drawn as the transcription holds them (:mod:`gamespec.ocp.control_signal`): the line
    passes through every control point, and at each interior mesh point it is drawn twice (each side
    of the jump from its own interval)."""
    mesh = result.arrays.get("control_mesh")
    for name, values in result.controls.items():
        line = _drawn(ax, name)
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        if "constant" in line.get_label():
            continue
        on_points = [y[np.isclose(x, t, rtol=0, atol=1e-9)] for t in result.control_time]
        assert all(
            np.any(np.isclose(ys, v, atol=1e-6 * max(1, abs(v))))
            for ys, v in zip(on_points, values, strict=True)
        ), name
        if mesh is not None:
            for t in mesh[1:-1]:
                assert np.count_nonzero(np.isclose(x, t, rtol=0, atol=1e-9)) >= 2, (name, t)


def _check_multiphase(result, saved) -> None:
    """An OCP figure with a vertical line on every axis at each boundary between phases."""
    _check_ocp(result, saved)
    figure = saved[f"{result.problem}_time.png"]
    for phase in result.metrics["phases"][1:]:
        for ax in figure.axes:
            assert any(np.allclose(line.get_xdata(), phase["start"]) for line in ax.lines), phase["name"]


def _ocp(plot: dict | None, constraints: list[str]) -> dict:
    data = {
        "kind": "optimal_control",
        "name": "around_a_disk",
        "problem": {
            "parameters": {"r": 0.5},
            "states": {"x": {"initial": 0.0, "final": 2.0}, "y": {"initial": 0.0, "final": 0.0}},
            "controls": {"th": {}},
            "dynamics": {"x": "cos(th)", "y": "sin(th)"},
            "objective": {"mayer": "t_f"},
            "time": {"final": "free", "bounds": [0.5, 6.0], "guess": 2.5},
            "path_constraints": constraints,
        },
        "method": {"intervals": 12, "degree": 3},
        "guess": {"controls": {"th": "1.0 - 2.0*tau"}},
    }
    return data | ({"plot": plot} if plot is not None else {})


def test_a_circular_obstacle_is_drawn_as_a_disk(tmp_path: Path) -> None:
    """(x − 1)² + (y − 0.05)² ≥ r² over the declared pair: a keep-out disk at (1, 0.05) of radius r,
    and the path around it stays outside (the distance from the centre ≥ r at every node)."""
    spec = gamespec.spec_from_dict(
        _ocp({"planar": [["x", "y"]], "units": {"x": "m", "y": "m"}}, ["(x - 1)**2 + (y - 0.05)**2 >= r**2"])
    )
    result = gamespec.solve(spec)
    assert result.ok
    with recording() as saved:
        plot_result(result, tmp_path)
    (ax,) = saved[-1].axes
    (disk,) = [p for p in ax.patches if isinstance(p, Circle)]
    assert disk.center == pytest.approx((1.0, 0.05)) and disk.radius == pytest.approx(0.5)
    assert disk.get_fill()
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    gap = np.hypot(result.states["x"] - 1.0, result.states["y"] - 0.05)
    assert gap.min() >= 0.5 - 1e-6


def test_a_keep_in_circle_is_an_outline() -> None:
    from gamespec.rcs.circles import circle_of

    inside = circle_of("x**2 + y**2 <= 4", ("x", "y"), ["x", "y"], {})
    assert inside.center == pytest.approx((0.0, 0.0)) and inside.radius == pytest.approx(2.0)
    assert not inside.keep_out
    assert circle_of("4 - (x - 1)**2 - y**2 >= 0", ("x", "y"), ["x", "y"], {}).keep_out is False
    assert circle_of("x**2 + 2*y**2 >= 1", ("x", "y"), ["x", "y"], {}) is None
    assert circle_of("(x - z)**2 + y**2 >= 1", ("x", "y"), ["x", "y", "z"], {}) is None


def test_the_planar_pair_is_declared_never_guessed(tmp_path: Path) -> None:
    """States named x, y get no path figure unless declared; a declared pair is drawn as declared,
    the second pair of a two-pair hint too."""
    plain = gamespec.solve(gamespec.spec_from_dict(_ocp(None, [])))
    names = [p.name for p in plot_result(plain, tmp_path / "plain")]
    assert names == ["around_a_disk_time.png"]
    declared = gamespec.solve(gamespec.spec_from_dict(_ocp({"planar": [["y", "x"]]}, [])))
    with recording() as saved:
        plot_result(declared, tmp_path / "declared")
    (ax,) = saved[-1].axes
    path = next(line for line in ax.lines if line.get_label() == "(y, x)")
    assert np.array_equal(path.get_xdata(), declared.states["y"])
    assert np.array_equal(path.get_ydata(), declared.states["x"])


def test_a_planar_pair_must_name_states(cli, tmp_path: Path) -> None:
    import yaml

    file = tmp_path / "bad.yaml"
    file.write_text(yaml.safe_dump(_ocp({"planar": [["x", "xE"]]}, [])))
    code, _, err = cli("validate", file)
    assert code == 2 and "plot.planar.0" in err and "xE" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("name", ["ch2/pure_pursuit_two_on_one.yaml", "ch3/mpse_five_on_one_cb.yaml"])
def test_animations_show_time_legend_labels_and_growing_paths(name, tmp_path, monkeypatch) -> None:
    import gamespec_geometric.plot as scenario_plots
    import matplotlib
    from matplotlib.animation import PillowWriter

    from gamespec.pursuit import plotting as engagement_plots

    frames = []
    original = PillowWriter.grab_frame

    def grab(self, **kwargs):
        ax = self.fig.axes[0]
        longest = max(len(line.get_xdata()) for line in ax.lines)
        frames.append((ax.get_title(), ax.get_legend() is not None, ax.get_xlabel(), longest))
        return original(self, **kwargs)

    monkeypatch.setattr(PillowWriter, "grab_frame", grab)
    monkeypatch.setitem(matplotlib.rcParams, "savefig.dpi", 20)
    monkeypatch.setattr(engagement_plots, "FRAMES", 12)
    monkeypatch.setattr(scenario_plots, "_FRAMES", 12)
    plot_result(fixtures.saved(PROBLEMS / name), tmp_path, animate=True)
    assert len(frames) > 10
    assert all("t = " in title and legend and xlabel for title, legend, xlabel, _ in frames)
    lengths = [n for *_, n in frames]
    assert lengths == sorted(lengths) and lengths[0] < lengths[-1]


def test_the_game_gif_ends_at_the_last_sample_without_warnings(tmp_path, monkeypatch, caplog) -> None:
    """Chapter 7's GIF: a frame per receding-horizon step and one at the run's last sample (the
    collision or capture), drawn without a library warning (fixed limits with a box aspect)."""
    import warnings

    import matplotlib
    from matplotlib.animation import PillowWriter

    result = fixtures.saved(PROBLEMS / "ch7/asymmetric_obstacle.yaml")
    frames = []
    original = PillowWriter.grab_frame

    def grab(self, **kwargs):
        frames.append(self.fig.axes[0].get_title())
        return original(self, **kwargs)

    monkeypatch.setattr(PillowWriter, "grab_frame", grab)
    monkeypatch.setitem(matplotlib.rcParams, "savefig.dpi", 20)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        written = plot_result(result, tmp_path, animate=True)
    assert [p.suffix for p in written].count(".gif") == 1
    assert not [r for r in caplog.records if r.levelname == "WARNING"], caplog.text
    assert frames[-1].endswith(f"t = {result.time[-1]:.2f}")
    assert len(frames) == len(result.control_time) + (result.control_time[-1] < result.time[-1])


def test_a_moving_obstacle_is_drawn_at_the_closest_approach(tmp_path) -> None:
    """With the true obstacle nearest the pursuer at sample k (it sits on the pursuer's path
    there), the paths figure draws it at t_k as well as at the end, with the players at t_k."""
    result = fixtures.saved(PROBLEMS / "ch7/asymmetric_obstacle.yaml")
    px, py = result.metrics["figure"]["positions"]["pursuer"]
    k = len(result.time) // 2
    x, y = result.states[px], result.states[py]
    arrays = dict(result.arrays)
    arrays["obstacle/true/x"] = np.full_like(x, x[k]) + 0.05 * (np.arange(len(x)) - k) ** 2
    arrays["obstacle/true/y"] = np.full_like(y, y[k])
    moved = result.model_copy(update={"arrays": arrays})
    with recording() as saved:
        plot_result(moved, tmp_path)
    labels = legend_texts(saved[0].axes[0])
    when = f"t = {result.time[k]:.2f}"
    assert f"obstacle at pursuer's closest approach, {when} (true)" in labels
    assert f"players at {when}" in labels
    disks = [
        p
        for p in saved[0].axes[0].patches
        if isinstance(p, Circle) and p.get_label().endswith(f"{when} (true)")
    ]
    assert [d.center for d in disks] == [pytest.approx((x[k], y[k]))]


def test_animate_says_when_a_kind_has_no_animation(cli, tmp_path) -> None:
    code, out, err = cli("plot", fixtures.FIXTURES / "linear_flow", "--out", tmp_path, "--animate")
    assert code == 0 and "no animation" in out and "flow_field_game" in out and err == ""
    assert not list(tmp_path.glob("*.gif"))


@pytest.mark.parametrize(
    "name",
    [
        "ocp/brachistochrone.yaml",
        "ch7/homicidal_chauffeur.yaml",
        "ch7/unicycle_pursuit_evasion.yaml",
        "ch7/lq_pursuit_evasion.yaml",
    ],
)
def test_planar_problems_and_open_loop_games_get_their_path_figure(name, tmp_path) -> None:
    """The planar OCP and the open-loop games with positions in a plane declare them (``plot.planar``)
    and get the x–y figure: one path per pair, through the Result's states."""
    result = fixtures.saved(PROBLEMS / name)
    pairs = result.metrics["plot"]["planar"]
    assert pairs
    with recording() as saved:
        plot_result(result, tmp_path)
    (ax,) = next(s for s in saved if s.name == f"{result.problem}_path.png").axes
    for xs, ys in pairs:
        line = next(line for line in ax.lines if line.get_label() == f"({xs}, {ys})")
        assert np.array_equal(line.get_xdata(), result.states[xs])
        assert np.array_equal(line.get_ydata(), result.states[ys])


@pytest.mark.parametrize("name", ["ch6/car_vs_train.yaml", "ch6/rcs_single_obstacle.yaml"])
def test_the_collision_probability_is_drawn_along_the_path(name, tmp_path) -> None:
    """Uncertainty drawn where it is: the fraction of Monte Carlo samples that have collided by
    each time never decreases and ends at the collision probability the analysis reports (counted
    per sample over the whole run), and the RCS figure draws that curve against time."""
    result = fixtures.saved(PROBLEMS / name)
    along = result.arrays["monte_carlo_violated"]
    assert np.all(np.diff(along) >= 0)
    assert along[-1] == pytest.approx(result.metrics["monte_carlo"]["collision_probability"], abs=1e-12)
    with recording() as saved:
        plot_result(result, tmp_path)
    figure = next(s for s in saved if s.name == f"{result.problem}_rcs.png")
    line = next(
        line for ax in figure.axes for line in ax.lines if line.get_label().startswith("collided by t")
    )
    assert np.array_equal(line.get_ydata(), along)
    assert np.array_equal(line.get_xdata(), result.arrays["monte_carlo_time"])


@pytest.mark.parametrize(
    "name", ["ch6/car_vs_train.yaml", "ch6/rcs_single_obstacle.yaml", "ch6/rcs_constraint_form.yaml"]
)
def test_the_sampled_obstacles_are_drawn_at_the_closest_approach(name, tmp_path) -> None:
    """Uncertainty drawn where it is: the saved sampled centres are the obstacle's motion
    (eq. 6.38: ``center + velocity·t``) recomputed from the kept draws at the saved time of closest
    approach, that time is where the agent is nearest the nominal centre, the saved verdicts are as
    many as the kept draws and collide at the rate P_c within sampling error, and the obstacle
    figure draws exactly those centres, split by verdict, with counts in the legend."""
    result = fixtures.saved(PROBLEMS / name)
    spec = fixtures.spec_of(PROBLEMS / name)
    ((obstacle, entry),) = result.metrics["obstacle_samples"].items()
    declared = spec.transforms[0]["moving_obstacles"]["obstacles"][obstacle]
    rho = result.arrays["monte_carlo_draw_rho"]
    p = dict(result.parameters)
    assert declared["center"] == ["c", "-d"] and declared["velocity"] == [0, "rho"]
    sx, sy = result.arrays[f"obstacle_{obstacle}_sampled_x"], result.arrays[f"obstacle_{obstacle}_sampled_y"]
    assert np.allclose(sx, p["c"]) and np.allclose(sy, -p["d"] + rho * entry["time"])
    y = result.states.get("y", np.zeros_like(result.states["x"]))
    gap = np.hypot(result.states["x"] - p["c"], y + p["d"] - p["rho"] * result.time)
    assert entry["time"] == result.time[int(np.argmin(gap))]
    verdicts = result.arrays["monte_carlo_draw_violated"]
    mc = result.metrics["monte_carlo"]
    assert set(np.unique(verdicts)) <= {0.0, 1.0} and len(verdicts) == len(rho) == min(200, mc["samples"])
    p_c = mc["collision_probability"]
    assert abs(verdicts.mean() - p_c) <= 4 * np.sqrt(max(p_c * (1 - p_c), 1e-3) / len(verdicts))
    with recording() as saved:
        plot_result(result, tmp_path)
    (ax,) = next(s for s in saved if s.name == f"{result.problem}_obstacles.png").axes
    clouds = {c.get_label().split(": ")[-1].split(" (")[0]: c.get_offsets() for c in ax.collections}
    hit = verdicts > 0
    assert np.array_equal(clouds["collided"], np.column_stack([sx[hit], sy[hit]]))
    assert np.array_equal(clouds["clear"], np.column_stack([sx[~hit], sy[~hit]]))
    labels = legend_texts(ax)
    assert any(f"collided ({np.count_nonzero(hit)} of {hit.size})" in label for label in labels)
    assert any(label.startswith(f"nominal {obstacle} at t = ") for label in labels)
