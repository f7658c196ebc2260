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
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.gp import gp_Pnt, gp_Vec
from OCP.IMeshTools import IMeshTools_Parameters
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..check.joints import norms
from ..core.units import length_unit
from .occ import as_occ_shape
from .readers import read_file

__all__ = ["ANGULAR", "DEFLECTION", "MAX_TRIANGLES", "PIXELS", "FaceMesh", "face_mesh"]

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
    """

    points: NDArray
    triangles: NDArray
    normals: NDArray
    mean_curvature: NDArray
    gaussian_curvature: NDArray
    face: NDArray
    units: str = "mm"

    @property
    def size(self) -> float:
        """Diagonal of the bounding box of the vertices."""
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0))) if len(self.points) else 0.0


def _mesh(shape: TopoDS_Shape, deflection: float | None, angle: float, pixels: int, max_triangles: int) -> bytes:
    """Mesh ``shape`` and evaluate its surfaces at the vertices: the arrays of a ``FaceMesh`` as
    ``np.savez`` bytes (plain data: runs in the reader's child for a file)."""
    from OCP.BRepTools import BRepTools

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = 1.0 if box.IsVoid() else math.sqrt(box.SquareExtent())
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    linear = deflection if deflection is not None else DEFLECTION * PIXELS / pixels * size
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
    p, su, sv, suu, svv, suv = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    offset, index = 0, 0
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
        raw = np.empty((mesh.NbNodes(), 18))
        for k in range(1, mesh.NbNodes() + 1):
            uv = mesh.UVNode(k)
            surface.D2(uv.X(), uv.Y(), p, su, sv, suu, svv, suv)
            raw[k - 1] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())
        tri = np.array([mesh.Triangle(k).Get() for k in range(1, mesh.NbTriangles() + 1)], dtype=np.int64) - 1
        reversed_ = face.Orientation() == TopAbs_REVERSED
        if reversed_:
            tri = tri[:, ::-1]
        points.append(raw[:, :3])
        values.append(_curvatures(raw, -1.0 if reversed_ else 1.0))
        triangles.append(tri + offset)
        owners.append(np.full(len(tri), index))
        offset += len(raw)
        index += 1
    buffer = io.BytesIO()
    empty = np.empty((0, 3))
    np.savez(
        buffer,
        points=np.vstack(points) if points else empty,
        triangles=np.vstack(triangles) if triangles else np.empty((0, 3), dtype=np.int64),
        values=np.vstack(values) if values else np.empty((0, 5)),
        face=np.concatenate(owners) if owners else np.empty(0, dtype=np.int64),
    )
    return buffer.getvalue()


#: The coarsest angular limit the triangle cap may push a mesh to, radians.
_COARSEST = 0.5


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
              pixels: int = PIXELS, max_triangles: int = MAX_TRIANGLES) -> FaceMesh:  # fmt: skip
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
    extract = partial(_mesh, deflection=deflection, angle=angle, pixels=pixels, max_triangles=max_triangles)
    if isinstance(shape_or_path, (str, os.PathLike)):
        try:
            unit, data = read_file(shape_or_path, units, extract)
        except ValueError as error:
            # the child reads and meshes: a file the checker has read fails here while meshing
            message = re.sub(r"^the (STEP|IGES) reader failed on", "reading and meshing failed on", str(error))
            raise ValueError(f"meshing for the picture: {message}") from None
    else:
        unit, data = (length_unit(units) if units is not None else ""), extract(as_occ_shape(shape_or_path))
    arrays = np.load(io.BytesIO(data))
    if len(arrays["triangles"]) == 0:
        raise ValueError("the shape has no faces to mesh")
    values = arrays["values"]
    return FaceMesh(arrays["points"], arrays["triangles"], values[:, :3], values[:, 3], values[:, 4], arrays["face"], unit)
