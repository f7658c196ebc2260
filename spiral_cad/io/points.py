"""Point lists in: CSV or whitespace-separated text (.csv, .txt, .xyz) with columns x, y[, z].

The format, as surveys, GPS exports and digitisers write it:

- one point per line, the numbers separated by commas, semicolons or
  whitespace (the first data line decides which);
- an optional header line naming the columns in any order: ``x``/``easting``/
  ``east``/``e``, ``y``/``northing``/``north``/``n``, ``z``/``elevation``/
  ``elev``/``height``/``h``; a name may carry its unit in brackets
  (``x [m]``, as the CSV files of this package write it). Without a header the
  columns are x, y[, z]. The other columns of this package's samples files
  (``s``, ``tx``, ``ty``, ``tz``, ``curvature``) are read and set aside, so a
  samples file reads back as its points;
- ``#`` starts a comment; a comment line ``# units: m`` states the unit of
  the numbers (as does a unit in the header). A file that states none is in
  the unit the caller gives.

Any text is either a table of finite points or a ``ValueError`` naming the
file, the line and the value. Valid files are parsed by numpy in one pass (a
million rows in about a second); only a file with a problem is scanned line
by line, to name the first problem.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..core.units import MM_PER_UNIT, UNITS, length_unit
from .samples import COLUMNS as SAMPLE_COLUMNS

__all__ = ["COLUMN_NAMES", "MAX_POINTS_BYTES", "PointTable", "parse_points", "read_points"]

#: The header names of each column (compared without case).
COLUMN_NAMES = {
    "x": ("x", "easting", "east", "e"),
    "y": ("y", "northing", "north", "n"),
    "z": ("z", "elevation", "elev", "height", "h"),
}
#: Point files larger than this are refused before they are read (about 20 million points).
MAX_POINTS_BYTES = 1_000_000_000

_COLUMN_OF = {name: column for column, names in COLUMN_NAMES.items() for name in names}
#: The other columns of a samples file (``export_samples``: station, tangent, curvature), read and set aside,
#: each with its dimension (``L``: the file's length unit).
_SET_ASIDE = {name: dimension for name, dimension in SAMPLE_COLUMNS if name not in _COLUMN_OF}
_UNITS_LINE = re.compile(r"#\s*units?\s*[:=]\s*(\S+)\s*$", re.IGNORECASE)
_HEADER_NAME = re.compile(r"(?P<name>[^\[\]()]*?)\s*(?:[\[(]\s*(?P<unit>[^\]\)]*?)\s*[\])])?")


@dataclass(frozen=True)
class PointTable:
    """The points of a file: ``points`` (N, 2) or (N, 3) in ``units``, in file order.

    ``lines[i]`` is the line number (from 1) of point ``i`` in ``source``, so
    a later error about a point can name its line.
    """

    points: NDArray[np.float64]
    units: str
    source: str
    lines: NDArray[np.int64]

    @property
    def dim(self) -> int:
        """2 for x, y; 3 with z."""
        return int(self.points.shape[1])

    @property
    def xy(self) -> NDArray[np.float64]:
        """The plan coordinates (N, 2)."""
        return self.points[:, :2]

    @property
    def z(self) -> NDArray[np.float64] | None:
        """The elevations (N,), or None without a z column."""
        return self.points[:, 2] if self.dim == 3 else None

    def __len__(self) -> int:
        return len(self.points)

    def in_units(self, units: str) -> PointTable:
        """The same points in ``units`` (a copy scaled by the ratio of the units, or self)."""
        units = length_unit(units)
        if units == self.units:
            return self
        scale = MM_PER_UNIT[self.units] / MM_PER_UNIT[units]
        return PointTable(self.points * scale, units, self.source, self.lines)


def read_points(path: str | os.PathLike, units: str = "mm") -> PointTable:
    """Read the point file ``path`` (see the module docstring).

    Args:
        path: a .csv, .txt or .xyz file (the content decides the separator).
        units: the unit of the numbers when the file states none (a ``# units:``
            line or units in the header); a file that states one keeps its own.

    Returns:
        The points in the unit the file states, else ``units``; convert with
        ``PointTable.in_units``.

    Raises:
        ValueError: the file cannot be read, is not UTF-8 text, holds no point,
            or the first malformed line, named with its number and value.
    """
    label = Path(path).name or str(path)
    try:
        size = os.stat(path).st_size
        if Path(path).is_dir():
            raise ValueError(f"cannot read points file {label}: it is a folder")
        if size > MAX_POINTS_BYTES:
            raise ValueError(f"points file {label} has {size:,} bytes; at most {MAX_POINTS_BYTES:,} are read")
        raw = Path(path).read_bytes()
    except OSError as e:
        raise ValueError(f"cannot read points file {label}: {e.strerror}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ValueError(f"{label}: not UTF-8 text (byte {e.start}: 0x{raw[e.start]:02x})") from None
    return parse_points(text, units, source=label)


def parse_points(text: str, units: str = "mm", source: str = "points") -> PointTable:
    """The points of ``text``, the content of a point file (see ``read_points``); ``source`` names it in errors."""
    units = length_unit(units)
    text = text.removeprefix("\ufeff")  # a byte order mark, as spreadsheets write it
    stated: tuple[str, int] | None = None
    if "#" not in text:  # no comment anywhere: the lines as they are (most of a large file's time)
        stripped = [line.strip() for line in text.splitlines()]
        numbers = [number for number, line in enumerate(stripped, 1) if line]
        data = [line for line in stripped if line]
    else:
        data, numbers, stated = _without_comments(text, source)
    if not data:
        raise ValueError(f"{source}: no points (every line is empty or a comment)")
    separator = ";" if ";" in data[0] else "," if "," in data[0] else None
    order, header_unit = _header(data[0], separator, numbers[0], source)
    if order is not None:
        if header_unit is not None:
            stated = _state_unit(stated, header_unit, numbers[0], source)
        if len(data) == 1:
            raise ValueError(f"{source}: no points after the header (line {numbers[0]})")
        data, numbers = data[1:], numbers[1:]

    width = len(order) if order is not None else len(_split(data[0], separator))
    if order is None:
        if width not in (2, 3):
            raise ValueError(f"{source}: line {numbers[0]}: {width} column{'s' * (width != 1)}; expected x, y or x, y, z "
                             "(or a header naming the columns)")  # fmt: skip
        order = ("x", "y", "z")[:width]
    try:
        # the fast path: numpy parses every line in one call (and checks the column count)
        table = np.loadtxt(data, delimiter=separator, dtype=np.float64, ndmin=2, comments=None)
    except ValueError:
        _first_problem(data, numbers, separator, width, order, source)
        raise  # _first_problem always raises; numpy and it disagree only on a bug
    if table.shape[1] != width:
        _first_problem(data, numbers, separator, width, order, source)
    finite = np.isfinite(table)
    if not finite.all():
        row, column = np.argwhere(~finite)[0]
        raise ValueError(f"{source}: line {numbers[row]}: {order[column]} is {_cell(data[row], separator, column)!r}; "
                         "every coordinate must be a finite number")  # fmt: skip
    points = table[:, [order.index(c) for c in ("x", "y", "z") if c in order]]
    return PointTable(np.ascontiguousarray(points), stated[0] if stated else units, source, np.asarray(numbers, dtype=np.int64))


def _without_comments(text: str, source: str) -> tuple[list[str], list[int], tuple[str, int] | None]:
    """The data lines of ``text`` without comments, their numbers, and the unit a ``# units:`` line states."""
    stated: tuple[str, int] | None = None
    data: list[str] = []
    numbers: list[int] = []
    for number, line in enumerate(text.splitlines(), 1):
        if "#" in line:
            found = _UNITS_LINE.match(line[line.index("#") :].strip())
            if found:
                stated = _state_unit(stated, found.group(1), number, source)
            line = line[: line.index("#")]
        line = line.strip()
        if line:
            data.append(line)
            numbers.append(number)
    return data, numbers, stated


