"""Hand-written CasADi Opti collocations, the baselines of ``test_bench_casadi.py``.

Each builds the same discretization as gamespec's CasADi backend (Legendre–Gauss–Radau of degree
d, controls at the collocation points, the same interval grading) directly with ``casadi.Opti``
and its own collocation coefficients from ``casadi.collocation_points``, then solves with IPOPT.
"""

from __future__ import annotations

from collections.abc import Callable

import casadi as ca
import numpy as np

IPOPT = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False, "ipopt.tol": 1e-8}


def _radau_coefficients(degree: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    tau = np.append(0.0, ca.collocation_points(degree, "radau"))
    C = np.zeros((degree + 1, degree + 1))
    B = np.zeros(degree + 1)
    for j in range(degree + 1):
        p = np.poly1d([1.0])
        for r in range(degree + 1):
            if r != j:
                p *= np.poly1d([1.0, -tau[r]]) / (tau[j] - tau[r])
        dp = np.polyder(p)
        C[j] = [dp(tau[r]) for r in range(degree + 1)]
        B[j] = np.polyint(p)(1.0)
    return tau, C, B


def _breaks(intervals: int, grading: float) -> np.ndarray:
    ratio = (1.0 / grading) ** (1.0 / max(intervals - 1, 1))
    lengths = ratio ** np.arange(intervals)
    return np.concatenate([[0.0], np.cumsum(lengths / lengths.sum())])


def collocate(
    f: Callable,
    nx: int,
    nu: int,
    *,
    intervals: int,
    degree: int,
    grading: float,
    setup: Callable[[ca.Opti, ca.MX, ca.MX, ca.MX], ca.MX],
    free_time: tuple[float, float, float] | None,
    horizon: float = 1.0,
    x_guess: Callable[[np.ndarray], np.ndarray],
    u_guess: float,
) -> float:
    """Build and solve ``min setup(...)`` subject to ``x' = f(x, u)`` by LGR collocation."""
    tau, C, _ = _radau_coefficients(degree)
    h = np.diff(_breaks(intervals, grading))
    opti = ca.Opti()
    X = opti.variable(nx, intervals * degree + 1)
    U = opti.variable(nu, intervals * degree)
    if free_time is not None:
        T = opti.variable()
        opti.subject_to(opti.bounded(free_time[0], T, free_time[1]))
        opti.set_initial(T, free_time[2])
    else:
        T = horizon
    for k in range(intervals):
        for j in range(1, degree + 1):
            col = k * degree + j
            xp = sum(C[r, j] * X[:, k * degree + r] for r in range(degree + 1))
            opti.subject_to(xp == h[k] * T * f(X[:, col], U[:, col - 1]))
    grid = np.concatenate(
        [[0.0], (_breaks(intervals, grading)[:-1, None] + h[:, None] * tau[None, 1:]).ravel()]
    )
    opti.set_initial(X, x_guess(grid))
    opti.set_initial(U, u_guess)
    objective = setup(opti, X, U, T)
    opti.minimize(objective)
    opti.solver("ipopt", IPOPT)
    return float(opti.solve().value(objective))


def two_on_one_pure_pursuit(intervals: int = 40, degree: int = 3, grading: float = 10.0) -> float:
    """Eq. 2.21 with u1 = u2 = 1, v = 0.5, eps = 0.001; returns the maximal capture time."""
    v, eps = 0.5, 0.001

    def f(x, u):
        r1, r2, psi = x[0], x[1], x[2]
        th = u[0]
        return ca.vertcat(
            -1 + v * ca.cos(th), -1 - v * ca.cos(psi - th), v / r2 * ca.sin(psi - th) - v / r1 * ca.sin(th)
        )

    def setup(opti, X, U, T):
        opti.subject_to(X[:, 0] == ca.DM([1.0, 1.75, -np.pi / 6]))
        opti.subject_to(X[0, -1] == eps)
        opti.subject_to(opti.bounded(eps, ca.vec(X[:2, :]), np.inf))
        opti.subject_to(opti.bounded(-np.pi, U, np.pi))
        return -T

    def x_guess(s):
        return np.vstack([1 - s, 1.75 - 1.75 * s, np.full_like(s, -np.pi / 6)])

    return -collocate(
        f,
        3,
        1,
        intervals=intervals,
        degree=degree,
        grading=grading,
        setup=setup,
        free_time=(0.1, 10.0, 2.0),
        x_guess=x_guess,
        u_guess=np.pi / 2,
    )


def zermelo_max_range(intervals: int = 20, degree: int = 3, rho: float = 10.0) -> float:
    """Eqs. 6.19–6.23 with t_f = 1; returns x1(t_f)."""

    def f(x, u):
        return ca.vertcat(ca.cos(u[0]) + rho * x[1], ca.sin(u[0]))

    def setup(opti, X, U, T):
        opti.subject_to(X[:, 0] == 0)
        opti.subject_to(X[1, -1] == 0)
        opti.subject_to(opti.bounded(-np.pi, U, np.pi))
        return -X[0, -1]

    def x_guess(s):
        return np.zeros((2, len(s)))

    return -collocate(
        f,
        2,
        1,
        intervals=intervals,
        degree=degree,
        grading=1.0,
        setup=setup,
        free_time=None,
        x_guess=x_guess,
        u_guess=0.0,
    )
