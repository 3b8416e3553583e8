"""CVXPY backend plugin (conic solvers: Clarabel by default, SCS or any installed one by name)."""