def _state_unit(stated: tuple[str, int] | None, given: str, number: int, source: str) -> tuple[str, int]:
    unit = given.strip().lower()
    if unit not in MM_PER_UNIT:
        raise ValueError(f"{source}: line {number}: unit {given!r} is not one of {', '.join(UNITS)}")
    if stated is not None and stated[0] != unit:
        raise ValueError(f"{source}: line {number}: unit {unit} differs from {stated[0]} stated on line {stated[1]}")
    return stated or (unit, number)


def _split(line: str, separator: str | None) -> list[str]:
    return [cell.strip() for cell in line.split(separator)]


def _cell(line: str, separator: str | None, column: int) -> str:
    cells = _split(line, separator)
    return cells[column] if column < len(cells) else ""


def _is_number(cell: str) -> bool:
    """A number as numpy reads it: Python's float() also takes '1_000' and non-ASCII digits, numpy does not."""
    if not cell.isascii() or "_" in cell:
        return False
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _header(line: str, separator: str | None, number: int, source: str) -> tuple[tuple[str, ...] | None, str | None]:
    """The column order and the unit a header states, or (None, None) when ``line`` is data (a number in it)."""
    cells = _split(line, separator)
    if any(_is_number(cell) for cell in cells):
        return None, None
    order, units = [], set()
    per_length = set()
    for cell in cells:
        match = _HEADER_NAME.fullmatch(cell)
        name = match.group("name").strip().lower() if match else cell.lower()
        unit = match.group("unit").strip() if match and match.group("unit") else None
        column = _COLUMN_OF.get(name, name if name in _SET_ASIDE else None)
        if column is None:
            known = "; ".join("/".join(names) for names in COLUMN_NAMES.values())
            raise ValueError(f"{source}: line {number}: column {cell!r} is not a coordinate ({known}) nor a column of a "
                             f"samples file ({', '.join(_SET_ASIDE)})")  # fmt: skip
        if column in order:
            raise ValueError(f"{source}: line {number}: column {cell!r} names {column} a second time")
        order.append(column)
        dimension = _SET_ASIDE.get(column, "L")
        if unit is None or dimension == "1":
            continue
        if dimension == "1/L":  # a curvature: its unit is one over the lengths'
            if not unit.startswith("1/"):
                raise ValueError(f"{source}: line {number}: column {cell!r} states {unit!r}, not one over a length")
            per_length.add(unit[2:].strip())
        else:
            units.add(unit)
    if "x" not in order or "y" not in order:
        raise ValueError(f"{source}: line {number}: the header {line!r} needs an x and a y column")
    if len(units | per_length) > 1:
        raise ValueError(f"{source}: line {number}: the header states several units ({', '.join(sorted(units | per_length))})")
    return tuple(order), units.pop() if units else None


def _first_problem(data: list[str], numbers: list[int], separator: str | None, width: int, order: tuple[str, ...], source: str) -> None:
    """Raise the ValueError of the first malformed line (numpy refused the table)."""
    for line, number in zip(data, numbers):
        cells = _split(line, separator)
        if len(cells) != width:
            raise ValueError(
                f"{source}: line {number}: {len(cells)} column{'s' * (len(cells) != 1)}, expected {width} ({', '.join(order)}): {line!r:.80}"
            )
        for column, cell in enumerate(cells):
            if not cell:
                raise ValueError(f"{source}: line {number}: {order[column]} is empty")
            if not _is_number(cell):
                raise ValueError(f"{source}: line {number}: {order[column]} is {cell!r:.40}, not a number")
            if not math.isfinite(float(cell)):
                raise ValueError(f"{source}: line {number}: {order[column]} is {cell!r}; every coordinate must be a finite number")
    raise ValueError(f"{source}: the points could not be read as a table of {width} columns")
