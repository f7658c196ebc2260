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
class (``EDGE_CLASSES``): ``"gap"`` (the faces do not meet: gap above
``gap_tol`` × model size), ``"sharp"`` (normals further apart than
``feature_angle``: a feature — a box's edge — listed, never failed),
``"crease"`` (an angle above ``angle_tol`` but below ``feature_angle``: a
near-tangent kink, a defect), ``"G1"`` (tangent, the curvature jumps),
``"G2"``. Edges that bound one face only (an open shell) are counted as
free; degenerate edges (a sphere's poles) are skipped.

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

__all__ = ["EDGE_CLASSES", "FEATURE_ANGLE", "FaceEdge", "FaceReport", "check_faces", "holds_faces"]

#: Normals further apart than this (radians, 5°) make an edge a sharp feature
#: (a box's edge), listed and never failed; between ``angle_tol`` and this the
#: edge is a crease — a near-tangent kink that reflection lines show as a flaw.
FEATURE_ANGLE = math.radians(5.0)

#: Edge classes, worst first. ``"sharp"`` is a feature and sits apart: it is
#: never compared with the required class.
EDGE_CLASSES = ("gap", "crease", "G1", "G2", "sharp")
_RANK = {"gap": 0, "crease": 1, "G1": 2, "G2": 3}

#: Floats per sample and face: point (3), oriented unit normal (3), normal curvature across the edge.
_FACE_FLOATS = 7

#: What is measured of a shape, as plain data for the reader's child process:
#: face count, per face its surface type, per checked edge (edge index, face a,
#: face b, seam), the number of free edges, the model size, and the samples as
#: float64 bytes (edges × samples × 2 faces × ``_FACE_FLOATS``).
Measured = tuple[int, list[str], list[tuple[int, int, int, bool]], int, float, bytes]


# ------------------------------------------------------------ measuring


def _surface_name(kind: GeomAbs_SurfaceType) -> str:
    """``GeomAbs_BSplineSurface`` → ``"bspline"``, ``GeomAbs_SurfaceOfRevolution`` → ``"revolution"``."""
    name = kind.name.removeprefix("GeomAbs_").removesuffix("Surface").removeprefix("SurfaceOf")
    return name.lower() or "other"


def _face_derivatives(surface: BRepAdaptor_Surface, face: TopoDS_Face, edge: TopoDS_Edge, params: NDArray, out: NDArray) -> None:
    """Fill ``out`` (samples × 18) with the face's surface point and derivatives (P, Su, Sv, Suu,
    Svv, Suv) at the pcurve's (u, v) at each edge parameter."""
    pcurve = BRepAdaptor_Curve2d(edge, face)
    uv, p = gp_Pnt2d(), gp_Pnt()
    su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    for k, t in enumerate(params.tolist()):
        pcurve.D0(t, uv)
        surface.D2(uv.X(), uv.Y(), p, su, sv, suu, svv, suv)
        out[k] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())


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


def _measure(shape: TopoDS_Shape, samples: int) -> Measured:
    """Everything ``check_faces`` needs of ``shape``, as plain data (see ``Measured``); runs in the
    reader's child process for a file."""
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    adaptors: dict[int, BRepAdaptor_Surface] = {}
    kinds: list[str] = []
    for i in range(1, faces.Extent() + 1):
        kinds.append(_surface_name(BRepAdaptor_Surface(TopoDS.Face_s(faces.FindKey(i)), False).GetType()))
    pairs: list[tuple[int, int, int, bool]] = []
    raw = np.empty((ancestors.Extent(), samples, 2, 18))  # surface derivatives per edge, sample, side
    tangents = np.empty((ancestors.Extent(), samples, 3))
    sign = np.empty((ancestors.Extent(), 2))
    free = 0
    for i in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        found: list[TopoDS_Face] = []
        for f in _shapes(ancestors.FindFromIndex(i)):
            if not any(f.IsSame(g) for g in found):
                found.append(TopoDS.Face_s(f))
        if len(found) == 1 and BRep_Tool.IsClosed_s(edge, found[0]):  # a seam: the face meets itself
            face = found[0]
            sides = [(face, TopoDS.Edge_s(edge.Oriented(TopAbs_FORWARD))), (face, TopoDS.Edge_s(edge.Oriented(TopAbs_REVERSED)))]
        elif len(found) >= 2:
            sides = [(found[0], edge), (found[1], edge)]  # a non-manifold edge: its first two faces
        else:
            free += 1
            continue
        row = len(pairs)
        params = _edge_points(edge, samples, tangents[row])
        for side, (face, oriented) in enumerate(sides):
            index = faces.FindIndex(face)
            if index not in adaptors:
                adaptors[index] = BRepAdaptor_Surface(face)
            _face_derivatives(adaptors[index], face, oriented, params, raw[row, :, side])
            sign[row, side] = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
        pairs.append((edges.FindIndex(edge) - 1, faces.FindIndex(sides[0][0]) - 1, faces.FindIndex(sides[1][0]) - 1,
                      len(found) == 1))  # fmt: skip
    count = len(pairs)
    flat = _samples(raw[:count].reshape(-1, 18), sign[:count, None, :].repeat(samples, axis=1).reshape(-1),
                    tangents[:count, :, None, :].repeat(2, axis=2).reshape(-1, 3))  # fmt: skip
    data = flat.reshape(count, samples, 2, _FACE_FLOATS)
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = 0.0 if box.IsVoid() else math.sqrt(box.SquareExtent())
    return faces.Extent(), kinds, pairs, free, size, data.tobytes()


# ------------------------------------------------------------ the report


@dataclass(frozen=True)
class FaceEdge:
    """How two faces meet along one edge: the worst of each measure along it, and where.

    Attributes:
        index: the edge's index among the shape's edges (0-based, ``TopExp.MapShapes`` order).
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
        if any(e.gap > self.gap_tol * self.size for e in self.edges):
            return "gap"
        return min((e.level for e in self.tangent_edges), key=_RANK.__getitem__, default="G2")

    def passes(self, require: str = "G2") -> bool:
        """True when every tangent edge is at least ``require`` (``"G2"`` or ``"G1"``) and no edge has a gap.

        Raises:
            ValueError: ``require`` is not ``"G1"`` or ``"G2"``.
        """
        if require not in ("G1", "G2"):
            raise ValueError(f"require must be 'G1' or 'G2'; got {require!r}")
        return _RANK[self.worst] >= _RANK[require]

    def describe(self) -> str:
        """What was found, e.g. ``"10 faces, 24 shared edges (8 G1, 16 sharp)"``."""
        counts = ", ".join(f"{n} {level}" for level, n in self.counts.items() if n)
        free = f", {self.free_edges} free" if self.free_edges else ""
        return f"{self.faces} faces, {len(self.edges)} shared edges ({counts or 'none'}){free}"

    def table(self) -> str:
        """Readable text: what was found, the tolerances, then one line per edge (worst first)."""
        unit = f" {self.units}" if self.units else " (model units)"
        inverse = f" 1/{self.units}" if self.units else ""
        out = [
            f"{self.source or 'shape'}: {self.describe()}; worst tangent edge {self.worst}",
            f"  tolerances: gap {self.gap_tol:g} × size, angle {self.angle_tol:g} rad, curvature jump "
            f"{self.curvature_tol:g} relative, sharp above {math.degrees(self.feature_angle):g}°; "
            f"{self.samples} samples per edge; model size {self.size:.6g}{unit}",
            f"  {'edge':>5} {'faces':>9} {'surfaces':<22} {'gap':>10} {'angle rad':>10} "
            f"{'κa':>10} {'κb':>10} {'jump rel':>9}  class  (worst jump at){inverse and f'  κ in{inverse}'}",
        ]
        order = sorted(self.edges, key=lambda e: (e.level == "sharp", _RANK.get(e.level, 9), -e.jump, e.index))
        for e in order:
            surfaces = f"{e.surfaces[0]}/{e.surfaces[1]}" + (" seam" if e.seam else "")
            at = ", ".join(f"{v:.4g}" for v in e.jump_at)
            out.append(
                f"  {e.index:5d} {e.faces[0]:4d}-{e.faces[1]:<4d} {surfaces:<22} {e.gap:10.3e} {e.angle:10.3e} "
                f"{e.curvatures[0]:10.4g} {e.curvatures[1]:10.4g} {e.jump:9.2e}  {e.level:<6} ({at})"
            )
        return "\n".join(out)


def _classify(measured: Measured, *, gap_tol: float, angle_tol: float, curvature_tol: float, feature_angle: float,
              samples: int, source: str, units: str, started: float) -> FaceReport:  # fmt: skip
    """The report of the measured samples: worst values per edge (vectorised over all edges) and classes."""
    count, kinds, pairs, free, size, data = measured
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
    for i, (edge, fa, fb, seam) in enumerate(pairs):
        # NaN (a sample at a singular point of a surface) never decides a worst value
        g, an, j = (int(np.nanargmax(v[i])) if np.isfinite(v[i]).any() else 0 for v in (gap, angle, jump))
        worst_gap, worst_angle, worst_jump = float(gap[i, g]), float(angle[i, an]), float(jump[i, j])
        if worst_gap > gap_limit:
            level = "gap"
        elif worst_angle > feature_angle:
            level = "sharp"
        elif worst_angle > angle_tol:
            level = "crease"
        elif worst_jump > curvature_tol or worst_jump != worst_jump:
            level = "G1"
        else:
            level = "G2"

        def at(k: int, row: int = i) -> tuple[float, float, float]:
            return (float(a[row, k, 0]), float(a[row, k, 1]), float(a[row, k, 2]))

        rows.append(FaceEdge(edge, (fa, fb), (kinds[fa], kinds[fb]), seam, worst_gap, at(g), worst_angle, at(an),
                             worst_jump, at(j), (float(ka[i, j]), float(kb[i, j])), level))  # fmt: skip
    return FaceReport(tuple(rows), count, free, size, gap_tol, angle_tol, curvature_tol, feature_angle, samples,
                      source, units, time.perf_counter() - started)  # fmt: skip


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
#: IGES entity types of a face: 510 face, 144 trimmed surface, 143 bounded surface.
_IGES_FACES = {b"510", b"144", b"143"}


def holds_faces(path: str | os.PathLike) -> bool:
    """Whether a STEP/IGES file declares faces, from its text alone (no reader runs): a STEP face
    entity, or an IGES directory entry of a face (510), trimmed (144) or bounded (143) surface.

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
