"""2.5-D G2 solids: closed vertical walls between horizontal faces, each chosen rim rolled with one profile.

A part that is a stack of right prisms along z — a plate with holes, pockets cut
into it, bosses standing on it, steps — is given by its walls. A wall is a closed
plan loop with the material on its left, from z ``low`` to ``high``. Its top rim
is convex (the material's top face goes off on the material side). Its bottom rim
is convex too (the part's underside) or a *foot*: a face rising on the open side,
a pocket's floor or the face a boss stands on, rounded by the roll turned over
(w < 0, a concave fillet).

Each wall gives its wall and roll faces (``roll_surfaces``). The horizontal faces
at each level are bounded by the rims' iso-curves: oriented with the face on their
left, the counterclockwise ones bound faces and the clockwise ones are holes in
the smallest face around them. Everything is sewn into one closed shell.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Pln
from OCP.TopAbs import TopAbs_REVERSED, TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Solid, TopoDS_Wire

from ..core._inputs import shown
from ..core.errors import NoSolutionError
from ..core.segments import Arc, Segment
from .roll_surfaces import _along, _along_spans, _faces_of, _plane_face, _record, _rim_wire, _sections, _surface_face

__all__ = ["Wall", "stack_problem", "stack_solid"]

#: Relative slack on "the roll fits" comparisons (equality itself is decided by the construction).
_FIT_SLACK = 1e-12


@dataclass(frozen=True)
class Wall:
    """A closed vertical wall of a 2.5-D part and the rolls of its two rims.

    Attributes:
        loop: its plan, closed, with the material on its left.
        low, high: the z of its bottom and top rims.
        top: the top roll's reach (0: the rim stays sharp).
        bottom: the bottom roll's reach (0: sharp).
        foot: the bottom rim meets a face rising on the open side (a pocket's
            floor, the face a boss stands on): rounded with the roll turned over.
        name: how messages name it ("the outline's rim", "pocket 0's rim" …).
    """

    loop: list[Segment]
    low: float
    high: float
    top: float = 0.0
    bottom: float = 0.0
    foot: bool = False
    name: str = "the outline's rim"

    def rims(self) -> tuple[tuple[float, bool, float, bool], tuple[float, bool, float, bool]]:
        """Each rim's (z, the face there faces up, the iso-curve's w, the face lies on the loop's right)."""
        foot_w = -self.bottom if self.foot else self.bottom
        return (self.high, True, self.top, False), (self.low, self.foot, foot_w, self.foot)


def _polygon(loop: list[Segment], w: float) -> NDArray[np.float64]:
    """The plan loop offset by ``w`` to its left, sampled (closing point excluded)."""
    points, normals, _ = _samples(loop)
    result: NDArray[np.float64] = points + w * normals
    return result


def _signed_area(polygon: NDArray[np.float64]) -> float:
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _samples(segments: list[Segment], count: int = 24) -> tuple[NDArray, NDArray, NDArray]:
    """Points, left normals and curvatures at ``count`` parameters per segment (closing point excluded)."""
    u = np.linspace(0.0, 1.0, count, endpoint=False)
    points = np.vstack([s.point(u)[:, :2] for s in segments])
    tangents = np.vstack([s.tangent(u)[:, :2] for s in segments])
    curvatures = np.concatenate([np.broadcast_to(s.curvature(u), u.shape) for s in segments])
    return points, np.stack([-tangents[:, 1], tangents[:, 0]], axis=1), curvatures


