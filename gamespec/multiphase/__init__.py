"""Multi-phase optimal control (``multiphase_optimal_control``): the kind (:mod:`.spec`), its
lowering to one ``optimal_control`` problem (:mod:`.lowering`, which the spec runs to validate
itself), the ``phases`` transform that applies it (:mod:`.transform`) and the split of a Result back
by phase (:mod:`.split`).
"""
