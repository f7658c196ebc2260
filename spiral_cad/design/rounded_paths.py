"""Rounded polylines as checked chains: ``round_corners`` (a polyline, its corners G2 by spiral pairs) and
``fillet_polyline`` (a polyline in space, its corners as fillets in their planes).

Built on the array API of ``spiral_cad.design.rounding`` (one batch solve for every corner of the
polyline), with the chain's joints checked G2 and a corner that cannot be rounded named with the
numbers: slivers (legs too short for their two corners) are resolved by stepping the corners back,
and a bound (``max_deviation``, ``max_curvature``) that no corner shape meets is refused with the
value that does.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.chain import JOIN_TOLERANCE, Chain, PartCircles, join_rows, join_tolerance
from ..core.errors import JointError, NoSolutionError, Status
from ..core.inputs import as_float, as_real_array
from ..core.rows import SegmentRows
from ..core.segments import Line, Segment
from ..core.shapes import DEFAULT_SHAPE
from ..core.space import PlaneFrame, norms
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS, length_unit
from .fillets import FilletCorner, _vertex_indices, fillet_path, first_broken_corner
from .rounding import (
    DEVIATION_MARGIN,
    EPS,
    ROUNDING_ULPS,
    CornerBatch,
    _coordinates,
    _exclusive,
    _per_corner,
    _polyline,
    corner_legs,
    corner_scale,
    corner_shape,
    round_corners_batch,
    straight_points,
)

__all__ = ["FilletedPolyline", "RoundedCorner", "RoundedPath", "SpaceFillet", "curvature_bound", "fillet_polyline", "round_corners"]


@dataclass(frozen=True)
class RoundedCorner:
    """One rounded corner: its index in the input points, its spiral pair and how far the path passes from it."""

    index: int
    theta: float
    distance: float
    curvature: float
    spirals: tuple[BezierSpiral, BezierSpiral]
    deviation: float = math.nan


@dataclass(frozen=True)
class RoundedPath:
    """A rounded polyline: the G2 chain and the data of every rounded corner."""

    chain: Chain
    corners: list[RoundedCorner]
    shape: str

    @property
    def method(self) -> str:
        """The former name of ``shape``."""
        return self.shape

    @property
    def max_curvature(self) -> float:
        """Largest peak |κ| over the corners (0 for a straight polyline)."""
        return max((c.curvature for c in self.corners), default=0.0)

    @property
    def max_deviation(self) -> float:
        """Largest distance between a corner point and the path, measured (0 for a straight polyline)."""
        return max((c.deviation for c in self.corners), default=0.0)


def curvature_bound(radius: float | None) -> float | None:
    """``max_curvature`` from the smallest radius of curvature a path may have (None stays None).

    Raises:
        ValueError: a radius that is not positive and finite.
    """
    if radius is None:
        return None
    radius = as_float(radius, "radius")
    if not (radius > 0.0 and radius < math.inf):
        raise ValueError(f"radius must be positive and finite; got {radius!r}")
    return 1.0 / radius


def _at_corners(value: ArrayLike | None, name: str, interior: int, index: NDArray) -> ArrayLike | None:
    """A per-corner argument (one value, or one per interior point) at the corners kept by ``corner_legs``."""
    if value is None:
        return None
    v = as_real_array(value, name)
    if v.ndim == 0 or v.size == 1:
        return _per_corner(v, name, 1)
    if v.ndim != 1 or v.size != interior:
        raise ValueError(f"{name} needs one value or one per interior point ({interior}); got shape {v.shape}")
    _per_corner(v, name, interior, first=1)
    return v[index - 1]


def round_corners(
    points: ArrayLike,
    *,
    curvature: ArrayLike | None = None,
    max_curvature: ArrayLike | None = None,
    max_deviation: ArrayLike | None = None,
    spiral_lengths: ArrayLike | None = None,
    shape: str | None = None,
    method: str | None = None,
    tolerance: float = JOIN_TOLERANCE,
    units: str = DEFAULT_UNITS,
) -> RoundedPath:
    """Round every corner of a polyline, in the plane or in space, with a G2 spiral pair.

    Each corner's pair lies in the plane of its two legs; between corners the
    path runs straight along the polyline, so the whole path is G2 even when
    every corner lies in another plane (a helix of lines).

    Args:
        points: (n ≥ 3, 2) or (n ≥ 3, 3) polyline vertices (3-D points whose z
            are all 0 make a plane path).
        curvature: joint (peak) curvature of every corner's pair.
        max_curvature: bound κmax; each corner uses the smallest distance
            from the corner that respects it (so its peak equals κmax).
        max_deviation: the largest distance allowed between a corner point
            and the path (a CNC or robot tolerance): each corner gets the
            largest pair within it and its legs. With ``max_curvature`` too,
            that pair's curvature must also respect κmax.
        spiral_lengths: the arc length of each corner's spirals.
        shape: ``"walton-meek"`` (Theorem 4.4; the default), ``"near-linear"`` (curvature
            almost linear in arc length; deflections up to 100°) or ``"g2cbs"``
            (Yang & Sukkarieh: about 24 % lower peak curvature for the same
            corner distance).
        method: the former name of ``shape`` (deprecated: it warns; refused when it differs from ``shape``).
        tolerance: the chain's relative join tolerance (``Chain``).
        units: length unit of the points (default mm); curvatures are per unit.

    Every value may be one number or one per interior point (n − 2; the value
    of a collinear point is not used). With none given, each corner uses as
    much of its legs as it may (Corollary 4.5): half of every interior
    segment, all of the first and last. Collinear interior points are passed
    through; a point where the polyline folds straight back is refused.

    Returns:
        A :class:`RoundedPath`: chain from the first to the last point, and
        per corner its pair, curvature and measured deviation.

    Raises:
        NoSolutionError: a corner that cannot be rounded as asked (the message
            names the corner's point index and the numbers it needs).
        ValueError: malformed input.
    """
    shape = corner_shape(shape, method)
    _exclusive(curvature, max_curvature, max_deviation, spiral_lengths)
    pts = _polyline(points)
    p0, corners, p1, index = corner_legs(pts)
    interior = len(pts) - 2
    options: dict[str, Any] = {name: _at_corners(v, name, interior, index) for name, v in
               (("curvature", curvature), ("max_curvature", max_curvature), ("max_deviation", max_deviation), ("spiral_lengths", spiral_lengths))}  # fmt: skip
    dim = pts.shape[1]
    rounded: list[RoundedCorner] = []
    spirals = np.empty((0, 2, 4, dim))
    if len(corners):
        result = round_corners_batch(p0, corners, p1, shape=shape, tolerance=tolerance, **options)
        _raise_first_failure(result, index)
        result = _without_slivers(result, pts, p0, corners, p1, index, options, tolerance, length_unit(units))
        spirals = result.control_points
        numbers = zip(index.tolist(), result.theta.tolist(), result.distance.tolist(), result.curvature.tolist(), result.deviation.tolist())
        for cp, (i, theta, distance, peak, deviation) in zip(spirals, numbers):
            pair = (BezierSpiral._wrap(cp[0], shape), BezierSpiral._wrap(cp[1], shape))
            rounded.append(RoundedCorner(i, theta, distance, peak, pair, deviation))
    # Each corner's pair is one part; the lines between them follow (``Chain.join`` on arrays).
    rows = SegmentRows.spirals(spirals.reshape(-1, 4, dim), shape)
    objects = [s for corner in rounded for s in corner.spirals]
    try:
        chain = join_rows(rows, np.full(len(rounded), 2), PartCircles(len(rounded)), tuple(pts[0].tolist()),
                          tuple(pts[-1].tolist()), join_tolerance(tolerance), length_unit(units), objects)  # fmt: skip
    except JointError as error:
        raise _refusal(
            f"corner {index[error.part]}: float64 cannot hold its spirals G2 at these coordinates: {error}", int(index[error.part])
        ) from None
    return RoundedPath(chain, rounded, shape)


#: The shortest line left between rounded corners, in the chain's unit: ten times OCCT's
#: Precision::Confusion (1e-7), below which a line cannot become an edge of a wire. OCCT applies it
#: in the model's own unit (a file is read in the unit it declares), whatever that unit is.
MIN_EDGE = 1e-6
#: ... and at most this share of the corner distance beside it (a path too small for CAD edges keeps its lines).
SLIVER_SHARE = 1e-3
#: Passes of mending slivers (each solves the moved corners again) before a corner is refused.
SLIVER_PASSES = 4


def _refusal(message: str, corner: int, kind: type[ValueError] = NoSolutionError) -> ValueError:
    """The error of a polyline's corner: ``corner`` (its point index) is kept on it as an attribute,
    so a reader of the polyline's source (e.g. G-code) can name where the point came from."""
    error = kind(message)
    error.corner = corner  # type: ignore[attr-defined]
    return error


def _raise_first_failure(result: CornerBatch, index: NDArray) -> None:
    """Raise the first corner ``result`` could not round, named by its point index."""
    for j in np.flatnonzero(~result.ok):
        message = result.reason(int(j), label=f"corner {index[j]}")
        refused = result.status[j] in (Status.LEGS_TOO_SHORT, Status.CORNER_REVERSAL, Status.UNVERIFIED, Status.OUTSIDE_SHAPE)
        raise _refusal(message, int(index[j]), NoSolutionError if refused else ValueError)


def _without_slivers(result: CornerBatch, pts: NDArray, p0: NDArray, corners: NDArray, p1: NDArray, index: NDArray,
                     options: dict, tolerance: float, units: str) -> CornerBatch:  # fmt: skip
    """``result`` with no line shorter than ``MIN_EDGE`` left between corners (or before the first,
    after the last): such a sliver cannot become a CAD edge.

    The corners beside a sliver are re-solved with a fixed curvature: under ``max_deviation`` they
    move back from it (a smaller pair: a smaller deviation) until the line is a real edge; under
    ``max_curvature`` alone they grow to meet across it (a lower curvature). Either keeps every bound;
    where neither applies (``curvature`` or ``spiral_lengths`` fix the pairs) or the bound would be
    broken, the corner is refused, named.
    """
    n = len(result)
    min_edge = MIN_EDGE
    # Each gap's line runs along the polyline: before corner 0, between corners, after the last.
    heading = np.concatenate([corners[:1] - p0[:1], corners[1:] - corners[:-1], p1[-1:] - corners[-1:]])
    heading /= norms(heading)[:, None]

    def lines(batch: CornerBatch) -> tuple[NDArray, NDArray]:
        """The signed length of every line (negative: the pairs overlap) and which are slivers."""
        starts, ends = batch.control_points[:, 0, 0], batch.control_points[:, 1, 3]
        step = np.concatenate([starts[:1] - pts[0], starts[1:] - ends[:-1], pts[-1:] - ends[-1:]])
        signed = np.einsum("ij,ij->i", step, heading)
        # Gaps the chain closes without a line (within its join tolerance) are no slivers.
        beside = np.concatenate([batch.distance[:1], np.maximum(batch.distance[:-1], batch.distance[1:]), batch.distance[-1:]])
        resolution = ROUNDING_ULPS * EPS * np.abs(pts).max()
        closed = norms(step) <= np.maximum(tolerance * beside, resolution)
        # A path too small for CAD edges altogether keeps its lines: a sliver is small beside its corners too.
        return signed, ~closed & (signed < np.minimum(min_edge, SLIVER_SHARE * beside))

    gaps, sliver = lines(result)
    if not sliver.any():
        return result
    bound, kmax = (None if options[name] is None else np.broadcast_to(np.asarray(options[name], dtype=float).ravel(), (n,))
                   for name in ("max_deviation", "max_curvature"))  # fmt: skip
    for _ in range(SLIVER_PASSES):
        if bound is not None:  # step back: smaller pairs, smaller deviations
            distance = result.distance - _steps_back(gaps, sliver, result.distance, min_edge)
        else:
            distance = result.distance.copy()
            for g in np.flatnonzero(sliver).tolist():
                pair = [j for j in (g - 1, g) if 0 <= j < n]  # the corners before and after gap g
                if kmax is None or not gaps[g] > 0.0:
                    j = pair[0]
                    raise _refusal(
                        f"corner {index[j]}: the line it leaves {'after' if j < g else 'before'} it would be {gaps[g]:.3g} long, "
                        f"too short for a CAD edge ({min_edge:.3g} {units} at least); give max_deviation or max_curvature "
                        "so the corners may move, or move the point", int(index[j]))  # fmt: skip
                for j in pair:  # grow to meet: the gap's share of each corner
                    distance[j] = max(distance[j], result.distance[j] + gaps[g] / len(pair))
        result = _resolved(result, distance, p0, corners, p1, index, bound, kmax, tolerance)
        gaps, sliver = lines(result)
        if not sliver.any():
            return result
    g = int(np.argmax(sliver))
    j = g - 1 if g > 0 else 0
    raise _refusal(f"corner {index[j]}: the line it leaves {'after' if j < g else 'before'} it would be {gaps[g]:.3g} long, "
                   f"too short for a CAD edge ({min_edge:.3g} {units} at least), and moving the corners beside it "
                   "would break their bounds; move the point or change the bounds", int(index[j]))  # fmt: skip


def _steps_back(gaps: NDArray, sliver: NDArray, distance: NDArray, min_edge: float) -> NDArray:
    """How far each corner steps back so that no line between corners is a sliver, in one sweep
    along the path: the whole deficit of a gap goes to the corner after it (before it, for the last),
    and a corner that steps back opens its next gap by as much, so the sweep carries that along
    (a densely linearised arc, whose pairs all meet, opens one gap rather than a chain of slivers)."""
    n = len(distance)
    steps = np.zeros(n)
    for g in range(n + 1):
        opened = gaps[g] + (steps[g - 1] if g > 0 else 0.0)
        if not (sliver[g] or (g > 0 and steps[g - 1] > 0.0)):
            continue
        edge = min(min_edge, SLIVER_SHARE * max(distance[j] for j in (g - 1, g) if 0 <= j < n))
        if opened >= edge:
            continue
        steps[g if g < n else g - 1] += 1.01 * (edge - opened)
    return steps


def _resolved(result: CornerBatch, distance: NDArray, p0: NDArray, corners: NDArray, p1: NDArray, index: NDArray,
              bound: NDArray | None, kmax: NDArray | None, tolerance: float) -> CornerBatch:  # fmt: skip
    """``result`` with the corners whose ``distance`` changed solved again at that distance, every
    bound checked (a corner that cannot keep one is refused, named)."""
    changed = np.flatnonzero(distance != result.distance)
    s, c = np.sin(result.theta[changed]), np.cos(result.theta[changed])
    k = corner_scale(s, c, distance[changed], result.shape)
    fixed = round_corners_batch(p0[changed], corners[changed], p1[changed], curvature=k, shape=result.shape, tolerance=tolerance)
    for m, j in enumerate(changed.tolist()):
        why = None
        if not fixed.ok[m]:
            why = fixed.reason(m, label=f"corner {index[j]}")
        elif bound is not None and not fixed.deviation[m] <= bound[j]:
            why = f"corner {index[j]}: closing a sliver line beside it would take it {fixed.deviation[m]:.6g} from the path"
        elif kmax is not None and not fixed.curvature[m] <= kmax[j] * (1.0 + DEVIATION_MARGIN):
            why = (
                f"corner {index[j]}: making the sliver line beside it a real edge needs curvature "
                f"{fixed.curvature[m]:.6g}, above max_curvature {kmax[j]:.6g}; allow a larger curvature or deviation"
            )
        if why is not None:
            raise _refusal(why, int(index[j]))
    arrays = {name: getattr(result, name).copy() for name in ("control_points", "distance", "curvature", "deviation")}
    solved = {name: getattr(fixed, name) for name in arrays}
    # The batch drops z when all of its rows lie in z = 0, so a space path's corners re-solved
    # alone may come back as plane pairs: those lie in z = 0 and get their z back.
    lost = result.control_points.shape[-1] - solved["control_points"].shape[-1]
    solved["control_points"] = np.pad(solved["control_points"], ((0, 0), (0, 0), (0, 0), (0, lost)))
    for name, array in arrays.items():
        array[changed] = solved[name]
    return CornerBatch(result.shape, arrays["control_points"], result.theta, arrays["distance"], arrays["curvature"],
                       result.available, result.status, result.corners, result.requested, result.residual,
                       arrays["deviation"], result.max_deviation, result.max_curvature, result.spiral_length)  # fmt: skip


# ------------------------------------------------------------ fillets in space


@dataclass(frozen=True)
class SpaceFillet:
    """One filleted corner of a polyline in space: its vertex, the plane of its two edges
    (``frame``, origin at the vertex) and the fillet in that plane's coordinates."""

    vertex: int
    frame: PlaneFrame
    fillet: FilletCorner


@dataclass(frozen=True)
class FilletedPolyline:
    """A polyline in space with G2 fillets: its segments in travel order (closed when the polyline
    was), the corner each segment belongs to (None: a trimmed edge) and the fillets."""

    segments: tuple[Segment, ...]
    owners: tuple[int | None, ...]
    corners: list[SpaceFillet]
    closed: bool
    units: str = DEFAULT_UNITS

    @property
    def chain(self) -> Chain:
        """The path as a ``Chain`` (every joint G2: every corner rounded).

        Raises:
            ValueError: a vertex left sharp, named as a joint.
        """
        return Chain(self.segments, units=self.units)


_INNER_CORNER = re.compile(r"^corner 1( at \([^)]*\))?: ")


def fillet_polyline(
    points: ArrayLike,
    radius: float,
    *,
    transition: float = 0.5,
    vertices: Iterable[int] | None = None,
    closed: bool = False,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
    tolerance: float = JOIN_TOLERANCE,
    units: str = DEFAULT_UNITS,
) -> FilletedPolyline:
    """G2 fillets at the corners of a polyline in space, each in the plane of its two edges.

    Every chosen corner becomes transition → arc of ``radius`` → transition
    exactly as a plane corner does (``spiral_cad.design.fillets.fillet_path``,
    solved in the corner's plane and placed back): the same ``radius``,
    ``transition`` and ``shape``. An edge between two rounded corners is
    shared half-and-half (an edge with one rounded corner belongs wholly to it).

    Args:
        points: (n, 3) vertices (an (n, 2) polyline works too, in the XY plane).
        radius: the fillet arc's radius, the smallest radius of curvature in each corner.
        transition: the share of each corner's turn made by its spirals, in (0, 1].
        vertices: the vertex indices to round (default every corner).
        closed: the polyline closes (its last point joins its first; a repeated
            first point at the end is dropped): vertex 0 is a corner too.
        same_sense, shape, tolerance, units: as ``fillet_path``.

    Raises:
        ValueError: malformed input, a vertex index that is no corner.
        NoSolutionError: a corner that cannot be rounded (named, with numbers).
    """
    pts = _polyline(points) if not closed else _coordinates(points, "points")
    if closed and len(pts) > 1 and np.array_equal(pts[0], pts[-1]):
        pts = pts[:-1]
    if pts.ndim != 2 or len(pts) < 3:
        raise ValueError(f"points must be an (n ≥ 3, 3) polyline; got shape {pts.shape}")
    if not np.isfinite(pts).all():
        i = int(np.argmax(~np.isfinite(pts).all(axis=1)))
        raise ValueError(f"points must be finite; point {i} is {pts[i].tolist()}")
    count = len(pts)
    edges = count if closed else count - 1
    ends = [(pts[i], pts[(i + 1) % count]) for i in range(edges)]
    for i, (a, b) in enumerate(ends):
        if np.array_equal(a, b):
            raise ValueError(f"points {i} and {(i + 1) % count} coincide at {a.tolist()}")
    candidates = list(range(count)) if closed else list(range(1, count - 1))
    chosen = candidates if vertices is None else _vertex_indices(vertices)
    unknown = [v for v in chosen if v not in candidates]
    if unknown:
        raise ValueError(f"vertices {unknown} are not corners of this polyline (corners: {candidates})")
    rounded: dict[int, None] = {}
    for v in chosen:
        before, after = ends[v - 1][0], ends[v % edges][1]
        if not straight_points(before[None], pts[v][None], after[None])[0][0]:
            rounded[v] = None  # a corner (straight vertices stay as they are)
    pieces: dict[int, list[Segment]] = {}
    fillets = []
    for v in rounded:
        before, after = pts[v - 1], pts[(v + 1) % count]
        share_in = 0.5 if (v - 1) % count in rounded and (closed or v - 1 > 0) else 1.0
        share_out = 0.5 if (v + 1) % count in rounded and (closed or v + 1 < count - 1) else 1.0
        frame = PlaneFrame.of_corner(before, pts[v], after)
        legs = frame.local([pts[v] + share_in * (before - pts[v]), pts[v] + share_out * (after - pts[v])])
        try:
            result = fillet_path([legs[0], (0.0, 0.0), legs[1]], radius, transition=transition, same_sense=same_sense,
                                 shape=shape, tolerance=tolerance)  # fmt: skip
        except ValueError as error:
            where = f"corner {v} at ({', '.join(f'{c:.10g}' for c in pts[v].tolist())})"
            message = _INNER_CORNER.sub("", str(error))  # the plane solve's own corner and edges are 1, 0 and 1
            message = re.sub(r"edge ([01])\b", lambda m: f"edge {(v - 1) % count if m.group(1) == '0' else v}", message)
            shared = " (each corner may use half of an edge it shares with another rounded corner)" if "edge" in message else ""
            raise type(error)(f"{where}: {message}{shared}") from None
        pieces[v] = [s.placed(frame) for s, owner in zip(result.segments, result.owners) if owner is not None]
        fillets.append(SpaceFillet(v, frame, result.corners[0]))
    segments: list[Segment] = []
    owners: list[int | None] = []
    for i, (a, b) in enumerate(ends):
        start = pieces[i][-1].point(1.0) if i in pieces else a
        j = (i + 1) % count
        stop = pieces[j][0].point(0.0) if j in pieces else b
        if not np.array_equal(start, stop):
            segments.append(Line(start, stop))
            owners.append(None)
        if j in pieces and (closed or j < count - 1):
            segments += pieces[j]
            owners += [j] * len(pieces[j])
    broken = first_broken_corner(segments, owners, closed, join_tolerance(tolerance))
    if broken:
        raise NoSolutionError(f"corner {broken[0]}: float64 cannot hold its fillet G2 at these coordinates ({broken[1]})")
    return FilletedPolyline(tuple(segments), tuple(owners), fillets, closed, length_unit(units))
