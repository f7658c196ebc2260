"""G0/G1/G2 continuity of faces across every edge they share: the face-to-face checker.

For every edge shared by two faces (and every seam edge, where a closed face
meets itself) the edge is sampled at ``samples`` interior points. At each
point both faces give, from their surface derivatives at the point's
parameters on the edge's pcurve:

* the surface point — the **gap** is the distance between the two;
* the oriented unit normal (flipped for a face REVERSED in its shell) — the
  **angle** is the angle between the two;
* the **normal curvature across the edge**, in the direction d = n × t of
  the common tangent plane (t the edge's unit tangent). Two surfaces that
  meet G1 along a curve are curvature continuous there exactly when their
  normal curvatures agree in one direction transversal to the curve (Pegna
  and Wolter's linkage-curve theorem), so the **jump** is
  ``|κa − κb| / max(|κa|, |κb|, 1/size)`` — relative, as the curve checker's.

The worst value of each along the edge, and where it was, give the edge's
class (``EDGE_CLASSES``): ``"unmeasurable"`` (no sample gave a point or a normal), ``"gap"`` (the faces do not meet: gap above
``gap_tol`` × model size), ``"sharp"`` (normals further apart than
``feature_angle``: a feature — a box's edge — listed, never failed),
``"crease"`` (an angle above ``angle_tol`` but below ``feature_angle``: a
near-tangent kink, a defect), ``"G1"`` (tangent, the curvature jumps),
``"G2"``. An edge is sharp only if it is sharp at every sample: one tangent
over part of its length is a crease. Edges that bound one face only (an open
shell) are counted as free; degenerate edges (a sphere's poles) are skipped.

What a file holds is not always one clean shell: faces written unstitched are
sewn first (``SEW_TOL`` × size) and the stitches counted; two faces that use
their edge in the same direction (an inconsistently oriented shell) are
compared with one normal flipped and the row says so; at an edge of three or
more faces every pair is judged; an internal knot line of a B-spline face
whose multiplicity allows a crease or a curvature jump is judged as a
pseudo-edge (index −1) between the two polynomial spans.

Files are read and measured in a child process (``spiral_cad.cad.readers``);
only the measured numbers come back. The time is linear in the faces: one
pass over the edge → faces map, a fixed number of evaluations per edge.
"""

from __future__ import annotations

import math
import os
import re
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape
from OCP.TopTools import (
    TopTools_IndexedDataMapOfShapeListOfShape,
    TopTools_IndexedMapOfShape,
    TopTools_ListOfShape,
)

from ..check.joints import check_tolerances, norms
from ..core.units import length_unit
from .occ import as_occ_shape
from .readers import IGES_SUFFIXES, STEP_SUFFIXES, read_file

__all__ = ["EDGE_CLASSES", "FEATURE_ANGLE", "SEW_TOL", "FaceEdge", "FaceReport", "check_faces", "holds_faces"]

#: Normals further apart than this (radians, 5°) make an edge a sharp feature
#: (a box's edge), listed and never failed; between ``angle_tol`` and this the
#: edge is a crease — a near-tangent kink that reflection lines show as a flaw.
FEATURE_ANGLE = math.radians(5.0)

#: Edge classes, worst first. ``"sharp"`` is a feature and sits apart: it is
#: never compared with the required class.
EDGE_CLASSES = ("unmeasurable", "gap", "crease", "G1", "G2", "sharp")
_RANK = {"unmeasurable": 0, "gap": 0, "crease": 1, "G1": 2, "G2": 3}

#: Floats per sample and face: point (3), oriented unit normal (3), normal curvature across the edge.
_FACE_FLOATS = 7

#: Free edges that coincide within this distance, relative to the model size, are sewn together
#: before the faces are judged (faces written one by one: IGES surface exports, loose compounds).
SEW_TOL = 1e-6

#: What is measured of a shape, as plain data for the reader's child process:
#: face count, per face its surface type, per checked pair (edge index, face a,
#: face b, seam, note), the free edges (index, midpoint), the model size, the samples as
#: float64 bytes (pairs × samples × 2 faces × ``_FACE_FLOATS``), and how many edges were sewn.
Measured = tuple[int, list[str], list[tuple[int, int, int, bool, str]], list[tuple[int, tuple[float, float, float]]], float,
                 bytes, int]  # fmt: skip


# ------------------------------------------------------------ measuring


