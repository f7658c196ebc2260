"""The kinds of segment a chain holds, numbered as its arrays, its compiled kernels and every file writer number them."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["ARC", "LINE", "SPIRAL", "SegmentKind"]

#: The kinds as plain integers, for compiled kernels and array comparisons (``rows.kind == SPIRAL``).
LINE, ARC, SPIRAL = 0, 1, 2


class SegmentKind(IntEnum):
    """A segment's kind: a ``Line``, an ``Arc`` or a ``BezierSpiral`` (equal to ``LINE``, ``ARC``, ``SPIRAL``)."""

    LINE = LINE
    ARC = ARC
    SPIRAL = SPIRAL
