"""G0/G1/G2 continuity of faces across every edge they share: the face-to-face checker.

For every edge shared by two faces (and every seam edge, where a closed face
meets itself) the edge is sampled where its geometry asks for it
(``spiral_cad.cad.face_sampling``): a floor of ``samples`` points and both
ends, every polynomial span between the knots of the edge's curve and of both
faces' surfaces, and bisection where the edge turns or a measure may cross its
tolerance between two samples. At each point both faces give, from their
surface derivatives where the edge's 3-D point projects onto each, read from
inside each face's own domain (``spiral_cad.cad.face_projection``; the pcurve
is only the starting guess):

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
the gap limit: ``gap_tol`` × model size, or by default the file's precision or twice the edge's tolerance), ``"sharp"`` (normals further apart than
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
more faces every pair is judged; an internal knot line of a face whose
surface is less than C2 there — a B-spline surface, an extrusion or
revolution of a B-spline curve, an offset or trimmed surface of one — is
judged as a pseudo-edge (index −1) between the two polynomial spans.

Files are read and measured in a child process (``spiral_cad.cad.readers``);
only the measured numbers come back. The time is linear in the faces: one
pass over the edge → faces map, the floor of evaluations per edge and more
only where knots or refinement ask for them.
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
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape
from OCP.TopTools import (
    TopTools_IndexedDataMapOfShapeListOfShape,
    TopTools_IndexedMapOfShape,
    TopTools_ListOfShape,
)

from ..continuity.joints import check_tolerances
from ..core.units import length_unit
from .face_projection import FaceDomain
from .face_sampling import FACE_FLOATS, EdgeLine, Line, Tolerances, knot_lines, measures, sample_lines
from .occ import as_occ_shape
from .readers import IGES_SUFFIXES, STEP_SUFFIXES, read_file

__all__ = ["CLASS_COLOURS", "EDGE_CLASSES", "FEATURE_ANGLE", "SEW_TOL", "FaceEdge", "FaceReport", "check_faces", "holds_faces"]

#: Normals further apart than this (radians, 5°) make an edge a sharp feature
#: (a box's edge), listed and never failed; between ``angle_tol`` and this the
#: edge is a crease — a near-tangent kink that reflection lines show as a flaw.
FEATURE_ANGLE = math.radians(5.0)

#: Edge classes, worst first. ``"sharp"`` is a feature and sits apart: it is
#: never compared with the required class.
EDGE_CLASSES = ("unmeasurable", "gap", "crease", "G1", "G2", "sharp")
#: The colour each class is drawn in (the web page of ``check --html``, ``show_continuity`` in OCP CAD Viewer).
CLASS_COLOURS = {"G2": "#1a9850", "G1": "#f28e2b", "crease": "#d62728", "gap": "#c51b7d", "unmeasurable": "#7b3294", "sharp": "#3c3c3c"}
_RANK = {"unmeasurable": 0, "gap": 0, "crease": 1, "G1": 2, "G2": 3}

#: Free edges that coincide within this distance, relative to the model size, are sewn together
#: before the faces are judged (faces written one by one: IGES surface exports, loose compounds).
SEW_TOL = 1e-6

#: What is measured of a shape, as plain data for the reader's child process:
#: face count, per face its surface type, per checked pair (edge index, face a,
#: face b, seam, note), the free edges (index, midpoint), the model size, the samples as
#: float64 bytes (samples × 2 faces × ``FACE_FLOATS``, pair after pair), how many samples
#: each pair got, how many edges were sewn, per pair twice the BRep tolerance of its edge (of its
#: face for a knot line: each face lies within it, so the two within twice it), and the precision the
#: file states (0.0: none).
Measured = tuple[int, list[str], list[tuple[int, int, int, bool, str]], list[tuple[int, tuple[float, float, float]]], float,
                 bytes, list[int], int, list[float], float]  # fmt: skip


# ------------------------------------------------------------ measuring


def _surface_name(kind: GeomAbs_SurfaceType) -> str:
    """``GeomAbs_BSplineSurface`` → ``"bspline"``, ``GeomAbs_SurfaceOfRevolution`` → ``"revolution"``."""
    name = kind.name.removeprefix("GeomAbs_").removesuffix("Surface").removeprefix("SurfaceOf")
    return name.lower() or "other"


def _shapes(shapes: TopTools_ListOfShape) -> list[TopoDS_Shape]:
    """The shapes of an OCCT list (Python iteration over it costs ~0.3 ms a list; this a few µs)."""
    if shapes.Extent() == 0:  # an edge of a loose wire, in no face
        return []
    if shapes.Extent() <= 2:
        return [shapes.First(), shapes.Last()][: shapes.Extent()]
    found, rest = [], TopTools_ListOfShape()
    rest.Assign(shapes)
    while not rest.IsEmpty():
        found.append(rest.First())
        rest.RemoveFirst()
    return found


def _edge_faces(shape: TopoDS_Shape) -> TopTools_IndexedDataMapOfShapeListOfShape:
    """Each edge of ``shape`` with the faces it bounds."""
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    return ancestors


def _free_edges(ancestors: TopTools_IndexedDataMapOfShapeListOfShape) -> list[TopoDS_Edge]:
    """The edges (of ``_edge_faces``) that bound one face only and are not its seam (degenerate edges left out)."""
    free = []
    for i in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        faces = _shapes(ancestors.FindFromIndex(i))
        if faces and all(f.IsSame(faces[0]) for f in faces) and not BRep_Tool.IsClosed_s(edge, TopoDS.Face_s(faces[0])):
            free.append(edge)
    return free


def _sewn(shape: TopoDS_Shape, size: float, ancestors: TopTools_IndexedDataMapOfShapeListOfShape) -> tuple[TopoDS_Shape, int]:
    """``shape`` with its coinciding free edges sewn (``SEW_TOL`` × ``size``), and how many edges were
    stitched; ``shape`` itself when it has no free edges (``ancestors``: its ``_edge_faces``) or none could be joined."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    if size <= 0.0 or not _free_edges(ancestors):
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