def _surface_name(kind: GeomAbs_SurfaceType) -> str:
    """``GeomAbs_BSplineSurface`` → ``"bspline"``, ``GeomAbs_SurfaceOfRevolution`` → ``"revolution"``."""
    name = kind.name.removeprefix("GeomAbs_").removesuffix("Surface").removeprefix("SurfaceOf")
    return name.lower() or "other"


def _face_derivatives(surface: BRepAdaptor_Surface, face: TopoDS_Face, edge: TopoDS_Edge, params: NDArray, out: NDArray) -> None:
    """Fill ``out`` (samples × 18) with the face's surface point and derivatives (P, Su, Sv, Suu,
    Svv, Suv) at the pcurve's (u, v) at each edge parameter; where the edge has no pcurve on the
    face (a file that left it out), at the (u, v) of the edge's points projected on the surface."""
    uv, p = gp_Pnt2d(), gp_Pnt()
    su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    if BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0) is not None:
        pcurve = BRepAdaptor_Curve2d(edge, face)
        uvs = []
        for t in params.tolist():
            pcurve.D0(t, uv)
            uvs.append((uv.X(), uv.Y()))
    else:
        uvs = _projected(edge, face, params)
    for k, (u, v) in enumerate(uvs):
        if not (math.isfinite(u) and math.isfinite(v)):
            out[k] = math.nan
            continue
        surface.D2(u, v, p, su, sv, suu, svv, suv)
        out[k] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())


def _projected(edge: TopoDS_Edge, face: TopoDS_Face, params: NDArray) -> list[tuple[float, float]]:
    """(u, v) on the face's surface of the edge's points at ``params`` (``ShapeAnalysis_Surface``:
    periodic and singular surfaces handled); NaN where no projection is found."""
    from OCP.ShapeAnalysis import ShapeAnalysis_Surface

    curve = BRepAdaptor_Curve(edge)
    analysis = ShapeAnalysis_Surface(BRep_Tool.Surface_s(face))  # located, as the edge's points
    tolerance = BRep_Tool.Tolerance_s(edge)
    found = []
    for t in params.tolist():
        try:
            uv = analysis.ValueOfUV(curve.Value(t), tolerance)
            found.append((uv.X(), uv.Y()))
        except Exception:  # noqa: BLE001 - OCCT's Standard_Failure: this sample is not measured
            found.append((math.nan, math.nan))
    return found


def _samples(raw: NDArray, sign: NDArray, tangents: NDArray) -> NDArray:
    """Point, oriented unit normal and normal curvature across the edge (d = n × t), rows of
    ``_FACE_FLOATS``, from rows of surface derivatives — all samples of all edges in one pass."""
    point, su, sv, suu, svv, suv = (raw[:, i : i + 3] for i in range(0, 18, 3))
    with np.errstate(all="ignore"):
        normal = np.cross(su, sv)
        normal *= (sign / norms(normal))[:, None]  # sign −1 for a face REVERSED in its shell
        across = np.cross(normal, tangents)  # d = n × t, in the tangent plane
        e, f, g = (np.einsum("ij,ij->i", x, y) for x, y in ((su, su), (su, sv), (sv, sv)))
        l_, m, n = (np.einsum("ij,ij->i", x, normal) for x in (suu, suv, svv))
        du, dv = np.einsum("ij,ij->i", across, su), np.einsum("ij,ij->i", across, sv)
        det = e * g - f * f
        a, b = (g * du - f * dv) / det, (e * dv - f * du) / det  # d = a Su + b Sv
        kappa = (l_ * a * a + 2.0 * m * a * b + n * b * b) / (e * a * a + 2.0 * f * a * b + g * b * b)
    return np.column_stack([point, normal, kappa])


def _edge_points(edge: TopoDS_Edge, samples: int, tangents: NDArray) -> NDArray:
    """``samples`` interior parameters of the edge (midpoints of equal parameter steps: no end, so no
    pole or corner); fills ``tangents`` with the unit tangent of the edge's 3-D curve there."""
    curve = BRepAdaptor_Curve(edge)
    u0, u1 = curve.FirstParameter(), curve.LastParameter()
    params = u0 + (u1 - u0) * (np.arange(samples) + 0.5) / samples
    p, d1 = gp_Pnt(), gp_Vec()
    for k, t in enumerate(params.tolist()):
        curve.D1(t, p, d1)
        tangents[k] = d1.Coord()
    with np.errstate(all="ignore"):
        tangents /= norms(tangents)[:, None]
    return params


