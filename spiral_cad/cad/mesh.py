"""A fine triangle mesh of a part's faces with normals and curvatures taken from the surfaces.

What zebra stripes and curvature maps are drawn from (``spiral_cad.app.zebra``): OCCT's
``BRepMesh_IncrementalMesh`` places the vertices, and at each vertex the face's surface gives
the exact oriented unit normal and mean and Gaussian curvature — not normals averaged over
triangles, which would smooth away the very kinks a zebra picture must show. A vertex on an edge
appears once per face, so the two faces' normals stay apart there.
"""

from __future__ import annotations

import io
import math
import os
import re
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.GCPnts import GCPnts_TangentialDeflection
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.IMeshTools import IMeshTools_Parameters
from OCP.Precision import Precision
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..continuity.joints import norms
from ..core.units import length_unit
from .face_projection import derivatives
from .faces import _edge_faces, _sewn
from .occ import as_occ_shape
from .readers import read_file

__all__ = ["ANGULAR", "DEFLECTION", "MAX_TRIANGLES", "PIXELS", "REFINED", "RELATIVE", "SLOPE", "FaceMesh", "edge_lines", "face_mesh"]

#: Pixels along the longer side of the picture a mesh is made for (``spiral_cad.app.zebra``).
PIXELS = 1000
#: Default linear deflection of the mesh, relative to the model size: half a pixel of a ``PIXELS`` picture
#: (scaled with the ``pixels`` asked for).
DEFLECTION = 0.5 / PIXELS
#: Angular deflection of the mesh, radians: how far the normals may turn across a triangle (stripes stay
#: straight), for a part of up to ``_FACES_AT_FINEST`` faces; coarser as the square root of the faces beyond.
ANGULAR = 0.03
#: Default cap on the triangles of a mesh: above it the part is meshed again, twice as coarse.
MAX_TRIANGLES = 300_000
_FACES_AT_FINEST = 64


@dataclass(frozen=True)
class FaceMesh:
    """Triangles of every face, with the surfaces' normals and curvatures at the vertices.

    Attributes:
        points: (n, 3) vertex coordinates, in ``units``.
        triangles: (m, 3) vertex indices, counter-clockwise seen from outside (the normal's side).
        normals: (n, 3) oriented unit normals of the surfaces (outward on a solid).
        mean_curvature: (n,) mean curvature, 1/unit; positive where the surface bends away from
            its normal (convex, like a sphere seen from outside).
        gaussian_curvature: (n,) Gaussian curvature, 1/unit².
        face: (m,) the index of the face each triangle belongs to.
        units: the unit of ``points``.
        edge_points: (k, 3) points along the edges, edge after edge, within the mesh's deflection of them.
        edge_starts: (e + 1,) where each edge's points start in ``edge_points`` (and where the last ends);
            edges are in the order ``spiral_cad.cad.faces.check_faces`` numbers them (``FaceEdge.index``),
            a degenerate edge with no points; only when asked for (``face_mesh(…, edges=True)``).
    """

    points: NDArray
    triangles: NDArray
    normals: NDArray
    mean_curvature: NDArray
    gaussian_curvature: NDArray
    face: NDArray
    units: str = "mm"
    edge_points: NDArray = field(default_factory=lambda: np.empty((0, 3)))
    edge_starts: NDArray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))

    @property
    def curvature_scale(self) -> float:
        """The mean curvature a colour map shows at full strength: the 95th percentile of its size over the
        curved vertices (so that a few sharp spots do not wash out the rest), 1/size where nothing is curved."""
        size = max(self.size, 1e-300)
        found = np.abs(self.mean_curvature[np.isfinite(self.mean_curvature)])
        curved = found[found > 1e-9 / size]
        return float(np.percentile(curved, 95)) if len(curved) else 1.0 / size

    @property
    def size(self) -> float:
        """Diagonal of the bounding box of the vertices."""
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0))) if len(self.points) else 0.0


