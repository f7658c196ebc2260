"""G2 fillets ("continuous corners"): round the corners of a planar path of lines and arcs.

A circular fillet makes the curvature jump from 0 to 1/r at both of its
ends. Here a chosen corner — a vertex where the tangent turns by Δ — becomes
transition → fillet arc → transition, joined G2 on both sides, where the
fillet arc's radius ``radius`` is the smallest radius of curvature in the
corner. The transition from each side onto the fillet circle is one of the
paper's:

* **line** side: one Bézier spiral (Theorem 4.1); the fillet circle's centre
  lies r·g1(θ) from the line;
* **arc** side, turning the other way: an S pair (Theorem 4.3), centre
  distance (|R| + r)·√(g1(θ)² + g2(θ)²) — curvature monotone through 0;
* **arc** side, turning the same way: the single nested-circle spiral (the
  fifth case), curvature monotone from 1/R to 1/r; or, with
  ``same_sense="C"``, the broken-back C pair (Theorem 4.2), which passes
  through zero curvature.

Each side's transition angle is θ = ``transition``·Δ/2. For a line–line
corner the two spirals thus make the share ``transition`` of the turn and
the arc the rest; ``transition = 1`` gives a spiral pair with no arc
(Theorem 4.4). The fillet centre is where the two sides' loci meet — two
offset lines, an offset line and a circle, or two circles — in closed form;
the original arcs stay true circles of their radius, trimmed.

Everything is checked before anything is returned, and errors name the
corner and the numbers: a transition that overruns the fillet circle, a
corner that needs more of an edge than it has (two corners may not claim the
same stretch), a fillet circle that no transition of the chosen kind can
reach. Corners that are already tangent are left as they are.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core import _kernel_circles as KC
from ..core import _kernels as K
from ..core.chain import JOIN_TOLERANCE, Chain, g2_mismatch, join_tolerance
from ..core.errors import NoSolutionError
from ..core.inputs import as_float, as_points, shown
from ..core.segments import Arc, Circle, Line, Ray, Segment
from ..core.shapes import DEFAULT_SHAPE, SHAPE_CODES, TRANSITION_SHAPES, shape_code, shape_limits
from ..core.transitions import Transition, circle_in_circle, circle_to_circle, line_to_circle
from ..core.units import DEFAULT_UNITS

#: A vertex whose tangent turns by less than this (radians) is already smooth.
TANGENT_TOL = 1e-9
SAME_SENSE = ("nested", "C")


@dataclass(frozen=True)
class FilletCorner:
    """One rounded corner.

    Attributes:
        vertex: index of the vertex (the start of segment ``vertex``; the
            closing vertex of a closed path is 0).
        kind: ``"line-line"``, ``"line-arc"``, ``"arc-line"`` or ``"arc-arc"``.
        turn: the tangent's signed turn Δ at the vertex (radians, left positive).
        center: the fillet circle's centre.
        radius: the fillet circle's signed radius (its sign is the turn's).
        sweep: the fillet arc's sweep (radians, 0 for a spiral pair).
        transitions: the transitions onto and off the fillet circle.
    """

    vertex: int
    kind: str
    turn: float
    center: tuple[float, float]
    radius: float
    sweep: float
    transitions: tuple[Transition, Transition]


@dataclass(frozen=True)
class FilletedPath:
    """The rounded path: its segments in travel order (closed when the path was) and the rounded corners.

    Every joint inside and around a rounded corner is G2 (checked); the
    path's other vertices (not chosen, or already tangent) stay as they were.
    """

    segments: tuple[Segment, ...]
    corners: list[FilletCorner]
    closed: bool
    units: str = DEFAULT_UNITS
    #: The vertex of the corner each segment belongs to (None: a trimmed original edge).
    owners: tuple[int | None, ...] = ()

    @property
    def chain(self) -> Chain:
        """The path as a ``Chain``: every joint must then be G2 (every corner rounded, none left tangent-only).

        Raises:
            ValueError: a joint that is not G2, named.
        """
        return Chain(self.segments, units=self.units)


# ------------------------------------------------------------------ input


def _as_segments(path: Any) -> list[Segment]:
    """Lines and arcs from ``path``: a sequence of ``Line``/``Arc``, or (n, 2) polyline points."""
    if isinstance(path, Chain):
        path = list(path)
    if isinstance(path, Sequence) and path and all(isinstance(s, Segment) for s in path):
        for i, s in enumerate(path):
            if not isinstance(s, (Line, Arc)):
                raise ValueError(f"fillets round paths of lines and arcs; segment {i} is a {type(s).__name__}")
        return list(path)
    points = as_points(path, "path")
    if points.ndim != 2 or len(points) < 2:
        raise ValueError(f"path must be lines and arcs, or (n ≥ 2, 2) points; got shape {points.shape}")
    for i, (a, b) in enumerate(zip(points[:-1], points[1:])):
        if np.array_equal(a, b):
            raise ValueError(f"path points {i} and {i + 1} coincide at {tuple(a.tolist())}")
    return [Line(a, b) for a, b in zip(points[:-1], points[1:])]


def _integer(value: Any) -> int | None:
    """``value`` as an int when it is an integer (numpy integers too; not a bool, float or string), else None."""
    if isinstance(value, (bool, np.bool_)):
        return None
    try:
        return operator.index(value)
    except TypeError:
        return None


def _vertex_indices(vertices: Any) -> list[int]:
    """``vertices`` as sorted distinct ints; anything that is not an integer (1.5, '1', True) is refused by name."""
    if isinstance(vertices, (str, bytes)) or not isinstance(vertices, Iterable):
        raise ValueError(f"vertices must be a list of vertex indices; got {type(vertices).__name__} {shown(vertices):.80}")
    items = list(vertices)
    indices = [_integer(v) for v in items]
    for i, (v, index) in enumerate(zip(items, indices)):
        if index is None:
            raise ValueError(f"vertices[{i}] must be a vertex index (an integer); got {type(v).__name__} {shown(v):.80}")
    return sorted({index for index in indices if index is not None})


def _side_geometry(segment: Segment, at_end: bool) -> tuple[str, Any]:
    """The geometry a transition leaves from / arrives on: a directed line or a travel-sense circle."""
    if isinstance(segment, Line):
        (x, y, tx, ty, _) = segment.ends[1 if at_end else 0]
        return "line", Ray((x, y), (tx, ty))
    assert isinstance(segment, Arc)  # a path's pieces are lines and arcs
    return "arc", segment.circle


def _offset_g1(theta: float, shape: str) -> float:
    return K.shape_g1(SHAPE_CODES[shape], math.sin(theta), math.cos(theta))


def _center_distance(kind: str, theta: float, side_radius: float, r: float, shape: str) -> float:
    """Distance from an arc side's centre to the fillet circle's for transition angle θ."""
    a0, a1 = abs(side_radius), r
    s, c = math.sin(theta), math.cos(theta)
    code = SHAPE_CODES[shape]
    g1, g2 = K.shape_g1(code, s, c), K.shape_g2(code, s, c)
    if kind == "S":
        return (a0 + a1) * math.hypot(g1, g2)
    if kind == "C":
        return math.hypot((a0 + a1) * g2, (a1 - a0) * g1)
    big, small = max(a0, a1), min(a0, a1)
    x, y = KC.nested_center_offset(theta, big, small, code)[:2]
    return math.hypot(x, y)


def _arc_kind(circle: Circle, turn: float, same_sense: str) -> str:
    return same_sense if (circle.radius > 0) == (turn > 0) else "S"


def _locus(kind: str, geometry: Any, theta: float, r: float, turn: float, same_sense: str, shape: str):
    """Where the fillet centre may lie for this side: ("line", point, direction) or ("circle", centre, distance)."""
    if kind == "line":
        (px, py), (tx, ty) = geometry.point, geometry.direction
        offset = math.copysign(r * _offset_g1(theta, shape), turn)
        return "line", np.array([px - ty * offset, py + tx * offset]), np.array([tx, ty])
    transition = _arc_kind(geometry, turn, same_sense)
    if transition == "nested" and abs(abs(geometry.radius) - r) <= 1e-12 * r:
        raise NoSolutionError(
            f"the fillet radius equals the arc's ({r:.6g}): no single spiral joins equal nested circles; "
            "change the radius or use same_sense='C'"
        )
    return "circle", np.array(geometry.center), _center_distance(transition, theta, geometry.radius, r, shape)


def _intersect(a, b, near: NDArray) -> NDArray | None:
    """The intersection of two loci nearest ``near`` (None when they do not meet): ``_intersect_xy`` of arrays.

    A locus is ``("line", point, direction)`` or ``("circle", centre, radius)``.
    """
    local = [(kind, (float(point[0]), float(point[1])), (float(other[0]), float(other[1])) if kind == "line" else float(other))
             for kind, point, other in (a, b)]  # fmt: skip
    root = _intersect_xy(local[0], local[1], (float(near[0]), float(near[1])))
    return None if root is None else np.array(root)


def _ldexp(x: float, exponent: int) -> float:
    """``x·2^exponent`` as ``np.ldexp`` gives it (an overflow: infinity of x's sign)."""
    try:
        return math.ldexp(x, exponent)
    except OverflowError:
        return math.copysign(math.inf, x)


def _intersect_xy(a, b, near: tuple[float, float]) -> tuple[float, float] | None:
    """The intersection of two loci nearest ``near`` (None when they do not meet), in plain floats (points as (x, y)).

    Solved relative to ``near`` and scaled by a power of two (exact), so the
    squares of distances neither overflow nor underflow at any magnitude.
    """
    nx, ny = near
    offsets = [max(abs(point[0] - nx), abs(point[1] - ny)) for _, point, _ in (a, b)]
    size = max(offsets + [abs(distance) for kind, _, distance in (a, b) if kind == "circle"])
    exponent = math.frexp(size)[1] if math.isfinite(size) else 0
    local = [(kind, (_ldexp(point[0] - nx, -exponent), _ldexp(point[1] - ny, -exponent)),
              other if kind == "line" else _ldexp(other, -exponent)) for kind, point, other in (a, b)]  # fmt: skip
    root = _nearest_intersection(*local)
    if root is None or not (math.isfinite(root[0]) and math.isfinite(root[1])):
        return None
    return nx + _ldexp(root[0], exponent), ny + _ldexp(root[1], exponent)


def _nearest_intersection(a, b) -> tuple[float, float] | None:
    """The intersection of two loci nearest the origin (None when they do not meet), in plain floats."""
    if a[0] == "circle" and b[0] == "line":
        a, b = b, a
    if a[0] == "line" and b[0] == "line":
        (_, (px, py), (ux, uy)), (_, (qx, qy), (vx, vy)) = a, b
        det = ux * vy - uy * vx
        if abs(det) <= 1e-15:
            return None
        wx, wy = qx - px, qy - py
        along = wx * vy - wy * vx
        return px + ux * along / det, py + uy * along / det
    if a[0] == "line":
        (_, (px, py), (ux, uy)), (_, (cx, cy), radius) = a, b
        wx, wy = px - cx, py - cy
        along = wx * ux + wy * uy
        disc = along * along - ((wx * wx + wy * wy) - radius * radius)
        if disc < 0.0:
            return None
        root = math.sqrt(disc)
        roots = [(px + ux * (-along + step), py + uy * (-along + step)) for step in (root, -root)]
    else:
        (_, (x0, y0), r0), (_, (x1, y1), r1) = a, b
        ox, oy = x1 - x0, y1 - y0
        d = float(np.hypot(ox, oy))
        if d == 0.0 or d > r0 + r1 or d < abs(r0 - r1):
            return None
        along = (r0 * r0 - r1 * r1 + d * d) / (2.0 * d)
        h = math.sqrt(max(r0 * r0 - along * along, 0.0))
        ex, ey = ox / d, oy / d
        bx, by = x0 + along * ex, y0 + along * ey
        roots = [(bx + h * -ey, by + h * ex), (bx - h * -ey, by - h * ex)]
    return min(roots, key=lambda x: float(np.hypot(x[0], x[1])))


def _transition_onto(kind: str, geometry: Any, center: NDArray, r: float, same_sense: str, shape: str) -> Transition:
    """From the incoming side's geometry onto the fillet circle (center, r signed)."""
    if kind == "line":
        return line_to_circle(geometry.point, geometry.direction, center, abs(r), shape=shape)
    solve = circle_in_circle if _arc_kind(geometry, r, same_sense) == "nested" else circle_to_circle
    return solve(geometry.center, geometry.radius, center, r, shape=shape)


def _transition_off(kind: str, geometry: Any, center: NDArray, r: float, same_sense: str, shape: str) -> Transition:
    """From the fillet circle (center, r signed) onto the outgoing side's geometry."""
    if kind == "line":
        (px, py), (tx, ty) = geometry.point, geometry.direction
        return line_to_circle((px, py), (-tx, -ty), center, abs(r), shape=shape).reversed()
    solve = circle_in_circle if _arc_kind(geometry, r, same_sense) == "nested" else circle_to_circle
    return solve(center, r, geometry.center, geometry.radius, shape=shape)


def _signed_sweep(center: NDArray, radius: float, a: NDArray, b: NDArray) -> float:
    """Angle from ``a`` to ``b`` about ``center`` in the travel sense of ``radius``, in (−π, π]."""
    turn = math.atan2(b[1] - center[1], b[0] - center[0]) - math.atan2(a[1] - center[1], a[0] - center[0])
    turn = math.copysign(1.0, radius) * turn
    return math.pi - (math.pi - turn) % (2.0 * math.pi)


def _round_corner(
    vertex: int, before: Segment, after: Segment, radius: float, transition: float, same_sense: str, shape: str
) -> FilletCorner:
    (_, _, tx0, ty0, _), (x, y, tx1, ty1, _) = before.ends[1], after.ends[0]
    turn = math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1)
    where = f"corner {vertex} at ({x:.10g}, {y:.10g})"
    if abs(turn) > math.pi - 1e-9:
        raise NoSolutionError(f"{where}: the path folds straight back (turn {math.degrees(turn):.6g}°); no fillet exists")
    theta = transition * abs(turn) / 2.0
    largest = shape_limits(shape)["theta"]
    if not theta < largest or (theta == largest and shape == "near-linear"):
        raise NoSolutionError(
            f"{where}: its transitions turn {math.degrees(theta):.6g}° each (transition {transition:g} × half the "
            f"{math.degrees(abs(turn)):.6g}° turn), beyond {math.degrees(largest):g}° for {shape} spirals; use a smaller "
            "transition or shape='walton-meek'"
        )
    kind_in, geometry_in = _side_geometry(before, at_end=True)
    kind_out, geometry_out = _side_geometry(after, at_end=False)
    try:
        locus_in = _locus(kind_in, geometry_in, theta, radius, turn, same_sense, shape)
        locus_out = _locus(kind_out, geometry_out, theta, radius, turn, same_sense, shape)
    except NoSolutionError as error:
        raise NoSolutionError(f"{where}: {error}") from None
    center = _intersect(locus_in, locus_out, np.array([x, y]))
    signed = math.copysign(radius, turn)
    if center is None:
        raise NoSolutionError(
            f"{where}: no fillet circle of radius {radius:.6g} can be placed with transition {transition:g}: the "
            f"{kind_in} and {kind_out} sides' transition loci do not meet; use a smaller radius or transition"
        )
    try:
        onto = _transition_onto(kind_in, geometry_in, center, signed, same_sense, shape)
        off = _transition_off(kind_out, geometry_out, center, signed, same_sense, shape)
    except NoSolutionError as error:
        raise NoSolutionError(f"{where}: {error}") from None
    for _, side in ((onto, onto.end_circle), (off, off.start_circle)):
        assert side is not None  # a transition onto or off a circle has that circle
        if side.radius * signed < 0:
            raise NoSolutionError(f"{where}: the fillet circle falls on the wrong side of the path; use a smaller radius")
    sweep = _signed_sweep(center, signed, onto.end, off.start)
    if sweep < -1e-9:
        raise NoSolutionError(
            f"{where}: with transition {transition:g} the two transitions overlap on the fillet circle by "
            f"{math.degrees(-sweep):.4g}°; use a smaller transition (the {kind_in}–{kind_out} corner turns "
            f"{math.degrees(abs(turn)):.6g}°)"
        )
    return FilletCorner(vertex, f"{kind_in}-{kind_out}", turn, (float(center[0]), float(center[1])),
                        signed, max(sweep, 0.0), (onto, off))  # fmt: skip


