"""Flow fields shared by the chapter-5 tests."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from gamespec.flowfield.field import FlowField

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


@pytest.fixture
def uniform() -> FlowField:
    return uniform_field()


@pytest.fixture
def linear() -> FlowField:
    return linear_field()
