"""Assembling design chains from solved transitions."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..chain import JOIN_TOLERANCE, Chain
from ..segments import Line, Segment
from ..transitions import Transition


def chain_through(start: NDArray, parts: list[Transition | Segment], end: NDArray, tolerance: float = JOIN_TOLERANCE) -> Chain:
    """``Chain.join`` from ``start`` to ``end``, leaving out lead/tail lines of (near) zero length.

    A transition may begin exactly at the start point (e.g. a corner that uses
    its whole first leg); a zero-length ``Line`` would be malformed there.
    """
    if not parts:
        return Chain([Line(start, end)], tolerance)
    size = float(np.hypot(*(end - start))) + sum(p.length for p in parts)
    lead = [Line(start, parts[0].start)] if np.hypot(*(parts[0].start - start)) > 1e-12 * size else []
    tail = [Line(parts[-1].end, end)] if np.hypot(*(end - parts[-1].end)) > 1e-12 * size else []
    return Chain.join(lead + parts + tail, tolerance=tolerance)
