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

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_FastSewing, BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Pln
from OCP.TopAbs import TopAbs_REVERSED, TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Solid, TopoDS_Wire
from scipy.spatial import cKDTree

from ..core.errors import NoSolutionError
from ..core.inputs import shown
from ..core.segments import Arc, Segment
from .roll_surfaces import _along, _along_spans, _faces_of, _plane_face, _record, _rim_wire, _sections, _surface_face

__all__ = ["Wall", "meeting_problem", "stack_problem", "stack_solid"]

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
        head: the top rim meets a face hanging over the open side (the floor of
            a pocket cut from below, a boss under the part): the roll turned over.
        name: how messages name it ("the outline's rim", "pocket 0's rim" …).
    """

    loop: list[Segment]
    low: float
    high: float
    top: float = 0.0
    bottom: float = 0.0
    foot: bool = False
    head: bool = False
    name: str = "the outline's rim"

    def rims(self) -> tuple[tuple[float, bool, float, bool], tuple[float, bool, float, bool]]:
        """Each rim's (z, the face there faces up, the iso-curve's w, the face lies on the loop's right)."""
        head_w = -self.top if self.head else self.top
        foot_w = -self.bottom if self.foot else self.bottom
        return (self.high, not self.head, head_w, self.head), (self.low, self.foot, foot_w, self.foot)

    def reaches(self) -> tuple[float, float]:
        """How far its rolls reach to the loop's left (the material's side) and to its right."""
        ws = [w for _, _, w, _ in self.rims()]
        return max(0.0, *ws), max(0.0, *(-w for w in ws))


#: Most turn (radians) between neighbouring samples of a dense plan polygon: chords within 1.25e-5 × the radius.
_TURN_STEP = 0.01


def _polygon(loop: list[Segment], w: float, spacing: float = math.inf) -> NDArray[np.float64]:
    """The plan loop offset by ``w`` to its left, sampled at most ``spacing`` apart and turning at most
    ``_TURN_STEP`` between samples (closing point excluded)."""
    pieces = []
    for segment in loop:
        u = np.linspace(0.0, 1.0, 9)
        kappa = np.broadcast_to(np.asarray(segment.curvature(u), dtype=float), u.shape)
        tangents = segment.tangent(u)[:, :2]
        (x0, y0), (x1, y1) = tangents[:-1].T, tangents[1:].T
        turn = float(np.sum(np.abs(np.arctan2(x0 * y1 - y0 * x1, x0 * x1 + y0 * y1))))
        stretch = 1.0 + abs(w) * float(np.max(np.abs(kappa)))
        count = max(
            2, math.ceil(turn / _TURN_STEP), min(100_000, math.ceil(segment.length * stretch / spacing)) if spacing < math.inf else 0
        )
        t = np.linspace(0.0, 1.0, count, endpoint=False)
        tangent = segment.tangent(t)[:, :2]
        tangent = tangent / np.linalg.norm(tangent, axis=1)[:, None]
        pieces.append(segment.point(t)[:, :2] + w * np.stack([-tangent[:, 1], tangent[:, 0]], axis=1))
    result: NDArray[np.float64] = np.vstack(pieces)
    return result


