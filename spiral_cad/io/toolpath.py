"""A toolpath as read from a G-code program: its moves, their source lines, and arcs as chords.

Both G-code readers (``spiral_cad.io.gcode``'s own and LinuxCNC's ``rs274``, ``spiral_cad.io.rs274``)
produce a ``GcodePath``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..core import bezier
from ..core.units import MM_PER_UNIT, length_unit

__all__ = ["PLANES", "GcodePath", "arc_points", "arc_sweep", "in_program_unit", "spline_points"]

#: The most chords of one G5 spline (a tolerance far below the spline's size is an error, not a full disk).
MAX_SPLINE_CHORDS = 1 << 16

#: The arc planes by LinuxCNC's ARC_FEED codes: (first, second, normal axis).
PLANES = {170: (0, 1, 2), 180: (2, 0, 1), 190: (1, 2, 0)}


@dataclass(frozen=True)
class GcodePath:
    """The straight moves of a G-code program.

    Attributes:
        points: (n, 3) where each move ends, in the program's unit.
        lines: (n,) the line (1-based) of each move.
        rapid: (n,) True where the move was a rapid (G0).
        units: ``"mm"`` (G21) or ``"in"`` (G20).
        source: the file's name, for messages.
        notes: what was read but does not move the tool and is worth telling (tool changes).
        feeds: the distinct feed rates (F, program unit per minute under G94) of the feed moves, in
            the order first used (empty when not read: LinuxCNC's rs274 reader).
        point_feeds: (n,) the feed in force on the move to each point (NaN for a rapid, a move with
            no F or not under G94); None when not read.
    """

    points: NDArray
    lines: NDArray
    rapid: NDArray
    units: str
    source: str = "G-code"
    notes: tuple[str, ...] = ()
    feeds: tuple[float, ...] = ()
    point_feeds: NDArray | None = None

    def __len__(self) -> int:
        return len(self.points)

    def in_units(self, units: str) -> GcodePath:
        """The same moves in ``units`` (mm, cm, m, km, in, ft): converted from the program's G20/G21 (feeds too)."""
        factor = MM_PER_UNIT[self.units] / MM_PER_UNIT[length_unit(units)]
        if factor == 1.0:
            return GcodePath(self.points, self.lines, self.rapid, units, self.source, self.notes, self.feeds, self.point_feeds)
        point_feeds = None if self.point_feeds is None else self.point_feeds * factor
        return GcodePath(self.points * factor, self.lines, self.rapid, units, self.source, self.notes,
                         tuple(f * factor for f in self.feeds), point_feeds)  # fmt: skip

    def at_lines(self, message: str) -> str:
        """``message`` with every ``point i``/``corner i`` followed by the G-code line of that move."""

        def line(match: re.Match) -> str:
            i = int(match.group(2))
            return f"{match.group(0)} (line {int(self.lines[i])})" if 0 <= i < len(self.lines) else match.group(0)

        return re.sub(r"\b(points?|corner) (\d+)\b", line, message)


def arc_points(
    start: list[float], end: list[float], plane: int, ca: float, cb: float, rotation: int, tolerance: float
) -> list[list[float]]:
    """The chords of an arc (helical along the plane's normal) from ``start`` to ``end`` about the centre
    (``ca``, ``cb``) in ``plane`` (170 XY, 180 ZX, 190 YZ): ends of chords at most ``tolerance`` from the arc.

    ``rotation`` is LinuxCNC's (ARC_FEED): positive counterclockwise, negative clockwise, and
    ``abs(rotation) - 1`` more full turns; the last point is ``end`` exactly.
    """
    first, second, normal = PLANES[plane]
    a0, b0, a1, b1 = start[first], start[second], end[first], end[second]
    t0, sweep = arc_sweep(start, end, plane, ca, cb, rotation)
    radius = (math.hypot(a0 - ca, b0 - cb) + math.hypot(a1 - ca, b1 - cb)) / 2
    # a chord of angle step is at most radius·(1 − cos(step/2)) from its arc
    step = 2 * math.acos(1 - tolerance / radius) if tolerance < radius else math.pi / 2
    count = max(2, math.ceil(abs(sweep) / min(step, math.pi / 2)))
    points = []
    for k in range(1, count):
        f = k / count
        t = t0 + sweep * f
        point = list(end)
        point[first] = ca + radius * math.cos(t)
        point[second] = cb + radius * math.sin(t)
        point[normal] = start[normal] + (end[normal] - start[normal]) * f
        points.append(point)
    points.append(list(end))
    return points


def arc_sweep(start: list[float], end: list[float], plane: int, ca: float, cb: float, rotation: int) -> tuple[float, float]:
    """(start angle, signed sweep) of LinuxCNC's arc from ``start`` to ``end`` about (``ca``, ``cb``) in ``plane``
    (``rotation`` as in ``arc_points``; the same end point is a full turn)."""
    first, second, _ = PLANES[plane]
    t0 = math.atan2(start[second] - cb, start[first] - ca)
    sweep = math.atan2(end[second] - cb, end[first] - ca) - t0
    if rotation > 0:
        sweep = (sweep if sweep > 0 else sweep + 2 * math.pi) + 2 * math.pi * (rotation - 1)
    else:
        sweep = (sweep if sweep < 0 else sweep - 2 * math.pi) - 2 * math.pi * (-rotation - 1)
    return t0, sweep


def spline_points(control_points: NDArray, tolerance: float) -> list[list[float]]:
    """Chord ends of a cubic (``control_points`` (4, 3), a G5 spline) at most ``tolerance`` from it: the
    parameter interval is cut into 2^k equal pieces until each piece's inner control points lie within
    ``tolerance`` of its chord (the curve lies in their hull, so within it too); the start is not included.

    Raises:
        ValueError: more than ``MAX_SPLINE_CHORDS`` chords would be needed.
    """
    count = 1
    while count <= MAX_SPLINE_CHORDS:
        pieces = np.array([bezier.split(control_points, k / count, (k + 1) / count) for k in range(count)])
        chord = pieces[:, 3] - pieces[:, 0]
        length2 = np.einsum("ij,ij->i", chord, chord)
        worst = 0.0
        for inner in (1, 2):
            offset = pieces[:, inner] - pieces[:, 0]
            t = np.clip(np.einsum("ij,ij->i", offset, chord) / np.where(length2 > 0.0, length2, 1.0), 0.0, 1.0)
            worst = float(np.maximum(worst, np.linalg.norm(offset - t[:, None] * chord, axis=1)).max())  # NaN stays NaN
        if not math.isfinite(worst):
            raise ValueError("a G5 spline too large for float64 arithmetic")
        if worst <= tolerance:
            return [list(map(float, p)) for p in pieces[:, 3]]
        count *= 2
    raise ValueError(f"a G5 spline needs more than {MAX_SPLINE_CHORDS:,} chords within {tolerance:g}")


def in_program_unit(length: float, units: str | None, program_units: str) -> float:
    """``length`` given in ``units`` (None: already the program's) in the program's unit (G20/G21)."""
    return length if units is None else length * MM_PER_UNIT[length_unit(units)] / MM_PER_UNIT[program_units]