def _trim(segment: Segment, index: int, start: NDArray | None, end: NDArray | None, claims: tuple[str, str]) -> Segment | None:
    """The part of ``segment`` between the contacts of its corners (None if they meet)."""
    u0 = 0.0 if start is None else _parameter(segment, start)
    u1 = 1.0 if end is None else _parameter(segment, end)
    length = segment.length
    for u, who in ((u0, claims[0]), (u1, claims[1])):
        if not -1e-12 <= u <= 1.0 + 1e-12:
            raise NoSolutionError(
                f"{who}: the fillet needs {abs(u if u < 0 else u - 1.0) * length:.6g} more of edge {index} than it "
                f"has ({length:.6g}); use a smaller radius or transition"
            )
    if u1 - u0 < -1e-12:
        raise NoSolutionError(
            f"{claims[0]} and {claims[1]} both claim the same stretch of edge {index}: together they need "
            f"{(1.0 + u0 - u1) * length:.6g} of its {length:.6g} (missing {(u0 - u1) * length:.6g}); use a smaller "
            "radius or transition"
        )
    if u1 - u0 <= 1e-12:
        return None
    return segment.piece(max(u0, 0.0), min(u1, 1.0))


def _parameter(segment: Segment, point: NDArray) -> float:
    """The parameter u of ``point`` (on the segment's line or circle)."""
    if isinstance(segment, Line):
        (ax, ay, tx, ty, _), length = segment.ends[0], segment.length  # unit tangent: no |b − a|² to overflow
        return float((point[0] - ax) * tx + (point[1] - ay) * ty) / length
    assert isinstance(segment, Arc)  # a path's pieces are lines and arcs
    c = segment.center
    angle = math.atan2(point[1] - c[1], point[0] - c[0]) - segment.start_angle
    travelled = (math.copysign(1.0, segment.radius) * angle) % (2.0 * math.pi)
    if travelled > segment.sweep + 0.5 * (2.0 * math.pi - segment.sweep):
        travelled -= 2.0 * math.pi  # just before the start
    return travelled / segment.sweep


