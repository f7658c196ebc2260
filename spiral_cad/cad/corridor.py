"""Roads in 3-D as OCCT/build123d shapes: the 3-D centre line as a wire, the corridor as a solid.

``centerline_wire`` turns a ``Centerline3D`` into one wire with one edge per
plan segment (a rational cubic B-spline through its pieces; plan exact).
``corridor`` sweeps a ``CrossSection`` — lanes and shoulders, the crown's
crossfall on tangents and the pavement depth — with the superelevation
along alignment and profile into a closed build123d ``Solid``: per plan
segment one ruled B-spline face per lane and shoulder on top, one per
side below, one vertical face at each outer edge, and a planar face at each
end, sewn and checked (``BRepCheck_Analyzer``) before it is returned.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
    BRepBuilderAPI_MakeSolid,
    BRepBuilderAPI_MakeVertex,
    BRepBuilderAPI_Sewing,
)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.gp import gp_Pnt
from OCP.Precision import Precision
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
from OCP.TopAbs import TopAbs_SHELL
from OCP.TopoDS import TopoDS, TopoDS_Wire

from ..core.units import to_metres
from ..design.centerline import Centerline3D, centerline_3d
from ..design.profile import Profile
from ..design.roadway import Roadway, roadway
from ..design.superelevation import Superelevation
from ..io.opendrive import CrossSection


@dataclass(frozen=True)
class Corridor:
    """A road's body: the solid, its faces by role, and the numbers they were built from.

    Attributes:
        solid: the closed, valid build123d ``Solid``.
        faces: role → faces of ``solid``: ``"lane 1"`` … (OpenDRIVE lane ids,
            left positive), ``"bottom"``, ``"side"``, ``"end"``.
        roadway: the swept cross-section edges (``spiral_cad.design.roadway``).
        centerline: the 3-D centre line.
    """

    solid: Any
    faces: dict[str, list] = field(repr=False)
    roadway: Roadway = field(repr=False)
    centerline: Centerline3D = field(repr=False)

    @property
    def deviation(self) -> float:
        """The largest measured distance of the solid's edges and centre line from the exact road."""
        return max(self.roadway.deviation, self.centerline.deviation)

    def describe(self) -> str:
        units = self.roadway.units
        return (
            f"corridor: 1 solid, {sum(len(f) for f in self.faces.values())} faces, volume {self.solid.volume:.6g} {units}³; "
            f"edges within {self.roadway.deviation:.2g} {units} (tolerance {self.roadway.tolerance:.2g} {units})"
        )


def centerline_wire(centerline: Centerline3D) -> Any:
    """The 3-D centre line as one build123d ``Wire``: an edge per plan segment, its pieces as one
    rational cubic B-spline (knots at the piece ends, spans their plan lengths).

    Raises:
        ValueError: consecutive segments further apart than OCCT's vertex tolerance.
    """
    from build123d import Wire

    curves = []
    for k in np.unique(centerline.segment):
        rows = np.flatnonzero(centerline.segment == k)
        spans = np.diff(centerline.stations[np.append(rows, rows[-1] + 1)])
        curves.append(_bspline_curve(centerline.control_points[rows], centerline.weights[rows], spans))
    ends = [(c.Value(c.FirstParameter()), c.Value(c.LastParameter())) for c in curves]
    vertices = [BRepBuilderAPI_MakeVertex(ends[0][0]).Vertex()]
    for i, ((_, end), (start, _)) in enumerate(zip(ends, ends[1:])):
        if end.Distance(start) > Precision.Confusion_s():
            raise ValueError(f"plan segment {i + 1} does not connect to segment {i}: gap {end.Distance(start):.3g}")
        vertices.append(BRepBuilderAPI_MakeVertex(end).Vertex())
    vertices.append(BRepBuilderAPI_MakeVertex(ends[-1][1]).Vertex())
    builder = BRep_Builder()
    wire = TopoDS_Wire()
    builder.MakeWire(wire)
    for curve, v0, v1 in zip(curves, vertices, vertices[1:]):
        builder.Add(wire, BRepBuilderAPI_MakeEdge(curve, v0, v1, curve.FirstParameter(), curve.LastParameter()).Edge())
    return Wire(wire)


