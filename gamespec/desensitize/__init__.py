"""Desensitized optimal control (chapter 6): sensitivity functions, Seywald's sensitivity matrix,
co-state desensitization (C-DOC), and the Monte Carlo re-simulation that checks them.

The requested transform's section (:mod:`.spec`) and the ``desensitize`` transform
(:mod:`.transform`), the augmentation and its report that the ``rcs`` transform shares
(:mod:`.penalized`), the numerics, figures and summary.
"""
