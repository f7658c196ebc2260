"""G2 fillets of 2.5-D parts: stacks of right prisms along one axis (pockets, bosses, steps, holes).

``fillet_part_edges`` is the front door for a solid's edges: a right prism goes to
``prism_fillet``; a part with horizontal faces at more than two levels is read here
as its walls (``stacks.Wall``). Each closed vertical wall lies between a horizontal
face at its top and one at its bottom. Its chosen rims are rolled: the top rim
convex, the bottom rim convex on the part's underside or a concave foot on a
pocket's floor or the face a boss stands on. Its chosen vertical corners are rounded
in plan. The solid is made again (``stacks.stack_solid``) and verified as returned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt, gp_Vec
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_IN, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape, TopoDS_Wire
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

from ..core.chain import JOIN_TOLERANCE, g2_mismatch
from ..core.errors import NoSolutionError
from ..core.inputs import as_float
from ..core.segments import Segment
from ..core.shapes import DEFAULT_SHAPE, shape_code
from ..design.fillets import fillet_path
from .advice import advice, refusal
from .faces import _shapes
from .fillet import wire_path
from .prism_fillet import (
    _SIDE_TOL,
    StackedPart,
    _corner_vertices,
    _edges_of,
    _lean,
    _line_direction,
    _to_global,
    _where,
    _wires_of,
    fillet_prism_edges,
    plan_radius,
)
from .roll_surfaces import _faces_of, roll_profile
from .slabs import Slab, _first_solid, _reverse, _turns, expected_level, forward_solid, verify_faces, verify_solid
from .stacks import Wall, _plane, _samples, _signed_area, stack_problem, stack_solid

__all__ = ["fillet_part_edges"]


def fillet_part_edges(solid: TopoDS_Shape, edges: Sequence[TopoDS_Edge], radius: float, **options: Any) -> Slab:
    """Round a solid's straight edges and rims with G2 fillets: a right prism as ``fillet_prism_edges``
    does, a 2.5-D part (horizontal faces at more than two levels: pockets, bosses, steps) as
    ``fillet_stack_edges`` does along the axis its walls stand on. Arguments, result and errors as
    ``fillet_prism_edges``."""
    _checked_options(radius, options)
    stacked = None
    try:
        return fillet_prism_edges(solid, edges, radius, **options)
    except StackedPart as error:
        stacked = error
    size = _size(solid)
    axes = [a for axis in stacked.axes for a in (axis, axis.Reversed())]
    for axis in axes:  # the first axis the part stands on as whole walls; else the first one's refusal
        try:
            _walls(solid, _frame(solid, axis), size)
        except NoSolutionError:
            continue
        return fillet_stack_edges(solid, edges, radius, axis, **options)
    return fillet_stack_edges(solid, edges, radius, axes[0], **options)


def _checked_options(radius: Any, options: dict[str, Any]) -> None:
    """ValueError naming a radius, transition or shape that no fillet takes."""
    value = as_float(radius, "radius")
    if not (value > 0.0 and math.isfinite(value)):
        raise ValueError(f"radius must be a positive finite number; got {radius!r:.40}")
    transition = as_float(options.get("transition", 0.5), "transition")
    if not 0.0 < transition <= 1.0:
        raise ValueError(f"transition must lie in (0, 1]; got {options.get('transition')!r:.40}")
    shape_code(options.get("shape", DEFAULT_SHAPE))


class _NoRadius(NoSolutionError):
    """A refusal no radius mends (a selection that cannot be rounded): no advice is searched."""


@dataclass
class _Rims:
    """One closed vertical wall of the part as read: its faces, and the wires of its bottom and top rims."""

    faces: list[TopoDS_Face]
    low: float
    high: float
    bottom: TopoDS_Wire
    top: TopoDS_Wire
    foot: bool
    head: bool
    loop: list[Segment]
    name: str = ""


def fillet_stack_edges(
    solid: TopoDS_Shape,
    edges: Sequence[TopoDS_Edge],
    radius: float,
    axis: gp_Dir,
    *,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
    tolerance: float | None = None,
    _advise: bool = True,
) -> Slab:
    """Round edges of a 2.5-D part along ``axis`` with G2 fillets, exactly.

    The part's faces are horizontal planes (perpendicular to ``axis``) and
    vertical walls; each closed wall runs from one horizontal face to another.
    A chosen rim (every edge of a wall's top or bottom wire) is rolled with the
    G2 profile of ``radius``: convex where the material turns away (a top, the
    underside), concave where a face rises on the open side (a pocket's floor,
    the base under a boss). Chosen vertical edges are rounded in plan, with
    ``plan_radius(radius)`` on walls with a rolled rim.

    Args:
        solid: one solid made of horizontal planar faces and vertical walls.
        edges: the edges to round (vertical edges and whole rims).
        radius: the smallest radius of curvature of each rounded edge.
        axis: the direction the part is stacked along.
        transition, same_sense, shape, tolerance: as in ``fillet_prism_edges``.

    Raises:
        NoSolutionError: a face neither horizontal nor vertical, walls of different heights meeting on
            one rim (a step reaching the outline), a rim partly chosen — named by point;
            rolls that do not fit — with the largest radius that builds.
    """
    frame, size = _frame(solid, axis), _size(solid)
    walls = _walls(solid, frame, size)
    chosen, corners = _chosen(solid, edges, walls, frame, size)
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape)
    at = lambda x, y, z: _where(_lifted_point(frame, (x, y), z))  # noqa: E731  (plan → the part)

    def plans(r: float) -> list[Wall]:
        reach = float(roll_profile(r, transition=transition, shape=shape)[-1].end[0])
        made = []
        for wall, (top, bottom), vertices in zip(walls, chosen, corners):
            loop = wall.loop
            if vertices:
                corner = plan_radius(r, transition=transition, shape=shape) if top or bottom else r
                try:
                    loop = list(fillet_path(loop, corner, vertices=vertices, closed=True, **options).segments)
                except NoSolutionError as error:
                    raise NoSolutionError(f"on {wall.name}: {error}") from None
            if top or bottom:
                for a, b in zip(loop, loop[1:] + loop[:1]):
                    if _turns(a, b):
                        raise _NoRadius(
                            f"g2_fillet rolls a rim along a smooth outline; the vertical edge of {wall.name} at "
                            f"{_where(_lifted_point(frame, a.end, wall.low))} is sharp and not chosen: choose it "
                            "too, or leave the rim sharp"
                        )
            made.append(Wall(loop, wall.low, wall.high, reach if top else 0.0, reach if bottom else 0.0, wall.foot, wall.head, wall.name))
        return made

    def problem(r: float) -> str | None:
        try:
            return stack_problem(plans(r), r, "radius", at)
        except _NoRadius:
            raise
        except NoSolutionError as error:
            return str(error)
        except ValueError as error:  # numbers past float64 (a radius of 1e308)
            return f"radius {r:.6g} is beyond what the part's numbers hold ({error})"

    def builds(r: float) -> Slab:
        return fillet_stack_edges(solid, edges, r, axis, **options, tolerance=tolerance, _advise=False)

    given = as_float(radius, "radius")
    upper = min(given, size)  # no roll wider than the part fits in it: the advice is searched below both
    try:
        found = problem(given)
    except _NoRadius as error:  # the user sees the public class
        raise NoSolutionError(str(error)) from None
    if found is not None:
        if not _advise:
            raise NoSolutionError(found)
        raise refusal(found, "radius", advice(lambda r: problem(r) is None, builds, upper))
    planned = plans(given)
    tol = 1e-7 * size if tolerance is None else as_float(tolerance, "tolerance")
    try:
        local, approximation = stack_solid(planned, roll_profile(given, **_roll_options(options)), tol, size)
        placed = BRepBuilderAPI_Transform(local, _to_global(frame), True).Shape()
        result = forward_solid(TopoDS.Solid_s(placed) if placed.ShapeType() == TopAbs_SOLID else _first_solid(placed))
        verify_solid(result, "rounded part", facing_out=True)  # the stack's shell faces out by construction
        levels = [expected_level(wall.loop) for wall in planned]
        verify_faces(result, "G1" if "G1" in levels else "G2", "rounded part")
    except NoSolutionError as error:
        if not _advise:
            raise
        raise refusal(str(error), "radius", advice(lambda r: problem(r) is None and r < given, builds, upper)) from None
    reach = max((max(w.top, w.bottom) for w in planned), default=0.0)
    height = max(w.high for w in planned) - min(w.low for w in planned)
    return Slab(result, approximation, (reach, reach), height)


def _roll_options(options: dict[str, Any]) -> dict[str, Any]:
    return {k: options[k] for k in ("transition", "shape")}


def _size(solid: TopoDS_Shape) -> float:
    points = [_point(e, 0.0) for e in _edges_of(solid)] + [_point(e, 1.0) for e in _edges_of(solid)]
    coords = np.array([p.Coord() for p in points])
    return float(np.ptp(coords, axis=0).max()) or 1.0


def _point(edge: TopoDS_Edge, share: float) -> gp_Pnt:
    curve = BRepAdaptor_Curve(edge)
    return curve.Value(curve.FirstParameter() + share * (curve.LastParameter() - curve.FirstParameter()))


def _level(frame: gp_Ax3, face: TopoDS_Face) -> float:
    plane = _plane(face)
    assert plane is not None
    return gp_Vec(frame.Direction()).Dot(gp_Vec(frame.Location(), plane.Location()))


def _frame(solid: TopoDS_Shape, axis: gp_Dir) -> gp_Ax3:
    """A frame with z along ``axis`` and its origin on the lowest horizontal face."""
    flat = [f for f in _faces_of(solid) if (p := _plane(f)) is not None and p.Axis().Direction().IsParallel(axis, 1e-12)]
    probe = gp_Ax3(gp_Pnt(), axis)
    lowest = min(flat, key=lambda f: _level(probe, f))
    plane = _plane(lowest)
    assert plane is not None
    frame = gp_Ax3(plane.Location(), axis, plane.Position().XDirection())
    return frame if not frame.XDirection().IsParallel(axis, 1e-9) else gp_Ax3(plane.Location(), axis)


def _facing_up(face: TopoDS_Face, axis: gp_Dir) -> bool:
    plane = _plane(face)
    assert plane is not None
    sign = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
    return sign * plane.Axis().Direction().Dot(axis) > 0.0


def _walls(solid: TopoDS_Shape, frame: gp_Ax3, size: float) -> list[_Rims]:
    """The part's closed vertical walls, each with its loop in plan (material on its left), in a fixed order:
    by level, then by area."""
    axis = frame.Direction()
    faces = _faces_of(solid)
    flat, upright = [], []
    for index, face in enumerate(faces):
        plane = _plane(face)
        if plane is not None and plane.Axis().Direction().IsParallel(axis, 1e-12):
            flat.append(face)
        elif _lean(face, axis) <= _SIDE_TOL:
            upright.append(face)
        else:
            raise NoSolutionError(
                f"g2_fillet rounds 2.5-D parts (horizontal faces and vertical walls along one axis); face {index} "
                f"near {_where(_point(_edges_of(face)[0], 0.5))} is neither: a draft, a slope or a curved top, which "
                "g2_fillet does not round"
            )
    neighbours = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid, TopAbs_EDGE, TopAbs_FACE, neighbours)

    def others(edge: TopoDS_Edge, face: TopoDS_Face) -> list[TopoDS_Face]:
        return [TopoDS.Face_s(f) for f in _shapes(neighbours.FindFromKey(edge)) if not f.IsSame(face)]

    group = list(range(len(upright)))  # union–find over the vertical faces joined by vertical edges

    def root(k: int) -> int:
        while group[k] != k:
            group[k] = group[group[k]]
            k = group[k]
        return k

    def index_of(face: TopoDS_Face) -> int:
        return next(k for k, f in enumerate(upright) if f.IsSame(face))

    for k, face in enumerate(upright):
        for edge in _edges_of(face):
            for other in others(edge, face):
                if any(other.IsSame(f) for f in upright):
                    group[root(index_of(other))] = root(k)
    rims: dict[int, list[tuple[float, TopoDS_Wire, TopoDS_Face]]] = {}
    for face in flat:
        z = _level(frame, face)
        for wire in _wires_of(face):
            touched = set()
            for edge in _edges_of(wire):
                for other in others(edge, face):
                    if not any(other.IsSame(f) for f in upright):
                        raise NoSolutionError(
                            f"g2_fillet rounds 2.5-D parts; the horizontal faces at {_where(_point(edge, 0.5))} meet "
                            "each other edge to edge: the part is not a stack of prisms"
                        )
                    touched.add(root(index_of(other)))
            if len(touched) != 1:
                raise _uneven(_point(_edges_of(wire)[0], 0.0))
            rims.setdefault(touched.pop(), []).append((z, TopoDS.Wire_s(wire), face))
    walls = []
    for key, ends in rims.items():
        ends.sort(key=lambda row: row[0])
        if len(ends) != 2 or ends[1][0] - ends[0][0] <= 1e-9 * size:
            raise _uneven(_point(_edges_of(ends[len(ends) // 2][1])[0], 0.0))  # a rim between the ends
        (low, bottom, under), (high, top, over) = ends
        loop = _plan(bottom, frame, low)
        if not _material_left(solid, loop, frame, low, high, size):
            loop = _reverse(loop)
        faces_here = [f for k, f in enumerate(upright) if root(k) == key]
        walls.append(_Rims(faces_here, low, high, bottom, top, _facing_up(under, axis), not _facing_up(over, axis), loop))
    walls.sort(key=lambda w: (w.low, -abs(_signed_area(_samples(w.loop)[0]))))
    counts: dict[str, int] = {}
    for wall in walls:
        ccw = _signed_area(_samples(wall.loop)[0]) > 0.0
        through = not (wall.foot or wall.head)
        role = ("outline" if through else "boss") if ccw else ("hole" if through else "pocket")
        k = counts[role] = counts.get(role, -1) + 1
        wall.name = f"{'the outline' if role == 'outline' and k == 0 else f'{role} {k}'}'s rim"
    return walls


def _uneven(point: gp_Pnt) -> NoSolutionError:
    return NoSolutionError(
        f"g2_fillet rounds 2.5-D parts whose walls each run whole from one horizontal face to another; at "
        f"{_where(point)} walls of different heights meet (a step, slot or pocket reaching the side), which "
        "g2_fillet does not round: the rim would end where the walls meet"
    )


def _plan(wire: TopoDS_Wire, frame: gp_Ax3, z: float) -> list[Segment]:
    """The wire at height ``z`` as a closed plan loop in the frame's coordinates."""
    try:
        return wire_path(wire, _lifted(frame, z), spirals=True)[0]
    except ValueError as error:
        raise NoSolutionError(f"g2_fillet reads each wall's rim as lines, arcs and spirals; {error}") from None


def _material_left(solid: TopoDS_Shape, loop: list[Segment], frame: gp_Ax3, low: float, high: float, size: float) -> bool:
    """Whether the solid lies on the loop's left, just off the middle of its longest piece, half way up."""
    piece = max(loop, key=lambda s: s.length)
    (x, y), (tx, ty) = (float(v) for v in piece.point(np.array([0.5]))[0, :2]), (float(v) for v in piece.tangent(np.array([0.5]))[0, :2])
    step = min(1e-4 * size, 0.25 * piece.length)
    probe = gp_Pnt(x - step * ty, y + step * tx, 0.5 * (low + high)).Transformed(_to_global(frame))
    classifier = BRepClass3d_SolidClassifier(solid, probe, 1e-9 * size)
    return classifier.State() == TopAbs_IN


def _chosen(solid: TopoDS_Shape, edges: Sequence[TopoDS_Edge], walls: list[_Rims], frame: gp_Ax3,
            size: float) -> tuple[list[tuple[bool, bool]], list[list[int]]]:  # fmt: skip
    """Each wall's (top, bottom) rims chosen whole, and its corners (loop vertices) under chosen vertical edges."""
    rims = [(wall, which, wire) for wall in walls for which, wire in (("top", wall.top), ("bottom", wall.bottom))]
    picked: dict[int, list[TopoDS_Edge]] = {}
    feet: list[list[gp_Pnt]] = [[] for _ in walls]
    axis = frame.Direction()
    all_edges = _edges_of(solid)
    for k, edge in enumerate(edges):
        where = next((i for i, (_, _, wire) in enumerate(rims) if any(edge.IsSame(e) for e in _edges_of(wire))), None)
        if where is not None:
            picked.setdefault(where, []).append(edge)
            continue
        line = _line_direction(edge)
        owner = next((i for i, wall in enumerate(walls) if any(edge.IsSame(e) for f in wall.faces for e in _edges_of(f))), None)
        if line is None or not line[2].IsParallel(axis, 1e-12) or owner is None:
            number = next((i for i, e in enumerate(all_edges) if e.IsSame(edge)), None)
            if number is None:
                raise ValueError(f"edge {k} of the selection is not an edge of the part")
            raise NoSolutionError(
                f"g2_fillet rounds a 2.5-D part's vertical edges and whole rims of its walls; edge {number} at "
                f"{_where(_point(edge, 0.0))} is neither"
            )
        feet[owner] += [line[0], line[1]]
    flags = [[False, False] for _ in walls]
    for i, chosen_here in picked.items():
        wall, which, wire = rims[i]
        missing = [e for e in _edges_of(wire) if not any(e.IsSame(c) for c in chosen_here)]
        if missing:
            raise NoSolutionError(
                f"g2_fillet rolls each rim whole; on {wall.name} ({which}) the edge at {_where(_point(missing[0], 0.0))} "
                "is not chosen while other edges of that rim are: choose every edge of the rim, or none (it then stays sharp)"
            )
        flags[walls.index(wall)][0 if which == "top" else 1] = True
    corners = []
    for wall, points in zip(walls, feet):
        found = _corner_vertices(wall.loop, _lifted(frame, wall.low), points, size) if points else []
        for i in found:
            before, after = wall.loop[i - 1], wall.loop[i]
            if not _turns(before, after) and g2_mismatch(before, after, JOIN_TOLERANCE, index=i) is not None:
                jump = (float(np.ravel(before.curvature(1.0))[0]), float(np.ravel(after.curvature(0.0))[0]))
                raise NoSolutionError(
                    f"g2_fillet rounds corners; the vertical edge of {wall.name} at "
                    f"{_where(_lifted_point(frame, before.end, wall.low))} is a tangent joint, not a corner: the "
                    f"outline's curvature jumps from {jump[0]:.6g} to {jump[1]:.6g} there, so its faces meet G1; "
                    "making tangent joints G2 is a separate feature: leave the edge out of the selection"
                )
        corners.append([i for i in found if _turns(wall.loop[i - 1], wall.loop[i])])
    return [(t, b) for t, b in flags], corners


def _lifted_point(frame: gp_Ax3, plan: Any, z: float) -> gp_Pnt:
    """The plan point (x, y) at height ``z`` of the frame, in the part's coordinates."""
    return gp_Pnt(float(plan[0]), float(plan[1]), z).Transformed(_to_global(frame))


def _lifted(frame: gp_Ax3, z: float) -> gp_Ax3:
    return gp_Ax3(frame.Location().Translated(gp_Vec(frame.Direction()).Multiplied(z)), frame.Direction(), frame.XDirection())
