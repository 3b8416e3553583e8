"""Controls as the transcription holds them (:mod:`gamespec.ocp.control_signal`)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gamespec.ocp.collocation import radau_points
from gamespec.ocp.control_signal import step_edges, transcribed_signal
from gamespec.result import Result, Status

MESH = np.array([0.0, 0.7, 1.5, 3.0])


def _quadratics(t: np.ndarray, interval: np.ndarray) -> np.ndarray:
    """A different quadratic on each interval (so the signal jumps at the mesh points)."""
    return (interval + 1.0) * t**2 - 3.0 * interval * t + 2.0 - interval


def _radau_result() -> Result:
    local = radau_points(3)
    times = np.concatenate([a + (b - a) * local for a, b in itertools.pairwise(MESH)])
    owner = np.repeat(np.arange(3), 3)
    return Result(
        status=Status.OPTIMAL,
        time=np.concatenate([[0.0], times]),
        control_time=times,
        controls={"u": _quadratics(times, owner)},
        arrays={"control_mesh": MESH},
    )


def test_radau_controls_are_each_intervals_polynomial_with_jumps() -> None:
    """Through the interval's three collocation points, continued to its start; a mesh point takes
    the value of the interval it ends; each step sees its own interval on both of its ends."""
    signal = transcribed_signal(_radau_result(), ["u"])
    t = np.linspace(0.0, 3.0, 301)
    interval = np.searchsorted(MESH[1:-1] + 1e-12, t, side="left")
    np.testing.assert_allclose(signal(t)[0], _quadratics(t, interval), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose([signal.at(float(x))[0] for x in t], signal(t)[0], rtol=1e-14, atol=1e-14)
    edges = np.array([0.0, 0.7, 1.5, 3.0])
    stages = signal.on_steps(edges)[0]
    ends = np.stack([edges[:-1], 0.5 * (edges[:-1] + edges[1:]), edges[1:]], axis=1)
    np.testing.assert_allclose(stages, _quadratics(ends, np.arange(3)[:, None]), rtol=1e-12)
    assert stages[0, 2] != pytest.approx(stages[1, 0]), "the jump at t = 0.7 is kept"


def test_trapezoidal_controls_are_linear_between_nodes() -> None:
    nodes = np.array([0.0, 0.5, 2.0])
    result = Result(
        status=Status.OPTIMAL,
        time=nodes,
        control_time=nodes,
        controls={"u": np.array([1.0, -1.0, 2.0])},
        arrays={"control_mesh": nodes},
    )
    signal = transcribed_signal(result, ["u"])
    t = np.linspace(0, 2, 41)
    np.testing.assert_allclose(signal(t)[0], np.interp(t, nodes, [1.0, -1.0, 2.0]), atol=1e-12)


def test_without_a_mesh_the_points_are_joined_linearly() -> None:
    times = np.array([0.1, 0.4, 1.0])
    result = Result(status=Status.OPTIMAL, time=times, control_time=times, controls={"u": [0.0, 3.0, 1.0]})
    signal = transcribed_signal(result, ["u"])
    t = np.linspace(0.1, 1.0, 19)
    np.testing.assert_allclose(signal(t)[0], np.interp(t, times, [0.0, 3.0, 1.0]), atol=1e-12)


@given(
    st.floats(0.0, 2.9),
    st.floats(0.01, 3.0),
    st.integers(1, 200),
)
def test_steps_cover_the_span_and_never_cross_a_mesh_point(start, length, steps) -> None:
    t0, tf = start, min(start + length, 3.0)
    if tf - t0 < 1e-6:
        return
    edges = step_edges(MESH, t0, tf, steps)
    assert edges[0] == t0 and edges[-1] == tf and np.all(np.diff(edges) > 0)
    inner = MESH[(t0 < MESH) & (tf > MESH)]
    for point in inner:
        assert np.min(np.abs(edges - point)) < 1e-12, "a mesh point inside the span is a step edge"
