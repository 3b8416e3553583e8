"""Reading ``.npz`` archives of untrusted origin (a saved Result's ``arrays.npz``), bounded before
anything is allocated (README, "Security" and "Limits"; :mod:`gamespec.limits`).

Only a plain zip is read: every member a ``NAME.npy`` of NumPy format 1, 2 or 3, stored or
deflated, not encrypted, named once. Each ``.npy`` header is parsed here by one regular expression
of what NumPy writes (``{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }``), never by an
evaluator, so a header holding code is refused as text; its dtype must be a boolean, integer,
float, complex or text type (never an object, a structure or anything pickled), and its shape
within :data:`~gamespec.limits.MAX_ARRAY_DIMENSIONS` and :data:`~gamespec.limits.MAX_ARRAY_VALUES`
(all members together within :data:`~gamespec.limits.MAX_RESULT_VALUES`). The member's declared
size must be exactly its header plus its data, and the central directory is sized from the zip's
end record before :class:`zipfile.ZipFile` reads it.
"""

from __future__ import annotations

import math
import re
import struct
import zipfile
import zlib
from typing import BinaryIO

import numpy as np

from gamespec import limits

MAGIC = b"\x93NUMPY"
MAX_HEADER_BYTES = 10_000
"""Longest ``.npy`` header read (NumPy's own default ``max_header_size``)."""

CHUNK_BYTES = 1 << 20
"""Bytes read from a member at a time."""

CENTRAL_ENTRY_BYTES = 1024
"""Most bytes per member the central directory may take (46 fixed, the name, extra fields)."""

_HEADER = re.compile(
    r"\{\s*'descr'\s*:\s*'(?P<descr>[<>|=]?[biufcU]\d{1,5})'\s*,"
    r"\s*'fortran_order'\s*:\s*(?P<fortran>True|False)\s*,"
    r"\s*'shape'\s*:\s*\((?P<shape>\s*(?:\d{1,19}\s*,\s*)*(?:\d{1,19}\s*)?)\)\s*,?\s*\}\s*",
    re.ASCII,
)
_ALLOWED_FLAGS = 0x0008 | 0x0800
"""Zip general-purpose flags a member may have: a data descriptor, UTF-8 names (no encryption)."""


class UnreadableArrays(ValueError):
    """An archive that is not read, and why (one line)."""


def read_npz(handle: BinaryIO) -> dict[str, np.ndarray]:
    """Every array of the archive open in ``handle`` by name (``NAME`` of ``NAME.npy``)."""
    _check_end_record(handle)
    try:
        archive = zipfile.ZipFile(handle)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, ValueError, EOFError) as err:
        raise UnreadableArrays(f"not a zip archive ({err})") from None
    with archive:
        members = archive.infolist()
        if len(members) > limits.MAX_RESULT_ARRAYS:
            raise UnreadableArrays(f"{len(members)} arrays, more than MAX_RESULT_ARRAYS")
        arrays: dict[str, np.ndarray] = {}
        total = 0
        for info in members:
            name = _member_name(info, arrays)
            try:
                with archive.open(info) as member:
                    array = _read_npy(member, info, total)
            except (
                zipfile.BadZipFile,
                zlib.error,
                OSError,
                EOFError,
                NotImplementedError,
                RuntimeError,
            ) as err:
                raise UnreadableArrays(f"{info.filename}: {err}") from None
            total += array.size
            arrays[name] = array
    return arrays


def _check_end_record(handle: BinaryIO) -> None:
    """Refuse an archive whose end record announces more members, or a larger central directory,
    than :data:`~gamespec.limits.MAX_RESULT_ARRAYS` allows, before the directory is read."""
    try:
        end = zipfile._EndRecData(handle)  # the record zipfile itself reads first
    except (OSError, struct.error) as err:
        raise UnreadableArrays(f"not a zip archive ({err})") from None
    if end is None:
        raise UnreadableArrays("not a zip archive (no end record)")
    entries, size = end[zipfile._ECD_ENTRIES_TOTAL], end[zipfile._ECD_SIZE]
    if entries > limits.MAX_RESULT_ARRAYS or size > limits.MAX_RESULT_ARRAYS * CENTRAL_ENTRY_BYTES:
        raise UnreadableArrays(f"{entries} arrays announced, more than MAX_RESULT_ARRAYS")
    handle.seek(0)


