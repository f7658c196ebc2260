"""DXF in: a drawing's lines and arcs, chained by their ends into paths (through ezdxf).

What is read, from the model space: ``LINE``, ``ARC``, ``CIRCLE``, ``LWPOLYLINE`` and ``POLYLINE``
(2-D with bulges, and 3-D polylines), in any object coordinate system (a mirrored arc, extrusion
(0, 0, -1), is a clockwise arc), and ``SPLINE`` s of degree 1 to 3 given by control points with equal
weights in a plane parallel to XY (as ``export_dxf`` writes a spiral, and most drawing programs a
free-form curve): each is cut into its Bézier pieces, and each piece at its inflections and curvature
extrema (``bezier.monotone_pieces``) into spiral pieces (``BezierSpiral``), so a spiral written by us
comes back as itself. ``ELLIPSE``, ``HELIX``, block references (``INSERT``), rational splines, splines
given by fit points only and polyface or mesh polylines are refused by name and handle; text,
dimensions, hatches, points and the other annotation are left out (``DxfPaths.notes`` counts them).

The unit is the header's ``$INSUNITS`` (1 in, 2 ft, 4 mm, 5 cm, 6 m, 7 km); a unitless drawing (0,
or an R12 file, which has no ``$INSUNITS``) is refused unless its unit is stated (``units=``;
``build``: ``--units``), and another unit is refused by name.

Chaining: the entities are joined end to start where their ends lie within ``join_tolerance``
times the drawing's size (its bounding box's diagonal) of each other, a segment turned round where
needed; a path runs on through a point only where exactly two ends meet (a branch ends every path
there), and is closed when its ends meet. Paths keep the drawing's order (of each path's first
entity).
"""

from __future__ import annotations

import math
import mmap
import os
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core import bezier
from ..core.segments import Arc, Line
from ..core.spiral import BezierSpiral
from ..core.units import MM_PER_UNIT, length_unit

__all__ = ["DXF_UNITS", "JOIN_TOLERANCE", "DxfPath", "DxfPaths", "drop_unstated_units", "read_dxf_paths"]

#: ``$INSUNITS`` codes read, and their units.
DXF_UNITS = {1: "in", 2: "ft", 4: "mm", 5: "cm", 6: "m", 7: "km"}
#: Ends closer than this times the drawing's size are one point (CAD writes ~1e-12; R12 text ~1e-6 of a part's size).
JOIN_TOLERANCE = 1e-6
#: Entities refused by name, and why.
REFUSED = {
    "ELLIPSE": "an ELLIPSE (not a line or a circular arc)",
    "HELIX": "a HELIX (not a plane curve)",
    "INSERT": "a block reference (INSERT): explode the block first",
}
#: Entities read as geometry.
READ = ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE")
#: Entities read as their Bézier pieces (the in-place rewrite, ``dxf_g2``, reads them as biarcs instead).
CUBICS = ("SPLINE",)


@dataclass(frozen=True)
class DxfPath:
    """One chained path of a drawing.

    Attributes:
        segments: the lines, arcs and spiral pieces (of SPLINEs), end to start (in the paths' unit).
        closed: whether the path's last end meets its first start.
        handles: the DXF handle of every segment's entity (for messages).
    """

    segments: tuple[Line | Arc | BezierSpiral, ...]
    closed: bool
    handles: tuple[str, ...]


@dataclass(frozen=True)
class DxfPaths:
    """The paths of a DXF drawing: ``paths``, their ``units``, the file's name and what was left out (``notes``)."""

    paths: tuple[DxfPath, ...]
    units: str
    source: str
    notes: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.paths)