def fillet_path(
    path: Any,
    radius: float,
    *,
    transition: float = 0.5,
    vertices: Iterable[int] | None = None,
    closed: bool | None = None,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
    tolerance: float = JOIN_TOLERANCE,
    units: str = DEFAULT_UNITS,
) -> FilletedPath:
    """Round the corners of a planar path of lines and arcs with G2 fillets (see the module docstring).

    Args:
        path: the segments (``Line``, ``Arc``) in travel order, meeting end
            to start, or (n, 2) polyline points.
        radius: the fillet circle's radius: the smallest radius of curvature
            in each rounded corner (> 0).
        transition: the share of the turn made by the transitions, in (0, 1].
        vertices: the corners to round, by vertex index (vertex i starts
            segment i; a closed path's vertex 0 is its closing vertex);
            default every corner that is not already tangent.
        closed: whether the path closes on itself (default: when its end
            meets its start).
        same_sense: for an arc that turns the same way as its corner,
            ``"nested"`` (one spiral, curvature monotone) or ``"C"``.
        shape: spiral shape of the transitions: ``"walton-meek"`` (default)
            or ``"near-linear"`` (curvature almost linear in arc length, like
            a clothoid; transitions of up to 50° each).
        tolerance, units: of the resulting ``Chain``.

    Raises:
        ValueError: malformed input (segments that do not meet, other segment
            kinds, a radius or transition out of range, unknown vertices).
        NoSolutionError: a corner that cannot be rounded as asked (the
            message names the corner and the numbers).
    """
    segments = _as_segments(path)
    radius = as_float(radius, "radius")
    transition = as_float(transition, "transition")
    if not radius > 0.0:
        raise ValueError(f"radius must be positive; got {radius!r}")
    if not 0.0 < transition <= 1.0:
        raise ValueError(f"transition must lie in (0, 1]; got {transition!r}")
    if not isinstance(same_sense, str) or same_sense not in SAME_SENSE:
        raise ValueError(f"same_sense must be one of {', '.join(SAME_SENSE)}; got {same_sense!r}")
    shape_code(shape, TRANSITION_SHAPES)
    size = max(s.length for s in segments)
    for i, (a, b) in enumerate(zip(segments, segments[1:])):
        gap = math.dist(a.ends[1][:2], b.ends[0][:2])
        if gap > 1e-9 * size:
            raise ValueError(f"segments {i} and {i + 1} do not meet: gap {gap:.3g}")
    if closed is None:
        closed = len(segments) > 1 and math.dist(segments[-1].ends[1][:2], segments[0].ends[0][:2]) <= 1e-9 * size
    count = len(segments)
    candidates = range(count) if closed else range(1, count)
    pairs = {v: (segments[v - 1], segments[v]) for v in candidates}  # segments[-1] before vertex 0 when closed
    if vertices is None:
        chosen = list(candidates)
    else:
        chosen = _vertex_indices(vertices)
        unknown = [v for v in chosen if v not in pairs]
        if unknown:
            raise ValueError(f"vertices {unknown} are not corners of this path (corners: {list(candidates)})")
    corners = []
    for v in chosen:
        before, after = pairs[v]
        (_, _, tx0, ty0, _), (_, _, tx1, ty1, _) = before.ends[1], after.ends[0]
        if abs(math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1)) > TANGENT_TOL:
            corners.append(_round_corner(v, before, after, radius, transition, same_sense, shape))
    tolerance = join_tolerance(tolerance)
    pieces, owners = _assemble(segments, corners, closed, tolerance)
    return FilletedPath(tuple(pieces), corners, closed, units, tuple(owners))


