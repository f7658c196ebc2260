"""A toolpath as read from a G-code program: its moves, their source lines, and arcs as chords.

Both G-code readers (``spiral_cad.io.gcode``'s own and LinuxCNC's ``rs274``, ``spiral_cad.io.rs274``)
produce a ``GcodePath``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from numpy.typing import NDArray

from ..core.units import MM_PER_UNIT, length_unit

__all__ = ["PLANES", "GcodePath", "arc_points", "in_program_unit"]

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
    """

    points: NDArray
    lines: NDArray
    rapid: NDArray
    units: str
    source: str = "G-code"
    notes: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.points)

    def in_units(self, units: str) -> GcodePath:
        """The same moves in ``units`` (mm, cm, m, km, in, ft): converted from the program's G20/G21."""
        factor = MM_PER_UNIT[self.units] / MM_PER_UNIT[length_unit(units)]
        return GcodePath(self.points * factor if factor != 1.0 else self.points, self.lines, self.rapid, units, self.source, self.notes)

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
    t0, t1 = math.atan2(b0 - cb, a0 - ca), math.atan2(b1 - cb, a1 - ca)
    sweep = t1 - t0
    if rotation > 0:
        sweep = (sweep if sweep > 0 else sweep + 2 * math.pi) + 2 * math.pi * (rotation - 1)
    else:
        sweep = (sweep if sweep < 0 else sweep - 2 * math.pi) - 2 * math.pi * (-rotation - 1)
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


def in_program_unit(length: float, units: str | None, program_units: str) -> float:
    """``length`` given in ``units`` (None: already the program's) in the program's unit (G20/G21)."""
    return length if units is None else length * MM_PER_UNIT[length_unit(units)] / MM_PER_UNIT[program_units]
