"""Flow fields shared by the chapter-5 tests."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from gamespec.flowfield.covariance_game import CovarianceGame, Feedforward, Payoff, PlayerBounds
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.linearize import DiscreteModel, lifted, zero_order_hold
from gamespec.flowfield.nominal import NominalPaths

X1, X2 = sp.symbols("x1 x2", real=True)
UNIFORM_DRIFT = np.array([0.4, -0.3])


def uniform_field(noise: float = 0.05) -> FlowField:
    """``f = (0.4, −0.3)``, ``g = noise · I``: reachable sets are discs of radius v̂t about x₀ + f t."""
    return FlowField((X1, X2), sp.Matrix(UNIFORM_DRIFT.tolist()), sp.eye(2) * noise)


def linear_field(noise: float = 0.025) -> FlowField:
    """Eqs. 5.37–5.38."""
    A = sp.Matrix([[0.2, 0.3], [-0.15, 0.1]])
    return FlowField((X1, X2), A * (sp.Matrix([X1, X2]) - sp.Matrix([10, 10])), sp.eye(2) * noise)


def vortex_field() -> FlowField:
    """A nonlinear field with a position-dependent diffusion (for the linearization tests)."""
    drift = sp.Matrix([-0.3 * (X2 - 1) + 0.05 * X1**2, 0.3 * (X1 - 1) - 0.02 * X1 * X2])
    diffusion = sp.Matrix([[0.05 + 0.01 * X1, 0], [0.01 * X2, 0.04]])
    return FlowField((X1, X2), drift, diffusion)


SMALL_STEPS = 6


def turning_paths(field: FlowField) -> NominalPaths:
    """Trajectories of ``field`` under turning unit headings at speeds 2.4 and 0.8, so the nominal
    controls do drive the nominal paths (eqs. 5.23–5.26)."""
    speeds = np.array([2.4, 0.8])
    t = np.linspace(0.0, 0.6, 601)
    heading = np.stack([0.3 + 0.5 * t, 2.0 - 0.4 * t])
    directions = np.stack([np.cos(heading), np.sin(heading)], axis=-1)
    x = np.zeros((2, t.size, 2))
    x[:, 0] = [[1.0, 0.5], [2.0, 1.0]]
    for j in range(t.size - 1):  # Heun on a fine grid: second order, h = 1e-3
        h = t[j + 1] - t[j]
        a = field.drift(x[:, j]) + speeds[:, None] * directions[:, j]
        b = field.drift(x[:, j] + h * a) + speeds[:, None] * directions[:, j + 1]
        x[:, j + 1] = x[:, j] + h * (a + b) / 2
    return NominalPaths(t, x, directions, speeds, np.zeros(2))


def small_game(
    field: FlowField, payoff: Payoff = "trace", feedforward: Feedforward = "free"
) -> tuple[CovarianceGame, DiscreteModel]:
    """The covariance game of :func:`turning_paths` in ``SMALL_STEPS`` steps, with the bounds of
    section 5.4 (v_max = 3 and 1, δ_x = 0.1, δ_u = 0.2 v_max, β = 0.01)."""
    paths = turning_paths(field)
    model = zero_order_hold(field, paths, SMALL_STEPS)
    _, x_hat, u_hat = paths.sampled(SMALL_STEPS)
    stack = lambda a: np.concatenate([a[0], a[1]], axis=1)  # noqa: E731
    bounds = (PlayerBounds(3.0, 0.1, 0.6, 0.01), PlayerBounds(1.0, 0.1, 0.2, 0.01))
    lift = lifted(model, x_hat[:, 0].reshape(-1))
    return CovarianceGame(lift, stack(x_hat[:, 1:]), stack(u_hat), bounds, payoff, feedforward), model


@pytest.fixture
def uniform() -> FlowField:
    return uniform_field()


@pytest.fixture
def linear() -> FlowField:
    return linear_field()