def _member_name(info: zipfile.ZipInfo, seen: dict[str, np.ndarray]) -> str:
    if info.flag_bits & ~_ALLOWED_FLAGS:
        raise UnreadableArrays(
            f"{info.filename}: an encrypted or unusual zip member (flags {info.flag_bits:#x})"
        )
    if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        raise UnreadableArrays(f"{info.filename}: compression {info.compress_type} (only stored or deflated)")
    if not info.filename.endswith(".npy") or len(info.filename) == 4:
        raise UnreadableArrays(f"{info.filename!r}: not a NAME.npy member")
    name = info.filename[:-4]
    if name in seen:
        raise UnreadableArrays(f"{info.filename}: named twice")
    return name


def _read_exactly(member: BinaryIO, count: int) -> bytes:
    data = member.read(count)
    if len(data) != count:
        raise UnreadableArrays("truncated")
    return data


def _read_npy(member: BinaryIO, info: zipfile.ZipInfo, before: int) -> np.ndarray:
    """One ``.npy`` member: header checked (module doc), then exactly its data, into a new array."""
    magic = _read_exactly(member, len(MAGIC) + 2)
    if magic[: len(MAGIC)] != MAGIC:
        raise UnreadableArrays(f"{info.filename}: not a .npy array")
    major = magic[len(MAGIC)]
    if major not in (1, 2, 3):
        raise UnreadableArrays(f"{info.filename}: .npy format {major} (1, 2 or 3 are read)")
    width = 2 if major == 1 else 4
    (length,) = struct.unpack("<H" if width == 2 else "<I", _read_exactly(member, width))
    if length > MAX_HEADER_BYTES:
        raise UnreadableArrays(f"{info.filename}: a header of {length} bytes")
    dtype, fortran, shape = parse_header(_read_exactly(member, length), info.filename)
    values = math.prod(shape)
    if math.prod(n for n in shape if n) > limits.MAX_ARRAY_VALUES:  # (0, 10**16, 10**16) too
        raise UnreadableArrays(f"{info.filename}: shape {shape}, more values than MAX_ARRAY_VALUES")
    if before + values > limits.MAX_RESULT_VALUES:
        raise UnreadableArrays(f"{info.filename}: more values in all arrays than MAX_RESULT_VALUES")
    nbytes = values * dtype.itemsize
    if info.file_size != len(magic) + width + length + nbytes:
        raise UnreadableArrays(f"{info.filename}: its size does not match its header (shape {shape})")
    buffer = bytearray(nbytes)
    view = memoryview(buffer)
    for start in range(0, nbytes, CHUNK_BYTES):
        chunk = _read_exactly(member, min(CHUNK_BYTES, nbytes - start))
        view[start : start + len(chunk)] = chunk
    member.read(1)  # the end of the member: zipfile checks its CRC there
    array = np.frombuffer(buffer, dtype=dtype, count=values)
    return array.reshape(shape, order="F" if fortran else "C")


def parse_header(text: bytes, filename: str = "array") -> tuple[np.dtype, bool, tuple[int, ...]]:
    """(dtype, Fortran order, shape) of a ``.npy`` header, or UnreadableArrays (module doc)."""
    match = _HEADER.fullmatch(text.decode("latin-1"))
    if match is None:
        raise UnreadableArrays(f"{filename}: a .npy header that is not a plain array's")
    try:
        dtype = np.dtype(match["descr"])
    except TypeError:
        raise UnreadableArrays(f"{filename}: dtype {match['descr']!r} is not one NumPy knows") from None
    if dtype.itemsize == 0 or dtype.kind not in "biufcU":
        raise UnreadableArrays(f"{filename}: dtype {match['descr']!r} holds no plain values")
    if dtype.kind == "U" and dtype.itemsize // 4 > limits.MAX_TEXT_CHARS:
        raise UnreadableArrays(f"{filename}: text items longer than MAX_TEXT_CHARS")
    shape = tuple(int(n) for n in match["shape"].replace(",", " ").split())
    if len(shape) == 1 and not match["shape"].rstrip().endswith(","):
        raise UnreadableArrays(f"{filename}: a .npy header whose shape is not a tuple")
    if len(shape) > limits.MAX_ARRAY_DIMENSIONS:
        raise UnreadableArrays(f"{filename}: {len(shape)} dimensions, more than MAX_ARRAY_DIMENSIONS")
    return dtype, match["fortran"] == "True", shape
