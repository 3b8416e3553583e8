"""The symbolic layer under the specs (DESIGN.md, "Layers"): the safe expression language of
problem files parsed into SymPy (:mod:`~gamespec.symbolic.language`) and SymPy translated into a
backend's own expressions (:mod:`~gamespec.symbolic.translate`)."""
