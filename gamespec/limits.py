"""Limits on what a problem file may ask for, each checked where the input is read (README, "Limits").

A file beyond one of these is bad input: exit 2 with one line naming the limit, never a hang, a
traceback or an exhausted memory. The values are far beyond every problem of the thesis and small
enough that the work or memory they allow takes seconds, not hours.
"""

from __future__ import annotations

import sys

MAX_FILE_BYTES = 4_000_000
"""Largest problem file read (bytes): room for per-step matrices over a long horizon."""

MAX_DEPTH = 64
"""Deepest nesting of mappings and lists in a problem file."""

MAX_VALUES = 1_000_000
"""Most values (mappings, lists and scalars) in a problem file after its YAML aliases are expanded:
a "billion laughs" file of nested aliases is refused at this count instead of being expanded."""

MAX_INT_DIGITS = 4300
"""Longest integer literal (decimal digits); Python's own limit on converting text to an integer."""

MAX_EXPRESSION_CHARS = 10_000
"""Longest expression string."""

MAX_EXPRESSION_NODES = 2_000
"""Most syntax-tree nodes in one expression."""

MAX_MAGNITUDE = sys.float_info.max
"""Largest absolute value of a constant (sub-)expression, the largest finite double: expressions are
evaluated in floating point, and one whose value or an intermediate value overflows is refused as out
of range instead of being computed exactly."""

MAX_INTERVALS = 10_000
"""Most intervals of a grid: collocation intervals of an ``optimal_control`` transcription (and of the
OCP an ``engagement`` becomes), steps of an ``lq_stochastic_game`` horizon."""

MAX_VECTOR_SIZE = 32
"""Most components of one vector state or control (``size:``): an expression such as ``norm(r)``
in every component grows as the square of the size, and the checks at load with it (a size of 100
validated in 28 s)."""

MAX_SIMULATION_VALUES = 2_000_000
"""Most positions a ``pursuit_scenario`` simulation records: time steps (``horizon / time_step``)
times players."""

MAX_SAMPLES = 1_000_000
"""Most Monte Carlo samples of an ``lq_stochastic_game``."""

MAX_SAMPLE_VALUES = 20_000_000
"""Most numbers the Monte Carlo samples of an ``lq_stochastic_game`` hold: samples times
(horizon + 1) times states (160 MB of doubles)."""

MAX_STUDY_POINTS = 10_000
"""Most points of a ``pursuit_suboptimal_study`` grid (angles times fractions times speeds), each an
OCP solve."""

MAX_SWEEP_POINTS = 10_000
"""Most points of a ``gamespec sweep`` grid (the product of the ``--param`` counts), each a solve."""

MAX_COORDINATE = 1e9
"""Largest absolute value of a position coordinate (``engagement``, ``pursuit_scenario``): beyond it
squared distances lose the precision a capture radius needs, and far beyond it they overflow."""

MAX_SPEED = 1e9
"""Largest speed of a player (``engagement``, ``pursuit_scenario``)."""

MAX_GAME_STATE = 1e9
"""Largest absolute value of a ``differential_game`` state's initial or final value (as
:data:`MAX_COORDINATE`: beyond it distances lose the precision a capture needs)."""

MAX_RECEDING_STEPS = 10_000
"""Most steps of a ``differential_game`` receding-horizon run (``time_limit / step``)."""

MAX_BEST_RESPONSES = 2_000_000
"""Most best-response solves a ``differential_game`` may ask for: steps times players² (one game
per player, each with every player's problem) times ``game.max_iterations``."""

MAX_RCS_OBSTACLES = 100
"""Most obstacles of one point of an ``rcs_multi_obstacle_study``."""

MAX_GRID_CELL_STEPS = 5e7
"""Most cell updates of a ``flow_field_game``'s level sets: grid cells times the fewest CFL time
steps up to ``max_time`` (the Chapter 5 files need about 2e6; 5e7 is minutes of CPU)."""

MAX_EXTREMAL_VALUES = 2e7
"""Most front points of a ``flow_field_game``'s extremal shooting, directions times RK4 steps up to
``max_time`` (each kept: 320 MB of doubles)."""

MAX_SAMPLE_STEPS = 1e9
"""Most Euler–Maruyama sample steps of a ``flow_field_game``'s Monte Carlo: samples times
``substeps`` per control step times the control steps up to ``max_time``."""

MAX_LQ_ENTRY = 1e12
"""Largest absolute value of an entry of an ``lq_stochastic_game``'s evaluated matrices, and of its
open-loop state transition and covariance over the horizon (products of a few of them stay far
from overflow)."""


# --- Saved Results and study stores (issue 27: a Result folder is untrusted input) -------------
# Checked by gamespec.result.Result.load and gamespec.npyfile before anything is allocated.

MAX_RESULT_JSON_BYTES = 64_000_000
"""Largest ``result.json`` (or ``--json`` dump) read back (bytes)."""

MAX_RESULT_NPZ_BYTES = 2_000_000_000
"""Largest ``arrays.npz`` read back (bytes on disk)."""

MAX_RESULT_ARRAYS = 10_000
"""Most members (named arrays) of an ``arrays.npz``."""

MAX_ARRAY_DIMENSIONS = 8
"""Most dimensions of one saved array."""

MAX_ARRAY_VALUES = 50_000_000
"""Most values of one saved array (400 MB of doubles): room for an ``lq_stochastic_game``'s
``MAX_SAMPLE_VALUES`` Monte Carlo samples."""

MAX_RESULT_VALUES = 100_000_000
"""Most values of all arrays of one saved Result together (800 MB of doubles)."""

MAX_TEXT_CHARS = 10_000
"""Longest text item of a saved text array (characters)."""

MAX_HJI_NODE_STEPS = 10_000_000_000
"""Most node updates of an ``hji`` value function: nodes per axis squared times the time steps the
CFL condition asks for (the largest grid, 801², over about 15,000 steps: minutes of CPU, and bounded
in wall time by ``solver.options.hji.max_wall_time``)."""
