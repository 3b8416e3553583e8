"""Backends of the ``flow_field_game`` kind: reachability by level sets (``levelset``) or by extremal
shooting (``extremals``), then the chapter-5 covariance game on CVXPY."""
