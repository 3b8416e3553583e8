"""The ``tables:`` section of an ``optimal_control`` problem: gridded data, inline or read from a CSV
or NPZ file next to the problem file, each entry a function of the expression language
(``CL(mach, alpha)``, :mod:`gamespec.symbolic.tables`).

Files are untrusted input: the path must stay inside the problem file's folder (symbolic links
resolved), the file within :data:`~gamespec.limits.MAX_FILE_BYTES`, the table within
:data:`MAX_TABLE_VALUES` values; CSV is read by :mod:`csv` into floats, NPZ by
:func:`gamespec.npyfile.read_npz` (no pickles, headers parsed by one regular expression). The data
read replace the file in the validated spec (``axes`` and ``values`` filled in), so a spec carried
to another process, hashed or saved with a Result holds the numbers, not a path; a spec that holds
``values`` already (such a saved one) is not read from its ``file`` again.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import Field, PrivateAttr, ValidationInfo, model_validator

from gamespec.limits import MAX_FILE_BYTES
from gamespec.specs.base import Number, StrictModel
from gamespec.symbolic.tables import MIN_POINTS, Method, Table

if TYPE_CHECKING:
    import numpy as np

MAX_TABLE_VALUES = 1_000_000
"""Most values one table holds (8 MB of doubles)."""
MAX_TABLE_AXES = 6
"""Most axes (arguments) of one table."""
FOLDER = "folder"
"""The key of the validation context that names the problem file's folder (:func:`gamespec.loader.
spec_from_dict`); without it, a table's file is looked up from the working directory."""


class TableSpec(StrictModel):
    """One table: ``values`` on the grid ``axes`` (one strictly increasing list per argument;
    ``values`` nested one level per axis, the first axis outermost), inline or from ``file``, and
    the interpolation ``method``."""

    axes: list[list[Number]] | None = Field(
        None, description="Grid of each argument, strictly increasing (from the file when omitted)."
    )
    values: list[Any] | None = Field(
        None, description="Values on the grid, nested one list per axis, first axis outermost."
    )
    file: str | None = Field(
        None,
        description="CSV or NPZ file in the problem file's folder. CSV: two columns (x, value) for "
        "one axis; for two, a first row of the second axis' values and a first column of the first's "
        "(its top-left cell ignored). NPZ: arrays values, axis0, axis1, ...",
    )
    _tables: dict[str, Table] = PrivateAttr(default_factory=dict)
    method: Method = Field(
        "linear",
        description="linear (multilinear, extended linearly beyond the grid), bspline (cubic "
        "not-a-knot spline, arguments clamped to the grid) or akima (Akima's piecewise cubic as "
        "SciPy's Akima1DInterpolator, one axis only, arguments clamped to the grid).",
    )

    @model_validator(mode="before")
    @classmethod
    def _read_file(cls, data: Any, info: ValidationInfo) -> Any:
        if not isinstance(data, dict) or data.get("file") is None or data.get("values") is not None:
            return data
        if data.get("axes") is not None:
            raise ValueError("a table from a file takes its axes from the file: give file or axes, not both")
        folder = (info.context or {}).get(FOLDER) or "."
        axes, values = read_table_file(str(data["file"]), Path(folder))
        return {**data, "axes": [a.tolist() for a in axes], "values": values.tolist()}

    @model_validator(mode="after")
    def _consistent(self) -> TableSpec:
        self.table("table")
        return self

    def table(self, name: str) -> Table:
        """The table as the function ``name`` of the language; a ValueError saying what is wrong
        with the data."""
        if self.axes is None or self.values is None:
            raise ValueError("a table needs axes and values, or a file")
        return checked_table(name, self.axes, self.values, self.method)

    def named(self, name: str) -> Table:
        """:meth:`table`, built once per name (so one CasADi interpolant serves every use)."""
        if name not in self._tables:
            self._tables[name] = self.table(name)
        return self._tables[name]


def checked_table(name: str, axes: list[list[float]], values: Any, method: Method) -> Table:
    """A :class:`Table` from raw lists, refused (ValueError) unless the axes are strictly increasing
    with enough points for ``method``, the values finite and of the grid's shape, all within the
    limits."""
    import numpy as np

    if not 1 <= len(axes) <= MAX_TABLE_AXES:
        raise ValueError(f"a table needs 1 to {MAX_TABLE_AXES} axes, got {len(axes)}")
    if method == "akima" and len(axes) > 1:
        raise ValueError(
            f"akima takes a table of one axis, this one has {len(axes)}: Akima's slopes depend on the "
            "data nonlinearly, so there is no tensor-product Akima spline (use bspline or linear)"
        )
    shape = tuple(len(a) for a in axes)
    if math.prod(shape) > MAX_TABLE_VALUES:
        raise ValueError(f"a table holds at most {MAX_TABLE_VALUES} values, this grid {math.prod(shape)}")
    grids = tuple(np.asarray(a, dtype=float) for a in axes)
    for i, grid in enumerate(grids):
        if grid.size < MIN_POINTS[method]:
            raise ValueError(f"axis {i} has {grid.size} points; {method} needs at least {MIN_POINTS[method]}")
        if not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0):
            raise ValueError(f"axis {i} must be finite and strictly increasing")
    try:
        data = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"values must be numbers nested as the grid {list(shape)}") from None
    if data.shape != shape:
        raise ValueError(f"values have shape {list(data.shape)}, the axes {list(shape)}")
    if not np.all(np.isfinite(data)):
        raise ValueError("values must be finite")
    for array in (*grids, data):
        array.flags.writeable = False
    return Table(name, grids, data, method)


def read_table_file(file: str, folder: Path) -> tuple[list[np.ndarray], np.ndarray]:
    """The axes and values of a CSV or NPZ table ``file`` inside ``folder``; a ValueError naming what
    is wrong (a path leaving the folder, a missing or oversized file, malformed data)."""
    base = folder.resolve()
    try:
        path = (base / file).resolve()
        if Path(file).is_absolute() or not path.is_relative_to(base):
            raise ValueError(f"table file {file!r} must lie inside the problem file's folder")
        if not path.is_file():
            raise ValueError(f"table file {file!r} not found next to the problem file")
        size = path.stat().st_size
    except OSError as err:
        raise ValueError(f"table file {file[:60]!r}: {err.strerror or err}") from None
    if size > MAX_FILE_BYTES:
        raise ValueError(f"table file {file!r} is larger than {MAX_FILE_BYTES} bytes")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return _read_csv(path.read_bytes(), file)
    if suffix == ".npz":
        return _read_npz(path, file)
    raise ValueError(f"table file {file!r}: give a .csv or .npz file")


def _read_csv(raw: bytes, file: str) -> tuple[list[np.ndarray], np.ndarray]:

    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"table file {file!r} is not UTF-8 text") from None
    rows = [r for r in csv.reader(io.StringIO(text)) if r and not r[0].lstrip().startswith("#")]
    rows = [[cell.strip() for cell in r] for r in rows]
    if not rows:
        raise ValueError(f"table file {file!r} holds no rows")
    width = len(rows[0])
    if any(len(r) != width for r in rows):
        raise ValueError(f"table file {file!r}: every row needs {width} cells")
    if width == 2:
        if not _numeric(rows[0]):
            rows = rows[1:]
        grid = _floats(rows, file)
        return [grid[:, 0]], grid[:, 1]
    if width < 3:
        raise ValueError(f"table file {file!r}: two columns (x, value) or a grid with a header row")
    body = _floats([r[1:] for r in rows[1:]], file)
    first = _floats([[r[0]] for r in rows[1:]], file)[:, 0]
    second = _floats([rows[0][1:]], file)[0]
    return [first, second], body


def _numeric(cells: list[str]) -> bool:
    try:
        [float(c) for c in cells]
    except ValueError:
        return False
    return True


def _floats(rows: list[list[str]], file: str) -> np.ndarray:
    import numpy as np

    try:
        return np.array([[float(c) for c in r] for r in rows], dtype=float)
    except ValueError as err:
        raise ValueError(f"table file {file!r}: {err}") from None


def _read_npz(path: Path, file: str) -> tuple[list[np.ndarray], np.ndarray]:
    import numpy as np

    from gamespec.npyfile import UnreadableArrays, read_npz

    try:
        with path.open("rb") as handle:
            arrays = read_npz(handle)
    except UnreadableArrays as err:
        raise ValueError(f"table file {file!r}: {err}") from None
    if "values" not in arrays:
        raise ValueError(f"table file {file!r} has no array 'values'")
    values = np.asarray(arrays["values"], dtype=float)
    names = [f"axis{i}" for i in range(values.ndim)]
    missing = [n for n in names if n not in arrays]
    extra = sorted(set(arrays) - {"values", *names})
    if missing or extra:
        raise ValueError(f"table file {file!r} needs arrays values and {', '.join(names)} only")
    return [np.asarray(arrays[n], dtype=float).ravel() for n in names], values