def _gap(p: NDArray[np.float64], q: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """The least distance between two closed polylines (vertices to the other's nearest segments, both
    ways; exact once the vertices are denser than the distance), and a point of ``p`` where it is."""
    best, where = math.inf, p[0]
    for a, b, swap in ((p, q, False), (q, p, True)):
        nearest = cKDTree(b).query(a)[1]
        d = np.full(len(a), np.inf)
        for step in (-1, 1):  # the two segments at each nearest vertex
            s0, s1 = b[nearest], b[(nearest + step) % len(b)]
            e = s1 - s0
            t = np.clip(np.einsum("ij,ij->i", a - s0, e) / np.maximum(np.einsum("ij,ij->i", e, e), 1e-300), 0.0, 1.0)
            d = np.minimum(d, np.linalg.norm(a - (s0 + t[:, None] * e), axis=1))
        k = int(np.argmin(d))
        if d[k] < best:
            best = float(d[k])
            where = b[nearest[k]] if swap else a[k]
    return best, where


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


#: OCCT's fast sewing joins patch corners this close, relative to the model size: the patches' corners are the
#: same numbers where they meet, so a tolerance far below the general sewing's keeps every edge's own tolerance
#: small (the face checker allows twice it) and never merges two walls that merely come close.
_FAST_SEWING = 1e-9


def _solid(patches: list[TopoDS_Face], caps: list[TopoDS_Face], size: float, top: TopoDS_Face, *, fast: bool = True) -> TopoDS_Solid:
    """The faces sewn into one closed shell (``_shell``) and made a FORWARD solid facing out: the shell faces
    out when the top cap (``top``, a plane z = height) does, as the construction knows (no volume needed).
    The patches are fast-sewn where ``fast``, and sewn the general way if that does not close the shell."""
    try:
        shell, sewn_top = _shell(patches, caps, size, top, fast=fast)
    except NoSolutionError:
        if not fast:
            raise
        shell, sewn_top = _shell(patches, caps, size, top, fast=False)
    cap = next((f for f in _faces_of(shell) if f.IsSame(sewn_top)), None)
    if cap is None or (plane := _plane(cap)) is None:
        raise NoSolutionError("the slab's top cap is not a plane of the sewn shell")
    up = plane.Axis().Direction().Z() * (-1.0 if cap.Orientation() == TopAbs_REVERSED else 1.0)
    if up < 0.0:  # the shell faces in: the solid of the turned shell (a fresh solid is FORWARD)
        shell = TopoDS.Shell_s(shell.Reversed())
    return BRepBuilderAPI_MakeSolid(shell).Solid()


def _shell(patches: list[TopoDS_Face], caps: list[TopoDS_Face], size: float, top: TopoDS_Face, *, fast: bool) -> tuple[Any, Any]:
    """The one closed shell of the faces and its top cap as sewn, or NoSolutionError.

    The patches are whole B-spline spans meeting their neighbours edge to edge with the same parameters, what
    OCCT's fast sewing assumes (a sixth of the general sewing's time); it pairs edges by their two corners,
    so it is only asked (``fast``) where no two spans join the same two corners. The trimmed caps are always
    sewn the general way (1e-7 × size), without cutting: their edges match the patches' whole."""
    sewing = BRepBuilderAPI_Sewing(1e-7 * size, True, True, False, False)
    joined = BRepBuilderAPI_FastSewing(_FAST_SEWING * size) if fast else None
    if joined is not None and all([joined.Add(face) for face in patches]):
        joined.Perform()
        sewing.Add(joined.GetResult())
    else:
        for face in patches:
            sewing.Add(face)
    for face in caps:
        sewing.Add(face)
    sewing.Perform()
    shells = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    found = []
    while shells.More():
        found.append(TopoDS.Shell_s(shells.Current()))
        shells.Next()
    if len(found) != 1 or not BRep_Tool.IsClosed_s(found[0]):
        raise NoSolutionError(f"the slab's {len(patches) + len(caps)} faces did not sew into one closed shell ({len(found)} shell(s))")
    sewn_top = sewing.Modified(top)
    if not any(f.IsSame(sewn_top) for f in _faces_of(found[0])):
        raise NoSolutionError("the slab's top cap is not a face of the sewn shell")
    return found[0], sewn_top


def _plane(face: TopoDS_Face) -> gp_Pln | None:
    surface = GeomAdaptor_Surface(BRep_Tool.Surface_s(face))
    return surface.Plane() if surface.GetType() == GeomAbs_SurfaceType.GeomAbs_Plane else None


def stack_problem(walls: Sequence[Wall], edge_radius: float, name: str,
                  at: Callable[[float, float, float], str]) -> str | None:  # fmt: skip
    """Why the walls' rolls do not fit, or None: each wall's rolls within its height, each offset
    below the loop's radii of curvature on its side and not crossing itself, and no two walls that
    share a height closer than their rolls reach towards each other. ``at(x, y, z)`` names a point."""
    for wall in walls:
        if wall.top + wall.bottom > (wall.high - wall.low) * (1.0 + _FIT_SLACK):
            both = wall.top > 0.0 and wall.bottom > 0.0
            return (
                f"{name} {shown(edge_radius)} gives rolls {max(wall.top, wall.bottom):.6g} high at {wall.name}; "
                f"{'together they' if both else 'it'} exceed its height {wall.high - wall.low:.6g}"
            )
        for z, _, w, _ in wall.rims():
            here = lambda x, y, z=z: at(x, y, z)  # noqa: E731
            if w != 0.0 and (problem := _fit_problem(wall.loop, math.copysign(1.0, w), abs(w), edge_radius, name, here)):
                return f"{problem} ({wall.name}{'' if w > 0.0 else ', turned over'})"
    return meeting_problem(walls, edge_radius, name, at)


def meeting_problem(walls: Sequence[Wall], edge_radius: float, name: str,
                    at: Callable[[float, float, float], str]) -> str | None:  # fmt: skip
    """Why two of the walls that share a height are closer than their rolls reach towards each other
    (the material between them narrower than both rolls), or None."""
    reaches = [wall.reaches() for wall in walls]
    coarse = [_polygon(wall.loop, 0.0) for wall in walls]
    boxes = [(loop.min(axis=0), loop.max(axis=0)) for loop in coarse]
    size = max((float(np.max(high - low)) for low, high in boxes), default=0.0)
    areas = [_signed_area(loop) for loop in coarse]
    sampled: dict[tuple[int, float], NDArray[np.float64]] = {}

    def dense(k: int, spacing: float) -> NDArray[np.float64]:  # a loop near several others is sampled once
        if (k, spacing) not in sampled:
            sampled[k, spacing] = _polygon(walls[k].loop, 0.0, spacing)
        return sampled[k, spacing]

    for i, a in enumerate(walls):
        for j in range(i + 1, len(walls)):
            b = walls[j]
            if a.low > b.high or b.low > a.high:  # no height in common
                continue
            left_of_a = _inside(coarse[j][0], coarse[i]) == (areas[i] > 0.0)  # b on a's material side
            left_of_b = _inside(coarse[i][0], coarse[j]) == (areas[j] > 0.0)
            needed = reaches[i][0 if left_of_a else 1] + reaches[j][0 if left_of_b else 1]
            apart = np.maximum(boxes[i][0] - boxes[j][1], boxes[j][0] - boxes[i][1]).max()
            if needed == 0.0 or apart > needed:
                continue
            gap, place = _least_gap(partial(dense, i), partial(dense, j), needed, size / 64.0)
            if gap < needed * (1.0 + _FIT_SLACK):
                return (
                    f"{name} {shown(edge_radius)} gives rolls {max(*reaches[i], *reaches[j]):.6g} wide; those of {a.name} "
                    f"and {b.name} meet near {at(float(place[0]), float(place[1]), min(a.high, b.high))}: the material "
                    f"between them is {gap:.6g} wide, narrower than the two rolls ({needed:.6g})"
                )
    return None


def _least_gap(p: Callable[[float], NDArray[np.float64]], q: Callable[[float], NDArray[np.float64]], needed: float,
               spacing: float) -> tuple[float, NDArray[np.float64]]:  # fmt: skip
    """The least distance between two plan loops, given as their polygons at a spacing (``_polygon``), sampled
    ``spacing`` apart and finer until it is known to be above ``needed`` or within a tenth of it (a distance
    over samples errs by at most half their spacing), and a point where it is."""
    while True:
        gap, place = _gap(p(spacing), q(spacing))
        if gap - spacing / 2.0 > needed or gap < needed or spacing <= needed / 20.0:
            return gap, place
        spacing /= 8.0


def stack_solid(walls: Sequence[Wall], roll: list[Segment], tolerance: float, size: float) -> tuple[TopoDS_Solid, float]:
    """The closed solid of ``walls`` (which fit: ``stack_problem``) with the roll profile ``roll`` (of
    reach 1 per unit w, scaled to each rim's reach), and the largest deviation of a patch over a spiral
    from the exact sweep. Sewn with tolerance 1e-7 × ``size``; not yet verified."""
    patches: list[TopoDS_Face] = []
    fast = True
    levels: dict[tuple[float, bool], list[tuple[TopoDS_Wire, NDArray[np.float64]]]] = {}
    approximation = 0.0
    for wall in walls:
        height = wall.high - wall.low
        d_top, d_bottom = wall.top, wall.bottom
        if d_top + d_bottom > height - 1e-7 * size:  # a wall thinner than the sewing tolerance: the rolls meet
            d_top, d_bottom = (height / 2.0, height / 2.0) if d_top and d_bottom else (d_top and height, d_bottom and height)
        reach = max(d_top, d_bottom)
        alongs = [span for s in wall.loop for span in _along_spans(_along(s, 1.0, reach, tolerance))]
        fast = fast and len(alongs) > 2  # two spans between the same two corners (a D: a chord and an arc) look alike to it
        sections = _sections(roll, d_top, d_bottom, wall.low, wall.high, foot=wall.foot, head=wall.head)
        made = [_surface_face(a, sec, 1e-9 * size) for a in alongs for sec in sections]
        patches += [face for face, _ in made]
        for k, (_, key) in enumerate(made):  # so export_step finds the note on parts built from this solid
            _record(key, reach * alongs[k // len(sections)].deviation)
        approximation = max(approximation, reach * max(a.deviation for a in alongs))
        clamped = Wall(wall.loop, wall.low, wall.high, d_top, d_bottom, wall.foot, wall.head, wall.name)
        for z, up, w, right in clamped.rims():
            polygon = _polygon(wall.loop, w, size / 64.0)
            wire = _rim_wire(alongs, w, z, reverse=right)
            levels.setdefault((z, up), []).append((wire, polygon[::-1] if right else polygon))
    caps, top = [], None
    for (z, up), rims in sorted(levels.items()):
        for face in _level_faces(z, rims):
            caps.append(face)
            top = face if up else top
    assert top is not None
    return _solid(patches, caps, size, top, fast=fast), approximation


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
