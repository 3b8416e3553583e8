"""IPOPT's own option list, read from the IPOPT inside the casadi wheel, and a check of raw options
against it (``solver.options.casadi.ipopt``), so that a misspelled option is refused at load with the
nearest valid name instead of failing in the solve.

The list comes from IPOPT's ``print_options_documentation`` (captured while a one-variable NLP is
solved); the values are checked by building that NLP with the options, which is where IPOPT rejects
an unknown option or a value of the wrong type.
"""

from __future__ import annotations

import difflib
import io
import os
import re
import sys
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, redirect_stdout, suppress
from functools import cache
from typing import Any

_OPTION_LINE = re.compile(r"^([a-z][a-z0-9_]*)\s{2,}\S", re.MULTILINE)


def _tiny_nlp(ipopt: Mapping[str, Any]) -> Any:
    import casadi as ca

    x = ca.SX.sym("x")
    return ca.nlpsol(
        "gamespec_option_check", "ipopt", {"x": x, "f": x**2}, {"ipopt": dict(ipopt), "print_time": False}
    )


@contextmanager
def _solver_output() -> Iterator[list[str]]:
    """Capture what IPOPT prints, whether casadi routes it through Python's ``sys.stdout`` or it
    reaches file descriptor 1 directly; the text is appended to the yielded list on exit."""
    sys.stdout.flush()
    saved = os.dup(1)
    out: list[str] = []
    python_level = io.StringIO()
    with tempfile.TemporaryFile() as captured:
        os.dup2(captured.fileno(), 1)
        try:
            with redirect_stdout(python_level):
                yield out
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            captured.seek(0)
            out.append(python_level.getvalue() + captured.read().decode("utf-8", "replace"))


@cache
def ipopt_option_names() -> frozenset[str]:
    """The names of every IPOPT option (empty when this IPOPT prints no documentation)."""
    with _solver_output() as text, suppress(RuntimeError):
        _tiny_nlp({"print_options_documentation": "yes", "max_iter": 0})(x0=1.0)
    return frozenset(_OPTION_LINE.findall(text[0]))


def check_ipopt_options(options: Mapping[str, Any]) -> None:
    """ValueError naming the first option IPOPT does not know (with the nearest valid name) or whose
    value it refuses."""
    names = ipopt_option_names()
    for key in options:
        if names and key not in names:
            near = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise ValueError(f"IPOPT has no option {key!r}{hint}")
    for key, value in options.items():
        with _solver_output() as text:
            try:
                _tiny_nlp({"print_level": 0, key: value})
                refused = ""
            except RuntimeError as err:
                refused = str(err).strip().splitlines()[-1].split(": ", 1)[-1].strip()
        if refused:
            said = next((line.strip() for line in text[0].splitlines() if line.strip()), refused)
            raise ValueError(f"IPOPT refuses {key}={value!r}: {said}")
