"""OpenCASCADE (OCP) edges and wires: the one place where segments become OCCT geometry.

Lines become ``Geom_Line`` edges, arcs true ``Geom_Circle`` edges and
spirals ``Geom_BezierCurve`` edges with their exact four control points, so
every CAD adapter and exporter hands the kernel the analytic curves rather
than approximations. All edges run in travel order (their curve parameter
increases along the path), which keeps wires, sweeps and exports free of
orientation flips.

A plane point (x, y) is placed at ``origin + x·X + y·Y`` of an optional
``gp_Ax3`` (None: the global XY plane), a point in space (x, y, z) of a 3-D
chain at ``origin + x·X + y·Y + z·(X × Y)``; counterclockwise plane arcs turn
from X towards Y, arcs in space about their own normal.
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.Geom import (
    Geom_BezierCurve,
    Geom_BSplineCurve,
    Geom_Circle,
    Geom_Curve,
    Geom_Line,
)
from OCP.gp import gp_Ax2, gp_Ax3, gp_Dir, gp_Pnt
from OCP.Precision import Precision
from OCP.TColgp import TColgp_Array1OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Compound, TopoDS_Edge, TopoDS_Shape, TopoDS_Vertex, TopoDS_Wire

from ..continuity.joints import ROUNDING_ULPS, norms
from ..core.kinds import ARC, LINE, SPIRAL
from ..core.rows import SegmentRows
from ..core.segments import Segment, row_frames
from .readers import read_shape

__all__ = ["as_occ_shape", "chain_wire", "nurbs_edge", "plane_ax3", "print_model", "segment_edge", "segment_edges"]

if TYPE_CHECKING:
    from ..core.nurbs import Nurbs


class _Frame:
    """Maps chain coordinates to 3-D points; precomputed once per call, not per edge.

    A chain's (x, y) — or (x, y, z) in space — lie at origin + x·X + y·Y + z·Z
    of the frame, Z = X × Y (the global coordinates when there is no plane).
    """

    __slots__ = ("origin", "x", "y", "z", "flat")

    def __init__(self, plane: gp_Ax3 | None):
        if plane is None:
            origin, x, y = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
        else:
            if not isinstance(plane, gp_Ax3):
                raise ValueError(f"plane must be an OCP gp_Ax3 or None; got {plane!r}")
            loc, xd, yd = plane.Location(), plane.XDirection(), plane.YDirection()
            origin, x, y = (loc.X(), loc.Y(), loc.Z()), (xd.X(), xd.Y(), xd.Z()), (yd.X(), yd.Y(), yd.Z())
        self.origin, self.x, self.y = origin, x, y
        # Z is X × Y (not the plane's main direction, which points the other way
        # for a left-handed gp_Ax3) so "counterclockwise" always means turning from X towards Y.
        self.z = (x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0])
        self.flat = plane is None or (origin == (0.0, 0.0, 0.0) and x == (1.0, 0.0, 0.0) and y == (0.0, 1.0, 0.0))

    def _map(self, coords: tuple[float, float, float], origin: tuple[float, float, float]) -> tuple[float, float, float]:
        x, y, z = coords
        (xx, xy, xz), (yx, yy, yz), (zx, zy, zz) = self.x, self.y, self.z
        return (
            origin[0] + x * xx + y * yx + z * zx,
            origin[1] + x * xy + y * yy + z * zy,
            origin[2] + x * xz + y * yz + z * zz,
        )

    def map(self, points: NDArray) -> NDArray:
        """Chain coordinates (..., 3) as OCCT's, all at once (``pnt`` for many points)."""
        return points if self.flat else np.asarray(self.origin) + self.turn(points)

    def turn(self, vectors: NDArray) -> NDArray:
        """Chain vectors (..., 3) as OCCT's (``dir`` for many vectors, unnormalised)."""
        return vectors if self.flat else vectors @ np.array([self.x, self.y, self.z])

    def pnt(self, x: float, y: float, z: float = 0.0) -> gp_Pnt:
        """The point at chain coordinates (x, y) or (x, y, z)."""
        if self.flat:
            return gp_Pnt(x, y, z)
        return gp_Pnt(*self._map((x, y, z), self.origin))

    def dir(self, x: float, y: float, z: float = 0.0) -> gp_Dir:
        """The direction of the chain vector (x, y[, z])."""
        if self.flat:
            return gp_Dir(x, y, z)
        return gp_Dir(*self._map((x, y, z), (0.0, 0.0, 0.0)))

    def poles(self, points: list[list[float]]) -> TColgp_Array1OfPnt:
        array = TColgp_Array1OfPnt(1, len(points))
        for i, p in enumerate(points, 1):
            array.SetValue(i, self.pnt(*p))
        return array