def drop_unstated_units(doc: Any, path: str | os.PathLike) -> None:
    """Take out of ``doc``'s header the ``$INSUNITS`` and ``$MEASUREMENT`` its file at ``path`` never stated.

    ezdxf gives a file without a HEADER section (many R12 writers leave it out) a header of its own defaults,
    ``$INSUNITS`` 6 (metres) among them: read as it comes, such a drawing would be measured, rewritten and
    reported in metres although it states no unit. The file's bytes are searched for the variable's name."""
    names = [name for name in ("$INSUNITS", "$MEASUREMENT") if name in doc.header]
    if not names:
        return
    with open(path, "rb") as file, mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ) as data:
        for name in names:
            if data.find(name.encode("ascii")) < 0:
                del doc.header[name]


def read_dxf_paths(path: str | os.PathLike, *, units: str | None = None, drawing_units: str | None = None,
                   join_tolerance: float = JOIN_TOLERANCE) -> DxfPaths:  # fmt: skip
    """The lines and arcs of a DXF file chained into paths (see the module docstring).

    Args:
        path: the .dxf file.
        units: the paths' unit (mm, cm, m, km, in, ft); the drawing's is converted to it (default: the drawing's).
        drawing_units: the unit of a unitless drawing (default ``units``; neither: a unitless drawing is refused);
            a drawing that states its unit is read in its own.
        join_tolerance: ends closer than this times the drawing's size are joined.

    Raises:
        ValueError: not a DXF file, a refused entity (named with its handle), a unitless drawing without
            ``units``, an unknown ``$INSUNITS``, no line or arc, a degenerate entity.
        OSError: the file could not be read.
    """
    import ezdxf

    name = os.fspath(path)
    label = os.path.basename(name) or name
    if not os.path.isfile(name):
        raise ValueError(f"{label}: the DXF file is {'a folder' if os.path.isdir(name) else 'missing'}")
    if not 0.0 < join_tolerance < 1.0:
        raise ValueError(f"join_tolerance must lie in (0, 1) (a share of the drawing's size); got {join_tolerance}")
    try:
        doc = ezdxf.readfile(name)
    except (ezdxf.DXFError, UnicodeDecodeError, OSError) as error:  # ezdxf says "not a DXF file" with an OSError
        raise ValueError(f"{label}: not a DXF file ezdxf can read ({error})") from None
    except Exception as error:  # a malformed tag ezdxf's loader trips on ('inf' as a colour, a broken VIEWPORT)
        raise ValueError(f"{label}: not a DXF file ezdxf can read ({type(error).__name__}: {error})") from None
    drop_unstated_units(doc, name)
    target = None if units is None else length_unit(units)
    code = int(doc.header.get("$INSUNITS", 0))
    if code == 0:
        stated = drawing_units or target
        if stated is None:
            raise ValueError(f"{label}: the drawing is unitless ($INSUNITS 0 or missing, as in R12); state its unit "
                             "(spiral-cad: --units mm; Python: drawing_units=\"mm\")")  # fmt: skip
        drawing = length_unit(stated)
    elif code in DXF_UNITS:
        drawing = DXF_UNITS[code]
    else:
        raise ValueError(f"{label}: $INSUNITS {code} is not a unit read here ({', '.join(f'{k} {u}' for k, u in DXF_UNITS.items())})")
    target = target or drawing
    factor = MM_PER_UNIT[drawing] / MM_PER_UNIT[target]
    pieces: list[tuple[list[tuple[str, np.ndarray, np.ndarray, tuple]], str]] = []  # per entity: its parts in WCS, its handle
    skipped: Counter[str] = Counter()
    for entity in doc.modelspace():
        kind = entity.dxftype()
        handle = str(entity.dxf.handle)
        if kind in REFUSED:
            raise ValueError(
                f"{label}: entity {handle} is {REFUSED[kind]}; only LINE, ARC, CIRCLE, LWPOLYLINE, POLYLINE and SPLINE are read"
            )
        if kind not in READ and kind not in CUBICS:
            skipped[kind] += 1
            continue
        try:
            parts = _entity_parts(entity, kind)
        except ValueError as error:
            raise ValueError(f"{label}: {kind} {handle}: {error}") from None
        if parts:
            pieces.append((parts, handle))
    if not pieces:
        raise ValueError(f"{label}: no LINE, ARC, CIRCLE, polyline or SPLINE in the model space")
    ends = np.array([p for parts, _ in pieces for part in (parts[0], parts[-1]) for p in (part[1], part[2])])
    extent = ends.max(axis=0) - ends.min(axis=0)
    widest = float(np.abs(extent).max())
    size = widest * float(np.linalg.norm(extent / widest)) if widest > 0.0 else 1.0  # no overflow at 1e200
    flat = all(
        abs(p[1][2]) == 0.0 and abs(p[2][2]) == 0.0 and (p[0] == "line" or p[0] == "cubic" or abs(p[3][1][:2]).max() == 0.0)
        for parts, _ in pieces
        for p in parts
    )  # fmt: skip (a cubic lies at one z: its ends')
    dim = 2 if flat else 3
    paths = []
    for order, closed in _chains(pieces, join_tolerance * size):
        segments, handles = [], []
        for index, reverse in order:
            parts, handle = pieces[index]
            try:
                made = [segment for part in parts for segment in _segments(part, factor, dim)]
            except ValueError as error:
                raise ValueError(f"{label}: entity {handle}: {error}") from None
            if reverse:
                made = [s.reversed() for s in reversed(made)]
            segments += made
            handles += [handle] * len(made)
        paths.append(DxfPath(tuple(segments), closed, tuple(handles)))
    notes = [f"left out {count} {kind}" for kind, count in sorted(skipped.items())]
    if code == 0:
        notes.append(f"the drawing is unitless: read in {drawing} as stated")
    return DxfPaths(tuple(paths), target, label, tuple(notes))