def _mesh(shape: TopoDS_Shape, deflection: float | None, angle: float, pixels: int, max_triangles: int, edges: bool = False) -> bytes:
    """Mesh ``shape`` and evaluate its surfaces at the vertices: the arrays of a ``FaceMesh`` as
    ``np.savez`` bytes (plain data: runs in the reader's child for a file)."""
    from OCP.BRepTools import BRepTools

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = 1.0 if box.IsVoid() else math.sqrt(box.SquareExtent())
    shape = _sewn(shape, size, _edge_faces(shape))[0]  # as the face checker judges it: its edges, its numbering
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    linear = deflection if deflection is not None else DEFLECTION * PIXELS / pixels * size
    linear = max(linear, 2.0 * Precision.Confusion_s())  # OCCT meshes nothing finer than its own tolerance (a part of 1e-4 mm)
    # the angular limit alone gives ~2 000 vertices a curved face whatever its size: coarser for many faces
    coarsest = max(angle, _COARSEST)
    angular = min(angle * max(1.0, math.sqrt(faces.Extent() / _FACES_AT_FINEST)), coarsest)
    while True:
        parameters = IMeshTools_Parameters()
        parameters.Deflection, parameters.Angle = linear, angular
        parameters.MinSize = 2.0 * linear  # no triangle edge below a pixel: finer ones cannot show
        # not in parallel: a file is meshed in a forked child, where a thread pool the parent started would hang
        parameters.InParallel = False
        BRepMesh_IncrementalMesh(shape, parameters)
        if _triangles(shape) <= max_triangles or angular >= coarsest:
            break
        BRepTools.Clean_s(shape)
        linear, angular = 2.0 * linear, min(2.0 * angular, coarsest)
    points, triangles, values, owners = [], [], [], []
    offset, index, budget = 0, 0, max_triangles
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face_s(explorer.Current())
        location = TopLoc_Location()
        mesh = BRep_Tool.Triangulation_s(face, location)
        explorer.Next()
        if mesh is None or mesh.NbTriangles() == 0 or not mesh.HasUVNodes():
            index += 1
            continue
        surface = BRepAdaptor_Surface(face)  # located: the points come out where the face is
        uvs = np.array([mesh.UVNode(k).Coord() for k in range(1, mesh.NbNodes() + 1)], dtype=float)
        raw = np.empty((len(uvs), 18))
        derivatives(surface, uvs, raw)
        tri = np.array([mesh.Triangle(k).Get() for k in range(1, mesh.NbTriangles() + 1)], dtype=np.int64) - 1
        room = min(budget, REFINED * len(tri) + 2_000) if surface.GetType() not in _EVEN else 0
        raw, tri = _refined(surface, uvs, raw, tri, slope=SLOPE / size, shortest=size / (2.0 * pixels), budget=room)
        budget -= len(tri)
        reversed_ = face.Orientation() == TopAbs_REVERSED
        if reversed_:
            tri = tri[:, ::-1]
        points.append(raw[:, :3])
        values.append(_curvatures(raw, -1.0 if reversed_ else 1.0))
        triangles.append(tri + offset)
        owners.append(np.full(len(tri), index))
        offset += len(raw)
        index += 1
    lines = edge_lines(shape, linear) if edges else []
    buffer = io.BytesIO()
    empty = np.empty((0, 3))
    np.savez(
        buffer,
        points=np.vstack(points) if points else empty,
        triangles=np.vstack(triangles) if triangles else np.empty((0, 3), dtype=np.int64),
        values=np.vstack(values) if values else np.empty((0, 5)),
        face=np.concatenate(owners) if owners else np.empty(0, dtype=np.int64),
        edge_points=np.vstack([empty, *lines]),
        edge_starts=np.concatenate([[0], np.cumsum([len(line) for line in lines], dtype=np.int64)]),
    )
    return buffer.getvalue()


#: Most points along one edge (a long edge at a fine deflection is thinned to this many, evenly).
_EDGE_POINTS = 2_000


