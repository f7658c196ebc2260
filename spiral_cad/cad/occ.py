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
from pathlib import Path
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


# ------------------------------------------------------------- file input

STEP_SUFFIXES = (".step", ".stp")
IGES_SUFFIXES = (".iges", ".igs")
#: OCCT's names for the target unit of its readers.
_READ_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "INCH", "ft": "FT"}
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


class ReadError(ValueError):
    """A STEP/IGES file that the reader rejected or could not read whole; the message gives its reason."""


def read_shape(path: str | os.PathLike, units: str = "mm") -> TopoDS_Shape:
    """Read a STEP (.step/.stp) or IGES (.igs/.iges) file into one shape, in ``units``.

    OCCT's readers convert from the unit the file declares to ``units``
    (default mm, as FreeCAD and build123d read). A file is accepted only if
    the reader read it whole: a syntax error, a truncated file (no end
    section) or entities that failed to load raise ``ReadError`` with the
    reader's own messages. Nothing the reader prints reaches the console.

    Raises:
        ReadError: the reader failed, or reported failed entities.
        ValueError: unknown suffix, missing file or unknown ``units``.
    """
    from OCP.IFSelect import IFSelect_RetDone

    from ..core.units import MM_PER_UNIT, length_unit

    p = Path(path)
    suffix = p.suffix.lower()
    length_unit(units)
    if suffix not in STEP_SUFFIXES + IGES_SUFFIXES:
        raise ValueError(f"cannot read {p.name!r}: expected a .step/.stp or .igs/.iges file")
    if not p.is_file():
        raise ValueError(f"cannot read {str(p)!r}: no such file")
    kind = "STEP" if suffix in STEP_SUFFIXES else "IGES"
    if kind == "IGES":
        _check_iges_sections(p)  # OCCT's IGES reader can crash on a truncated file
    with captured_messages() as printed:
        if kind == "STEP":
            from OCP.STEPControl import STEPControl_Reader

            reader = STEPControl_Reader()
            status = reader.ReadFile(str(p))
            reader.SetSystemLengthUnit(MM_PER_UNIT[units])
            transfer = reader.TransferRoots
        else:
            from OCP.IGESControl import IGESControl_Controller, IGESControl_Reader
            from OCP.Interface import Interface_Static

            IGESControl_Controller.Init_s()
            # The IGES reader takes its target unit from this session setting
            # when it reads the file; it is restored at once.
            previous = Interface_Static.CVal_s("xstep.cascade.unit")
            Interface_Static.SetCVal_s("xstep.cascade.unit", _READ_UNIT[units])
            try:
                reader = IGESControl_Reader()
                status = reader.ReadFile(str(p))
            finally:
                Interface_Static.SetCVal_s("xstep.cascade.unit", previous)
            transfer = reader.TransferRoots

        failures = _reader_failures(reader) if status == IFSelect_RetDone else []
        if status == IFSelect_RetDone and not failures:
            roots = reader.NbRootsForTransfer()
            transferred = transfer()
            if transferred < roots:
                failures.append(f"only {transferred} of {roots} root entities could be transferred")
    if status != IFSelect_RetDone or failures:
        reasons = failures or _printed_reasons(printed) or [status.name]
        more = f" (and {len(reasons) - 3} more)" if len(reasons) > 3 else ""
        raise ReadError(f"cannot read {p.name!r}: the {kind} reader reports: " + "; ".join(reasons[:3]) + more)
    shape = reader.OneShape()
    if shape.IsNull():
        raise ReadError(f"cannot read {p.name!r}: the {kind} reader found no transferable geometry")
    return shape


def _check_iges_sections(path: Path) -> None:
    """Refuse an IGES file whose sections disagree with its terminate record (cut short or damaged).

    Every IGES record carries its section letter in column 73 (S, G, D, P,
    T); the single T record at the end counts the S, G, D and P records.
    """
    counts = {"S": 0, "G": 0, "D": 0, "P": 0, "T": 0}
    last = ""
    with open(path, "rb") as handle:
        for raw in handle:
            record = raw.rstrip(b"\r\n")
            letter = chr(record[72]) if len(record) >= 73 else "?"
            if letter in counts:
                counts[letter] += 1
                last = record.decode("ascii", "replace") if letter == "T" else last
    if counts["T"] != 1:
        raise ReadError(f"cannot read {path.name!r}: no IGES terminate section (the file is cut short or not IGES)")
    declared = {}
    for key, start in (("S", 0), ("G", 8), ("D", 16), ("P", 24)):
        field = last[start : start + 8]
        try:
            declared[key] = int(field[1:])
        except ValueError:
            raise ReadError(f"cannot read {path.name!r}: damaged IGES terminate record {last[:32]!r}") from None
    found = {key: counts[key] for key in declared}
    if found != declared:
        raise ReadError(
            f"cannot read {path.name!r}: the IGES terminate record declares {declared} records per section, "
            f"the file holds {found} (cut short or damaged)"
        )


def _reader_failures(reader: Any) -> list[str]:
    """The reader's failure messages (and a missing end of file), de-duplicated, in order."""
    found: list[str] = []
    checks = reader.WS().ModelCheckList()
    checks.Start()
    while checks.More():
        check = checks.Value()
        texts = [check.CFail(i) for i in range(1, check.NbFails() + 1)]
        texts += [w for w in (check.CWarning(i) for i in range(1, check.NbWarnings() + 1)) if "Terminate Section" in w]
        for text in texts:
            text = text.strip()
            if text and text not in found:
                found.append(text)
        checks.Next()
    return found


def _printed_reasons(printed: list[str]) -> list[str]:
    """Error lines the reader printed (its only report of a syntax error)."""
    lines = [line.strip(" *") for line in printed if "ERR" in line or "rror" in line]
    return [line for line in lines if line]


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