def _shapes(shapes: TopTools_ListOfShape) -> list[TopoDS_Shape]:
    """The shapes of an OCCT list (Python iteration over it costs ~0.3 ms a list; this a few µs)."""
    if shapes.Extent() <= 2:
        return [shapes.First(), shapes.Last()][: shapes.Extent()]
    found, rest = [], TopTools_ListOfShape()
    rest.Assign(shapes)
    while not rest.IsEmpty():
        found.append(rest.First())
        rest.RemoveFirst()
    return found


def _free_edges(shape: TopoDS_Shape) -> list[TopoDS_Edge]:
    """The edges of ``shape`` that bound one face only and are not its seam (degenerate edges left out)."""
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    free = []
    for i in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        faces = _shapes(ancestors.FindFromIndex(i))
        if all(f.IsSame(faces[0]) for f in faces) and not BRep_Tool.IsClosed_s(edge, TopoDS.Face_s(faces[0])):
            free.append(edge)
    return free


def _sewn(shape: TopoDS_Shape, size: float) -> tuple[TopoDS_Shape, int]:
    """``shape`` with its coinciding free edges sewn (``SEW_TOL`` × ``size``), and how many edges were
    stitched; ``shape`` itself when it has no free edges or none could be joined."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    if size <= 0.0 or not _free_edges(shape):
        return shape, 0
    sewing = BRepBuilderAPI_Sewing(SEW_TOL * size)
    sewing.SetNonManifoldMode(True)  # an edge where three faces meet is sewn to all three
    sewing.Add(shape)
    sewing.Perform()
    stitched = sewing.NbContigousEdges() + sewing.NbMultipleEdges()
    return (sewing.SewedShape(), stitched) if stitched else (shape, 0)


def _edge_uses(face: TopoDS_Face, edges: TopTools_IndexedMapOfShape) -> dict[int, set[Any]]:
    """The orientations with which ``face`` (as placed in its shell) uses each of its edges, by edge index."""
    from OCP.TopExp import TopExp_Explorer

    uses: dict[int, set[Any]] = {}
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        current = explorer.Current()
        uses.setdefault(edges.FindIndex(current), set()).add(current.Orientation())
        explorer.Next()
    return uses


def _knot_lines(face: TopoDS_Face, samples: int) -> list[tuple[str, NDArray, NDArray]]:
    """The internal knot lines of a B-spline face where it may crease (knot multiplicity ≥ degree) or
    its curvature may jump (≥ degree − 1): per line its name, the surface derivatives from either
    side (samples × 2 × 18, the two spans' polynomials, ``LocalD2``) and the line's unit tangents.
    The line is sampled across the face's (u, v) bounds, so a trimmed face's line may be sampled
    a little beyond its trimming."""
    from OCP.BRepTools import BRepTools
    from OCP.Geom import Geom_BSplineSurface

    surface = BRep_Tool.Surface_s(face)  # located: the points come out where the face is
    if not isinstance(surface, Geom_BSplineSurface):
        return []
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    p = gp_Pnt()
    su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    lines = []
    for along_u in (True, False):
        degree = surface.UDegree() if along_u else surface.VDegree()
        first, last = (surface.FirstUKnotIndex(), surface.LastUKnotIndex()) if along_u else (
            surface.FirstVKnotIndex(), surface.LastVKnotIndex())  # fmt: skip
        knot = surface.UKnot if along_u else surface.VKnot
        multiplicity = surface.UMultiplicity if along_u else surface.VMultiplicity
        low, high = (u0, u1) if along_u else (v0, v1)
        other_low, other_high = (v0, v1) if along_u else (u0, u1)
        ofirst, olast = (surface.FirstVKnotIndex(), surface.LastVKnotIndex()) if along_u else (
            surface.FirstUKnotIndex(), surface.LastUKnotIndex())  # fmt: skip
        oknots = np.array([(surface.VKnot if along_u else surface.UKnot)(i) for i in range(ofirst, olast + 1)])
        for i in range(first + 1, last):
            k = knot(i)
            if multiplicity(i) < max(1, degree - 1) or not low < k < high:
                continue
            others = other_low + (other_high - other_low) * (np.arange(samples) + 0.5) / samples
            spans = ofirst + np.clip(np.searchsorted(oknots, others, side="right") - 1, 0, len(oknots) - 2)
            raw = np.empty((samples, 2, 18))
            for n, (t, j) in enumerate(zip(others.tolist(), spans.tolist())):
                for side, (a, b) in enumerate(((i - 1, i), (i, i + 1))):
                    if along_u:
                        surface.LocalD2(k, t, a, b, j, j + 1, p, su, sv, suu, svv, suv)
                    else:
                        surface.LocalD2(t, k, j, j + 1, a, b, p, su, sv, suu, svv, suv)
                    raw[n, side] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())
            tangents = raw[:, 0, 6:9] if along_u else raw[:, 0, 3:6]  # along the line: Sv on a u line, Su on a v line
            with np.errstate(all="ignore"):
                tangents = tangents / norms(tangents)[:, None]
            lines.append((f"{'u' if along_u else 'v'} = {k:.6g} (knot of multiplicity {multiplicity(i)})", raw, tangents))
    return lines


def _measure(shape: TopoDS_Shape, samples: int) -> Measured:
    """Everything ``check_faces`` needs of ``shape``, as plain data (see ``Measured``); runs in the
    reader's child process for a file. Faces that were written unstitched (coinciding free edges)
    are sewn first."""
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = 0.0 if box.IsVoid() else math.sqrt(box.SquareExtent())
    shape, stitched = _sewn(shape, size)
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    adaptors: dict[int, BRepAdaptor_Surface] = {}
    uses: dict[int, dict[int, set[Any]]] = {}
    kinds: list[str] = []
    for i in range(1, faces.Extent() + 1):
        kinds.append(_surface_name(BRepAdaptor_Surface(TopoDS.Face_s(faces.FindKey(i)), False).GetType()))
    pairs: list[tuple[int, int, int, bool, str]] = []
    raw: list[NDArray] = []  # surface derivatives per pair: samples × 2 sides × 18
    tangents: list[NDArray] = []
    sign: list[tuple[float, float]] = []
    free: list[tuple[int, tuple[float, float, float]]] = []
    for i in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        index = edges.FindIndex(edge)
        found: list[TopoDS_Face] = []
        for f in _shapes(ancestors.FindFromIndex(i)):
            if not any(f.IsSame(g) for g in found):
                found.append(TopoDS.Face_s(f))
        if len(found) == 1 and BRep_Tool.IsClosed_s(edge, found[0]):  # a seam: the face meets itself
            face = found[0]
            forward, backward = TopoDS.Edge_s(edge.Oriented(TopAbs_FORWARD)), TopoDS.Edge_s(edge.Oriented(TopAbs_REVERSED))
            couples = [((face, forward), (face, backward), "")]
        elif len(found) >= 2:
            # a non-manifold edge (three or more faces): every pair of its faces is judged
            note = f"non-manifold: {len(found)} faces" if len(found) > 2 else ""
            couples = [((a, edge), (b, edge), note) for k, a in enumerate(found) for b in found[k + 1 :]]
        else:
            point = BRepAdaptor_Curve(edge)
            middle = point.Value(0.5 * (point.FirstParameter() + point.LastParameter()))
            free.append((index - 1, (middle.X(), middle.Y(), middle.Z())))
            continue
        for (fa, ea), (fb, eb), note in couples:
            row_tangents = np.empty((samples, 3))
            params = _edge_points(edge, samples, row_tangents)
            row = np.empty((samples, 2, 18))
            signs = []
            for side, (face, oriented) in enumerate(((fa, ea), (fb, eb))):
                face_index = faces.FindIndex(face)
                if face_index not in adaptors:
                    adaptors[face_index] = BRepAdaptor_Surface(face)
                _face_derivatives(adaptors[face_index], face, oriented, params, row[:, side])
                signs.append(-1.0 if face.Orientation() == TopAbs_REVERSED else 1.0)
            if fa is not fb and not fa.IsSame(fb):
                for face in (fa, fb):
                    if faces.FindIndex(face) not in uses:  # each face's edges explored once
                        uses[faces.FindIndex(face)] = _edge_uses(face, edges)
                ua = uses[faces.FindIndex(fa)].get(index, set())
                ub = uses[faces.FindIndex(fb)].get(index, set())
                if len(ua) == 1 and ua == ub:
                    # a consistent shell uses each edge once FORWARD and once REVERSED: these two faces
                    # disagree on their outside, so one normal is flipped before they are compared
                    # (at a non-manifold edge no orientation suits every pair: flipped, not reported)
                    signs[1] = -signs[1]
                    if len(found) == 2:
                        note = "; ".join(filter(None, [note, "orientation: both faces use the edge in the same direction "
                                                       "(inconsistent shell); compared with one normal flipped"]))  # fmt: skip
            raw.append(row)
            tangents.append(row_tangents)
            sign.append((signs[0], signs[1]))
            pairs.append((index - 1, faces.FindIndex(fa) - 1, faces.FindIndex(fb) - 1, len(found) == 1, note))
    for face_index in range(1, faces.Extent() + 1):
        face = TopoDS.Face_s(faces.FindKey(face_index))
        for name, row, row_tangents in _knot_lines(face, samples):
            raw.append(row)
            tangents.append(row_tangents)
            sign.append((-1.0, -1.0) if face.Orientation() == TopAbs_REVERSED else (1.0, 1.0))
            pairs.append((-1, face_index - 1, face_index - 1, False, f"inside face {face_index - 1}, {name}"))
    count = len(pairs)
    if count:
        flat = _samples(np.stack(raw).reshape(-1, 18), np.repeat(np.array(sign)[:, None, :], samples, axis=1).reshape(-1),
                        np.repeat(np.stack(tangents)[:, :, None, :], 2, axis=2).reshape(-1, 3))  # fmt: skip
    else:
        flat = np.empty((0, _FACE_FLOATS))
    data = flat.reshape(count, samples, 2, _FACE_FLOATS)
    return faces.Extent(), kinds, pairs, free, size, data.tobytes(), stitched


# ------------------------------------------------------------ the report


@dataclass(frozen=True)
class FaceEdge:
    """How two faces meet along one edge: the worst of each measure along it, and where.

    Attributes:
        index: the edge's index among the shape's edges (0-based, ``TopExp.MapShapes`` order); -1 for a
            knot line inside a B-spline face (a pseudo-edge: the face's two polynomial spans meet there).
        faces: the indices of the two faces (0-based, ``TopExp.MapShapes`` order); equal for a seam.
        surfaces: their surface types (``"plane"``, ``"cylinder"``, ``"bspline"``, …).
        seam: the edge is a seam where one closed face meets itself.
        gap: largest distance between the two faces' points, in the report's unit.
        gap_at: the edge point where it was largest.
        angle: largest angle between the oriented normals, radians.
        angle_at: where it was largest.
        jump: largest relative jump of the normal curvature across the edge,
            ``|κa − κb| / max(|κa|, |κb|, 1/size)``.
        jump_at: where it was largest.
        curvatures: the two faces' normal curvatures across the edge there (sign: positive
            bends towards the normal), in 1/unit.
        level: the edge's class, one of ``EDGE_CLASSES``.
        note: what else was seen, e.g. ``"non-manifold: 3 faces"``, an orientation defect (the two
            faces use the edge in the same direction; compared with one normal flipped) or a
            partly tangent edge (angle below ``feature_angle`` at some samples, judged there).
    """

    index: int
    faces: tuple[int, int]
    surfaces: tuple[str, str]
    seam: bool
    gap: float
    gap_at: tuple[float, float, float]
    angle: float
    angle_at: tuple[float, float, float]
    jump: float
    jump_at: tuple[float, float, float]
    curvatures: tuple[float, float]
    level: str
    note: str = ""

    @property
    def tangent(self) -> bool:
        """The faces meet tangentially or nearly (every class but ``"sharp"``): the edge is judged."""
        return self.level != "sharp"


@dataclass(frozen=True)
class FaceReport:
    """Continuity of the faces of a shape across every edge they share (``check_faces``).

    Attributes:
        edges: one row per shared or seam edge, in edge order.
        faces: how many faces the shape holds.
        free_edges: edges that bound one face only (an open shell's border), not judged.
        size: the model size (diagonal of the bounding box), the scale of ``gap_tol`` and the curvature floor.
        gap_tol: largest gap, relative to ``size``.
        angle_tol: largest angle between normals of a tangent edge, radians.
        curvature_tol: largest relative jump of normal curvature of a G2 edge.
        feature_angle: normals further apart make an edge a sharp feature.
        samples: points sampled along each edge.
        source: file name or shape description.
        units: the unit of every length (``""``: not known).
        seconds: how long the check took, reading included.
        stitched: edges where faces written unstitched were sewn together (within ``SEW_TOL`` × size)
            before being judged; face and edge indices then count in the sewn shape.
        free_at: the free edges left after sewing: (edge index, midpoint) each.
    """

    edges: tuple[FaceEdge, ...]
    faces: int
    free_edges: int
    size: float
    gap_tol: float
    angle_tol: float
    curvature_tol: float
    feature_angle: float
    samples: int
    source: str = ""
    units: str = ""
    seconds: float = 0.0
    stitched: int = 0
    free_at: tuple[tuple[int, tuple[float, float, float]], ...] = ()

    @property
    def tangent_edges(self) -> list[FaceEdge]:
        """The edges that are judged: every one that is not a sharp feature."""
        return [e for e in self.edges if e.tangent]

    @property
    def sharp_edges(self) -> list[FaceEdge]:
        """The sharp features, listed and never failed."""
        return [e for e in self.edges if not e.tangent]

    @property
    def counts(self) -> dict[str, int]:
        """How many edges fall in each class of ``EDGE_CLASSES``."""
        return {level: sum(e.level == level for e in self.edges) for level in EDGE_CLASSES}

    @property
    def worst(self) -> str:
        """The worst class of a tangent edge (``"G2"`` when there is none); ``"gap"`` if any edge,
        sharp ones too, has a gap."""
        for level in ("unmeasurable", "gap"):
            if any(e.level == level for e in self.edges):
                return level
        return min((e.level for e in self.tangent_edges), key=_RANK.__getitem__, default="G2")

    def passes(self, require: str = "G2") -> bool:
        """True when every tangent edge is at least ``require`` (``"G2"`` or ``"G1"``) and no edge has a gap;
        never when no shared edge was judged at all (loose faces that could not be sewn).

        Raises:
            ValueError: ``require`` is not ``"G1"`` or ``"G2"``.
        """
        if require not in ("G1", "G2"):
            raise ValueError(f"require must be 'G1' or 'G2'; got {require!r}")
        return bool(self.edges) and _RANK[self.worst] >= _RANK[require]

    def failing(self, require: str = "G2") -> list[FaceEdge]:
        """The edges that keep the report from passing ``require``: tangent edges below it, and any
        edge with a gap or that could not be measured — worst first, to name in a refusal.

        Raises:
            ValueError: ``require`` is not ``"G1"`` or ``"G2"``.
        """
        if require not in ("G1", "G2"):
            raise ValueError(f"require must be 'G1' or 'G2'; got {require!r}")
        bad = [e for e in self.edges if e.level in ("unmeasurable", "gap") or (e.tangent and _RANK[e.level] < _RANK[require])]
        return sorted(bad, key=lambda e: (_RANK[e.level], -e.angle, -e.jump, e.index))

    def describe(self) -> str:
        """What was found, e.g. ``"10 faces, 24 shared edges (8 G1, 16 sharp)"``."""
        counts = ", ".join(f"{n} {level}" for level, n in self.counts.items() if n)
        free = f", {self.free_edges} free" if self.free_edges else ""
        sewn = f", {self.stitched} stitched" if self.stitched else ""
        return f"{self.faces} faces, {len(self.edges)} shared edges ({counts or 'none'}){sewn}{free}"

    def table(self) -> str:
        """Readable text: what was found, the tolerances, then one line per edge (worst first), then
        the free edges left unjoined."""
        from ..design.tables import fixed_columns

        unit = f" {self.units}" if self.units else " (model units)"
        inverse = f" 1/{self.units}" if self.units else ""
        sewn = f"; faces sewn within {SEW_TOL:g} × size" if self.stitched else ""
        out = [
            f"{self.source or 'shape'}: {self.describe()}; worst tangent edge {self.worst}",
            f"  tolerances: gap {self.gap_tol:g} × size, angle {self.angle_tol:g} rad, curvature jump "
            f"{self.curvature_tol:g} relative, sharp above {math.degrees(self.feature_angle):g}°; "
            f"{self.samples} samples per edge; model size {self.size:.6g}{unit}{sewn}",
        ]
        order = sorted(self.edges, key=lambda e: (e.level == "sharp", _RANK.get(e.level, 9), -e.jump, e.index))
        names = [f"{e.surfaces[0]}/{e.surfaces[1]}" + (" seam" if e.seam else "") for e in order]
        width = max([22, *map(len, names)])  # long surface names widen the column, never shift the others
        columns = [("  edge", "6d"), ("faces", ">9"), ("surfaces", f"<{width}"), ("gap", "10.3e"), ("angle rad", "10.3e"),
                   ("κa", "10.4g"), ("κb", "10.4g"), ("jump rel", "9.2e"), (" class", "<7"),
                   (f"(worst jump at){inverse and f'  κ in{inverse}'}", "")]  # fmt: skip
        rows = [(e.index, f"{e.faces[0]}-{e.faces[1]}", name, e.gap, e.angle, e.curvatures[0], e.curvatures[1], e.jump,
                 f" {e.level}", f"({', '.join(f'{v:.4g}' for v in e.jump_at)})" + (f"  {e.note}" if e.note else ""))
                for e, name in zip(order, names)]  # fmt: skip
        out += fixed_columns(columns, rows, rule=False)
        if self.free_at:
            out.append(f"  free edges that no other face could be sewn to ({len(self.free_at)}):")
            out += [f"  {i:6d} at ({', '.join(f'{v:.4g}' for v in at)})" for i, at in self.free_at[:_FREE_LISTED]]
            if len(self.free_at) > _FREE_LISTED:
                out.append(f"  … and {len(self.free_at) - _FREE_LISTED} more")
        return "\n".join(out)


#: Free edges listed by name in a table; the rest are counted.
_FREE_LISTED = 20


def _classify(measured: Measured, *, gap_tol: float, angle_tol: float, curvature_tol: float, feature_angle: float,
              samples: int, source: str, units: str, started: float) -> FaceReport:  # fmt: skip
    """The report of the measured samples: worst values per edge (vectorised over all edges) and classes."""
    count, kinds, pairs, free, size, data, stitched = measured
    x = np.frombuffer(data, dtype=float).reshape(len(pairs), samples, 2, _FACE_FLOATS)
    a, b = x[:, :, 0], x[:, :, 1]
    with np.errstate(all="ignore"):
        gap = norms((a[..., :3] - b[..., :3]).reshape(-1, 3)).reshape(len(pairs), samples)
        dot = np.einsum("esi,esi->es", a[..., 3:6], b[..., 3:6])
        cross = norms(np.cross(a[..., 3:6], b[..., 3:6]).reshape(-1, 3)).reshape(len(pairs), samples)
        angle = np.arctan2(cross, dot)
        ka, kb = a[..., 6], b[..., 6]
        floor = 1.0 / size if size > 0.0 else 0.0
        jump = np.abs(ka - kb) / np.maximum(np.maximum(np.abs(ka), np.abs(kb)), floor)
    rows = []
    gap_limit = gap_tol * size
    for i, (edge, fa, fb, seam, note) in enumerate(pairs):
        # NaN (a sample at a singular point of a surface) never decides a worst value
        g, an, j = (int(np.nanargmax(v[i])) if np.isfinite(v[i]).any() else 0 for v in (gap, angle, jump))
        worst_gap, worst_angle, worst_jump = float(gap[i, g]), float(angle[i, an]), float(jump[i, j])
        least_angle = float(np.nanmin(angle[i])) if np.isfinite(angle[i]).any() else math.nan
        if not (math.isfinite(worst_gap) and math.isfinite(worst_angle)):
            level = "unmeasurable"  # no sample gave a point or a normal: never passed
        elif worst_gap > gap_limit:
            level = "gap"
        elif least_angle > feature_angle:
            level = "sharp"  # sharp at every sample: a feature
        elif worst_angle > angle_tol:
            level = "crease"  # a kink somewhere, or tangent over part of the edge and sharp over the rest
            if worst_angle > feature_angle:
                note = "; ".join(filter(None, [note, f"partly tangent: angle {least_angle:.3g} to {worst_angle:.3g} rad "
                                               "along the edge, judged where below the feature angle"]))  # fmt: skip
        elif worst_jump > curvature_tol or worst_jump != worst_jump:
            level = "G1"
        else:
            level = "G2"

        def at(k: int, row: int = i) -> tuple[float, float, float]:
            return (float(a[row, k, 0]), float(a[row, k, 1]), float(a[row, k, 2]))

        rows.append(FaceEdge(edge, (fa, fb), (kinds[fa], kinds[fb]), seam, worst_gap, at(g), worst_angle, at(an),
                             worst_jump, at(j), (float(ka[i, j]), float(kb[i, j])), level, note))  # fmt: skip
    return FaceReport(tuple(rows), count, len(free), size, gap_tol, angle_tol, curvature_tol, feature_angle, samples,
                      source, units, time.perf_counter() - started, stitched, tuple(free))  # fmt: skip


def check_faces(shape_or_path: Any, *, gap_tol: float = 1e-7, angle_tol: float = 1e-7, curvature_tol: float = 1e-4,
                feature_angle: float = FEATURE_ANGLE, samples: int = 16, units: str | None = "mm",
                label: str | None = None) -> FaceReport:  # fmt: skip
    """G0/G1/G2 continuity of the faces of a solid or shell across every edge they share.

    Example:
        A box with its vertical edges filleted meets its fillets G1 (the normal curvature
        across the edge jumps from 0 to 1/r), and its other edges are sharp features:

        ```python
        import build123d as bd
        from spiral_cad.cad.faces import check_faces

        box = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 2)
        report = check_faces(box)
        assert report.counts["G1"] == 8 and report.counts["sharp"] == 16
        assert report.worst == "G1" and not report.passes("G2")
        ```

    Args:
        shape_or_path: a build123d or CadQuery shape, a ``TopoDS_Shape``, or a
            .step/.stp/.igs/.iges path.
        gap_tol: largest distance between the two faces' points, relative to the model size.
        angle_tol: largest angle between the oriented normals of a tangent edge, radians.
        curvature_tol: largest jump of the normal curvature across the edge, relative to
            ``max(|κa|, |κb|, 1/size)``.
        feature_angle: normals further apart than this (radians) make an edge a sharp
            feature, listed and not failed (default ``FEATURE_ANGLE``, 5°).
        samples: points sampled along each edge (interior points: ends, where poles and
            corners are, are not sampled).
        units: for a file, the unit to read it in (None: the unit it declares); for a
            shape, the unit its numbers are in (default mm, build123d's).
        label: name shown in the report (default: the file's name).

    Returns:
        A ``FaceReport``; ``report.passes("G2")`` is the verdict.

    Raises:
        ValueError: an unreadable file (``ReadError``), a negative or non-finite tolerance,
            ``feature_angle`` not within (``angle_tol``, π], ``samples`` not an integer ≥ 1.
    """
    started = time.perf_counter()
    check_tolerances(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, feature_angle=feature_angle)
    if not angle_tol < feature_angle <= math.pi:
        raise ValueError(f"feature_angle must be above angle_tol ({angle_tol:g}) and at most π; got {feature_angle!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples must be an integer ≥ 1; got {samples!r:.40}")
    options: dict[str, Any] = dict(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
                                   feature_angle=feature_angle, samples=samples)  # fmt: skip
    if isinstance(shape_or_path, (str, os.PathLike)):
        unit, measured = read_file(shape_or_path, units, partial(_measure, samples=samples))
        source = label or os.path.basename(os.fspath(shape_or_path))
    else:
        unit = length_unit(units) if units is not None else ""
        measured = _measure(as_occ_shape(shape_or_path), samples)
        source = label or type(shape_or_path).__name__
    return _classify(measured, source=source, units=unit, started=started, **options)


#: STEP entities of a face (AP203/AP214/AP242 B-rep and surface models).
_STEP_FACE = re.compile(rb"\b(?:ADVANCED_FACE|FACE_SURFACE|ORIENTED_FACE)\s*\(", re.IGNORECASE)
#: IGES entity types OCCT makes faces of: surfaces (108 plane … 198 toroidal), bounded and trimmed
#: surfaces (143, 144), faces, shells and solids (510, 514, 186). A file with none of them has no faces;
#: one with them that still reads without faces is judged by its wires (``spiral-cad check``).
_IGES_FACES = {str(t).encode() for t in (108, 114, 118, 120, 122, 128, 140, 143, 144, 186, 190, 192, 194, 196, 198, 510, 514)}


def holds_faces(path: str | os.PathLike) -> bool:
    """Whether a STEP/IGES file declares faces, from its text alone (no reader runs): a STEP face
    entity, or an IGES directory entry of a surface, face, shell or solid (``_IGES_FACES``).

    ``spiral-cad check`` judges faces when this is true and wires otherwise; False for a missing
    file or another suffix (the wire checker then names the problem).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if not p.is_file() or suffix not in STEP_SUFFIXES + IGES_SUFFIXES:
        return False
    with open(p, "rb") as handle:
        if suffix in STEP_SUFFIXES:
            tail = b""
            while chunk := handle.read(1 << 20):
                if _STEP_FACE.search(tail + chunk):
                    return True
                tail = chunk[-64:]  # an entity name cut by the chunk boundary
            return False
        # IGES directory records: section letter D in column 73, the entity type in columns 1–8
        return any(len(line) >= 73 and line[72:73] == b"D" and line[:8].strip() in _IGES_FACES for line in handle)
