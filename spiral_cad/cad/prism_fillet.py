"""G2 fillets of a right prism's straight edges: side edges as exact extrusions of the plan's G2 corners,
cap edges rolled as a G2 slab (``slabs.rolled_slab``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeVertex,
    BRepBuilderAPI_Transform,
)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln, gp_Pnt, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

from ..core.chain import JOIN_TOLERANCE, g2_mismatch
from ..core.errors import NoSolutionError
from ..core.inputs import as_float, shown
from ..core.segments import Segment
from ..core.shapes import DEFAULT_SHAPE
from ..design.fillets import fillet_path
from .advice import advice, refusal
from .fillet import wire_path
from .occ import chain_wire
from .roll_surfaces import _faces_of, roll_profile
from .slabs import (
    Slab,
    _first_solid,
    _loops,
    _roll_problem,
    _turns,
    _volume,
    expected_level,
    forward_solid,
    rolled_slab,
    verify_faces,
    verify_solid,
)
from .stacks import _plane

__all__ = ["PLAN_OVER_REACH", "StackedPart", "fillet_prism_edges", "plan_radius"]


class StackedPart(NoSolutionError):
    """The part has planar faces at more than two levels along ``axis``: no prism, maybe a 2.5-D part
    (``stack_fillet``)."""

    def __init__(self, message: str, axis: gp_Dir) -> None:
        super().__init__(message)
        self.axis = axis
        self.axes = [axis]  # every direction the part has planar faces at more than two levels along


@dataclass(frozen=True)
class _Prism:
    """A solid that is a right prism: two parallel planar caps, the bottom one framed with z into the solid."""

    frame: gp_Ax3
    bottom: TopoDS_Face
    top: TopoDS_Face
    height: float


def _edges_of(shape: TopoDS_Shape) -> list[TopoDS_Edge]:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        found.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    return found


def _line_direction(edge: TopoDS_Edge) -> tuple[gp_Pnt, gp_Pnt, gp_Dir] | None:
    curve = BRepAdaptor_Curve(edge)
    if curve.GetType() != GeomAbs_CurveType.GeomAbs_Line:
        return None
    return curve.Value(curve.FirstParameter()), curve.Value(curve.LastParameter()), curve.Line().Direction()


def _where(point: gp_Pnt) -> str:
    return f"({point.X():.6g}, {point.Y():.6g}, {point.Z():.6g})"


def _area(shape: TopoDS_Shape) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    return props.Mass()


def _prism(solid: TopoDS_Shape, direction: gp_Dir, edge_name: str) -> _Prism:
    """The solid as a right prism along ``direction``, or NoSolutionError naming what is not."""
    caps = [f for f in _faces_of(solid) if (p := _plane(f)) is not None and p.Axis().Direction().IsParallel(direction, 1e-12)]
    levels = sorted({round(gp_Vec(direction).Dot(gp_Vec(_plane(f).Location().XYZ())), 9) for f in caps})  # type: ignore[union-attr]
    if len(levels) > 2:
        shown_levels = ", ".join(f"{level:.6g}" for level in levels)
        raise StackedPart(
            f"g2_fillet rounds right prisms (two parallel planar caps; through holes allowed); {edge_name}: the part "
            f"has planar faces at {len(levels)} levels along ({direction.X():.6g}, {direction.Y():.6g}, "
            f"{direction.Z():.6g}) — {shown_levels} — as a pocket, a boss or a step makes, which g2_fillet does not "
            "round: round the plain prism first and cut the pocket (or add the boss) afterwards, or use build123d's "
            "fillet on those edges",
            direction,
        )
    if len(caps) != 2:
        raise NoSolutionError(
            f"g2_fillet rounds solid edges of right prisms (two parallel planar caps, side faces along the edges); "
            f"{edge_name}: the part has {len(caps)} planar face(s) perpendicular to it, not 2: it is no right prism"
        )
    for index, face in enumerate(_faces_of(solid)):
        if any(face.IsSame(cap) for cap in caps):
            continue
        lean = _lean(face, direction)
        if lean > _SIDE_TOL:
            surface = BRepAdaptor_Surface(face)
            u, v = (
                0.5 * (surface.FirstUParameter() + surface.LastUParameter()),
                0.5 * (surface.FirstVParameter() + surface.LastVParameter()),
            )
            raise NoSolutionError(
                f"g2_fillet rounds solid edges of right prisms (side faces perpendicular to the caps); {edge_name}: "
                f"side face {index} near {_where(surface.Value(u, v))} leans {math.degrees(lean):.6g}° from the caps' "
                "normal: the part is no right prism (an oblique prism, a taper), which g2_fillet does not round"
            )
    origins = [_plane(f).Location() for f in caps]  # type: ignore[union-attr]
    offsets = [gp_Vec(direction).Dot(gp_Vec(o.XYZ())) for o in origins]
    low, high = (0, 1) if offsets[0] < offsets[1] else (1, 0)
    height = offsets[high] - offsets[low]
    if not abs(_volume(solid) - _area(caps[low]) * height) <= 1e-9 * abs(_volume(solid)):
        raise NoSolutionError(
            f"g2_fillet rounds solid edges of right prisms; {edge_name}: the part is not its cap extruded by "
            f"{height:.6g} (volume {_volume(solid):.9g}, cap area × height {_area(caps[low]) * height:.9g})"
        )
    plane = _plane(caps[low])
    assert plane is not None
    frame = gp_Ax3(plane.Location(), direction, plane.Position().XDirection())
    if frame.XDirection().IsParallel(direction, 1e-9):
        frame = gp_Ax3(plane.Location(), direction)
    return _Prism(frame, caps[low], caps[high], height)


#: Most angle (radians) a prism's side face may lean from the caps' normal.
_SIDE_TOL = 1e-9
#: Samples per parameter direction when a side face's surface gives no direction of its own.
_SIDE_SAMPLES = 9


def _lean(face: TopoDS_Face, axis: gp_Dir) -> float:
    """How far (radians) the face leans from containing the direction ``axis`` everywhere: from its
    surface's own direction (plane normal, cylinder axis, extrusion direction) where it has one, else
    the largest over a grid of its normals (a face perpendicular to the caps has every normal ⟂ axis)."""
    surface = BRepAdaptor_Surface(face)
    kind = surface.GetType()
    if kind == GeomAbs_SurfaceType.GeomAbs_Plane:
        return abs(math.asin(max(-1.0, min(1.0, surface.Plane().Axis().Direction().Dot(axis)))))
    along = {GeomAbs_SurfaceType.GeomAbs_Cylinder: lambda: surface.Cylinder().Axis().Direction(),
             GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion: surface.Direction}.get(kind)  # fmt: skip
    if along is not None:
        angle = along().Angle(axis)
        return min(angle, math.pi - angle)
    u0, u1, v0, v1 = surface.FirstUParameter(), surface.LastUParameter(), surface.FirstVParameter(), surface.LastVParameter()
    worst = 0.0
    for u in np.linspace(u0, u1, _SIDE_SAMPLES):
        for v in np.linspace(v0, v1, _SIDE_SAMPLES):
            point, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
            surface.D1(float(u), float(v), point, du, dv)
            normal = du.Crossed(dv)
            if normal.Magnitude() > 1e-12 * (1.0 + du.Magnitude() * dv.Magnitude()):
                worst = max(worst, abs(math.asin(max(-1.0, min(1.0, normal.Normalized().Dot(gp_Vec(axis)))))))
    return worst


def _on(face: TopoDS_Face, point: gp_Pnt, size: float) -> bool:
    return BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(point).Vertex(), face).Value() <= 1e-9 * size


def fillet_prism_edges(
    solid: TopoDS_Shape,
    edges: Sequence[TopoDS_Edge],
    radius: float,
    *,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
    tolerance: float | None = None,
    _advise: bool = True,
) -> Slab:
    """Round straight edges of a right prism with G2 fillets, exactly.

    Side edges (along the prism's axis, between two planar faces, any
    dihedral angle, convex or concave) become exact extrusions of the 2-D G2
    corner of the cap's outline; when every edge of a cap is chosen too, the
    cap's edge is rolled by the G2 profile of the same radius (``rolled_slab``),
    and the chosen side corners are rounded with ``plan_radius(radius)`` so
    the roll fits inside them (``radius`` stays the smallest radius of
    curvature of every rounded edge).

    Args:
        solid: one solid, a right prism (two parallel planar caps; the part's
            volume is its cap's area times its height).
        edges: the edges to round (all side edges, or side edges and every edge of
            one or both caps).
        radius: the smallest radius of curvature of each rounded edge.
        transition, same_sense, shape: as in ``design.fillets.fillet_path``.
        tolerance: for a slab's sweep over spirals, as in ``rolled_slab``.

    Raises:
        NoSolutionError: an edge that is not straight, not between planar faces, a part that
            is no right prism, or a cap partly chosen — named by edge index and point;
            side corners, rolls and height that do not fit together — with the largest radius that does.
    """
    if not edges:
        raise ValueError("g2_fillet needs at least one edge")
    all_edges = _edges_of(solid)
    index = {i: e for i, e in enumerate(all_edges)}
    position = {}
    for k, edge in enumerate(edges):
        match = next((i for i, e in index.items() if e.IsSame(edge)), None)
        if match is None:
            raise ValueError(f"edge {k} of the selection is not an edge of the part")
        position[k] = match
    size = max(BRepAdaptor_Curve(e).Value(BRepAdaptor_Curve(e).FirstParameter()).Distance(gp_Pnt()) for e in all_edges) + 1.0
    neighbours = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid, TopAbs_EDGE, TopAbs_FACE, neighbours)
    named = []
    candidates: list[gp_Dir] = []  # prism axes: chosen straight edges meeting perpendicular faces at both ends,
    for k, edge in enumerate(edges):  # and the normals of planar faces holding chosen edges
        curve = BRepAdaptor_Curve(edge)
        named.append(f"edge {position[k]} at {_where(curve.Value(curve.FirstParameter()))}")
        line = _line_direction(edge)
        if line is not None:
            ends = [f for f in _faces_of(solid) if (p := _plane(f)) is not None and p.Axis().Direction().IsParallel(line[2], 1e-12)]
            if all(any(_on(f, end, size) for f in ends) for end in line[:2]):
                candidates.append(line[2])
    for face in _faces_of(solid):
        plane = _plane(face)
        if plane is not None and any(any(e.IsSame(h) for h in _edges_of(face)) for e in edges):
            candidates.append(plane.Axis().Direction())
    candidates = [c for k, c in enumerate(candidates) if not any(c.IsParallel(d, 1e-12) for d in candidates[:k])]
    ranked, failed = [], []
    for candidate in candidates:
        try:
            ranked.append((_fit(solid, edges, candidate, named), candidate))
        except NoSolutionError as error:  # the most telling first: levels (nearest z first), then a leaning side
            failed.append(((" levels " not in str(error), " leans " not in str(error), -abs(candidate.Z())), error))
    if not ranked and failed:
        first = min(failed, key=lambda row: row[0])[1]
        if isinstance(first, StackedPart):
            first.axes = [e.axis for _, e in sorted(failed, key=lambda row: row[0]) if isinstance(e, StackedPart)]
        raise first
    if not ranked:
        raise NoSolutionError(
            f"g2_fillet rounds a solid's straight edges when each end meets a face perpendicular to it (prism side "
            f"edges) and the rims of right prisms' caps; {named[0]} is neither (it is curved, slanted or on a "
            "curved face)"
        )
    axis = min(ranked, key=lambda row: row[0])[1]
    sides, caps, side_names = [], [], []
    for k, edge in enumerate(edges):
        line = _line_direction(edge)
        if line is not None and line[2].IsParallel(axis, 1e-12):
            sides.append(edge)
            side_names.append(named[k])
        else:
            caps.append((k, edge, named[k]))
    prism = _prism(solid, axis, f"edge {position[0]}")
    frame = prism.frame
    loops = _cap_loops(prism)
    flags = [[False, False] for _ in loops]  # each loop's (top, bottom) rim chosen
    for which, face in (("top", prism.top), ("bottom", prism.bottom)):
        for wire in _wires_of(face):
            wire_edges = _edges_of(wire)
            picked = [c for c in caps if any(c[1].IsSame(e) for e in wire_edges)]
            if not picked:
                continue
            loop = _loop_of(loops, frame, _start(wire_edges[0]), size)
            missing = [e for e in wire_edges if not any(c[1].IsSame(e) for c in picked)]
            if missing:
                raise NoSolutionError(
                    f"g2_fillet rolls each rim of a cap whole; on the {which} cap's {_rim_name(loop)} the edge at "
                    f"{_where(_start(missing[0]))} is not chosen while other edges of that rim are: choose every "
                    "edge of the rim, or none (it then stays sharp)"
                )
            flags[loop][0 if which == "top" else 1] = True
            for c in picked:
                caps.remove(c)
    if caps:
        raise NoSolutionError(f"g2_fillet cannot round {caps[0][2]}: neither a side edge nor a cap edge of the prism")
    feet = [_start(e) for e in sides] + [_end(e) for e in sides]
    for name, edge in zip(side_names, sides):
        for segments in loops:
            for i in _corner_vertices(segments, frame, [_start(edge), _end(edge)], size):
                before, after = segments[i - 1], segments[i]
                mismatch = None if _turns(before, after) else g2_mismatch(before, after, JOIN_TOLERANCE, index=i)
                if mismatch is not None:
                    jump = (float(np.ravel(before.curvature(1.0))[0]), float(np.ravel(after.curvature(0.0))[0]))
                    raise NoSolutionError(
                        f"g2_fillet rounds corners; {name} is a tangent joint, not a corner: the outline's curvature "
                        f"jumps from {jump[0]:.6g} to {jump[1]:.6g} there, so its faces meet G1; making tangent joints "
                        "G2 is a separate feature: leave the edge out of the selection"
                    )
    chosen = [[i for i in _corner_vertices(s, frame, feet, size) if _turns(s[i - 1], s[i])] for s in loops]
    rolled = [(f[0], f[1]) for f in flags]
    at = lambda x, y: _where(gp_Pnt(x, y, 0.0).Transformed(_to_global(frame)))  # noqa: E731  (plan → the part's place)
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape, tolerance=tolerance)
    both = any(c and any(f) for c, f in zip(chosen, rolled))  # side and cap edges chosen on one loop

    def builds(r: float) -> Slab:  # the same edges rounded with ``r``: what a refusal may suggest
        return fillet_prism_edges(solid, edges, r, **options, _advise=False)

    def plans(r: float) -> list[list[Segment]]:
        """Each loop with its chosen corners rounded (with the plan radius on rolled loops), or NoSolutionError."""
        made = []
        for index, (segments, corners, (top, bottom)) in enumerate(zip(loops, chosen, rolled)):
            try:
                if corners and (top or bottom):
                    caps_here = {"top": top, "bottom": bottom}
                    made.append(_rolled_plan(segments, corners, prism.height, r, caps_here, transition, same_sense,
                                             shape, None, at))  # fmt: skip
                elif corners:
                    made.append(list(fillet_path(segments, r, transition=transition, vertices=corners, closed=True,
                                                 same_sense=same_sense, shape=shape).segments))  # fmt: skip
                else:
                    made.append(segments)
            except NoSolutionError as error:
                raise NoSolutionError(f"on the {_rim_name(index)} (near {at(*segments[0].start[:2])}): {error}") from None
        return made

    def fits(r: float) -> bool:
        try:
            plan = plans(r)
        except NoSolutionError:
            return False
        return not any(any(f) for f in rolled) or _roll_problem(
            plan[0], prism.height, r, prism.height, "radius", holes=plan[1:], rolled=rolled, top=True, bottom=True,
            profile="g2", transition=transition, shape=shape, at=at) is None  # fmt: skip

    def refused(error: NoSolutionError) -> NoSolutionError:
        note = (f" (side and cap edges chosen together: the side edges get the plan radius {PLAN_OVER_REACH:g} × "
                "the roll's reach)") if both and "plan radius" not in str(error) and " meet near " not in str(error) else ""  # fmt: skip
        return refusal(f"{error}{note}", "radius", advice(fits, builds, as_float(radius, "radius")))

    try:
        planned = plans(radius)
    except NoSolutionError as error:
        if not _advise:
            raise
        raise refused(error) from None
    if not any(any(f) for f in rolled):
        local = _extrusion(planned, prism.height)
        approximation = 0.0
        roll = (0.0, 0.0)
    else:
        for segments, loop_rolled in zip(planned, rolled):
            for a, b in zip(segments, segments[1:] + segments[:1]):
                if any(loop_rolled) and _turns(a, b):
                    corner = gp_Pnt(*a.end[:2], 0.0).Transformed(_to_global(frame))
                    raise NoSolutionError(
                        f"g2_fillet rolls a rim along a smooth outline; the side edge at {_where(corner)} is sharp and "
                        "not chosen: choose it too (a roll cannot turn a sharp corner), or leave that rim sharp"
                    )
        try:  # with chosen side edges the plan changes with the radius: a suggestion is built from the start
            slab = rolled_slab(
                planned[0],
                prism.height,
                radius,
                holes=planned[1:],
                _rolled=rolled,
                transition=transition,
                shape=shape,
                tolerance=tolerance,
                _name="radius",
                _at=at,
                _advise=False,
                _verify=False,
            )  # fmt: skip  (verified below, as placed and returned)
        except NoSolutionError as error:
            if not _advise:
                raise
            raise refused(error) from None
        local, approximation, roll = slab.shape, slab.approximation, slab.roll
    placed = BRepBuilderAPI_Transform(local, _to_global(frame), True).Shape()
    result = forward_solid(TopoDS.Solid_s(placed) if placed.ShapeType() == TopAbs_SOLID else _first_solid(placed))
    verify_solid(result, "rounded part")
    levels = [expected_level(segments) for segments in planned]
    verify_faces(result, "G1" if "G1" in levels else "G2", "rounded part")
    return Slab(result, approximation, roll, prism.height)


#: Side edges chosen with the cap edges: their plan corners' radius over the roll's reach into the part.
PLAN_OVER_REACH = 1.25


def plan_radius(radius: float, *, transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> float:
    """The plan corner radius ``fillet_prism_edges`` gives side edges chosen together with the cap edges
    and one ``radius``: ``PLAN_OVER_REACH`` × the G2 roll's reach (1.25 × 1.257 × radius = 1.571 × radius
    with the default transition), so the roll fits inside every plan corner and ``radius`` stays the
    smallest radius of curvature of every rounded edge.

    Args:
        radius: the roll's smallest radius of curvature (> 0).
        transition, shape: of the roll's spirals, as in ``roll_profile``.

    Raises:
        ValueError: a non-positive radius.
    """
    return PLAN_OVER_REACH * float(roll_profile(radius, transition=transition, shape=shape)[-1].end[0])


def _succeeds(make: Callable[[], object]) -> bool:
    """Whether ``make()`` returns rather than refusing (NoSolutionError)."""
    try:
        make()
    except NoSolutionError:
        return False
    return True


def _rolled_plan(segments: list[Segment], chosen: list[int], height: float, radius: float, caps: dict[str, bool],
                 transition: float, same_sense: str, shape: str,
                 builds: Callable[[float], object] | None,
                 at: Callable[[float, float], str] | None = None) -> list[Segment]:  # fmt: skip
    """The cap outline with the chosen corners rounded by ``plan_radius(radius)``, or NoSolutionError naming
    what does not fit and the largest radius that does (side corners, rolls and height together)."""
    options: dict[str, Any] = dict(top=caps["top"], bottom=caps["bottom"], profile="g2", transition=transition,
                                   shape=shape)  # fmt: skip
    if at is not None:
        options["at"] = at

    def attempt(r: float) -> tuple[list[Segment] | None, str | None]:
        corner = plan_radius(r, transition=transition, shape=shape)
        try:
            path = fillet_path(segments, corner, transition=transition, vertices=chosen, closed=True,
                               same_sense=same_sense, shape=shape)  # fmt: skip
        except NoSolutionError as error:
            return None, f"radius {shown(r)} rounds the side edges with the plan radius {corner:.6g} ({error})"
        plan = list(path.segments)
        return plan, _roll_problem(plan, height, r, height, "radius", **dict(options))

    plan, problem = attempt(radius)
    if problem is None and plan is not None:
        return plan
    if builds is None:
        raise NoSolutionError(str(problem))
    fits = advice(lambda r: attempt(r)[1] is None, builds, radius)
    raise refusal(
        f"{problem} (side and cap edges chosen together: the side edges get the plan radius {PLAN_OVER_REACH:g} × the roll's reach)",
        "radius",
        fits,
    )


def _fit(solid: TopoDS_Shape, edges: Sequence[TopoDS_Edge], axis: gp_Dir, named: list[str]) -> tuple:
    """How well the chosen edges fit a prism along ``axis`` (smaller is better; NoSolutionError: no prism):
    edges left unexplained, caps chosen in part, then the axis nearest z, y."""
    prism = _prism(solid, axis, named[0])
    caps = [_edges_of(prism.bottom), _edges_of(prism.top)]
    unexplained, partial = 0, 0
    for edge in edges:
        line = _line_direction(edge)
        if not (line is not None and line[2].IsParallel(axis, 1e-12)) and not any(any(edge.IsSame(e) for e in c) for c in caps):
            unexplained += 1
    for cap in caps:
        count = sum(any(edge.IsSame(e) for edge in edges) for e in cap)
        partial += 0 < count < len(cap)
    return unexplained, partial, -abs(axis.Z()), -abs(axis.Y())


def _wires_of(face: TopoDS_Face) -> list[TopoDS_Shape]:
    found, explorer = [], TopExp_Explorer(face, TopAbs_WIRE)
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def _to_global(frame: gp_Ax3) -> gp_Trsf:
    trsf = gp_Trsf()
    trsf.SetTransformation(frame)  # global → local
    return trsf.Inverted()


def _corner_vertices(segments: list[Segment], frame: gp_Ax3, feet: list[gp_Pnt], size: float) -> list[int]:
    """Indices of the outline vertices under the chosen side edges' ends."""
    back = gp_Trsf()
    back.SetTransformation(frame)
    local = [p.Transformed(back) for p in feet]
    chosen = []
    for i, segment in enumerate(segments):
        x, y = segment.start[:2]
        if any(abs(p.X() - x) <= 1e-9 * size and abs(p.Y() - y) <= 1e-9 * size and abs(p.Z()) <= 1e-9 * size for p in local):
            chosen.append(i)
    return chosen