_XY = _Frame(None)


def _frame(plane: gp_Ax3 | None) -> _Frame:
    return _XY if plane is None else _Frame(plane)


# Each segment becomes (curve, first, last): its exact OCCT curve and the
# parameter range that runs in travel order.
CurveSpan = tuple[Geom_Curve, float, float]


# The segments as columns of floats made from a chain's arrays (``spiral_cad.core.rows``): the
# four points of each (x, y, z: columns 0–11), its arc numbers (signed radius, start angle,
# sweep: 12–14), and what its curve needs besides (15–18): a line's unit direction and length,
# an arc's axis in the travel sense and first parameter. Columns, not a list per segment: a
# long chain would otherwise hold one live list per segment, and the garbage collector walks them.
Columns = list[list[float]]

# Each maker takes the columns, the segment's index, its first point as a ``gp_Pnt`` (a line's or
# spiral's start, an arc's centre) and a 4-pole array to fill (a Bézier copies its poles: one
# array serves all).


def _line_curve(c: Columns, i: int, first: gp_Pnt, poles: TColgp_Array1OfPnt) -> CurveSpan:
    return Geom_Line(first, gp_Dir(c[15][i], c[16][i], c[17][i])), 0.0, c[18][i]


def _arc_curve(c: Columns, i: int, first: gp_Pnt, poles: TColgp_Array1OfPnt) -> CurveSpan:
    """A ``Geom_Circle`` about the arc's normal e1 × e2, flipped for clockwise travel so that the
    parameter increases along the path (the point at polar angle a then has parameter -a)."""
    axis = gp_Ax2(first, gp_Dir(c[15][i], c[16][i], c[17][i]), gp_Dir(c[3][i], c[4][i], c[5][i]))
    return Geom_Circle(axis, abs(c[12][i])), c[18][i], c[18][i] + c[14][i]


def _bezier_curve(c: Columns, i: int, first: gp_Pnt, poles: TColgp_Array1OfPnt) -> CurveSpan:
    poles.SetValue(1, first)
    for k in (1, 2, 3):
        poles.SetValue(k + 1, gp_Pnt(c[3 * k][i], c[3 * k + 1][i], c[3 * k + 2][i]))
    return Geom_BezierCurve(poles), 0.0, 1.0


_MAKERS = {LINE: _line_curve, ARC: _arc_curve, SPIRAL: _bezier_curve}


def _segment_rows(segments: Any) -> SegmentRows:
    """The rows of a ``Chain`` (its own arrays) or of any segments."""
    from ..core.chain import Chain  # chain.py imports this module lazily in turn
    from ..core.rows import SegmentRows

    if isinstance(segments, Chain):
        return segments.rows
    items = list(segments)
    for segment in items:
        if not isinstance(segment, Segment):
            raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {segment!r}")
    return SegmentRows.of_segments(items)


def _columns(rows: SegmentRows, frame: _Frame) -> tuple[list[int], Columns]:
    """The kinds and ``Columns`` of ``rows`` in OCCT's coordinates (``frame``), in one pass over the arrays."""
    kind, g, p = rows.kind, rows.geometry, rows.params
    extra = np.zeros((len(kind), 4))
    with np.errstate(all="ignore"):
        line = kind == LINE
        step = g[line, 1] - g[line, 0]
        length = np.hypot(np.hypot(step[:, 0], step[:, 1]), step[:, 2])
        extra[line, :3], extra[line, 3] = step / length[:, None], length
        arc = kind == ARC
        turn = np.where(p[arc, 0] > 0.0, 1.0, -1.0)
        extra[arc, :3] = turn[:, None] * np.cross(g[arc, 1], g[arc, 2])
        extra[arc, 3] = turn * p[arc, 1]
    if not frame.flat:  # points move and turn, directions (an arc's basis, the extras) only turn
        arc_basis = frame.turn(g[arc, 1:3])
        g = frame.map(g)
        g[arc, 1:3] = arc_basis
        extra[:, :3] = frame.turn(extra[:, :3])
    table = np.concatenate([g.reshape(len(kind), 12), p, extra], axis=1)
    return kind.tolist(), table.T.tolist()