def _assemble(
    segments: list[Segment], corners: list[FilletCorner], closed: bool, tolerance: float
) -> tuple[list[Segment], list[int | None]]:
    """Trimmed edges and each corner's transition – arc – transition, in travel order, with the
    corner each piece belongs to.

    A closed path's pieces start where edge 0 resumes after corner 0 and end
    with corner 0. Every joint that touches a rounded corner is checked G2;
    only joints between two original edges (vertices left as they were) are not.
    """
    at = {c.vertex: c for c in corners}
    count = len(segments)
    pieces: list[Segment] = []
    owners: list[int | None] = []  # the corner each piece belongs to (None: an original edge)
    for i in range(count):
        start_corner, end_corner = at.get(i), at.get((i + 1) % count if closed else i + 1)
        claims = (f"corner {i}" if start_corner else "", f"corner {(i + 1) % count}" if end_corner else "")
        trimmed = _trim(
            segments[i], i,
            None if start_corner is None else start_corner.transitions[1].end,
            None if end_corner is None else end_corner.transitions[0].start,
            claims,
        )  # fmt: skip
        if trimmed is not None:
            pieces.append(trimmed)
            owners.append(None)
        if end_corner is not None:
            onto, off = end_corner.transitions
            corner: list[Segment] = [*onto.spirals]
            if end_corner.sweep > 1e-9:
                corner.append(Arc.between(end_corner.center, end_corner.radius, onto.end, off.start))
            corner += off.spirals
            pieces += corner
            owners += [end_corner.vertex] * len(corner)
    broken = first_broken_corner(pieces, owners, closed, tolerance)
    if broken:
        raise NoSolutionError(f"corner {broken[0]}: the fillet is not G2 at {broken[1]}")
    return pieces, owners


