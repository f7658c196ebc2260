"""A toolpath rounded G2: the corners of a G-code program's straight moves as spirals, with the G-code
line and feed of every segment (``round_toolpath``: a ``Chain``; ``round_toolpath_arrays``: arrays for
programs of millions of moves)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .progress import ticking
from .toolpath import GcodePath

if TYPE_CHECKING:
    from ..design.rounded_paths import RoundedPath

__all__ = ["OCCT_CONFUSION", "ToolpathCorners", "round_toolpath", "round_toolpath_arrays", "segment_feeds", "segment_lines"]

#: OCCT's Precision::Confusion (model units): two points closer than this are one point, so no edge is shorter.
OCCT_CONFUSION = 1e-7


def segment_lines(rounded: RoundedPath, path: GcodePath) -> NDArray:
    """The G-code line of every segment of ``rounded.chain`` (rounded from ``path``): a corner's
    spirals take the line of the move that ends at the corner, a straight piece the line of its move."""
    kind = np.asarray(rounded.chain.rows.kind)
    corner_of = np.cumsum(kind != 0) - 1  # the spiral's number along the chain
    index = np.array([c.index for c in rounded.corners], dtype=np.int64)
    lines = np.empty(len(kind), dtype=np.int64)
    spiral = kind != 0
    if spiral.sum() == 2 * len(index):  # two spirals a corner, in order
        lines[spiral] = path.lines[index[corner_of[spiral] // 2]]
        # a straight piece runs from the previous corner to the next point: the move that ends there
        after = np.searchsorted(np.flatnonzero(spiral), np.flatnonzero(~spiral))  # spirals before each straight piece
        ahead = after // 2  # the corner the straight piece leads to (len(index) past the last corner)
        ends = np.where(ahead < len(index), index[np.minimum(ahead, len(index) - 1)] if len(index) else 0, len(path) - 1)
        lines[~spiral] = path.lines[ends]
    else:  # another layout: the line of the nearest point to each segment's middle
        middles = np.asarray(rounded.chain.segment_ends).mean(axis=1)
        for i, middle in enumerate(middles):
            lines[i] = path.lines[int(np.argmin(np.linalg.norm(path.points - middle, axis=1)))]
    return lines


def segment_feeds(rounded: RoundedPath, path: GcodePath) -> NDArray | None:
    """The feed of every segment of ``rounded.chain`` (rounded from ``path``, its unit per minute): the F in force
    on the move of the segment's line (``segment_lines``); NaN where that move has none, None when ``path`` has no
    feeds (read by rs274)."""
    if path.point_feeds is None or not len(path.point_feeds):
        return None
    lines = segment_lines(rounded, path)
    at = np.clip(np.searchsorted(path.lines, lines, side="right") - 1, 0, len(path.lines) - 1)
    feeds: NDArray = path.point_feeds[at]
    return feeds


def round_toolpath(path: GcodePath, *, for_occt: bool = True, **options) -> RoundedPath:
    """The G2 rounding of a toolpath's polyline (``spiral_cad.design.round_corners`` with ``options``:
    ``max_deviation``, ``max_curvature``, ``shape``, …) in the program's unit; an error names the
    G-code line of the corner or point it is about. With ``for_occt`` (the default), a segment
    shorter than OCCT's point tolerance (1e-7 model units, so never a STEP edge) is refused here,
    naming the G-code line of its move (``segment_lines``), rather than later by OCCT by index only.

    Raises:
        ValueError, NoSolutionError: as ``round_corners``, with the line.
    """
    from ..design.rounded_paths import round_corners

    if "units" in options:
        raise ValueError("units: the program's own (G20/G21); convert the path with GcodePath.in_units first")
    try:
        with ticking(f"rounding {path.source} ({len(path):,} points)"):
            rounded = round_corners(path.points, units=path.units, **options)
    except ValueError as error:
        raise type(error)(f"{path.source}: {path.at_lines(str(error))}") from None
    lengths = np.asarray(rounded.chain.lengths)
    short: NDArray | tuple[int, ...] = np.flatnonzero(lengths <= OCCT_CONFUSION) if for_occt else ()
    if len(short):
        i = int(short[0])
        kind = ("Line", "Arc", "BezierSpiral")[int(np.asarray(rounded.chain.rows.kind)[i])]
        line = int(segment_lines(rounded, path)[i])
        raise ValueError(
            f"{path.source} line {line}: the rounded path's segment {i} ({kind}, length {lengths[i]:.3g} {path.units}) is shorter "
            f"than OCCT's {OCCT_CONFUSION:g} and cannot be an OCCT edge ({len(short)} such segment(s)); "
            "change the tolerance slightly, or move the corner's points"
        )
    return rounded


@dataclass(frozen=True)
class ToolpathCorners:
    """The G2 rounding of a toolpath as arrays, one row per rounded corner (no object per move).

    Between corners the path runs straight along the program's moves, so the corners and
    ``points`` are the whole path; ``round_toolpath`` builds the same spirals as a ``Chain``
    (for STEP, IGES, samples), at far higher cost in time and memory on long programs.

    Attributes:
        index: (k,) the point of ``path.points`` each corner is at.
        lines: (k,) the G-code line of each corner (the move that ends there).
        control_points: (k, 2, 4, 3) the corner's two Bézier spirals in travel order.
        curvature: (k,) the pair's peak |κ| (1/unit).
        deviation: (k,) the distance from the corner point to the path (unit).
        units: the program's unit.
        shape: the spiral shape.
    """

    index: NDArray
    lines: NDArray
    control_points: NDArray
    curvature: NDArray
    deviation: NDArray
    units: str
    shape: str

    def __len__(self) -> int:
        return len(self.index)


def round_toolpath_arrays(
    path: GcodePath,
    *,
    shape: str = "walton-meek",
    max_deviation: float | None = None,
    max_curvature: float | None = None,
    curvature: float | None = None,
    spiral_lengths: float | None = None,
) -> ToolpathCorners:
    """Round every corner of a toolpath G2 as ``round_toolpath`` does, into arrays (one value per
    option for every corner): what a program of millions of moves needs.

    Raises:
        NoSolutionError: a corner that cannot be rounded as asked (its point, G-code line and numbers).
        ValueError: malformed options or points (two moves to one point are one point: never here).
    """
    from ..core.errors import NoSolutionError, Status
    from ..design.rounding import corner_legs, round_corners_batch

    options = {"max_deviation": max_deviation, "max_curvature": max_curvature, "curvature": curvature,
               "spiral_lengths": spiral_lengths}  # fmt: skip
    for name, value in options.items():
        if value is not None and not (isinstance(value, (int, float)) and 0.0 < value < math.inf):
            raise ValueError(f"{name} must be one positive finite number here; got {value!r:.40}")
    given: dict[str, Any] = {name: value for name, value in options.items() if value is not None}
    with ticking(f"rounding {path.source} ({len(path):,} points)"):
        try:
            p0, corners, p1, index = corner_legs(path.points)
        except ValueError as error:
            raise ValueError(f"{path.source}: {path.at_lines(str(error))}") from None
        result = round_corners_batch(p0, corners, p1, shape=shape, **given)
    bad = np.flatnonzero(~result.ok)
    if bad.size:
        j = int(bad[0])
        message = result.reason(j, label=f"corner {index[j]} (line {int(path.lines[index[j]])})")
        refused = NoSolutionError if result.status[j] in (Status.LEGS_TOO_SHORT, Status.CORNER_REVERSAL, Status.UNVERIFIED,
                                                           Status.OUTSIDE_SHAPE) else ValueError  # fmt: skip
        raise refused(f"{path.source}: {message}" + (f" ({bad.size:,} corners fail)" if bad.size > 1 else ""))
    control = result.control_points
    if control.shape[-1] == 2:  # a flat program is rounded in its plane: back to x, y, z
        control = np.concatenate([control, np.full(control.shape[:-1] + (1,), path.points[0, 2])], axis=-1)
    return ToolpathCorners(index, path.lines[index], control, result.curvature, result.deviation, path.units, shape)