def edge_lines(shape: TopoDS_Shape, deflection: float) -> list[NDArray]:
    """Points (k × 3) along every edge of ``shape`` (``TopExp.MapShapes`` order, as the face checker numbers
    them), within ``deflection`` of the edge; none for a degenerate edge or one without a 3-D curve."""
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    lines = []
    for i in range(1, edges.Extent() + 1):
        edge = TopoDS.Edge_s(edges.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            lines.append(np.empty((0, 3)))
            continue
        lines.append(_edge_points(BRepAdaptor_Curve(edge), deflection))
    return lines


def _edge_points(curve: BRepAdaptor_Curve, deflection: float) -> NDArray:
    """Points along ``curve`` whose chords stay within ``deflection`` of it: OCCT's tangential deflection to
    start (it may give a helix of high degree two points, its ends), then every span whose middle lies
    farther than ``deflection`` from its chord's halved, up to ``_EDGE_POINTS`` points."""
    lo, hi = curve.FirstParameter(), curve.LastParameter()
    spaced = GCPnts_TangentialDeflection(curve, 0.1, deflection, 9)
    params = np.array([spaced.Parameter(k) for k in range(1, spaced.NbPoints() + 1)] if spaced.NbPoints() >= 2 else [lo, hi])
    if params[0] > params[-1]:
        params = params[::-1]
    if len(params) > _EDGE_POINTS:
        params = params[np.linspace(0, len(params) - 1, _EDGE_POINTS).round().astype(int)]
    points = np.array([curve.Value(float(t)).Coord() for t in params], dtype=float)
    while len(params) < _EDGE_POINTS:
        middles = 0.5 * (params[:-1] + params[1:])
        at = np.array([curve.Value(float(t)).Coord() for t in middles], dtype=float)
        far = np.linalg.norm(at - 0.5 * (points[:-1] + points[1:]), axis=1) > deflection
        far &= np.flatnonzero(far).size + len(params) <= _EDGE_POINTS  # never past the cap
        if not far.any():
            break
        params = np.insert(params, np.flatnonzero(far) + 1, middles[far])
        points = np.insert(points, np.flatnonzero(far) + 1, at[far], axis=0)
    return points


#: The coarsest angular limit the triangle cap may push a mesh to, radians.
_COARSEST = 0.5
#: How far the normal's rate of turn along a triangle edge may differ from the rate the triangle
#: interpolates, in radians per model size, before the edge is split (``_refined``).
SLOPE = 0.02
#: ... or by more than this share of the surface's own rate there (where the normal turns fast anyway, a small
#: change of rate does not show).
RELATIVE = 0.5
#: Surfaces whose normal turns at one rate everywhere along any direction: never split.
_EVEN = (GeomAbs_SurfaceType.GeomAbs_Plane, GeomAbs_SurfaceType.GeomAbs_Cylinder, GeomAbs_SurfaceType.GeomAbs_Sphere)
#: A face's triangles may grow this many times over by splitting (the worst edges first).
REFINED = 3
#: Rounds of splitting.
_ROUNDS = 8


def _normal_slopes(raw: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Unit normals and their derivatives along u and v (n × 3 each), from rows of surface derivatives."""
    su, sv, suu, svv, suv = (raw[:, i : i + 3] for i in range(3, 18, 3))
    with np.errstate(all="ignore"):
        big = np.cross(su, sv)
        length = norms(big)[:, None]
        normal = big / length
        turns = []
        for d in (np.cross(suu, sv) + np.cross(su, suv), np.cross(suv, sv) + np.cross(su, svv)):
            turns.append((d - normal * np.einsum("ij,ij->i", normal, d)[:, None]) / length)
    return normal, turns[0], turns[1]


def _refined(surface: BRepAdaptor_Surface, uvs: NDArray, raw: NDArray, tri: NDArray, *, slope: float, shortest: float,
             budget: int) -> tuple[NDArray, NDArray]:  # fmt: skip
    """The face's triangles split where a picture's normals, interpolated linearly over a triangle, would
    turn at another rate than the surface's: the normal turns at a constant rate across a triangle, so
    where curvature grows from zero (a G2 spiral leaving a plane) a coarse triangle starts it with a jump,
    and zebra stripes drawn from it would kink where the surface has none. An edge is split at its
    parameter midpoint (the surface evaluated there) while the surface's rate of turn at either end
    differs from the edge's by more than ``slope`` (radians per unit length) and the edge is longer than
    ``shortest``, for ``_ROUNDS`` rounds or until ``budget`` triangles. Returns (raw, triangles)."""
    normal, nu, nv = _normal_slopes(raw)
    for _ in range(_ROUNDS):
        if len(tri) >= budget:
            break
        ends = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        keys, which = np.unique(ends[:, 0] * len(uvs) + ends[:, 1], return_inverse=True)
        a, b = keys // len(uvs), keys % len(uvs)
        step = uvs[b] - uvs[a]
        chord = normal[b] - normal[a]  # what a triangle interpolates along the edge (per unit of its parameter)
        with np.errstate(all="ignore"):
            length = norms(raw[b, :3] - raw[a, :3])
            excess = np.zeros(len(keys))
            for end in (a, b):
                exact = nu[end] * step[:, :1] + nv[end] * step[:, 1:]  # the surface's turn over the edge, at this end's rate
                excess = np.fmax(excess, norms(exact - chord) / (slope * length + RELATIVE * norms(exact)))
            excess[~(length > 2.0 * shortest)] = 0.0  # NaN too
        split = excess > 1.0
        room = (budget - len(tri)) // 2  # a split edge adds a triangle on each side
        if split.sum() > room:  # the worst first
            split[np.argsort(excess)[: len(excess) - room]] = False
        if not split.any():
            break
        mids = 0.5 * (uvs[a[split]] + uvs[b[split]])
        found = np.empty((len(mids), 18))
        derivatives(surface, mids, found)
        new_index = np.full(len(keys), -1)
        new_index[split] = len(uvs) + np.arange(int(split.sum()))
        uvs, raw = np.vstack([uvs, mids]), np.vstack([raw, found])
        normal, nu, nv = (np.vstack([x, y]) for x, y in zip((normal, nu, nv), _normal_slopes(found)))
        tri = _split(tri, new_index[which.reshape(3, -1).T])
    return raw, tri


#: How a triangle is split, by which of its edges 01, 12, 20 hold a midpoint (bit 1, 2, 4): the new
#: triangles as positions in its ring (corner 0, midpoint 01, corner 1, midpoint 12, corner 2, midpoint 20),
#: fanned from a midpoint so that each keeps the triangle's orientation.
_SPLITS = {
    0: [(0, 2, 4)],
    1: [(1, 2, 4), (1, 4, 0)],
    2: [(3, 4, 0), (3, 0, 2)],
    4: [(5, 0, 2), (5, 2, 4)],
    3: [(1, 2, 3), (1, 3, 4), (1, 4, 0)],
    6: [(3, 4, 5), (3, 5, 0), (3, 0, 2)],
    5: [(1, 2, 4), (1, 4, 5), (1, 5, 0)],
    7: [(0, 1, 5), (1, 2, 3), (5, 3, 4), (1, 3, 5)],
}


def _split(tri: NDArray, mid: NDArray) -> NDArray:
    """Triangles with the midpoints ``mid`` (m × 3: of edges 01, 12, 20; -1: not split) put in, each split
    into 2, 3 or 4 (``_SPLITS``)."""
    ring = np.column_stack([tri[:, 0], mid[:, 0], tri[:, 1], mid[:, 1], tri[:, 2], mid[:, 2]])
    code = (mid >= 0) @ np.array([1, 2, 4])
    out = [ring[code == c][:, np.array(shape)].reshape(-1, 3) for c, shape in _SPLITS.items()]
    return np.vstack(out).astype(np.int64)


def _triangles(shape: TopoDS_Shape) -> int:
    """How many triangles the faces' triangulations hold."""
    count = 0
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        mesh = BRep_Tool.Triangulation_s(TopoDS.Face_s(explorer.Current()), TopLoc_Location())
        count += 0 if mesh is None else mesh.NbTriangles()
        explorer.Next()
    return count


def _curvatures(raw: NDArray, sign: float) -> NDArray:
    """Rows of (oriented unit normal, mean curvature, Gaussian curvature) from rows of surface
    derivatives (point, Su, Sv, Suu, Svv, Suv); ``sign`` −1 for a reversed face."""
    su, sv, suu, svv, suv = (raw[:, i : i + 3] for i in range(3, 18, 3))
    with np.errstate(all="ignore"):
        normal = np.cross(su, sv)
        normal /= norms(normal)[:, None]
        normal *= sign
        e, f, g = (np.einsum("ij,ij->i", x, y) for x, y in ((su, su), (su, sv), (sv, sv)))
        l_, m, n = (np.einsum("ij,ij->i", x, normal) for x in (suu, suv, svv))
        det = e * g - f * f
        # second form taken against the normal: a convex surface (bending away from n) has positive mean curvature
        mean = -(e * n - 2.0 * f * m + g * l_) / (2.0 * det)
        gauss = (l_ * n - m * m) / det
    return np.column_stack([normal, mean, gauss])


def face_mesh(shape_or_path: Any, *, deflection: float | None = None, angle: float = ANGULAR, units: str | None = "mm",
              pixels: int = PIXELS, max_triangles: int = MAX_TRIANGLES, edges: bool = False) -> FaceMesh:  # fmt: skip
    """Mesh the faces of a part with the surfaces' own normals and curvatures at the vertices.

    Args:
        shape_or_path: a build123d or CadQuery shape, a ``TopoDS_Shape``, or a
            .step/.stp/.igs/.iges path (read in a child process).
        deflection: largest distance of a triangle from its surface, in ``units``
            (default half a pixel of a picture ``pixels`` wide: ``DEFLECTION`` × model size at ``PIXELS``);
            no triangle edge is made shorter than twice it (a pixel).
        angle: largest turn of the normals across a triangle, radians (default ``ANGULAR``),
            for up to 64 faces; coarser as the square root of the face count beyond.
        units: for a file, the unit to read it in (None: the unit it declares); for
            a shape, the unit its numbers are in.
        pixels: the longer side of the picture the mesh is for.
        max_triangles: above this many triangles the part is meshed again with both limits
            doubled (up to an angular limit of 0.5 rad), so that memory stays bounded.
        edges: also the points along every edge (``FaceMesh.edge_points``), within the deflection; else
            ``edge_starts`` holds one 0 (no edge sampled).

    Raises:
        ValueError: an unreadable file, a ``deflection`` or ``angle`` that is not a positive number,
            ``pixels`` or ``max_triangles`` not a positive integer, a shape without faces, or a
            failure (crash, timeout, memory) while a file is meshed, named as such.
    """
    for name, value in (("deflection", deflection), ("angle", angle)):
        if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number; got {value!r}")
    for name, value in (("pixels", pixels), ("max_triangles", max_triangles)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} must be a positive integer; got {value!r:.40}")
    extract = partial(_mesh, deflection=deflection, angle=angle, pixels=pixels, max_triangles=max_triangles, edges=edges)
    if isinstance(shape_or_path, (str, os.PathLike)):
        try:
            unit, data = read_file(shape_or_path, units, extract)
        except ValueError as error:
            # the child reads and meshes: a file the checker has read fails here while meshing
            message = re.sub(r"^the (STEP|IGES) reader failed on", "reading and meshing failed on", str(error))
            raise ValueError(f"meshing for the picture: {message}") from None
    else:
        unit, shape = (length_unit(units) if units is not None else ""), as_occ_shape(shape_or_path)
        try:
            data = extract(shape)
        except ValueError:
            raise
        except Exception as error:  # noqa: BLE001 - OCCT's Standard_Failure (a part too small to mesh): named, as for a file
            raise ValueError(f"meshing for the picture failed: {type(error).__name__}: {error or 'no message'}") from None
    arrays = np.load(io.BytesIO(data))
    if len(arrays["triangles"]) == 0:
        raise ValueError("the shape has no faces to mesh")
    values = arrays["values"]
    return FaceMesh(arrays["points"], arrays["triangles"], values[:, :3], values[:, 3], values[:, 4], arrays["face"], unit,
                    arrays["edge_points"], arrays["edge_starts"])  # fmt: skip