def _entity_parts(entity, kind: str) -> list[tuple]:
    """The parts of one entity in world coordinates: ``("line", start, end, None)`` and
    ``("arc", start, end, (centre, normal, sweep))``, in drawing order."""
    from ezdxf.math import OCS, Vec3

    if kind == "LINE":
        start, end = np.array(entity.dxf.start, dtype=float), np.array(entity.dxf.end, dtype=float)
        return [] if np.array_equal(start, end) else [("line", start, end, None)]
    if kind == "SPLINE":
        return _spline_parts(entity)
    extrusion = Vec3(entity.dxf.get("extrusion", (0.0, 0.0, 1.0)))
    ocs = OCS(extrusion)
    normal = np.array(extrusion.normalize(), dtype=float)

    def wcs(x: float, y: float, z: float) -> np.ndarray:
        return np.array(ocs.to_wcs(Vec3(x, y, z)), dtype=float)

    if kind in ("ARC", "CIRCLE"):
        cx, cy, cz = entity.dxf.center
        radius = float(entity.dxf.radius)
        if not radius > 0.0:
            raise ValueError(f"radius {radius:g}: an arc needs a positive radius")
        a0 = math.radians(entity.dxf.start_angle) if kind == "ARC" else 0.0
        sweep = (math.radians(entity.dxf.end_angle) - a0) % (2 * math.pi) if kind == "ARC" else 2 * math.pi
        sweep = sweep or 2 * math.pi
        start = wcs(cx + radius * math.cos(a0), cy + radius * math.sin(a0), cz)
        end = wcs(cx + radius * math.cos(a0 + sweep), cy + radius * math.sin(a0 + sweep), cz)
        return [("arc", start, end, (wcs(cx, cy, cz), normal, sweep))]
    if kind == "POLYLINE" and not (entity.is_2d_polyline or entity.is_3d_polyline):
        raise ValueError("a polyface or mesh POLYLINE is a surface, not a path")
    if kind == "LWPOLYLINE":
        elevation = float(entity.dxf.get("elevation", 0.0))
        vertices = [(x, y, elevation, b) for x, y, b in entity.get_points("xyb")]
    elif entity.is_3d_polyline:
        vertices = [(*v.dxf.location, 0.0) for v in entity.vertices]
        ocs = OCS()  # 3-D polylines are in world coordinates
    else:
        vertices = [(*v.dxf.location, float(v.dxf.get("bulge", 0.0))) for v in entity.vertices]
    if entity.is_closed and len(vertices) > 1:
        vertices.append((*vertices[0][:3], 0.0))
    parts: list[tuple] = []
    for (x0, y0, z0, bulge), (x1, y1, z1, _) in zip(vertices[:-1], vertices[1:]):
        start, end = wcs(x0, y0, z0), wcs(x1, y1, z1)
        if np.array_equal(start, end):
            continue
        if bulge == 0.0:
            parts.append(("line", start, end, None))
            continue
        theta = 4.0 * math.atan(bulge)  # the included angle, counterclockwise in the OCS when positive
        chord = math.hypot(x1 - x0, y1 - y0)
        along = chord / 2 / math.tan(theta / 2)  # the centre's distance left of the chord's middle
        cx, cy = (x0 + x1) / 2 - along * (y1 - y0) / chord, (y0 + y1) / 2 + along * (x1 - x0) / chord
        parts.append(("arc", start, end, (wcs(cx, cy, z0), normal if theta > 0 else -normal, abs(theta))))
    return parts