def _extrusion(loops: list[list[Segment]], height: float) -> TopoDS_Shape:
    """The plane region inside the first loop and outside the others, extruded by ``height``."""
    oriented = _loops(loops[0], loops[1:])
    maker = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(0.0, 0.0, 1.0)), chain_wire(oriented[0]))
    for hole in oriented[1:]:
        maker.Add(chain_wire(hole))
    solid = BRepPrimAPI_MakePrism(maker.Face(), gp_Vec(0.0, 0.0, height)).Shape()
    explorer = TopExp_Explorer(solid, TopAbs_SOLID)
    result = TopoDS.Solid_s(explorer.Current())
    return forward_solid(TopoDS.Solid_s(result.Reversed()) if _volume(result) < 0.0 else result)


def _start(edge: TopoDS_Edge) -> gp_Pnt:
    curve = BRepAdaptor_Curve(edge)
    return curve.Value(curve.FirstParameter())


def _end(edge: TopoDS_Edge) -> gp_Pnt:
    curve = BRepAdaptor_Curve(edge)
    return curve.Value(curve.LastParameter())


def _cap_loops(prism: _Prism) -> list[list[Segment]]:
    """The bottom cap's boundary loops in the prism's frame: the outer one first, then its holes."""
    outer = BRepTools.OuterWire_s(prism.bottom)
    if outer.IsNull():
        raise NoSolutionError("g2_fillet rounds prisms whose caps have an outer boundary; this cap has none")
    inner = [TopoDS.Wire_s(w) for w in _wires_of(prism.bottom) if not w.IsSame(outer)]
    return [wire_path(w, prism.frame, spirals=True)[0] for w in [outer, *inner]]


def _loop_of(loops: list[list[Segment]], frame: gp_Ax3, point: gp_Pnt, size: float) -> int:
    """The index of the loop passing (in plan) through ``point``, a vertex of a cap's wire."""
    back = gp_Trsf()
    back.SetTransformation(frame)
    local = point.Transformed(back)
    distances = [min(math.hypot(local.X() - s.start[0], local.Y() - s.start[1]) for s in loop) for loop in loops]
    best = int(np.argmin(distances))
    if distances[best] > 1e-7 * size:
        raise NoSolutionError(f"g2_fillet found no rim of the bottom cap under the cap edge at {_where(point)}")
    return best


def _rim_name(loop: int) -> str:
    return "outer rim" if loop == 0 else f"rim of hole {loop - 1}"
