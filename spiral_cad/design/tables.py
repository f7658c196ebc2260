"""Tables of design results (stationing, criteria): text for the terminal, CSV with the unit in every header.

A column's dimension is a string in ``L`` (the design's length unit), e.g.
``"L"``, ``"1/L²"``, ``"deg"``; the header becomes ``name [m]``,
``name [1/m²]`` or ``name [deg]``. Only ``TEXT_COLUMNS`` have none: ``pi``
and ``pvi`` (indices), ``kind`` (crest or sag), ``spiral_shape`` and ``verdict`` (text). Every other cell is a plain
decimal that ``float()`` reads: numbers of any type (numpy scalars too)
are written as Python floats, at full precision in CSV.
"""

from __future__ import annotations

import csv
import numbers
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

#: The columns without a unit: indices and texts.
TEXT_COLUMNS = ("pi", "pvi", "kind", "spiral_shape", "verdict")


def header(key: str, dimensions: Mapping[str, str], units: str) -> str:
    """``key [unit]`` for a column with a dimension, else ``key``."""
    dimension = dimensions.get(key)
    return f"{key} [{dimension.replace('L', units)}]" if dimension else key


def cell(value: Any, digits: int | None = None) -> str:
    """A table cell: integers as integers, other real numbers as Python floats (``repr``, or
    ``digits`` significant digits), anything else as its text."""
    kind = type(value)
    if kind is float or kind is int:  # the common cells, without the abstract type checks below
        return str(value) if kind is int else repr(value) if digits is None else f"{value:.{digits}g}"
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return repr(float(value)) if digits is None else f"{float(value):.{digits}g}"
    return str(value)


def write_csv(path: str | Path, rows: Sequence[Mapping[str, Any]], dimensions: Mapping[str, str], units: str) -> Path:
    """Write ``rows`` as CSV: numbers at full precision (``repr`` of a Python float), units in the headers."""
    path = Path(path)
    keys = list(rows[0]) if rows else list(dimensions)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow([header(k, dimensions, units) for k in keys])
        for row in rows:
            writer.writerow([cell(row[k]) for k in keys])
    return path


def text_table(rows: Sequence[Mapping[str, Any]], dimensions: Mapping[str, str], units: str, digits: int = 8) -> str:
    """``rows`` as right-aligned text columns with unit headers."""
    if not rows:
        return ""
    keys = list(rows[0])
    head = [header(k, dimensions, units) for k in keys]
    cells = [[cell(row[k], digits) for k in keys] for row in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, widths))]
    lines += ["  ".join(c.rjust(w) for c, w in zip(row, widths)) for row in cells]
    return "\n".join(lines)


def fixed_columns(columns: Sequence[tuple[str, str]], rows: Iterable[Sequence[Any]], rule: bool = True) -> list[str]:
    """Lines of a fixed-width text table: a header, a rule of dashes under it, one line per row.

    Args:
        columns: (title, format spec) per column, e.g. ``("θ°", "9.4f")``, ``("case", "30")``;
            a title is aligned as its values are (text left, numbers right) and as wide.
            A column whose spec is ``""`` (the last, free text) has no width.
        rows: the values, one sequence per row.
        rule: a line of dashes under the header.
    """
    widths = [re.sub(r"^[<>^]?(\d*).*$", r"\1", spec) for _, spec in columns]
    numeric = [spec[-1:] in ("f", "e", "g", "d", "%") for _, spec in columns]
    head = " ".join(f"{title:{'>' if number else '<'}{width}}" for (title, _), width, number in zip(columns, widths, numeric))
    lines = [head.rstrip()] + (["-" * len(head.rstrip())] if rule else [])
    lines += [" ".join(format(value, spec) for value, (_, spec) in zip(row, columns)) for row in rows]
    return lines