def _spline_parts(spline: Any) -> list[tuple]:
    """A SPLINE's Bézier pieces, in world coordinates: ``("cubic", start, end, (4, 3) control points)`` (degree 2
    pieces raised to degree 3, exactly), or ``("line", start, end, None)`` for a straight one."""
    from ezdxf.math import BSpline

    if not len(spline.control_points):
        raise ValueError("a SPLINE given by fit points only: its curve is the writer's interpolation, not stated; "
                         "save it with control points")  # fmt: skip
    points = np.array(spline.control_points, dtype=float).reshape(-1, 3)
    if not np.isfinite(points).all():
        raise ValueError(f"control point {int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])} is not finite")
    weights = list(spline.weights)
    if weights and max(weights) != min(weights):
        raise ValueError(f"a rational SPLINE (weights from {min(weights):g} to {max(weights):g}): a conic, not a cubic")
    degree = int(spline.dxf.degree)
    if degree not in (1, 2, 3):
        raise ValueError(f"a SPLINE of degree {degree}: only degrees 1 to 3 are read")
    extent = float(np.ptp(points, axis=0).max()) if len(points) > 1 else 0.0
    if np.ptp(points[:, 2]) > 1e-12 * max(extent, abs(points[:, 2]).max()):
        raise ValueError(f"a SPLINE off the XY plane (control points at z from {points[:, 2].min():g} to {points[:, 2].max():g})")
    knots = np.array(spline.knots, dtype=float)
    if len(knots) != len(points) + degree + 1 or not np.isfinite(knots).all() or np.any(np.diff(knots) < 0.0):
        raise ValueError(f"a SPLINE whose {len(knots)} knots are not {len(points) + degree + 1} non-decreasing numbers")
    _, repeats = np.unique(knots[degree + 1 : len(knots) - degree - 1], return_counts=True)
    if len(repeats) and repeats.max() > degree:
        raise ValueError(f"a SPLINE with an inner knot repeated {repeats.max()} times (more than its degree {degree}: "
                         "the curve breaks there)")  # fmt: skip
    try:  # equal weights: the same curve as none (ezdxf's decomposition takes no weights)
        pieces = list(BSpline(points.tolist(), order=degree + 1, knots=knots.tolist()).bezier_decomposition())
    except Exception as error:  # an unclamped (periodic) knot vector, or knots ezdxf cannot split
        raise ValueError(f"a SPLINE ezdxf cannot cut into Bézier pieces ({type(error).__name__}: {error})") from None
    parts: list[tuple] = []
    for piece in pieces:
        cp = np.array(piece, dtype=float)
        if not np.any(np.diff(cp, axis=0)):
            continue  # a piece that goes nowhere
        chord = cp[-1] - cp[0]
        along = (cp - cp[0]) @ chord
        off = np.linalg.norm(np.cross(cp - cp[0], chord), axis=-1)
        if along.min() >= 0.0 and along.max() <= chord @ chord and off.max() <= 1e-12 * (chord @ chord):
            parts.append(("line", cp[0], cp[-1], None))  # straight and never back (every degree-1 piece): a line
            continue
        if degree == 2:  # degree elevation: the same curve
            cp = np.array([cp[0], cp[0] + 2 / 3 * (cp[1] - cp[0]), cp[2] + 2 / 3 * (cp[1] - cp[2]), cp[2]])
        parts.append(("cubic", cp[0], cp[-1], cp))
    return parts


