"""An independent per-edge measure of how two faces meet, sharing no code with spiral_cad's face checker:
OCCT's own projection (``GeomAPI_ProjectPointOnSurf``) of the edge's 3-D points onto each face's surface,
OCCT's local properties (``GeomLProp_SLProps``) read just inside each face (the side OCCT's classifier
finds inside it), the normal curvature across the edge from the principal curvatures (Euler's formula).
Used to calibrate the checker on parts other systems made (issue 39)."""

from __future__ import annotations

import math

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepTools import BRepTools
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Dir, gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_IN, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

#: how far inside the face the normal and curvature are read, in 3-D, relative to the smaller of the model size and
#: the surface's smallest radius of curvature there (so the normal turns by at most 1e-9 rad on the way: a step
#: relative to the parameter range turned a small cylinder's normal by 1e-6 rad on a 6.7 m Pro/ENGINEER model)
INSIDE = 1e-9
END = 1e-3  # the samples next to the vertices, this far in (relative to the edge's parameter range)


def _side(face, surface, u: float, v: float, across: np.ndarray, bounds, sign: float, inward: list[float], size: float):
    """Normal, and normal curvature along ``across`` (3-D), read ``INSIDE`` × ``size`` (or × the smallest radius
    of curvature, if smaller) into the face from (u, v);
    ``inward`` holds the side found inside the face along ``across`` (classified once per edge and face)."""
    props = GeomLProp_SLProps(surface, u, v, 2, 1e-9)
    if not props.IsNormalDefined():
        return None
    su, sv = props.D1U(), props.D1V()
    a = np.array([[su.X(), sv.X()], [su.Y(), sv.Y()], [su.Z(), sv.Z()]])
    along = np.linalg.lstsq(a, across, rcond=None)[0]  # (u, v) per unit length across the edge
    along /= np.linalg.norm(a @ along) or 1.0
    step = along / (np.linalg.norm(along) or 1.0)
    width = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    bend = max(abs(props.MaxCurvature()), abs(props.MinCurvature())) if props.IsCurvatureDefined() else 0.0
    reach = INSIDE * min(size, 1.0 / bend if bend > 0.0 else size)
    if not inward:
        classifier = BRepClass_FaceClassifier()
        for direction in (1.0, -1.0, 0.0):
            probe = gp_Pnt2d(u + direction * 1e-4 * width * step[0], v + direction * 1e-4 * width * step[1])
            classifier.Perform(face, probe, 1e-9 * width)
            if direction == 0.0 or classifier.State() == TopAbs_IN:
                inward.append(direction)
                break
    uu, vv = u + inward[0] * reach * along[0], v + inward[0] * reach * along[1]
    props = GeomLProp_SLProps(surface, uu, vv, 2, 1e-9)
    if not props.IsNormalDefined():
        return None
    n = props.Normal()
    normal = sign * np.array([n.X(), n.Y(), n.Z()])
    if not props.IsCurvatureDefined():
        return normal, math.nan
    d1, d2 = gp_Dir(), gp_Dir()
    props.CurvatureDirections(d1, d2)
    k1, k2 = props.MaxCurvature(), props.MinCurvature()
    e1 = np.array([d1.X(), d1.Y(), d1.Z()])
    d = across - normal * (across @ normal)
    d /= np.linalg.norm(d) or 1.0
    c = d @ e1
    return normal, sign * (k1 * c * c + k2 * (1.0 - c * c))


def _direction_in(face, edge):
    """The orientation of ``edge`` as ``face`` (with the face's own orientation) runs it."""
    from OCP.TopExp import TopExp_Explorer

    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        if explorer.Current().IsSame(edge):
            return explorer.Current().Orientation()
        explorer.Next()
    return None


