"""The plain-script baseline of ``test_bench_startup.py``: ``problems/ch6/zermelo_min_time.yaml``
(eqs. 6.19–6.21, rho = 10, from the origin to (2, 0) in minimum time) solved by a Python script
that imports only NumPy and CasADi and writes the same Radau collocation (20 intervals, degree 3)
with ``casadi.Opti`` (:func:`benchmarks.opti_baselines.collocate`).

Run: ``python -m benchmarks.plain_zermelo_min_time`` (prints the minimum time).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from benchmarks.opti_baselines import collocate


def zermelo_min_time(intervals: int = 20, degree: int = 3, rho: float = 10.0, xf: float = 2.0) -> float:
    """Eqs. 6.19–6.21 with free t_f in [0.05, 5]; returns the minimum time."""

    def f(x, u):
        return ca.vertcat(ca.cos(u[0]) + rho * x[1], ca.sin(u[0]))

    def setup(opti, X, U, T):
        opti.subject_to(X[:, 0] == 0)
        opti.subject_to(X[:, -1] == ca.DM([xf, 0.0]))
        opti.subject_to(opti.bounded(-np.pi, U, np.pi))
        return T

    def x_guess(s):
        return np.zeros((2, len(s)))

    return collocate(
        f,
        2,
        1,
        intervals=intervals,
        degree=degree,
        grading=1.0,
        setup=setup,
        free_time=(0.05, 5.0, 1.0),
        x_guess=x_guess,
        u_guess=0.7,
    )


if __name__ == "__main__":
    print(f"{zermelo_min_time():.12g}")