def _measure(shape: TopoDS_Shape, stated: float = 0.0, *, samples: int, gap_tol: float | None, angle_tol: float,
             curvature_tol: float, feature_angle: float) -> Measured:  # fmt: skip
    """Everything ``check_faces`` needs of ``shape``, as plain data (see ``Measured``); runs in the
    reader's child process for a file (``stated``: the precision the file states). Faces that were
    written unstitched (coinciding free edges) are sewn first."""
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = 0.0 if box.IsVoid() else math.sqrt(box.SquareExtent())
    ancestors = _edge_faces(shape)
    shape, stitched = _sewn(shape, size, ancestors)
    if stitched:
        ancestors = _edge_faces(shape)
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    domains: dict[int, FaceDomain] = {}
    uses: dict[int, dict[int, set[Any]]] = {}
    kinds: list[str] = []
    for i in range(1, faces.Extent() + 1):
        kinds.append(_surface_name(BRepAdaptor_Surface(TopoDS.Face_s(faces.FindKey(i)), False).GetType()))

    def domain(face: TopoDS_Face) -> FaceDomain:
        index = faces.FindIndex(face)
        if index not in domains:
            domains[index] = FaceDomain(face, BRepAdaptor_Surface(face))
        return domains[index]

    pairs: list[tuple[int, int, int, bool, str]] = []
    limits: list[float] = []
    lines: list[Line] = []
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
        elif not found:  # an edge of a wire beside the faces (a centre line exported with its corridor): not a face's
            continue
        else:
            point = BRepAdaptor_Curve(edge)
            middle = point.Value(0.5 * (point.FirstParameter() + point.LastParameter()))
            free.append((index - 1, (middle.X(), middle.Y(), middle.Z())))
            continue
        for (fa, ea), (fb, eb), note in couples:
            signs = [-1.0 if face.Orientation() == TopAbs_REVERSED else 1.0 for face in (fa, fb)]
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
            sides = [(domain(fa), ea), (domain(fb), eb)]
            lines.append(EdgeLine(edge, sides, (signs[0], signs[1]), samples))
            limits.append(2.0 * BRep_Tool.Tolerance_s(edge))  # each face within the tolerance of the edge
            pairs.append((index - 1, faces.FindIndex(fa) - 1, faces.FindIndex(fb) - 1, len(found) == 1, note))
    for face_index in range(1, faces.Extent() + 1):
        face = TopoDS.Face_s(faces.FindKey(face_index))
        sign = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
        for line in knot_lines(domain(face), sign, samples):
            lines.append(line)
            pairs.append((-1, face_index - 1, face_index - 1, False, f"inside face {face_index - 1}, {line.name}"))
            limits.append(2.0 * BRep_Tool.Tolerance_s(face))
    gap = gap_tol * size if gap_tol is not None else max([stated, *limits])  # what refinement watches
    rows, counts = sample_lines(lines, Tolerances(gap, angle_tol, curvature_tol, feature_angle, size))
    return faces.Extent(), kinds, pairs, free, size, rows.tobytes(), counts, stitched, limits, stated


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
        samples: how many points of the edge were evaluated (the floor, the spans between knots, the
            refinement: ``spiral_cad.cad.face_sampling``).
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
    samples: int = 0

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
        gap_tol: largest gap, relative to ``size``: as given, or (``gap_from`` the file) the largest limit
            an edge was judged against, relative to ``size``.
        angle_tol: largest angle between normals of a tangent edge, radians.
        curvature_tol: largest relative jump of normal curvature of a G2 edge.
        feature_angle: normals further apart make an edge a sharp feature.
        samples: the floor of points sampled along each edge (more where the geometry asks for them).
        source: file name or shape description.
        units: the unit of every length (``""``: not known).
        seconds: how long the check took, reading included.
        stitched: edges where faces written unstitched were sewn together (within ``SEW_TOL`` × size)
            before being judged; face and edge indices then count in the sewn shape.
        free_at: the free edges left after sewing: (edge index, midpoint) each.
        evaluated: how many points were evaluated on all edges and knot lines together.
        gap_from: where the gap limit came from: ``"given"`` (``gap_tol`` × size), or the precision the file
            states (``UNCERTAINTY_MEASURE_WITH_UNIT``) and twice each edge's own BRep tolerance, the larger of
            the two per edge, e.g. ``"file: stated uncertainty 1e-07, twice the edge tolerances, 2e-07 to 4e-05"``.
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
    evaluated: int = 0
    gap_from: str = "given"

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
            f"  tolerances: gap {self._gap_text()}, angle {self.angle_tol:g} rad, curvature jump "
            f"{self.curvature_tol:g} relative, sharp above {math.degrees(self.feature_angle):g}°; "
            f"at least {self.samples} samples per edge, more at knots and where the geometry turns "
            f"({self.evaluated} in all); model size {self.size:.6g}{unit}{sewn}",
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

    def _gap_text(self) -> str:
        """The gap limit as the table states it."""
        if self.gap_from == "given":
            return f"{self.gap_tol:g} × size (given)"
        return f"from the {self.gap_from} (at most {self.gap_tol * self.size:.3g}{' ' + self.units if self.units else ''})"