def corridor(
    alignment: Any,
    profile: Profile,
    cross_section: CrossSection = CrossSection(),
    *,
    superelevation: Superelevation | None = None,
    tolerance: float | None = None,
) -> Corridor:
    """Sweep ``cross_section`` along ``alignment`` and ``profile`` into a valid solid.

    Args:
        alignment: the horizontal ``Alignment``.
        profile: its ``Profile``.
        cross_section: lanes and shoulders, crossfall and pavement depth
            (widths and depth in metres, converted to the alignment's unit).
        superelevation: the banking (default: from the alignment's criteria;
            level without them).
        tolerance: the largest distance of any edge from the exact road
            (default 1e-6 × the alignment's length).

    Raises:
        ValueError: bad input (see ``spiral_cad.design.roadway``), or a solid
            OCCT does not find valid (never returned).
    """
    units = alignment.chain.units
    metres = to_metres(units)
    if not isinstance(cross_section, CrossSection):
        raise ValueError(f"cross_section must be a CrossSection; got {type(cross_section).__name__}")
    offsets = section_offsets(cross_section) / metres
    road = roadway(alignment, profile, offsets, superelevation, cross_section.crossfall, cross_section.depth / metres, tolerance)
    line = centerline_3d(alignment, profile, tolerance)
    try:
        solid, faces = _sewn_solid(road, _lane_roles(cross_section))
    except Exception as error:  # OCCT's own exceptions (Standard_*) become ValueError; anything else is a bug
        if not type(error).__module__.startswith("OCP"):
            raise
        raise ValueError(f"OCCT could not build the corridor ({type(error).__name__}: {error})") from None
    return Corridor(solid, faces, road, line)


def _sewn_solid(road: Roadway, roles: list[str]) -> tuple[Any, dict[str, list]]:
    """The faces of the road per plan segment and its two ends, sewn into one checked solid, and the faces by role."""
    from build123d import Face, Solid

    pieces: list[tuple[str, Any]] = []
    for k in np.unique(road.segment):
        rows = np.flatnonzero(road.segment == k)
        spans = np.diff(road.stations[np.append(rows, rows[-1] + 1)])
        top = [road.edges[v, rows] for v in range(len(road.offsets))]
        for v, role in enumerate(roles):
            pieces.append((role, _ruled(top[v], top[v + 1], spans)))
        bottom = [road.bottom(v)[rows] for v in (0, road.centre, len(road.offsets) - 1)]
        pieces.append(("bottom", _ruled(bottom[1], bottom[0], spans)))
        pieces.append(("bottom", _ruled(bottom[2], bottom[1], spans)))
        pieces.append(("side", _ruled(bottom[0], top[0], spans)))
        pieces.append(("side", _ruled(top[-1], bottom[2], spans)))
    for end in (0, 1):
        pieces.append(("end", _polygon(road.section(end))))
    size = float(np.ptp(road.edges.reshape(-1, 3), axis=0).max())
    sewing = BRepBuilderAPI_Sewing(max(1e-9 * size, 1e-3 * Precision.Confusion_s()))
    for _, face in pieces:
        sewing.Add(face)
    sewing.Perform()
    shell = sewing.SewedShape()
    if shell.IsNull() or shell.ShapeType() != TopAbs_SHELL or sewing.NbFreeEdges() or sewing.NbMultipleEdges():
        raise ValueError(
            f"the corridor's faces do not close into one shell ({sewing.NbFreeEdges()} free, {sewing.NbMultipleEdges()} multiple edges)"
        )
    solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell_s(shell)).Solid()
    BRepLib.OrientClosedSolid_s(solid)
    if not BRepCheck_Analyzer(solid).IsValid():
        raise ValueError("OCCT finds the corridor solid invalid; nothing is returned")
    result = Solid(solid)
    if not result.volume > 0.0:
        raise ValueError(f"the corridor solid has volume {result.volume!r}; nothing is returned")
    faces: dict[str, list] = {}
    for role, face in pieces:
        faces.setdefault(role, []).append(Face(sewing.Modified(face)))
    return result, faces


