"""The straight end of a spiral next to a line made exactly straight, before a document is written.

A spiral leaving a line has zero curvature there: its first three control points lie on the line. At
large coordinates (a road 5 000 ft from its origin) the solvers' spirals keep a residue of about 1e-7
of their size off that line, a curvature of ~1e-9 where the line has 0: a curvature jump to a reader,
and an inflection that no LandXML ``Spiral`` holds. ``straight_ends`` moves the control point beside
the straight end onto the line through the end and its neighbour (the end, its tangent and the line are
kept; the far end's tangent and curvature move by that residue over the leg, ~1e-8).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..core.segments import Line, Segment
from ..core.spiral import BezierSpiral

__all__ = ["RESIDUE", "straight_ends"]

#: A control point is moved only this close to the line, as a share of the spiral's length (a residue, not a shape).
RESIDUE = 1e-5


def _onto(point: np.ndarray, origin: np.ndarray, along: np.ndarray) -> np.ndarray:
    unit = along / np.linalg.norm(along)
    return origin + unit * float((point - origin) @ unit)


def straight_ends(segments: Sequence[Segment]) -> tuple[list[Segment], int]:
    """The segments with every spiral's end next to a line made straight; and how many ends were moved."""
    out = list(segments)
    moved = 0
    for i, segment in enumerate(out):
        if not isinstance(segment, BezierSpiral):
            continue
        cp = np.array(segment.control_points, dtype=float)
        limit = RESIDUE * segment.length
        if i > 0 and isinstance(out[i - 1], Line):
            target = _onto(cp[2], cp[0], cp[1] - cp[0])
            if 0.0 < np.linalg.norm(target - cp[2]) <= limit:
                cp[2], moved = target, moved + 1
        if i + 1 < len(out) and isinstance(out[i + 1], Line):
            target = _onto(cp[1], cp[3], cp[3] - cp[2])
            if 0.0 < np.linalg.norm(target - cp[1]) <= limit:
                cp[1], moved = target, moved + 1
        if not np.array_equal(cp, segment.control_points):
            out[i] = BezierSpiral.from_control_points(cp, segment.shape)
    return out, moved
