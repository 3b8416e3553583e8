"""Zero-order hold (eq. 5.8) against direct integration and closed forms; the lifting (eq. 5.10)."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from gamespec.flowfield.linearize import lifted, zero_order_hold
from gamespec.flowfield.nominal import NominalPaths
from gamespec.specs.lq_model import zero_order_hold as constant_hold
from tests.flowfield.conftest import linear_field, vortex_field


def _paths(final_time: float = 1.2) -> NominalPaths:
    """Two smooth curved paths (any curves do: eq. 5.8 only needs x̂(t))."""
    t = np.linspace(0.0, final_time, 241)
    p = np.stack([1.0 + 0.8 * t, 0.5 + 0.3 * np.sin(2 * t)], axis=-1)
    e = np.stack([2.0 - 0.2 * t**2, 1.0 + 0.5 * t], axis=-1)
    directions = np.zeros((2, t.size, 2))
    directions[..., 0] = 1.0
    return NominalPaths(t, np.stack([p, e]), directions, np.array([1.0, 0.5]), np.zeros(2))


def test_zoh_matches_direct_integration_of_the_linearized_system() -> None:
    """``x_{k+1} = A_k x_k + B_k u_k + r_k`` and ``D_k D_kᵀ`` against solve_ivp of
    ``ẋ = A(t)x + u + r(t)`` and ``Ṗ = AP + PAᵀ + g gᵀ`` (eq. 5.5) over one step."""
    field, paths = vortex_field(), _paths()
    N = 6
    model = zero_order_hold(field, paths, N)
    rng = np.random.default_rng(3)
    for k in (0, 3, 5):
        x, u = rng.normal(size=4), rng.normal(size=4)
        t0, t1 = k * model.step, (k + 1) * model.step

        def rate(t: float, z: np.ndarray, u: np.ndarray = u) -> np.ndarray:
            xh = paths.position(np.array([t]))[:, 0]
            A, g = field.jacobian(xh), field.diffusion(xh)
            r = field.drift(xh) - np.einsum("aij,aj->ai", A, xh)
            xs, P = z[:4].reshape(2, 2), z[4:].reshape(2, 2, 2)
            dx = np.einsum("aij,aj->ai", A, xs) + u.reshape(2, 2) + r
            dP = A @ P + P @ np.swapaxes(A, 1, 2) + g @ np.swapaxes(g, 1, 2)
            return np.concatenate([dx.ravel(), dP.ravel()])

        z = solve_ivp(rate, (t0, t1), np.concatenate([x, np.zeros(8)]), rtol=1e-11, atol=1e-13).y[:, -1]
        np.testing.assert_allclose(model.A[k] @ x + model.B[k] @ u + model.r[k], z[:4], atol=1e-9)
        P = z[4:].reshape(2, 2, 2)
        np.testing.assert_allclose(model.DD[k][:2, :2], P[0], atol=1e-11)
        np.testing.assert_allclose(model.DD[k][2:, 2:], P[1], atol=1e-11)
        np.testing.assert_allclose(model.D[k] @ model.D[k].T, model.DD[k], atol=1e-12)


def test_linear_field_hold_is_the_matrix_exponential() -> None:
    """Eq. 5.37: ``A_k = e^{Ah}``, ``B_k = ∫e^{As}ds`` (eq. 4.70) and Van Loan's ``D_kD_kᵀ``."""
    field = linear_field(noise=0.3)
    model = zero_order_hold(field, _paths(), 4)
    A = np.array([[0.2, 0.3], [-0.15, 0.1]])
    h = model.step
    Phi, (B,) = constant_hold(A, [np.eye(2)], h)
    van_loan = expm(np.block([[-A, 0.09 * np.eye(2)], [np.zeros((2, 2)), A.T]]) * h)
    DD = van_loan[2:, 2:].T @ van_loan[:2, 2:]
    for k in range(4):
        np.testing.assert_allclose(model.A[k][:2, :2], Phi, atol=1e-12)
        np.testing.assert_allclose(model.B[k][2:, 2:], B, atol=1e-12)
        np.testing.assert_allclose(model.DD[k][:2, :2], DD, atol=1e-12)
        np.testing.assert_allclose(model.r[k][:2], -B @ A @ np.array([10.0, 10.0]), atol=1e-10)


def test_lifted_mean_is_the_recursion() -> None:
    """Eq. 5.31a against ``x_{k+1} = A_k x_k + B_k v_k + r_k``; ``Y = 𝒟_y W`` against eq. 5.28."""
    model = zero_order_hold(vortex_field(), _paths(), 5)
    x0 = np.array([1.0, 0.5, 2.0, 1.0])
    lift = lifted(model, x0)
    rng = np.random.default_rng(0)
    V, W = rng.normal(size=(5, 4)), rng.normal(size=(5, 4))
    x, y, xs, ys = x0, np.zeros(4), [], []
    for k in range(5):
        ys.append(y)
        x = model.A[k] @ x + model.B[k] @ V[k] + model.r[k] + model.D[k] @ W[k]
        y = model.A[k] @ y + model.D[k] @ W[k]
        xs.append(x)
    np.testing.assert_allclose(lift.mean(V.ravel()) + lift.D @ W.ravel(), np.concatenate(xs), atol=1e-12)
    np.testing.assert_allclose(lift.D_y @ W.ravel(), np.concatenate(ys), atol=1e-12)