def measure_edges(shape, samples: int = 32, angle_tol: float = 1e-7, curvature_tol: float = 1e-4,
                  feature_angle: float = math.radians(5.0), stated: float = 0.0,
                  only: set[int] | None = None) -> dict[int, dict]:  # fmt: skip
    """Per edge shared by two distinct faces (0-based index in ``TopExp.MapShapes`` order): the worst gap,
    angle and relative curvature jump at ``samples`` equally spaced points and two ``END`` from the vertices,
    and the class, by the checker's own rules; ``only``: just the edges of these indices."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    size = math.sqrt(box.SquareExtent())
    edges, ancestors = TopTools_IndexedMapOfShape(), TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    found = {}
    for i in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(i))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        if only is not None and edges.FindIndex(edge) - 1 not in only:
            continue
        listed = ancestors.FindFromIndex(i)
        faces = []
        for face in (listed.First(), listed.Last()) if listed.Extent() == 2 else ():
            faces.append(TopoDS.Face_s(face))
        if len(faces) != 2 or faces[0].IsSame(faces[1]):
            continue
        # faces oriented alike run a shared edge in opposite directions; the same direction in both: one is
        # reversed (decided by the topology, so that a fold of 177° stays a fold and is not read as a crease)
        flip = _direction_in(faces[0], edge) == _direction_in(faces[1], edge)
        curve = BRepAdaptor_Curve(edge)
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        gaps, angles, jumps = [], [], []
        inwards: list[list[float]] = [[], []]
        ends = [t0 + END * (t1 - t0), t1 - END * (t1 - t0)]  # where faces may turn tangent, near the vertices
        for t in [*np.linspace(t0, t1, samples + 2)[1:-1], *ends]:
            p, d1 = gp_Pnt(), gp_Vec()
            curve.D1(float(t), p, d1)
            tangent = np.array([d1.X(), d1.Y(), d1.Z()])
            tangent /= np.linalg.norm(tangent) or 1.0
            sides, points = [], []
            for face, inward in zip(faces, inwards):
                surface = BRep_Tool.Surface_s(face)
                bounds = BRepTools.UVBounds_s(face)
                projection = GeomAPI_ProjectPointOnSurf(p, surface, *bounds)  # within the face's bounds
                if not projection.NbPoints():
                    break
                u, v = projection.LowerDistanceParameters()
                q = projection.NearestPoint()
                points.append(np.array([q.X(), q.Y(), q.Z()]))
                props = GeomLProp_SLProps(surface, u, v, 1, 1e-9)
                if not props.IsNormalDefined():
                    break
                n = props.Normal()
                sign = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
                across = np.cross(sign * np.array([n.X(), n.Y(), n.Z()]), tangent)
                side = _side(face, surface, u, v, across, bounds, sign, inward, size)
                if side is None:
                    break
                sides.append((side[0], side[1], across))
            if len(sides) != 2:
                continue
            (na, ka, across), (nb, kb, _) = sides
            if flip:  # the faces disagree on their outside: compared with one flipped
                nb, kb = -nb, -kb
            # both curvatures along the same direction across the edge (d = n × t of the first face)
            gaps.append(float(np.linalg.norm(points[0] - points[1])))
            angles.append(float(math.atan2(np.linalg.norm(np.cross(na, nb)), na @ nb)))
            jumps.append(abs(ka - kb) / max(abs(ka), abs(kb), 1.0 / size))
        if not gaps:
            found[edges.FindIndex(edge) - 1] = {"level": "unmeasurable"}
            continue
        gap, angle, least = max(gaps), max(angles), min(angles)
        jump = max((j for j in jumps if j == j), default=math.nan)
        limit = max(stated, 2.0 * BRep_Tool.Tolerance_s(edge))  # each face within the edge's tolerance
        if gap > limit:
            level = "gap"
        elif least > feature_angle:
            level = "sharp"
        elif angle > angle_tol:
            level = "crease"
        elif not jump <= curvature_tol:
            level = "G1"
        else:
            level = "G2"
        found[edges.FindIndex(edge) - 1] = {"level": level, "gap": gap, "angle": angle, "jump": jump}
    return found