def _segments(part: tuple, factor: float, dim: int) -> list[Line | Arc | BezierSpiral]:
    """A part as segments in the paths' unit, in the plane (``dim`` 2) or in space: one line or arc, or a
    cubic's spiral pieces."""
    kind, start, end, data = part
    if kind == "line":
        line = Line(start[:dim] * factor, end[:dim] * factor)
        return [Line._of(start * factor, end * factor) if line.dim != dim else line]
    if kind == "cubic":
        cubic = data * factor
        pieces: list[Line | Arc | BezierSpiral] = []
        for u0, u1 in bezier.monotone_pieces(cubic[:, :2]):
            piece = cubic[:, :2] if (u0, u1) == (0.0, 1.0) else bezier.split(cubic[:, :2], u0, u1)
            pieces.append(BezierSpiral.from_control_points(np.column_stack([piece, cubic[:, 2]])[:, :dim]))
        return pieces
    centre, normal, sweep = data
    if dim == 2:
        angle = math.atan2(start[1] - centre[1], start[0] - centre[0])
        radius = math.hypot(start[0] - centre[0], start[1] - centre[1]) * factor
        return [Arc(centre[:2] * factor, math.copysign(radius, normal[2]), angle, sweep)]
    return [Arc.in_space(centre * factor, normal, start * factor, sweep)]


def _chains(pieces: list, tolerance: float) -> list[tuple[list[tuple[int, bool]], bool]]:
    """The entities chained: per path, (entity index, reversed) in travel order, and whether it is closed."""
    from scipy.spatial import cKDTree

    count = len(pieces)
    ends = np.array([point for parts, _ in pieces for point in (parts[0][1], parts[-1][2])])  # 2k: start, 2k+1: end
    scale = float(np.abs(ends).max()) or 1.0  # the tree squares distances: coordinates of 1e200 must not overflow
    tree = cKDTree(ends / scale)
    near = tree.query_ball_point(ends / scale, tolerance / scale)
    mates: list[int | None] = []
    for k, found in enumerate(near):
        others = [j for j in found if j != k]
        mates.append(others[0] if len(others) == 1 else None)  # runs on only where exactly two ends meet
    used = [False] * count
    chains = []
    for first in range(count):
        if used[first]:
            continue
        used[first] = True
        order = [(first, False)]
        at = 2 * first + 1  # the path's end: entity first's end
        while (mate := mates[at]) is not None and not used[mate // 2]:
            used[mate // 2] = True
            reverse = mate % 2 == 1  # met at its end: travel it backwards
            order.append((mate // 2, reverse))
            at = mate - 1 if reverse else mate + 1
        back = 2 * first  # the path's start: extend backwards
        while (mate := mates[back]) is not None and not used[mate // 2]:
            used[mate // 2] = True
            reverse = mate % 2 == 0  # met at its start: it runs into the path backwards
            order.insert(0, (mate // 2, reverse))
            back = mate + 1 if reverse else mate - 1
        closed = mates[at] == back or (len(order) == 1 and float(np.linalg.norm(ends[at] - ends[back])) <= tolerance)
        chains.append((order, closed))
    return chains
