"""A Pyomo model's AMPL NL file, written once and re-solved by rewriting two segments.

Pyomo's NL writer walks every expression of the model on every write (0.2–0.7 s at N = 1000
collocation intervals). In an NL file the expressions, the Jacobian pattern and the constraint
ranges depend only on the model's structure when nothing in it is a Param or a fixed Var (those
are written as constants): with parameters, grid inputs and a fixed horizon as Vars held by equal
bounds (:mod:`gamespec_pyomo.model`), what a re-solve changes is the ``b`` segment (variable
bounds) and the ``x`` segment (the start). :class:`NLFile` keeps the rest of the text and writes
these two from the model's Vars the way Pyomo's writer does, with the configuration Pyomo's
NL-file solvers use (no scaling or presolve by the writer, trivial constraints kept), so the text
equals a fresh write of the model (tested). The SOL file's values go back to the model by the
writer's column and row order.
"""

from __future__ import annotations

import io
import re
from typing import Any

_X_HEADER = re.compile(r"^x\d+[^\n]*\n", re.MULTILINE)
_NEXT_SEGMENT = re.compile(r"^[A-Za-z]", re.MULTILINE)
_B_HEADER = re.compile(r"^b[^\n]*\n", re.MULTILINE)
_K_HEADER = re.compile(r"^k\d+[^\n]*\n", re.MULTILINE)

WRITER_CONFIG = {"scale_model": False, "linear_presolve": False, "skip_trivial_constraints": False}
"""What Pyomo's ``SolverFactory`` NL-file solvers write with: the ``scaling_factor`` Suffix goes to
the solver as a suffix and no variable is eliminated, so the solver sees the model as it is."""


def _bound_line(lb: float | None, ub: float | None) -> str:
    """One ``b`` line in Pyomo's writer's format (``str`` of the bound values)."""
    if lb == ub:
        return "3\n" if lb is None else f"4 {lb!s}\n"
    if lb is None:
        return f"1 {ub!s}\n"
    if ub is None:
        return f"2 {lb!s}\n"
    return f"0 {lb!s} {ub!s}\n"


class NLFile:
    """The NL file of ``model``, written once; :meth:`text` is the file for the Vars' current bounds
    and values, :meth:`load` puts a SOL file's solution back on the Vars and the ``dual`` Suffix."""

    def __init__(self, model: Any) -> None:
        from pyomo.repn.plugins.nl_writer import NLWriter

        stream = io.StringIO()
        info = NLWriter().write(model, stream, None, None, **WRITER_CONFIG)
        text = stream.getvalue()
        self.model = model
        self.variables = info.variables
        self.constraints = info.constraints
        x = _X_HEADER.search(text)
        b = _B_HEADER.search(text, x.end())
        k = _K_HEADER.search(text, b.end())
        self._head = text[: x.start()]
        self._ranges = text[_NEXT_SEGMENT.search(text, x.end()).start() : b.end()]
        self._tail = text[k.start() :]

    def _start(self) -> str:
        """The ``x`` segment: the value of every variable that has one."""
        lines = [
            f"{i} {v if v.__class__ in (int, float) else float(v)!s}\n"
            for i, v in enumerate(var.value for var in self.variables)
            if v is not None
        ]
        return f"x{len(lines)}\n" + "".join(lines)

    def text(self) -> str:
        """The NL file for the current bounds and values of the model's Vars."""
        bounds = "".join(_bound_line(*var.bounds) for var in self.variables)
        return self._head + self._start() + self._ranges + bounds + self._tail

    def load(self, solution: Any) -> None:
        """Set the Vars and the ``dual`` Suffix from one solution of Pyomo's SOL reader (keys
        ``v<column>`` and ``c<row>``)."""
        for i, var in enumerate(self.variables):
            var.set_value(solution.variable[f"v{i}"]["Value"], skip_validation=True)
        duals = solution.constraint
        for i, con in enumerate(self.constraints):
            self.model.dual[con] = duals[f"c{i}"]["Dual"]
