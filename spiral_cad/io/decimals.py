"""Numbers as text in the files we write ourselves (STEP, SVG, OpenDRIVE)."""

from __future__ import annotations

import math


def shortest_decimal(value: float, file_format: str) -> str:
    """The shortest decimal that reads back to the same double (≤ 17 significant digits).

    Raises:
        ValueError: a non-finite value, which none of these formats can hold.
    """
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{file_format} cannot hold the non-finite number {value}")
    return repr(value + 0.0)  # + 0.0 turns -0.0 into 0.0