def _curves(rows: SegmentRows, frame: _Frame) -> tuple[Iterator[CurveSpan], list[gp_Pnt]]:
    """The exact curve of every segment row with its travel-order range, made as they are used,
    and each row's first point (a line's or spiral's start: ``chain_wire`` puts its vertex there)."""
    kinds, columns = _columns(rows, frame)
    firsts = [gp_Pnt(x, y, z) for x, y, z in zip(columns[0], columns[1], columns[2])]
    poles = TColgp_Array1OfPnt(1, 4)
    made = (_MAKERS[kind](columns, i, first, poles) for i, (kind, first) in enumerate(zip(kinds, firsts)))
    return made, firsts


def segment_edge(segment: Segment, plane: gp_Ax3 | None = None) -> TopoDS_Edge:
    """The exact OCCT edge of one segment, running in travel order.

    Args:
        segment: a ``Line`` (edge on a ``Geom_Line``), ``Arc`` (on a
            ``Geom_Circle``) or ``BezierSpiral`` (``Geom_BezierCurve`` with
            its four control points).
        plane: local frame of the coordinates (plane segments: its XY plane;
            segments in space: its coordinate system); None is the global one.

    Raises:
        ValueError: an unsupported segment type or a ``plane`` that is not a
            ``gp_Ax3``.
    """
    (span,) = _curves(_segment_rows([segment]), _frame(plane))[0]
    return BRepBuilderAPI_MakeEdge(*span).Edge()


def segment_edges(segments: Iterable[Segment], plane: gp_Ax3 | None = None) -> list[TopoDS_Edge]:
    """``segment_edge`` for many segments sharing one frame (a ``Chain``: from its arrays, no segment objects)."""
    return [BRepBuilderAPI_MakeEdge(*span).Edge() for span in _curves(_segment_rows(segments), _frame(plane))[0]]


def plane_ax3(plane: Any) -> gp_Ax3 | None:
    """A build123d ``Plane`` (or None) as the OCP ``gp_Ax3`` the edge makers take."""
    if plane is None:
        return None
    to_gp_ax3 = getattr(plane, "to_gp_ax3", None)
    if to_gp_ax3 is None:
        raise ValueError(f"plane must be a build123d Plane or None; got {plane!r}")
    return to_gp_ax3()


def chain_wire(chain: Iterable[Segment], plane: gp_Ax3 | None = None, *, closes: bool = True) -> TopoDS_Wire:
    """One wire of the exact edges of ``chain`` (a ``Chain`` or any segments in travel order).

    Consecutive edges share their vertex, and the wire is assembled directly
    (linear time: ``BRepBuilderAPI_MakeWire`` searches every vertex so far at
    each ``Add``, quadratic for long chains). A chain whose end meets its
    start gives a closed wire. Ends meet when they are within OCCT's vertex
    tolerance (1e-7) plus the rounding the G2 checker allows at their
    coordinates (``ROUNDING_ULPS`` units in the last place), and each vertex
    carries that tolerance (1e-7 for coordinates up to ~1e8). The ends and
    their gaps are computed for all joints at once from the segment rows. ``closes=False`` keeps a chain
    that ends where it starts open (a tool's cutting run: it stops there, it does not go on).

    Raises:
        ValueError: consecutive segments do not meet, a segment too short
            for OCCT to make an edge of, or no segments.
    """
    frame = _frame(plane)
    rows = _segment_rows(chain)
    if not len(rows):
        raise ValueError("chain_wire needs at least one segment")
    curves, firsts = _curves(rows, frame)
    ends = frame.map(row_frames(rows.kind, rows.geometry, rows.params, rows.dim)[0][:, :, :3])  # (n, 2: start, end; xyz)
    before, after = ends[:, 1], np.roll(ends[:, 0], -1, axis=0)  # joint i: end of segment i, start of the next
    tolerance = Precision.Confusion_s() + ROUNDING_ULPS * np.spacing(np.maximum(np.abs(before), np.abs(after)).max(axis=1))
    gap = norms(before - after)
    apart = np.flatnonzero(~(gap[:-1] <= tolerance[:-1]))
    if apart.size:
        i = int(apart[0])
        raise ValueError(f"segment {i + 1} does not connect to segment {i}: gap {gap[i]:.3g}")
    closed = closes and bool(gap[-1] <= tolerance[-1])
    # each vertex at its segment's start (the point a line or spiral starts from exactly), with
    # the tolerance of the joint before it; the first with the closing joint's or its own
    single = Precision.Confusion_s() + ROUNDING_ULPS * np.spacing(np.abs(ends[[0, -1], [0, 1]]).max(axis=1))
    tolerances = np.roll(tolerance, 1)
    tolerances[0] = tolerance[-1] if closed else single[0]
    builder = BRep_Builder()
    starts = [first if kind != ARC else gp_Pnt(*start) for kind, first, start in
              zip(rows.kind.tolist(), firsts, ends[:, 0].tolist())]  # fmt: skip
    if not closed:
        starts.append(gp_Pnt(*ends[-1, 1].tolist()))
    vertices = [TopoDS_Vertex() for _ in starts]
    make_vertex, add = builder.MakeVertex, builder.Add
    for vertex, point, vertex_tolerance in zip(vertices, starts, tolerances.tolist() + [float(single[1])]):
        make_vertex(vertex, point, vertex_tolerance)
    if closed:
        vertices.append(vertices[0])
    # a segment that ends where it starts (a whole circle inside the chain) runs from a vertex to itself
    for i in np.flatnonzero(norms(ends[:, 1] - ends[:, 0]) <= tolerance).tolist():
        vertices[i + 1] = vertices[i]
    wire = TopoDS_Wire()
    builder.MakeWire(wire)
    for i, ((curve, u0, u1), v0, v1) in enumerate(zip(curves, vertices, vertices[1:])):
        maker = BRepBuilderAPI_MakeEdge(curve, v0, v1, u0, u1)
        try:
            add(wire, maker.Edge())
        except Exception:  # OCCT's StdFail_NotDone: say why, below
            length, name = float(rows.lengths[i]), ("Line", "Arc", "BezierSpiral")[int(rows.kind[i])]
            short = length <= 10.0 * BRep_Tool.Tolerance_s(v0)
            raise ValueError(
                f"segment {i} ({name}, length {length:.3g}) cannot be an OCCT edge "
                f"({maker.Error().name})"
                + (
                    f": OCCT merges points closer than {BRep_Tool.Tolerance_s(v0):.3g} model units, so its edges must be "
                    "longer than that; scale the model up or use a smaller unit"
                    if short
                    else ""
                )
            ) from None
    wire.Closed(closed)
    return wire


