"""A G-code program's moves, read in exact mode, as chain segments: a line, an arc, or a ``G5`` cubic cut into
spiral pieces (``bezier.monotone_pieces``; the cubics that are one piece as they are found all at once first).
Shared by the exact chain reader (``gcode.parse_gcode_chain``) and the cutting paths (``gcode_paths``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core import bezier
from ..core.segments import Arc, Line
from ..core.spiral import BezierSpiral
from .toolpath import PLANES, arc_sweep

__all__ = ["piece_segments", "plain_cubics"]


def plain_cubics(pieces: list[Any], factor: float) -> set[int]:
    """The places in ``pieces`` of the G5 cubics that are one spiral piece as they are (``bezier.plain_spirals``,
    all at once): the others are cut by ``bezier.monotone_pieces``, one by one."""
    at = [k for k, piece in enumerate(pieces) if piece[0] == "cubic"]
    if not at:
        return set()
    cubics = np.array([np.asarray(pieces[k][4], dtype=float)[:, :2] * factor for k in at])
    return {at[i] for i in np.flatnonzero(bezier.plain_spirals(cubics)).tolist()}


def piece_segments(kind: str, start: list[float], data: list[Any], factor: float, dim: int, plain: bool = False) -> Any:
    """The chain segments of one move read in exact mode (None for a move that goes nowhere); a ``plain`` cubic
    is one spiral piece (``plain_cubics``)."""
    begin = np.array(start) * factor
    if kind == "line":
        end = np.array(data[0]) * factor
        return None if np.array_equal(begin, end) else [Line(begin[:dim], end[:dim])]
    if kind == "arc":
        end, plane, ca, cb, rotation = data
        a, b, normal = PLANES[plane]
        if end[normal] != start[normal] or abs(rotation) != 1:
            raise ValueError("a helical or multi-turn arc is not one arc of a chain")
        t0, sweep = arc_sweep(start, end, plane, ca, cb, rotation)
        radius = math.hypot(start[a] - ca, start[b] - cb) * factor
        if dim == 2:
            return [Arc((ca * factor, cb * factor), math.copysign(radius, sweep), t0, abs(sweep))]
        centre = begin.copy()
        centre[a], centre[b] = ca * factor, cb * factor
        axis = np.zeros(3)
        axis[normal] = 1.0
        return [Arc.in_space(centre, axis, begin, sweep)]
    cp = np.asarray(data[0]) * factor
    cubic = cp[:, :2]
    if not np.any(np.diff(cubic, axis=0)):
        return None
    pieces = []
    for u0, u1 in [(0.0, 1.0)] if plain else bezier.monotone_pieces(cubic):
        piece = cp.copy() if (u0, u1) == (0.0, 1.0) else np.column_stack([bezier.split(cubic, u0, u1), cp[:, 2]])
        pieces.append(BezierSpiral.from_control_points(piece[:, :dim]))
    return pieces
