"""Tables of design results (stationing, criteria): text for the terminal, CSV with the unit in every header.

A column's dimension is a string in ``L`` (the design's length unit), e.g.
``"L"``, ``"1/L²"``; the header becomes ``name [m]`` or ``name [1/m²]``.
Columns without a dimension keep their name (angles say ``_deg`` in it).
"""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


def header(key: str, dimensions: Mapping[str, str], units: str) -> str:
    """``key [unit]`` for a column with a dimension, else ``key``."""
    dimension = dimensions.get(key)
    return f"{key} [{dimension.replace('L', units)}]" if dimension else key


def write_csv(path: str | Path, rows: Sequence[Mapping[str, Any]], dimensions: Mapping[str, str], units: str) -> Path:
    """Write ``rows`` as CSV: floats at full precision (``repr``), units in the headers."""
    path = Path(path)
    keys = list(rows[0]) if rows else list(dimensions)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow([header(k, dimensions, units) for k in keys])
        for row in rows:
            writer.writerow([repr(v) if isinstance(v, float) else v for v in (row[k] for k in keys)])
    return path


def text_table(rows: Sequence[Mapping[str, Any]], dimensions: Mapping[str, str], units: str, digits: int = 8) -> str:
    """``rows`` as right-aligned text columns with unit headers."""
    if not rows:
        return ""
    keys = list(rows[0])
    head = [header(k, dimensions, units) for k in keys]
    cells = [[f"{v:.{digits}g}" if isinstance(v, float) else str(v) for v in (row[k] for k in keys)] for row in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, widths))]
    lines += ["  ".join(c.rjust(w) for c, w in zip(row, widths)) for row in cells]
    return "\n".join(lines)