def _crossing(polygon: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """A point where the closed polygon crosses itself (non-adjacent edges), or None."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    d = b - a
    n = len(a)
    i, j = np.triu_indices(n, 2)
    keep = (j - i) < n - 1  # the last edge is adjacent to the first
    i, j = i[keep], j[keep]
    denom = d[i, 0] * d[j, 1] - d[i, 1] * d[j, 0]
    diff = a[j] - a[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (diff[:, 0] * d[j, 1] - diff[:, 1] * d[j, 0]) / denom
        u = (diff[:, 0] * d[i, 1] - diff[:, 1] * d[i, 0]) / denom
    hit = (denom != 0.0) & (t > 0.0) & (t < 1.0) & (u > 0.0) & (u < 1.0)
    if not hit.any():
        return None
    k = int(np.argmax(hit))
    result: NDArray[np.float64] = a[i[k]] + t[k] * d[i[k]]
    return result


def _plain(x: float, y: float) -> str:
    return f"({x:.6g}, {y:.6g})"


def _fit_problem(segments: list[Segment], sigma: float, roll: float, given: Any, name: str,
                 at: Callable[[float, float], str] = _plain) -> str | None:  # fmt: skip
    """Why a roll ``roll`` wide does not fit inside the outline, or None: it must stay below every convex
    radius of curvature (equal only on arcs: a clean pole) and its inner offset must not cross itself."""
    for index, segment in enumerate(segments):
        u = np.linspace(0.0, 1.0, 65)
        bend = float(np.max(sigma * np.broadcast_to(segment.curvature(u), u.shape)))
        if bend <= 0.0:
            continue
        product = roll * bend
        exact_pole = isinstance(segment, Arc) and abs(product - 1.0) <= 1e-12
        if product > 1.0 - _FIT_SLACK and not exact_pole:
            return (
                f"{name} {shown(given)} gives a roll {roll:.6g} wide, not below the outline's smallest convex radius "
                f"of curvature {1.0 / bend:.6g} (segment {index}, a {type(segment).__name__}): the inner offset "
                "would fold"
            )
    points, normals, _ = _samples(segments)
    place = _crossing(points + sigma * roll * normals)
    if place is not None:
        return (
            f"{name} {shown(given)} gives a roll {roll:.6g} wide whose inner offset crosses itself near "
            f"{at(place[0], place[1])}: the outline is too narrow there"
        )
    return None


def _inside(point: NDArray[np.float64], polygon: NDArray[np.float64]) -> bool:
    """Whether ``point`` lies inside the closed ``polygon`` (even–odd rule)."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    straddle = (a[:, 1] > point[1]) != (b[:, 1] > point[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x = a[:, 0] + (point[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(straddle & (x > point[0])) % 2)


def _between(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """A point where the closed polygons ``p`` and ``q`` cross, or None."""
    a, d = p, np.roll(p, -1, axis=0) - p
    c, e = q, np.roll(q, -1, axis=0) - q
    denom = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
    diff = c[None, :, :] - a[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (diff[..., 0] * e[None, :, 1] - diff[..., 1] * e[None, :, 0]) / denom
        u = (diff[..., 0] * d[:, None, 1] - diff[..., 1] * d[:, None, 0]) / denom
    hit = (denom != 0.0) & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)
    if not hit.any():
        return None
    i, j = np.unravel_index(int(np.argmax(hit)), hit.shape)
    result: NDArray[np.float64] = a[i] + t[i, j] * d[i]
    return result


def _solid(faces: list[TopoDS_Face], tolerance: float, top: TopoDS_Face) -> TopoDS_Solid:
    """The faces sewn into one closed shell and made a FORWARD solid facing out: the shell faces out
    when the top cap (``top``, a plane z = height) does, as the construction knows (no volume needed)."""
    sewing = BRepBuilderAPI_Sewing(tolerance)
    for face in faces:
        sewing.Add(face)
    sewing.Perform()
    sewn = sewing.SewedShape()
    shells = TopExp_Explorer(sewn, TopAbs_SHELL)
    count = 0
    shell = None
    while shells.More():
        count += 1
        shell = TopoDS.Shell_s(shells.Current())
        shells.Next()
    if count != 1 or shell is None or not BRep_Tool.IsClosed_s(shell):
        raise NoSolutionError(f"the slab's {len(faces)} faces did not sew into one closed shell ({count} shell(s))")
    sewn_top = sewing.Modified(top)
    cap = next((f for f in _faces_of(shell) if f.IsSame(sewn_top)), None)
    if cap is None or (plane := _plane(cap)) is None:
        raise NoSolutionError("the slab's top cap is not a plane of the sewn shell")
    up = plane.Axis().Direction().Z() * (-1.0 if cap.Orientation() == TopAbs_REVERSED else 1.0)
    if up < 0.0:  # the shell faces in: the solid of the turned shell (a fresh solid is FORWARD)
        shell = TopoDS.Shell_s(shell.Reversed())
    return BRepBuilderAPI_MakeSolid(shell).Solid()


def _plane(face: TopoDS_Face) -> gp_Pln | None:
    surface = GeomAdaptor_Surface(BRep_Tool.Surface_s(face))
    return surface.Plane() if surface.GetType() == GeomAbs_SurfaceType.GeomAbs_Plane else None


def stack_problem(walls: Sequence[Wall], edge_radius: float, name: str,
                  at: Callable[[float, float], str]) -> str | None:  # fmt: skip
    """Why the walls' rolls do not fit, or None: each wall's rolls within its height, each offset
    below the loop's radii of curvature on its side and not crossing itself, and no two walls that
    share a height with rolls crossing or lying in each other's roll."""
    for wall in walls:
        if wall.top + wall.bottom > (wall.high - wall.low) * (1.0 + _FIT_SLACK):
            both = wall.top > 0.0 and wall.bottom > 0.0
            return (
                f"{name} {shown(edge_radius)} gives rolls {max(wall.top, wall.bottom):.6g} high at {wall.name}; "
                f"{'together they' if both else 'it'} exceed its height {wall.high - wall.low:.6g}"
            )
        for sigma, width in ((1.0, wall.top), (-1.0 if wall.foot else 1.0, wall.bottom)):
            if width > 0.0 and (problem := _fit_problem(wall.loop, sigma, width, edge_radius, name, at)) is not None:
                return f"{problem} ({wall.name}{', its foot' if sigma < 0.0 else ''})"
    curves = []
    for wall in walls:
        offsets = {0.0, wall.top, -wall.bottom if wall.foot else wall.bottom}
        curves.append([_polygon(wall.loop, w) for w in sorted(offsets)])
    for i, a in enumerate(walls):
        for j in range(i + 1, len(walls)):
            b = walls[j]
            if a.low > b.high or b.low > a.high:  # no height in common
                continue
            place = next((p for p in (_between(c, d) for c in curves[i] for d in curves[j]) if p is not None), None)
            if place is None:  # no crossing: one rim's curves lying inside the other's roll
                place = next((c[0] for one, other in ((i, j), (j, i)) for c in curves[one]
                              if _in_band(c[0], curves[other], _inside)), None)  # fmt: skip
            if place is not None:
                return (
                    f"{name} {shown(edge_radius)} gives rolls {max(a.top, a.bottom, b.top, b.bottom):.6g} wide; those of "
                    f"{a.name} and {b.name} meet near {at(float(place[0]), float(place[1]))}: the material between "
                    "them is narrower than the two rolls"
                )
    return None


def _in_band(point: NDArray[np.float64], curves: list[NDArray[np.float64]], inside: Callable[..., bool]) -> bool:
    """Whether ``point`` lies between a wall's outermost offsets (inside one, outside the other)."""
    return len(curves) > 1 and inside(point, curves[0]) != inside(point, curves[-1])


def stack_solid(walls: Sequence[Wall], roll: list[Segment], tolerance: float, size: float) -> tuple[TopoDS_Solid, float]:
    """The closed solid of ``walls`` (which fit: ``stack_problem``) with the roll profile ``roll`` (of
    reach 1 per unit w, scaled to each rim's reach), and the largest deviation of a patch over a spiral
    from the exact sweep. Sewn with tolerance 1e-7 × ``size``; not yet verified."""
    faces: list[TopoDS_Face] = []
    levels: dict[tuple[float, bool], list[tuple[TopoDS_Wire, NDArray[np.float64]]]] = {}
    approximation = 0.0
    for wall in walls:
        height = wall.high - wall.low
        d_top, d_bottom = wall.top, wall.bottom
        if d_top + d_bottom > height - 1e-7 * size:  # a wall thinner than the sewing tolerance: the rolls meet
            d_top, d_bottom = (height / 2.0, height / 2.0) if d_top and d_bottom else (d_top and height, d_bottom and height)
        reach = max(d_top, d_bottom)
        alongs = [span for s in wall.loop for span in _along_spans(_along(s, 1.0, reach, tolerance))]
        sections = _sections(roll, d_top, d_bottom, wall.low, wall.high, foot=wall.foot)
        made = [_surface_face(a, sec, 1e-9 * size) for a in alongs for sec in sections]
        faces += [face for face, _ in made]
        for k, (_, key) in enumerate(made):  # so export_step finds the note on parts built from this solid
            _record(key, reach * alongs[k // len(sections)].deviation)
        approximation = max(approximation, reach * max(a.deviation for a in alongs))
        clamped = Wall(wall.loop, wall.low, wall.high, d_top, d_bottom, wall.foot, wall.name)
        for z, up, w, right in clamped.rims():
            polygon = _polygon(wall.loop, w)
            wire = _rim_wire(alongs, w, z, reverse=right)
            levels.setdefault((z, up), []).append((wire, polygon[::-1] if right else polygon))
    top = None
    for (z, up), rims in sorted(levels.items()):
        for face in _level_faces(z, rims):
            faces.append(face)
            top = face if up else top
    assert top is not None
    return _solid(faces, 1e-7 * size, top), approximation


def _level_faces(z: float, rims: list[tuple[TopoDS_Wire, NDArray[np.float64]]]) -> list[TopoDS_Face]:
    """The plane faces at z bounded by ``rims`` (each wire with its polygon, the face on its left)."""
    areas = [_signed_area(polygon) for _, polygon in rims]
    outers = [k for k, area in enumerate(areas) if area > 0.0]
    holes: dict[int, list[TopoDS_Wire]] = {k: [] for k in outers}
    for k, area in enumerate(areas):
        if area > 0.0:
            continue
        around = [o for o in outers if _inside(rims[k][1][0], rims[o][1])]
        if not around:
            raise ValueError(f"a hole at z = {z:.6g} lies in no face (walls given out of place)")
        holes[min(around, key=lambda o: areas[o])].append(rims[k][0])
    return [_plane_face(z, rims[o][0], holes[o]) for o in outers]