#: Free edges listed by name in a table; the rest are counted.
_FREE_LISTED = 20


def _worst_of_each(values: NDArray, ends: NDArray) -> NDArray:
    """Per line (samples ``ends[i]`` to ``ends[i + 1]``, none empty), the index of its largest value, the
    first of equals; NaN (a sample at a singular point of a surface) never decides it (all NaN: the first)."""
    finite = np.where(np.isnan(values), -np.inf, values)
    line = np.repeat(np.arange(len(ends) - 1), np.diff(ends))
    order = np.lexsort((-np.arange(len(values)), finite, line))  # by line, then value, then the first index last
    found = order[ends[1:] - 1]
    return np.where(np.isnan(values[found]), ends[:-1], found)


def _classify(measured: Measured, *, gap_tol: float | None, angle_tol: float, curvature_tol: float, feature_angle: float,
              samples: int, source: str, units: str, started: float) -> FaceReport:  # fmt: skip
    """The report of the measured samples: worst values per edge (measures vectorised over all samples) and classes."""
    count, kinds, pairs, free, size, data, counts, stitched, limits, stated = measured
    x = np.frombuffer(data, dtype=float).reshape(-1, 2, FACE_FLOATS)
    gap, angle, jump = measures(x, size)
    ends = np.cumsum([0, *counts])
    rows = []
    given = gap_tol is not None
    gap_limits = [gap_tol * size if gap_tol is not None else max(stated, limit) for limit in limits]
    worst = [_worst_of_each(v, ends).tolist() for v in (gap, angle, jump)]
    least = np.fmin.reduceat(angle, ends[:-1]).tolist() if len(angle) else []
    for i, (edge, fa, fb, seam, note) in enumerate(pairs):
        start, stop = int(ends[i]), int(ends[i + 1])
        g, an, j = worst[0][i], worst[1][i], worst[2][i]
        worst_gap, worst_angle, worst_jump = float(gap[g]), float(angle[an]), float(jump[j])
        least_angle = least[i]
        if not (math.isfinite(worst_gap) and math.isfinite(worst_angle)):
            level = "unmeasurable"  # no sample gave a point or a normal: never passed
        elif worst_gap > gap_limits[i]:
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

        def at(k: int) -> tuple[float, float, float]:
            return (float(x[k, 0, 0]), float(x[k, 0, 1]), float(x[k, 0, 2]))

        rows.append(FaceEdge(edge, (fa, fb), (kinds[fa], kinds[fb]), seam, worst_gap, at(g), worst_angle, at(an),
                             worst_jump, at(j), (float(x[j, 0, 6]), float(x[j, 1, 6])), level, note, stop - start))  # fmt: skip
    if given:
        relative, gap_from = float(gap_tol or 0.0), "given"
    else:
        edge_limits = [limit for (edge, *_), limit in zip(pairs, limits) if edge >= 0]
        relative = max([stated, *limits]) / size if size > 0.0 else 0.0
        stated_text = f"stated uncertainty {stated:.3g}" if stated > 0.0 else "no stated uncertainty"
        own = (f"twice the edge tolerances, {min(edge_limits):.3g} to {max(edge_limits):.3g}" if edge_limits
               else f"twice the face tolerances, up to {max(limits, default=0.0):.3g}")  # fmt: skip
        gap_from = f"file: {stated_text}, {own}"
    return FaceReport(tuple(rows), count, len(free), size, relative, angle_tol, curvature_tol, feature_angle, samples,
                      source, units, time.perf_counter() - started, stitched, tuple(free), int(ends[-1]),
                      gap_from)  # fmt: skip