def section_offsets(cross_section: CrossSection) -> NDArray:
    """Lateral offsets (m, left positive, decreasing) of the lane and shoulder edges and the centre line."""
    edges = [cross_section.lane_width * k for k in range(1, cross_section.driving_lanes + 1)]
    if cross_section.shoulder_width > 0:
        edges.append(edges[-1] + cross_section.shoulder_width)
    side = np.array(edges)
    return np.concatenate([side[::-1], [0.0], -side])


def _lane_roles(cross_section: CrossSection) -> list[str]:
    """The OpenDRIVE lane of every top strip, left to right."""
    count = cross_section.driving_lanes + (1 if cross_section.shoulder_width > 0 else 0)
    return [f"lane {k}" for k in range(count, 0, -1)] + [f"lane {-k}" for k in range(1, count + 1)]


def _knots(spans: NDArray, degree: int) -> tuple[TColStd_Array1OfReal, TColStd_Array1OfInteger]:
    """Knots at the cumulative ``spans`` (0 first), end multiplicity degree + 1, interior ``degree``."""
    values = np.concatenate([[0.0], np.cumsum(spans)]).tolist()
    knots = TColStd_Array1OfReal(1, len(values))
    mults = TColStd_Array1OfInteger(1, len(values))
    for i, value in enumerate(values, 1):
        knots.SetValue(i, value)
        mults.SetValue(i, degree + 1 if i in (1, len(values)) else degree)
    return knots, mults


def _chained(pieces: NDArray) -> NDArray:
    """(pn + 1, d) poles of n Bézier pieces (n, p + 1, d) of degree p that share their ends (the earlier piece's end is kept)."""
    return np.concatenate([pieces[0], *[p[1:] for p in pieces[1:]]])


def _bspline_curve(pieces: NDArray, weights: NDArray, spans: NDArray) -> Geom_BSplineCurve:
    poles = _chained(pieces)
    array = TColgp_Array1OfPnt(1, len(poles))
    for i, (x, y, z) in enumerate(poles.tolist(), 1):
        array.SetValue(i, gp_Pnt(x, y, z))
    degree = pieces.shape[1] - 1
    knots, mults = _knots(spans, degree)
    if np.all(weights == 1.0):
        return Geom_BSplineCurve(array, knots, mults, degree)
    w = TColStd_Array1OfReal(1, len(poles))
    for i, value in enumerate(_chained(weights[..., None])[:, 0].tolist(), 1):
        w.SetValue(i, value)
    return Geom_BSplineCurve(array, w, knots, mults, degree)


def _ruled(first: NDArray, second: NDArray, spans: NDArray) -> Any:
    """The face ruled between two edges given as Bézier pieces (n, 4, 3) on the same knot spans."""
    a, b = _chained(first), _chained(second)
    poles = TColgp_Array2OfPnt(1, len(a), 1, 2)
    for i, (p, q) in enumerate(zip(a.tolist(), b.tolist()), 1):
        poles.SetValue(i, 1, gp_Pnt(*p))
        poles.SetValue(i, 2, gp_Pnt(*q))
    u_knots, u_mults = _knots(spans, 3)
    v_knots, v_mults = _knots(np.array([1.0]), 1)
    surface = Geom_BSplineSurface(poles, u_knots, v_knots, u_mults, v_mults, 3, 1)
    return BRepBuilderAPI_MakeFace(surface, Precision.Confusion_s()).Face()


def _polygon(points: NDArray) -> Any:
    polygon = BRepBuilderAPI_MakePolygon()
    for p in points.tolist():
        polygon.Add(gp_Pnt(*p))
    polygon.Close()
    return BRepBuilderAPI_MakeFace(polygon.Wire(), True).Face()
