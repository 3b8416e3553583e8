"""The symbolic layer under the specs (DESIGN.md, "Layers"):

- :mod:`~gamespec.symbolic.grammar`: the safe expression language of problem files, one whitelist
  walk that builds its value in an algebra (``expression``, ``relation``; floats for the values of
  numbers, ``numeric_value``; the names a term depends on, ``dependencies``), without SymPy;
- :mod:`~gamespec.symbolic.canonical`: the check at load (``check``), refusing exactly what the solve
  path refuses: SymPy's canonical form and its derivatives, asked only where a screen without SymPy
  cannot prove the text defined;
- :mod:`~gamespec.symbolic.library`: a backend's functions (``Library``, ``NUMPY``) and the algebra
  that builds that backend's expressions straight from the text (``LibraryAlgebra``: the CasADi
  graph, the Pyomo model, NumPy arrays for the checks);
- :mod:`~gamespec.symbolic.language`: the same walk into SymPy (``parse``, ``parse_relation``,
  ``symbol``, ``FUNCTIONS``), for the transforms that differentiate and the generated problems;
- :mod:`~gamespec.symbolic.printer`: SymPy back to that language (``to_text``, with
  ``parse(to_text(e)) == e``), so generated problems are built in SymPy, never from f-strings;
- :mod:`~gamespec.symbolic.translate`: SymPy into a backend's own expressions by walking the tree
  (``translate``, ``numeric``);
- :mod:`~gamespec.symbolic.tape`: a walk recorded once and replayed over NumPy arrays;
- :mod:`~gamespec.symbolic.calculus`: Jacobians and gradients of expression maps, vectorized NumPy
  evaluation and the linearization about a trajectory (eqs. 5.5–5.6).

SymPy's import costs more than a small solve (about 0.3 s of CPU), so only the modules that need a
computer-algebra system import it: loading, validating and solving an ``optimal_control`` file on
CasADi or Pyomo do only when one of its expressions is outside what the check's screen settles (a
division by an expression, ``log``, ``sqrt``, ...).
"""