def first_broken_corner(pieces: Sequence[Segment], owners: Sequence[int | None], closed: bool, tolerance: float) -> tuple[int, str] | None:
    """The first joint touching a rounded corner (``owners``: the corner of each piece, None for an
    original edge) that is not G2, as (corner, why), or None; joints between original edges are not judged."""
    pairs = list(zip(range(len(pieces)), range(1, len(pieces))))
    if closed:
        pairs.append((len(pieces) - 1, 0))
    for a, b in pairs:
        vertex = owners[a] if owners[a] is not None else owners[b]
        if vertex is not None:
            problem = g2_mismatch(pieces[a], pieces[b], tolerance)
            if problem:
                return vertex, problem
    return None


# ---------------------------------------------------------- shapes with continuous corners


def _polygon(points: Sequence[tuple[float, float]], radius: float, transition: float, units: str, shape: str) -> FilletedPath:
    closed_points = [*points, points[0]]
    return fillet_path(closed_points, radius, transition=transition, closed=True, units=units, shape=shape)


def corner_distance(radius: float, turn: float, transition: float, shape: str = DEFAULT_SHAPE) -> float:
    """How far from a line–line corner of turn Δ its fillet starts: r·(g1(θ)·tan(Δ/2) + g2(θ)), θ = transition·Δ/2."""
    theta = transition * abs(turn) / 2.0
    s, c = math.sin(theta), math.cos(theta)
    code = SHAPE_CODES[shape]
    return radius * (K.shape_g1(code, s, c) * math.tan(abs(turn) / 2.0) + K.shape_g2(code, s, c))


