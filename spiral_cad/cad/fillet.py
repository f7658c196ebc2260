"""G2 fillets on OCCT wires and faces: planar lines and arcs in, exact LINE/CIRCLE/BEZIER edges out.

The numeric work is ``spiral_cad.design.fillets``; this module reads a
planar OCCT wire into lines and arcs in its plane, rounds the chosen
vertices and builds the wire (or face) again with shared vertices, closing
joint included. build123d's ``g2_fillet`` and the CadQuery plugin call it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepLib import BRepLib_FindSurface
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.Geom import Geom_BSplineCurve
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Ax3, gp_Pnt, gp_Vec
from OCP.Precision import Precision
from OCP.TopAbs import TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Wire

from ..continuity.joints import Continuity
from ..core.errors import NoSolutionError
from ..core.inputs import as_float
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..design.fillets import FilletedPath, fillet_path
from .advice import advice, refusal
from .occ import chain_wire

__all__ = ["fillet_face", "fillet_wire", "planar_frame", "wire_path"]

#: Points further than this (relative to the wire's size) from its plane make it non-planar.
PLANAR_TOL = 1e-9


def planar_frame(shape) -> gp_Ax3:
    """The plane of a planar wire or face as a ``gp_Ax3`` (a face's own plane, oriented as the face).

    The frame's origin is the plane's point nearest the world origin, so plane
    coordinates are as large as world ones: a corner far from the origin is
    judged with the rounding its world coordinates really carry.

    Raises:
        ValueError: the shape does not lie in one plane.
    """
    if isinstance(shape, TopoDS_Face):
        surface = GeomAdaptor_Surface(BRep_Tool.Surface_s(shape))
        if surface.GetType() != GeomAbs_SurfaceType.GeomAbs_Plane:
            raise ValueError("g2 fillets need a planar face; this face is curved")
        frame = surface.Plane().Position()
        if shape.Orientation() == TopAbs_REVERSED:
            frame.ZReverse()
    else:
        finder = BRepLib_FindSurface(shape, 1e-7, True)
        if not finder.Found():
            raise ValueError("g2 fillets need a planar wire; this wire does not lie in one plane (or is a single straight line)")
        frame = GeomAdaptor_Surface(finder.Surface()).Plane().Position()
    location, normal = gp_Vec(frame.Location().XYZ()), gp_Vec(frame.Direction())
    frame.SetLocation(gp_Pnt(normal.Multiplied(location.Dot(normal)).XYZ()))
    return frame


def _local(frame: gp_Ax3, p: gp_Pnt) -> tuple[float, float, float]:
    v = gp_Vec(frame.Location(), p)
    return v.Dot(gp_Vec(frame.XDirection())), v.Dot(gp_Vec(frame.YDirection())), v.Dot(gp_Vec(frame.Direction()))


def wire_path(wire: TopoDS_Wire, frame: gp_Ax3, *, spirals: bool = False) -> tuple[list[Segment], bool]:
    """The wire's edges, in connection order, as lines and arcs in the frame's plane coordinates
    (and, with ``spirals``, cubic Bézier edges as ``BezierSpiral``: the outlines of G2 sketches).

    Raises:
        ValueError: an edge other than a line or circular arc (named by its
            index and curve type), or a point off the plane.
    """
    segments: list[Segment] = []
    lifts: list[float] = []
    explorer = BRepTools_WireExplorer(wire)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        index = len(segments)
        curve = BRepAdaptor_Curve(edge)
        first, last = curve.FirstParameter(), curve.LastParameter()
        reverse = edge.Orientation() == TopAbs_REVERSED
        t0, t1 = (last, first) if reverse else (first, last)
        (x0, y0, z0), (x1, y1, z1) = _local(frame, curve.Value(t0)), _local(frame, curve.Value(t1))
        lifts += [z0, z1]
        kind = curve.GetType()
        if kind == GeomAbs_CurveType.GeomAbs_Line:
            segments.append(Line((x0, y0), (x1, y1)))
        elif kind == GeomAbs_CurveType.GeomAbs_Circle:
            cx, cy, cz = _local(frame, curve.Circle().Location())
            lifts.append(cz)
            derivative = curve.DN(t0, 1)
            dx, dy = derivative.Dot(gp_Vec(frame.XDirection())), derivative.Dot(gp_Vec(frame.YDirection()))
            sense = 1.0 if ((x0 - cx) * dy - (y0 - cy) * dx) * (-1.0 if reverse else 1.0) > 0 else -1.0
            radius = sense * curve.Circle().Radius()
            sweep = abs(t1 - t0)  # circle parameters are angles
            segments.append(Arc((cx, cy), radius, math.atan2(y0 - cy, x0 - cx), sweep))
        elif (
            spirals
            and kind == GeomAbs_CurveType.GeomAbs_BezierCurve
            and curve.Degree() == 3
            and not curve.IsRational()
            and (first, last) == (0.0, 1.0)
        ):
            poles = [_local(frame, curve.Bezier().Pole(k)) for k in range(1, 5)]
            lifts += [p[2] for p in poles]
            points = [(x, y) for x, y, _ in (poles[::-1] if reverse else poles)]
            segments.append(BezierSpiral.from_control_points(points))
        elif spirals and kind == GeomAbs_CurveType.GeomAbs_BSplineCurve:
            # a builder (BuildSketch) merges joined Bézier spirals into one B-spline: read its cubic spans back
            pieces = _bezier_spans(curve, first, last)
            if pieces is None:
                raise ValueError(
                    f"a wire is read as lines, circular arcs and cubic spirals; edge {index} is a BSPLINE curve that is not joined cubic "
                    "Bézier spans (degree 3, non-rational, its whole knot range): pass "
                    "the continuous sketch object itself (not the builder's sketch) or its Chain"
                )
            for poles in pieces[::-1] if reverse else pieces:
                local = [_local(frame, p) for p in poles]
                lifts += [p[2] for p in local]
                points = [(x, y) for x, y, _ in (local[::-1] if reverse else local)]
                segments.append(BezierSpiral.from_control_points(points))
        else:
            name = kind.name.removeprefix("GeomAbs_").removesuffix("Curve").upper()
            raise ValueError(f"a wire is read as lines, circular arcs and cubic spirals; edge {index} is a {name} curve")
        explorer.Next()
    if not segments:
        raise ValueError("the wire has no edges")
    size = max(s.length for s in segments)
    lift = max(abs(z) for z in lifts)
    if lift > PLANAR_TOL * size + 1e-7:
        raise ValueError(f"g2 fillets need a planar wire; its points leave the plane by {lift:.3g}")
    closed = BRep_Tool.IsClosed_s(wire) or math.dist(segments[-1].ends[1][:2], segments[0].ends[0][:2]) <= 1e-9 * size
    return segments, closed


def _bezier_spans(curve: BRepAdaptor_Curve, first: float, last: float) -> list[list[gp_Pnt]] | None:
    """The poles of the cubic Bézier spans of a non-rational, non-periodic cubic B-spline edge over its whole
    knot range (its interior knots raised to multiplicity 3: exact), else None."""
    if curve.Degree() != 3 or curve.IsRational():
        return None
    spline = curve.BSpline().Copy()  # the edge keeps its own curve
    assert isinstance(spline, Geom_BSplineCurve)
    if spline.IsPeriodic() or (first, last) != (spline.FirstParameter(), spline.LastParameter()):
        return None
    for k in range(2, spline.NbKnots()):
        spline.IncreaseMultiplicity(k, 3)
    poles = [spline.Pole(k) for k in range(1, spline.NbPoles() + 1)]
    return [poles[3 * k : 3 * k + 4] for k in range(spline.NbKnots() - 1)]


def _vertex_indices(segments: Sequence[Segment], closed: bool, frame: gp_Ax3, points: Iterable | None) -> list[int] | None:
    """Indices of the wire's vertices at ``points`` (3-D tuples); None means every corner."""
    if points is None:
        return None
    size = max(s.length for s in segments)
    starts = [s.ends[0][:2] for s in segments]
    chosen = []
    for point in points:
        x, y, _ = _local(frame, gp_Pnt(*point))
        for i, (sx, sy) in enumerate(starts):
            if math.hypot(x - sx, y - sy) <= 1e-7 * max(size, 1.0) and (closed or i > 0):
                chosen.append(i)
    return chosen


def fillet_wire(
    wire: TopoDS_Wire,
    radius: float,
    vertices: Iterable | None = None,
    *,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = "walton-meek",
    frame: gp_Ax3 | None = None,
    _advise: bool = True,
) -> tuple[TopoDS_Wire, FilletedPath]:
    """Round the wire's corners at ``vertices`` (3-D points; None: every corner) with G2 fillets.

    Returns the new wire (LINE, CIRCLE and BEZIER edges on shared vertices,
    closed when the input was) and the numeric result. Vertices that are not
    corners of this wire are ignored (they may belong to another wire of a face).

    Raises:
        ValueError: a non-planar wire or an edge that is not a line or arc.
        NoSolutionError: a corner that cannot be rounded (named, with numbers),
            also when a piece of it would be shorter than OCCT can hold (2e-7).
    """
    frame = planar_frame(wire) if frame is None else frame
    segments, closed = wire_path(wire, frame)
    chosen = _vertex_indices(segments, closed, frame, vertices)
    options = dict(transition=transition, vertices=chosen, closed=closed, same_sense=same_sense, shape=shape)
    try:
        result = fillet_path(segments, radius, **options)  # type: ignore[arg-type]
    except NoSolutionError as error:
        if not _advise:
            raise
        again = dict(transition=transition, same_sense=same_sense, shape=shape, frame=frame, _advise=False)
        fits = advice(
            lambda r: _fillets(segments, r, options),
            lambda r: fillet_wire(wire, r, vertices, **again),
            as_float(radius, "radius"),
        )
        raise refusal(str(error), "radius", fits) from None
    if not result.corners:  # nothing to round: the wire stays as it was
        return wire, result
    shortest = 2.0 * Precision.Confusion_s()
    for i, (segment, owner) in enumerate(zip(result.segments, result.owners)):
        if not segment.length > shortest:
            near = owner if owner is not None else next(o for o in result.owners[i:] + result.owners[:i] if o is not None)
            what = "the fillet" if owner is not None else "the edge it trims"
            raise NoSolutionError(
                f"corner {near}: a {type(segment).__name__} of {what} is {segment.length:.3g} long; OCCT merges "
                f"points closer than {Precision.Confusion_s():g} model units, so no edge can be shorter than "
                f"{shortest:g}: use a larger radius, or a smaller unit for the model"
            )
    rounded = chain_wire(result.segments, frame)
    _verify(rounded, result)
    return rounded, result


def _fillets(segments: list[Segment], radius: float, options: dict) -> bool:
    """Whether ``fillet_path`` rounds the corners with ``radius`` (a refusal's advice bisects on it)."""
    try:
        fillet_path(segments, radius, **options)
    except NoSolutionError:
        return False
    return True


def _verify(wire: TopoDS_Wire, result: FilletedPath) -> None:
    """NoSolutionError unless the G2 checker (``spiral_cad.cad.continuity``, default tolerances) grades
    every joint of every rounded corner G2 in the built wire: float64 rounding of 3-D coordinates
    may break what held in the plane (a tiny fillet far from the origin or on a tilted plane)."""
    from .continuity import check_continuity  # late: the checker imports the edge makers of this layer

    report = check_continuity(wire)
    count = len(result.segments)
    if report.pieces != 1 or report.wires[0].edge_count != count:
        raise NoSolutionError(f"the rounded wire does not read back as one wire of {count} edges: {report.describe()}")
    for joint in report.wires[0].joints:
        owner = result.owners[joint.index]
        owner = owner if owner is not None else result.owners[(joint.index + 1) % count]
        if owner is not None and joint.level < Continuity.G2:
            raise NoSolutionError(
                f"corner {owner}: in 3-D its wire is only {joint.level.name} at joint {joint.index} (gap {joint.gap:.3g}, "
                f"tangent angle {joint.angle:.3g} rad, relative curvature jump {joint.relative_curvature_jump:.3g}; the "
                f"G2 checker allows {report.gap_tol:g}, {report.angle_tol:g} and {report.curvature_tol:g}): float64 "
                "cannot hold this fillet at these coordinates; use a larger radius, or move the model nearer the origin"
            )


def fillet_face(
    face: TopoDS_Face,
    radius: float,
    vertices: Iterable | None = None,
    *,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = "walton-meek",
    _advise: bool = True,
) -> TopoDS_Face:
    """Round the corners of a planar face (outer and inner wires) at ``vertices`` (None: every corner).

    Raises:
        ValueError, NoSolutionError: as ``fillet_wire``; the face is rebuilt
        on its own plane and keeps its orientation.
    """
    frame = planar_frame(face)
    points = None if vertices is None else list(vertices)
    outer = BRepTools.OuterWire_s(face)
    wires = [outer] + [w for w in _wires(face) if not w.IsSame(outer)]
    options = dict(transition=transition, same_sense=same_sense, shape=shape, frame=frame, _advise=False)
    try:
        rounded = [fillet_wire(w, radius, points, **options)[0] for w in wires]
    except NoSolutionError as error:
        if not _advise or "fits" in str(error):
            raise
        paths = [wire_path(w, frame) for w in wires]
        chosen = [_vertex_indices(segments, closed, frame, points) for segments, closed in paths]
        fits = advice(
            lambda r: all(
                _fillets(segments, r, dict(transition=transition, vertices=c, closed=closed, same_sense=same_sense, shape=shape))
                for (segments, closed), c in zip(paths, chosen)
            ),  # fmt: skip
            lambda r: fillet_face(face, r, points, transition=transition, same_sense=same_sense, shape=shape, _advise=False),
            as_float(radius, "radius"),
        )
        raise refusal(str(error), "radius", fits) from None
    maker = BRepBuilderAPI_MakeFace(BRep_Tool.Surface_s(face), rounded[0], True)
    for inner in rounded[1:]:
        maker.Add(inner)
    if not maker.IsDone():
        raise ValueError(f"the rounded wires do not make a face ({maker.Error().name})")
    result = maker.Face()
    return TopoDS.Face_s(result.Reversed()) if face.Orientation() != result.Orientation() else result


def _wires(face: TopoDS_Face) -> list[TopoDS_Wire]:
    found, explorer = [], TopExp_Explorer(face, TopAbs_WIRE)
    while explorer.More():
        found.append(TopoDS.Wire_s(explorer.Current()))
        explorer.Next()
    return found
