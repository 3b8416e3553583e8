"""Table 2.1 (§2.4.4): how much longer pure pursuit takes than the optimal time to capture, over a
grid of speeds and initial positions.

The kind (:mod:`.spec`), the grid of points and the generated engagement of each (:mod:`.points`),
the study that solves them into a store (:mod:`.study`, a ``gamespec.studies`` plugin), its
metrics (:mod:`.metrics`) and its figure (:mod:`.plotting`).
"""