def check_faces(shape_or_path: Any, *, gap_tol: float | None = None, angle_tol: float = 1e-7, curvature_tol: float = 1e-4,
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
        gap_tol: largest distance between the two faces' points (each the projection of the edge's point
            on its face), relative to the model size; None (default): per edge the larger of the precision
            the file states (STEP's ``UNCERTAINTY_MEASURE_WITH_UNIT``, IGES's resolution) and twice the edge's
            own BRep tolerance (each face lies within it of the edge; ``FaceReport.gap_from`` says which was used).
        angle_tol: largest angle between the oriented normals of a tangent edge, radians.
        curvature_tol: largest jump of the normal curvature across the edge, relative to
            ``max(|κa|, |κb|, 1/size)``.
        feature_angle: normals further apart than this (radians) make an edge a sharp
            feature, listed and not failed (default ``FEATURE_ANGLE``, 5°).
        samples: the floor of points sampled along each edge: equal steps, and both ends moved in
            by ``END_INSET`` (poles and apexes are never evaluated); two more in every span between
            knots of the edge's curve and of both faces' surfaces, and bisection where the edge turns
            or a measure may cross its tolerance (``spiral_cad.cad.face_sampling``).
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
    check_tolerances(gap_tol=0.0 if gap_tol is None else gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
                     feature_angle=feature_angle)  # fmt: skip
    if not angle_tol < feature_angle <= math.pi:
        raise ValueError(f"feature_angle must be above angle_tol ({angle_tol:g}) and at most π; got {feature_angle!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples must be an integer ≥ 1; got {samples!r:.40}")
    options: dict[str, Any] = dict(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
                                   feature_angle=feature_angle, samples=samples)  # fmt: skip
    if isinstance(shape_or_path, (str, os.PathLike)):
        unit, measured = read_file(shape_or_path, units, partial(_measure, **options), stated=True)
        source = label or os.path.basename(os.fspath(shape_or_path))
    else:
        unit = length_unit(units) if units is not None else ""
        measured = _measure(as_occ_shape(shape_or_path), **options)
        source = label or type(shape_or_path).__name__
    return _classify(measured, source=source, units=unit, started=started, **options)


#: STEP entities of a face (AP203/AP214/AP242 B-rep and surface models), and the bounded surfaces a
#: surface-only file lists in a geometric set (OCCT makes a face of each).
_STEP_FACE = re.compile(rb"\b(?:ADVANCED_FACE|FACE_SURFACE|ORIENTED_FACE|B_SPLINE_SURFACE\w*|BEZIER_SURFACE"
                        rb"|RECTANGULAR_TRIMMED_SURFACE|CURVE_BOUNDED_SURFACE)\s*\(", re.IGNORECASE)  # fmt: skip
#: IGES entity types OCCT makes faces of: surfaces (108 plane … 198 toroidal), bounded and trimmed
#: surfaces (143, 144), faces, shells and solids (510, 514, 186). A file with none of them has no faces;
#: one with them that still reads without faces is judged by its wires (``spiral-cad check``).
_IGES_FACES = {str(t).encode() for t in (108, 114, 118, 120, 122, 128, 140, 143, 144, 186, 190, 192, 194, 196, 198, 510, 514)}


def holds_faces(path: str | os.PathLike) -> bool:
    """Whether a STEP/IGES file declares faces, from its text alone (no reader runs): a STEP face
    entity or bounded surface (a surface-only file), or an IGES directory entry of a surface, face, shell
    or solid (``_IGES_FACES``).

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
