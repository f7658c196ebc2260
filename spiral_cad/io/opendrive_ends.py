"""A road's end on an arc kept where it was (``fixed_ends``: ``rewrite_opendrive_g2``'s helper).

``make_g2`` shrinks an arc about its centre by the shift its transition needs, so a road that starts (or
ends) on an arc would start ``p`` further in: its links and junction connections would break. The end
arc is instead turned into the arc through the road's own end point, along its own heading, whose radius
``r'`` is smaller by just enough that, where the old arc met its neighbour, it lies the same shift ``p``
inside: ``R − r' = p / (1 − cos φ)`` for an arc of sweep ``φ`` (the shrunk arc grows away from the end
point, by ``p`` at most across the old arc; an arc turning more than π, a loop ramp, takes φ = π, where
the two circles are furthest apart). The transition from it to the neighbour ``make_g2`` placed
(the next line, or the next arc as shifted) is then solved again by the exact solvers
(``spiral_cad.io.landxml_fit.solve_run``: ``line_to_circle``, ``circle_in_circle`` or the S of
``circle_to_circle``) and spliced in; smaller shifts are tried in turn when one has no solution or its
spirals run past the pieces on either side. The end's point and heading are exact; its curvature becomes
``1/r'``. The caller measures the result against the file.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..core.segments import Arc, Segment
from ..core.spiral import BezierSpiral
from .landxml_fit import Carrier, solve_run

__all__ = ["SHIFT_SHARES", "fixed_ends"]

#: The shares of make_g2's shift tried in turn for the end arc (the first whose transition fits).
SHIFT_SHARES = (1.0, 0.7, 0.5, 0.35, 0.25)
#: Arcs after the end arc whose curvature is within this share of its own are one arc with it (make_g2 merges them).
MERGED = 1e-6
#: The end arc's radius may shrink to this share of its own at most (its curvature then grows by a quarter).
SMALLEST_RADIUS = 0.8


def _carrier(segment: Segment) -> Carrier:
    """The line or circle a result's line or arc lies on, placed at its start."""
    (x, y, tx, ty, k), _ = segment.ends
    return Carrier(np.array([x, y]), math.atan2(ty, tx), float(k) if isinstance(segment, Arc) else 0.0, segment.length)


def _end_arc(old: Sequence[Segment]) -> tuple[Segment, float] | None:
    """The old line's first arc and the length of the run of arcs of its circle it starts (make_g2 merges them:
    files split one curve into many arcs), or None when it starts on something else."""
    first = old[0]
    if not isinstance(first, Arc):
        return None
    k0, length = first.ends[0][4], 0.0
    for segment in old:
        if not (isinstance(segment, Arc) and abs(segment.ends[0][4] - k0) <= MERGED * abs(k0)):
            break
        length += segment.length
    return first, length


def _fixed_start(old: Sequence[Segment], made: list[Segment], shape: str) -> list[Segment] | None:
    """``made`` with its first arc turned about the old start (see the module docstring), or None."""
    found = _end_arc(old)
    if found is None or not isinstance(made[0], Arc):
        return None
    first, length = found
    spirals = 1
    while spirals < len(made) and isinstance(made[spirals], BezierSpiral):
        spirals += 1
    if spirals == 1 or spirals == len(made) or spirals > 3:
        return None
    after = made[spirals]  # the neighbour make_g2 placed: a line, or an arc as shifted
    (x0, y0, tx0, ty0, k0), _ = first.ends
    radius, sweep = 1.0 / abs(k0), abs(k0) * length
    shift = radius - 1.0 / abs(made[0].ends[0][4])
    if not (shift > 0.0 and sweep > 0.0):
        return None
    spread = 1.0 - math.cos(min(sweep, math.pi))  # how far apart the two circles get along the old arc, per unit of R − r'
    exit_ = _carrier(after)
    for share in SHIFT_SHARES:
        smaller = radius - share * shift / spread
        if not smaller > SMALLEST_RADIUS * radius:
            continue
        entry = Carrier(np.array([x0, y0]), math.atan2(ty0, tx0), math.copysign(1.0 / smaller, k0), length)  # read around its middle
        curvatures = [entry.curvature, *([0.0] if spirals == 3 else []), exit_.curvature]
        try:
            _, solved = solve_run(entry, exit_, curvatures, shape)
        except ValueError:
            continue
        begin, end = entry.station(solved[0].start), exit_.station(solved[-1].end)
        if not (0.0 < begin and end < exit_.length):  # the neighbour may start earlier on its line or circle
            continue
        return [entry.piece(0.0, begin), *solved, exit_.piece(end, exit_.length), *made[spirals + 1 :]]
    return None


def _reversed(segments: Sequence[Segment]) -> list[Segment]:
    return [s.reversed() for s in reversed(segments)]


def fixed_ends(old: Sequence[Segment], made: Sequence[Segment], shape: str) -> tuple[list[Segment], list[str]]:
    """``made`` (make_g2's G2 line for the old one) with each end on an arc that moved turned back through the old end.

    Returns:
        The segments, and what was done at each end, in words (empty when nothing was).
    """
    out, done = list(made), []
    for which in ("start", "end"):
        flip = which == "end"
        first_old = _reversed(old) if flip else list(old)
        current = _reversed(out) if flip else out
        a, b = first_old[0].ends[0], current[0].ends[0]
        if math.hypot(b[0] - a[0], b[1] - a[1]) == 0.0:
            continue
        fixed = _fixed_start(first_old, current, shape)
        if fixed is None:
            continue
        out = _reversed(fixed) if flip else fixed
        k = abs(fixed[0].ends[0][4])
        done.append(f"its {which} arc turned about the {which} point (radius {1.0 / abs(first_old[0].ends[0][4]):.6g} → {1.0 / k:.6g} m)")
    return out, done