def nurbs_edge(nurbs: Nurbs, plane: gp_Ax3 | None = None) -> TopoDS_Edge:
    """The OCCT edge on the rational B-spline ``nurbs`` (same knots, so same parameters)."""
    frame = _frame(plane)
    poles = frame.poles(nurbs.control_points.tolist())
    weights = TColStd_Array1OfReal(1, len(nurbs.weights))
    for i, w in enumerate(nurbs.weights.tolist(), 1):
        weights.SetValue(i, w)
    knots = TColStd_Array1OfReal(1, len(nurbs.knots))
    mults = TColStd_Array1OfInteger(1, len(nurbs.knots))
    for i, (k, m) in enumerate(zip(nurbs.knots.tolist(), nurbs.multiplicities.tolist()), 1):
        knots.SetValue(i, k)
        mults.SetValue(i, m)
    curve = Geom_BSplineCurve(poles, weights, knots, mults, nurbs.degree)
    return BRepBuilderAPI_MakeEdge(curve).Edge()


# ------------------------------------------------------------- console


def print_model(printer: Any, protocol: Any, path: str | os.PathLike, kind: str) -> None:
    """Print an OCCT model (``printer``: its STEP or IGES writer) to ``path`` with 17 significant digits.

    OCCT's writers print 9 (IGES) or 13 (STEP) by default; 17 keep every double.

    Raises:
        OSError: the printer failed; nothing is written.
    """
    printer.FloatWriter().SetFormat("%.16E")
    printer.SendModel(protocol)
    buffer = io.BytesIO()
    if not printer.Print(buffer):
        raise OSError(f"could not print the {kind} model for {os.fspath(path)!r}")
    with open(path, "wb") as handle:
        handle.write(buffer.getvalue())


def as_occ_shape(obj: Any) -> TopoDS_Shape:
    """One ``TopoDS_Shape`` from an OCP shape, a build123d/CadQuery shape
    (``.wrapped``), a ``Chain`` (its wire), a STEP/IGES path, or an iterable
    of those (made into a compound).

    Raises:
        ValueError: anything else.
    """
    from ..core.chain import Chain  # chain.py imports this module lazily in turn

    if isinstance(obj, TopoDS_Shape):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        return read_shape(obj)
    wrapped = getattr(obj, "wrapped", None)
    if isinstance(wrapped, TopoDS_Shape):
        return wrapped
    if isinstance(obj, Chain):
        return chain_wire(obj)
    if isinstance(obj, Iterable):
        builder = BRep_Builder()
        compound = TopoDS_Compound()
        builder.MakeCompound(compound)
        for item in obj:
            builder.Add(compound, as_occ_shape(item))
        return compound
    raise ValueError(f"expected a Chain, an OCP/build123d/CadQuery shape or a STEP/IGES path; got {type(obj).__name__}")
