"""Geometric allocator plugin (thesis chapter 3): Apollonius geometry, active pursuers, AVAA/A2.

Public API: :func:`active_pursuers` (which pursuers are active against one evader),
:func:`allocate` (the AVAA and A2 allocation of pursuers to evaders) and the ``pursuit_scenario``
problem kind, simulated by the ``geometric`` backend.
"""

from gamespec_geometric.active import aapc, active_pursuers
from gamespec_geometric.allocation import allocate

__all__ = ["aapc", "active_pursuers", "allocate"]
