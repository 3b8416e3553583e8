"""The symbolic layer under the specs (DESIGN.md, "Layers"), four modules:

- :mod:`~gamespec.symbolic.language`: the safe expression language of problem files, parsed by a
  whitelist into SymPy (``parse``, ``parse_relation``, ``symbol``, ``FUNCTIONS``);
- :mod:`~gamespec.symbolic.printer`: SymPy back to that language (``to_text``, with
  ``parse(to_text(e)) == e``), so generated problems are built in SymPy, never from f-strings;
- :mod:`~gamespec.symbolic.translate`: SymPy into a backend's own expressions by walking the tree
  (``Library``, ``translate``, ``numeric``, ``NUMPY``);
- :mod:`~gamespec.symbolic.calculus`: Jacobians and gradients of expression maps, vectorized NumPy
  evaluation and the linearization about a trajectory (eqs. 5.5–5.6).
"""