def continuous_rectangle(
    width: float, height: float, radius: float, transition: float = 0.5, units: str = DEFAULT_UNITS, shape: str = DEFAULT_SHAPE
) -> FilletedPath:
    """A width × height rectangle centred on the origin, every corner a G2 fillet of ``radius``
    (spirals of ``shape``, as in ``fillet_path``).

    Raises:
        NoSolutionError: the corners do not fit (the message says how much is missing).
    """
    w, h = as_float(width, "width") / 2.0, as_float(height, "height") / 2.0
    if not (w > 0 and h > 0):
        raise ValueError(f"width and height must be positive; got {shown(width)}, {shown(height)}")
    return _polygon([(-w, -h), (w, -h), (w, h), (-w, h)], radius, transition, units, shape)


def continuous_polygon(radius: float, side_count: int, corner_radius: float, transition: float = 0.5,
                       major_radius: bool = True, units: str = DEFAULT_UNITS, shape: str = DEFAULT_SHAPE) -> FilletedPath:  # fmt: skip
    """A regular polygon centred on the origin (first vertex on +x), every corner a G2 fillet.

    Args:
        radius: circumradius (``major_radius``) or inradius of the polygon.
        side_count: number of sides (≥ 3).
        corner_radius: the fillet circle's radius at each corner.
    """
    count = _integer(side_count)
    if count is None or count < 3:
        raise ValueError(f"side_count must be an integer ≥ 3; got {shown(side_count)}")
    side_count = count
    outer = as_float(radius, "radius") / (1.0 if major_radius else math.cos(math.pi / side_count))
    if not outer > 0:
        raise ValueError(f"radius must be positive; got {radius!r}")
    angles = [2.0 * math.pi * k / side_count for k in range(side_count)]
    return _polygon([(outer * math.cos(a), outer * math.sin(a)) for a in angles], corner_radius, transition, units, shape)


def continuous_slot(
    width: float, height: float, transition: float = 0.5, units: str = DEFAULT_UNITS, shape: str = DEFAULT_SHAPE
) -> FilletedPath:
    """A slot of overall ``width`` × ``height`` whose ends are G2 all the way round.

    Each end is two 90° corners whose fillets meet in the middle of the end:
    the fillet radius is chosen so that each corner uses exactly half the
    height (``corner_distance``), which makes the slot's straight sides
    tangent to curvature-continuous ends instead of to semicircles.
    """
    w, h = as_float(width, "width"), as_float(height, "height")
    if not (w > h > 0):
        raise ValueError(f"a slot needs width > height > 0; got width {shown(width)}, height {shown(height)}")
    transition = as_float(transition, "transition")
    if not 0.0 < transition <= 1.0:
        raise ValueError(f"transition must lie in (0, 1]; got {transition!r}")
    shape_code(shape, TRANSITION_SHAPES)
    radius = 0.5 * h / corner_distance(1.0, math.pi / 2.0, transition, shape)
    return continuous_rectangle(w, h, radius, transition, units, shape)
