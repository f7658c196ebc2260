"""OpenCASCADE (OCP) edges and wires: the one place where segments become OCCT geometry.

Lines become ``Geom_Line`` edges, arcs true ``Geom_Circle`` edges and
spirals ``Geom_BezierCurve`` edges with their exact four control points, so
every CAD adapter and exporter hands the kernel the analytic curves rather
than approximations. All edges run in travel order (their curve parameter
increases along the path), which keeps wires, sweeps and exports free of
orientation flips.

A 2-D point (x, y) is placed at ``origin + x·X + y·Y`` of an optional
``gp_Ax3`` (None: the global XY plane); counterclockwise arcs turn from X
towards Y.
"""

from __future__ import annotations

import io
import math
import os
import re
import sys
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.Geom import (
    Geom_BezierCurve,
    Geom_BSplineCurve,
    Geom_Circle,
    Geom_Curve,
    Geom_Line,
)
from OCP.gp import gp_Ax2, gp_Ax3, gp_Dir, gp_Pnt, gp_Vec
from OCP.Precision import Precision
from OCP.TColgp import TColgp_Array1OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Compound, TopoDS_Edge, TopoDS_Shape, TopoDS_Vertex, TopoDS_Wire

from ..core.segments import Arc, Line, Segment
from ..formats.joints import ROUNDING_ULPS
from ..core.spiral import BezierSpiral
from .readers import ReadError, read_shape

__all__ = ["ReadError", "as_occ_shape", "captured_messages", "chain_wire", "nurbs_edge", "read_shape", "segment_edge", "segment_edges"]

if TYPE_CHECKING:
    from ..core.nurbs import Nurbs


class _Frame:
    """Maps plane coordinates to 3-D points; precomputed once per call, not per edge."""

    __slots__ = ("ox", "oy", "oz", "xx", "xy", "xz", "yx", "yy", "yz", "normal", "x_dir", "flat")

    def __init__(self, plane: gp_Ax3 | None):
        if plane is None:
            origin, x, y = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
        else:
            if not isinstance(plane, gp_Ax3):
                raise ValueError(f"plane must be an OCP gp_Ax3 or None; got {plane!r}")
            loc, xd, yd = plane.Location(), plane.XDirection(), plane.YDirection()
            origin, x, y = (loc.X(), loc.Y(), loc.Z()), (xd.X(), xd.Y(), xd.Z()), (yd.X(), yd.Y(), yd.Z())
        self.ox, self.oy, self.oz = origin
        self.xx, self.xy, self.xz = x
        self.yx, self.yy, self.yz = y
        # The circle axis is X × Y (not the plane's main direction, which points
        # the other way for a left-handed gp_Ax3) so "counterclockwise" always
        # means turning from X towards Y.
        self.normal = gp_Dir(x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0])
        self.x_dir = gp_Dir(*x)
        self.flat = plane is None or (origin == (0.0, 0.0, 0.0) and x == (1.0, 0.0, 0.0) and y == (0.0, 1.0, 0.0))

    def pnt(self, x: float, y: float) -> gp_Pnt:
        if self.flat:
            return gp_Pnt(x, y, 0.0)
        return gp_Pnt(
            self.ox + x * self.xx + y * self.yx,
            self.oy + x * self.xy + y * self.yy,
            self.oz + x * self.xz + y * self.yz,
        )

    def poles(self, points: list[list[float]]) -> TColgp_Array1OfPnt:
        array = TColgp_Array1OfPnt(1, len(points))
        for i, (x, y) in enumerate(points, 1):
            array.SetValue(i, self.pnt(x, y))
        return array


_XY = _Frame(None)


def _frame(plane: gp_Ax3 | None) -> _Frame:
    return _XY if plane is None else _Frame(plane)


# Each segment becomes (curve, first, last): its exact OCCT curve and the
# parameter range that runs in travel order.
CurveSpan = tuple[Geom_Curve, float, float]


def _line_curve(line: Line, frame: _Frame) -> CurveSpan:
    (ax, ay), (bx, by) = line._a.tolist(), line._b.tolist()
    a, b = frame.pnt(ax, ay), frame.pnt(bx, by)
    return Geom_Line(a, gp_Dir(gp_Vec(a, b))), 0.0, a.Distance(b)


def _arc_curve(arc: Arc, frame: _Frame) -> CurveSpan:
    cx, cy = arc.center.tolist()
    radius, a0, sweep = arc.radius, arc.start_angle, arc.sweep
    if radius > 0.0:
        axis, first = frame.normal, a0
    else:
        # Clockwise travel: the circle's axis is flipped so its parameter still
        # increases along the path; the point at plane angle a has parameter -a.
        axis, first = frame.normal.Reversed(), -a0
    circle = Geom_Circle(gp_Ax2(frame.pnt(cx, cy), axis, frame.x_dir), abs(radius))
    return circle, first, first + sweep


def _bezier_curve(spiral: BezierSpiral, frame: _Frame) -> CurveSpan:
    return Geom_BezierCurve(frame.poles(spiral.control_points.tolist())), 0.0, 1.0


_MAKERS = {Line: _line_curve, Arc: _arc_curve, BezierSpiral: _bezier_curve}


def _curve_span(segment: Segment, frame: _Frame) -> CurveSpan:
    """The exact curve of ``segment`` (subclasses included) and its travel-order range."""
    maker = _MAKERS.get(type(segment))
    if maker is None:
        maker = next((m for kind, m in _MAKERS.items() if isinstance(segment, kind)), None)
        if maker is None:
            raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {segment!r}")
    return maker(segment, frame)


