"""Backends of chapter 5's two stages (a ``flow_field_game`` reaches them through the staged
transform :mod:`gamespec.flowfield.transform`): the reachability by level sets (``levelset``,
``hj_reachability``) or by extremal shooting (``extremals``) in :mod:`.reachability`, then the
covariance game on CVXPY in :mod:`.game`."""
