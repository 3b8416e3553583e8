"""Chapter 4: discrete-time LQ stochastic games with one-sided terminal mean and covariance targets.

``game`` (the arrays of eq. 4.1 and the zero-order hold of eq. 4.70), ``lifting`` (eq. 4.6–4.7),
``checks`` (eq. 4.27, Lemmas 10–11), ``mean_steering`` (Props. 9–10), ``covariance`` (eq. 4.56–4.62,
Algorithm 2), ``montecarlo`` (closed-loop sampling), ``solution`` (the Result of a solve),
``backend`` (the base classes of the backend plugins) and ``plotting``. NumPy/SciPy only; the CVXPY
and qpsolvers plugins live in ``backends/``.
"""