def segment_edge(segment: Segment, plane: gp_Ax3 | None = None) -> TopoDS_Edge:
    """The exact OCCT edge of one segment, running in travel order.

    Args:
        segment: a ``Line`` (edge on a ``Geom_Line``), ``Arc`` (on a
            ``Geom_Circle``) or ``BezierSpiral`` (``Geom_BezierCurve`` with
            its four control points).
        plane: local frame of the 2-D coordinates; None is the XY plane.

    Raises:
        ValueError: an unsupported segment type or a ``plane`` that is not a
            ``gp_Ax3``.
    """
    return BRepBuilderAPI_MakeEdge(*_curve_span(segment, _frame(plane))).Edge()


def segment_edges(segments: Iterable[Segment], plane: gp_Ax3 | None = None) -> list[TopoDS_Edge]:
    """``segment_edge`` for many segments sharing one frame (a chain, a transition's spirals)."""
    frame = _frame(plane)
    return [BRepBuilderAPI_MakeEdge(*_curve_span(s, frame)).Edge() for s in segments]


def chain_wire(chain: Iterable[Segment], plane: gp_Ax3 | None = None) -> TopoDS_Wire:
    """One wire of the exact edges of ``chain`` (a ``Chain`` or any segments in travel order).

    Consecutive edges share their vertex, and the wire is assembled directly
    (linear time: ``BRepBuilderAPI_MakeWire`` searches every vertex so far at
    each ``Add``, quadratic for long chains). A chain whose end meets its
    start gives a closed wire. Ends meet when they are within OCCT's vertex
    tolerance (1e-7) plus the rounding the G2 checker allows at their
    coordinates (``ROUNDING_ULPS`` units in the last place), and each vertex
    carries that tolerance (1e-7 for coordinates up to ~1e8).

    Raises:
        ValueError: consecutive segments do not meet, a segment too short
            for OCCT to make an edge of, or no segments.
    """
    frame = _frame(plane)
    segments = list(chain)
    spans = [_curve_span(s, frame) for s in segments]
    if not spans:
        raise ValueError("chain_wire needs at least one segment")
    ends = [(curve.Value(first), curve.Value(last)) for curve, first, last in spans]
    builder = BRep_Builder()
    vertices = [_vertex(builder, ends[0][0], ends[0][0])]
    for i, ((_, end), (start, _)) in enumerate(zip(ends, ends[1:])):
        if end.Distance(start) > _tolerance(end, start):
            raise ValueError(f"segment {i + 1} does not connect to segment {i}: gap {end.Distance(start):.3g}")
        vertices.append(_vertex(builder, end, start))
    closed = ends[-1][1].Distance(ends[0][0]) <= _tolerance(ends[-1][1], ends[0][0])
    if closed:
        vertices[0] = _vertex(builder, ends[0][0], ends[-1][1])
    vertices.append(vertices[0] if closed else _vertex(builder, ends[-1][1], ends[-1][1]))
    wire = TopoDS_Wire()
    builder.MakeWire(wire)
    for i, ((curve, first, last), v0, v1) in enumerate(zip(spans, vertices, vertices[1:])):
        maker = BRepBuilderAPI_MakeEdge(curve, v0, v1, first, last)
        if not maker.IsDone():
            short = segments[i].length <= 10.0 * BRep_Tool.Tolerance_s(v0)
            raise ValueError(
                f"segment {i} ({type(segments[i]).__name__}, length {segments[i].length:.3g}) cannot be an OCCT edge "
                f"({maker.Error().name})"
                + (
                    f": OCCT merges points closer than {BRep_Tool.Tolerance_s(v0):.3g} model units, so its edges must be "
                    "longer than that; scale the model up or use a smaller unit"
                    if short
                    else ""
                )
            )
        builder.Add(wire, maker.Edge())
    wire.Closed(closed)
    return wire


def _tolerance(a: gp_Pnt, b: gp_Pnt) -> float:
    """How far apart two edge ends may be and share a vertex: OCCT's 1e-7 plus the rounding the
    G2 checker allows at their coordinates (``ROUNDING_ULPS`` units in the last place)."""
    magnitude = max(abs(a.X()), abs(a.Y()), abs(a.Z()), abs(b.X()), abs(b.Y()), abs(b.Z()))
    return Precision.Confusion_s() + ROUNDING_ULPS * math.ulp(magnitude)


def _vertex(builder: BRep_Builder, point: gp_Pnt, other: gp_Pnt) -> TopoDS_Vertex:
    """The vertex at ``point`` shared with an edge end at ``other``, with that joint's tolerance."""
    vertex = TopoDS_Vertex()
    builder.MakeVertex(vertex, point, _tolerance(point, other))
    return vertex


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

_ANSI = re.compile(r"\x1b\[[0-9;]*m")


@contextmanager
def captured_messages() -> Iterator[list[str]]:
    """Capture everything OCCT prints (its messenger writes to the process's stdout and stderr).

    Yields a list that holds the printed lines, ANSI colour codes removed,
    once the block ends; nothing reaches the console.
    """
    lines: list[str] = []
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            text = _ANSI.sub("", sink.read().decode("utf-8", "replace"))
            lines.extend(line for line in text.splitlines() if line.strip())


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
