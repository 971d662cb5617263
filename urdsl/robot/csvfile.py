"""Recording files: the CSV that ``urdsl record`` writes and ``urdsl plot`` reads.

The format is the one of UR's ``record.py`` (RTDE_Python_Client_Library ``csv_writer.py``),
so that files work with UR's ``csv_reader.py`` and every script written for it:

* one header line, then one line per sample, fields separated by one space;
* a scalar field is one column named after the field; a vector field is expanded into
  ``name_0 … name_5`` (``_0 … _2`` for 3-vectors), e.g. ``actual_q_0 … actual_q_5``;
* ``timestamp`` (s since the controller started) is the first column.

One difference, on purpose: booleans are written as ``1``/``0`` (record.py writes
``True``/``False``, which UR's own reader cannot turn into the float it makes of every
column). Floats are written in their shortest exact form (``repr``), so a file read back
gives the very numbers received.

Writing is crash-safe at the granularity of a row: each row is one ``write`` of a complete
line, and the file is flushed at least every :data:`FLUSH_INTERVAL` seconds, so a recording
stopped by Ctrl-C, a dropped connection or a power cut keeps every flushed sample and never
ends in half a line.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import numpy as np

__all__ = [
    "VECTOR_SIZES", "expand_names", "CsvWriter", "Recording", "read_recording",
    "RecordingFormatError", "FLUSH_INTERVAL",
]

VECTOR_SIZES = {"VECTOR6D": 6, "VECTOR3D": 3, "VECTOR6INT32": 6, "VECTOR6UINT32": 6}
"""RTDE vector types and their lengths (docs/controller-facts.md §6); every other type is a
scalar."""

FLUSH_INTERVAL = 0.5
"""Seconds between flushes of a recording: at most this much is lost if the machine dies.
(Ctrl-C and dropped connections lose nothing: the file is flushed and closed then.)"""


class RecordingFormatError(ValueError):
    """A recording file that cannot be read: the message names ``file:line``."""


def expand_names(names: Sequence[str], types: Sequence[str]) -> list[str]:
    """Column names for RTDE fields: ``actual_q`` (VECTOR6D) → ``actual_q_0 … actual_q_5``."""
    columns: list[str] = []
    for name, kind in zip(names, types, strict=True):
        size = VECTOR_SIZES.get(kind.upper())
        if size is None:
            columns.append(name)
        else:
            columns.extend(f"{name}_{i}" for i in range(size))
    return columns


def _cell(value: object) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if value != value else
                                                         ("inf" if value > 0 else "-inf"))
    return str(value)


class CsvWriter:
    """Writes samples to a recording file (see the module docstring).

    ``names`` and ``types`` are the RTDE fields in the order of the values given to
    :meth:`write`; ``timestamp`` should be first (the recorder puts it there). The file is
    created (or truncated) at once, with its header.
    """

    def __init__(self, path: str | Path, names: Sequence[str], types: Sequence[str], *,
                 delimiter: str = " ", flush_interval: float = FLUSH_INTERVAL) -> None:
        self.path = Path(path)
        self.names = list(names)
        self.types = [t.upper() for t in types]
        self.columns = expand_names(self.names, self.types)
        self.delimiter = delimiter
        self.flush_interval = flush_interval
        self.rows = 0
        self._sizes = [VECTOR_SIZES.get(t) for t in self.types]
        self._file: IO[str] | None = open(self.path, "w", encoding="ascii", newline="")
        self._file.write(delimiter.join(self.columns) + "\n")
        self._file.flush()
        self._last_flush = time.monotonic()

    def write(self, values: Sequence[object]) -> None:
        """One sample: a value per field (a sequence for a vector field)."""
        if self._file is None:
            raise ValueError(f"{self.path} is closed")
        cells: list[str] = []
        for name, size, value in zip(self.names, self._sizes, values, strict=True):
            if size is None:
                cells.append(_cell(value))
            else:
                items = list(value)  # type: ignore[call-overload]
                if len(items) != size:
                    raise ValueError(f"{name}: expected {size} values, got {len(items)}")
                cells.extend(_cell(v) for v in items)
        self._file.write(self.delimiter.join(cells) + "\n")  # one write: never half a row
        self.rows += 1
        now = time.monotonic()
        if now - self._last_flush >= self.flush_interval:
            self._file.flush()
            self._last_flush = now

    def flush(self) -> None:
        if self._file is not None:
            self._file.flush()

    def close(self) -> None:
        if self._file is not None:
            self._file.flush()
            self._file.close()
            self._file = None

    def __enter__(self) -> CsvWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass
class Recording:
    """A recording read back: ``columns`` maps each column name to a float array."""

    path: str
    header: list[str]
    columns: dict[str, np.ndarray] = field(repr=False)

    @property
    def rows(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def fields(self) -> list[str]:
        """Field names in file order, vectors once (``actual_q`` for ``actual_q_0..5``)."""
        seen: list[str] = []
        for column in self.header:
            name = _field_of(column, self.header)
            if name not in seen:
                seen.append(name)
        return seen

    def field(self, name: str) -> np.ndarray:
        """A field's values: shape (N,) for a scalar column, (N, k) for a vector field given
        by its name (``actual_q`` → the columns ``actual_q_0 … actual_q_5``). Raises
        ``KeyError`` naming the fields that exist."""
        if name in self.columns:
            return self.columns[name]
        parts = [c for c in self.header if _field_of(c, self.header) == name]
        if not parts:
            raise KeyError(f"{self.path} has no field {name!r}; it has: "
                           f"{', '.join(self.fields())}")
        return np.column_stack([self.columns[c] for c in parts])


def _field_of(column: str, header: Sequence[str]) -> str:
    """``actual_q_3`` → ``actual_q`` when ``actual_q_0`` is in the header too."""
    base, _, index = column.rpartition("_")
    if base and index.isdigit() and f"{base}_0" in header:
        return base
    return column


def read_recording(path: str | Path) -> Recording:
    """Read a file written by ``urdsl record`` or UR's ``record.py`` (space-separated), or
    the same table with commas. Blank lines are skipped; a row with the wrong number of
    cells or a cell that is not a number raises :class:`RecordingFormatError` with
    ``file:line``."""
    path = Path(path)
    name = str(path)
    with open(path, encoding="utf-8", errors="replace") as handle:
        lines = handle.read().splitlines()
    numbered = [(i + 1, line) for i, line in enumerate(lines) if line.strip()]
    if not numbered:
        raise RecordingFormatError(f"{name}: the file is empty (no header line)")
    header_line, header_text = numbered[0]
    delimiter = "," if "," in header_text else None
    header = [h.strip() for h in header_text.split(delimiter)]
    if len(set(header)) != len(header) or not all(header):
        raise RecordingFormatError(f"{name}:{header_line}: the header has empty or repeated "
                                   "column names")
    try:
        float(header[0])
        raise RecordingFormatError(f"{name}:{header_line}: the first line holds numbers, "
                                   "not column names (a binary or header-less file?)")
    except ValueError:
        pass
    data = np.empty((len(numbered) - 1, len(header)))
    for row, (number, text) in enumerate(numbered[1:]):
        cells = text.split(delimiter)
        if len(cells) != len(header):
            raise RecordingFormatError(f"{name}:{number}: {len(cells)} values, but the header "
                                       f"names {len(header)} columns")
        try:
            data[row] = [float(c) for c in cells]
        except ValueError:
            bad = next(c for c in cells if not _is_number(c))
            raise RecordingFormatError(f"{name}:{number}: {bad!r} is not a number") from None
    columns = {h: data[:, i] for i, h in enumerate(header)}
    return Recording(name, header, columns)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
