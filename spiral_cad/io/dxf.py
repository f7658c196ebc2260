"""DXF (R2010) through ezdxf: LINE, ARC and exact cubic SPLINE entities on a layer named after the design.

Chains in space are written in 3-D: lines and spline control points with
their z, and an arc in space as an ARC in its own object coordinate system
(OCS): its ``extrusion`` is the arc's normal, turned so that the arc runs
counterclockwise about it as DXF arcs do, its centre and angles in OCS
coordinates (DXF's arbitrary axis algorithm, ``ezdxf.math.OCS``).

The header declares the unit twice, as readers differ in which they use:
``$INSUNITS`` (4 mm, 5 cm, 6 m, 7 km, 1 in, 2 ft) and ``$MEASUREMENT``
(1 metric, 0 imperial, which Inkscape and LibreCAD use for scaling). The
extents (``$EXTMIN``/``$EXTMAX``) are the drawing's bounding box and the
limits (``$LIMMIN``/``$LIMMAX``) that box with a margin of 5 % of its
diagonal, in the drawing's unit, so viewers open and print the whole
drawing. The layer name follows DXF's rules (``formats.names.dxf_layer_name``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import cast

import numpy as np

from ..core.chain import Chain
from ..core.kinds import ARC, SPIRAL
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..core.units import IMPERIAL
from .names import dxf_layer_name

#: ``$INSUNITS`` codes.
INSUNITS = {"in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6, "km": 7}
#: Knot vector of one cubic Bézier written as a B-spline.
BEZIER_KNOTS = (0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)
#: The limits' margin around the extents, a fraction of their diagonal.
LIMITS_MARGIN = 0.05


def _xyz(point) -> tuple[float, float, float]:
    x, y, *z = point.tolist()
    return x, y, (z[0] if z else 0.0)


def _add(msp, seg: Segment, layer: str, attribs: dict | None = None):
    """Add one segment to ``msp`` on ``layer``, with the other graphic attributes ``attribs`` (colour, linetype …); the entity."""
    attribs = {**(attribs or {}), "layer": layer}
    if isinstance(seg, Line):
        return msp.add_line(_xyz(seg.start), _xyz(seg.end), dxfattribs=attribs)
    if isinstance(seg, Arc) and seg.dim == 2:
        # DXF arcs run counterclockwise: a clockwise arc is written from its end.
        a, b = math.degrees(seg.start_angle), math.degrees(seg.start_angle + math.copysign(seg.sweep, seg.radius))
        start, end = (a, b) if seg.radius > 0 else (b, a)
        return msp.add_arc(tuple(seg.center), abs(seg.radius), start, end, dxfattribs=attribs)
    if isinstance(seg, Arc):
        return _add_arc_in_space(msp, seg, attribs)
    if isinstance(seg, BezierSpiral):
        points = [_xyz(p) for p in seg.control_points]
        spline = msp.add_open_spline(points, degree=3, knots=BEZIER_KNOTS, dxfattribs=attribs)
        spline.dxf.flags |= spline.PLANAR  # every spiral lies in one plane
        return spline
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {seg!r}")


def _add_arc_in_space(msp, arc: Arc, attribs: dict):
    """An ARC in the OCS whose extrusion is the arc's normal, turned for counterclockwise travel."""
    from ezdxf.math import OCS

    extrusion = tuple((math.copysign(1.0, arc.radius) * arc.normal).tolist())
    ocs = OCS(extrusion)
    center, start = ocs.from_wcs(_xyz(arc.center)), ocs.from_wcs(_xyz(arc.start))
    a = math.degrees(math.atan2(start.y - center.y, start.x - center.x))
    return msp.add_arc((center.x, center.y, center.z), abs(arc.radius), a, a + math.degrees(arc.sweep),
                dxfattribs={**attribs, "extrusion": extrusion})  # fmt: skip


def _arc_extreme_parameters(arc: Arc) -> list[float]:
    """Where inside an arc (u in (0, 1)) a coordinate can be extreme: where it runs across an axis."""
    found = []
    (e1, e2), sense = arc.basis, math.copysign(1.0, arc.radius)
    for axis in range(arc.dim):
        # the axis coordinate is c + |r|·(cos a·e1 + sin a·e2): extreme where tan a = e2/e1
        peak = math.atan2(e2[axis], e1[axis])
        for angle in (peak, peak + math.pi):
            u = (sense * (angle - arc.start_angle)) % (2.0 * math.pi) / arc.sweep
            if 0.0 < u < 1.0:
                found.append(u)
    return found


def _cubic_extreme_points(cp: np.ndarray) -> np.ndarray:
    """Points of N cubic Béziers (N, 4, 3) where a coordinate can be extreme inside (0, 1):
    the roots of B'(t)/3 = a(1−t)² + 2b(1−t)t + ct² per axis, (N, 6, 3) (an end where a root is not inside)."""
    a, b, c = cp[:, 1] - cp[:, 0], cp[:, 2] - cp[:, 1], cp[:, 3] - cp[:, 2]
    qa, qb, qc = a - 2.0 * b + c, 2.0 * (b - a), a  # qa·t² + qb·t + qc, per curve and axis
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(qb * qb - 4.0 * qa * qc)  # NaN where the roots are complex
        q = -0.5 * (qb + np.copysign(root, qb))  # the stable pair: q/qa and qc/q
        t = np.stack([np.where(qa != 0.0, q / qa, -qc / qb), qc / q], axis=1).reshape(len(cp), 6)
    t = np.where((t > 0.0) & (t < 1.0), t, 0.0)[..., None]
    s = 1.0 - t
    return (s**3 * cp[:, None, 0] + 3.0 * s * s * t * cp[:, None, 1] + 3.0 * s * t * t * cp[:, None, 2]
            + t**3 * cp[:, None, 3])  # fmt: skip


def extents(chains: Sequence[Chain]) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The drawing's exact bounding box ((xmin, ymin, zmin), (xmax, ymax, zmax)); z is 0 in the plane.

    From the rows of every chain: every segment's ends, the spirals' interior
    extremes (all spirals at once) and each arc's axis crossings."""
    points = []
    for chain in chains:
        rows = chain.rows
        ends = chain.segment_ends.reshape(-1, chain.dim)
        points.append(np.column_stack([ends, np.zeros((len(ends), 3 - chain.dim))]))
        spirals = rows.geometry[rows.kind == SPIRAL]
        if len(spirals):
            points.append(_cubic_extreme_points(spirals).reshape(-1, 3))
        for i in np.flatnonzero(rows.kind == ARC).tolist():
            arc = cast(Arc, chain[i])  # the row's kind says so
            inside = _arc_extreme_parameters(arc)
            if inside:
                found = np.atleast_2d(arc.point(np.array(inside)))
                points.append(np.column_stack([found, np.zeros((len(found), 3 - found.shape[1]))]))
    everything = np.vstack(points)
    low, high = everything.min(axis=0), everything.max(axis=0)
    return (float(low[0]), float(low[1]), float(low[2])), (float(high[0]), float(high[1]), float(high[2]))


def _set_extents_and_limits(doc, msp, chains: Sequence[Chain]) -> None:
    low, high = extents(chains)
    (x0, y0, _), (x1, y1, _) = low, high
    pad = LIMITS_MARGIN * math.hypot(x1 - x0, y1 - y0)
    limits = (x0 - pad, y0 - pad), (x1 + pad, y1 + pad)
    msp.reset_extents(low, high)
    msp.reset_limits(*limits)
    doc.header["$EXTMIN"], doc.header["$EXTMAX"] = low, high
    doc.header["$LIMMIN"], doc.header["$LIMMAX"] = limits


def write_dxf(chains: Sequence[Chain], path: str | os.PathLike, name: str, units: str) -> None:
    """Write ``chains`` in travel order on the layer named after ``name``; a full circle is an ARC
    from an angle to itself + 360°."""
    import ezdxf

    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = INSUNITS[units]
    doc.header["$MEASUREMENT"] = 0 if units in IMPERIAL else 1
    doc.header["$LUNITS"] = 2  # decimal
    layer = dxf_layer_name(name)
    if not doc.layers.has_entry(layer):  # "0" exists already
        doc.layers.add(layer)
    msp = doc.modelspace()
    for chain in chains:
        for seg in chain:
            _add(msp, seg, layer)
    _set_extents_and_limits(doc, msp, chains)
    doc.saveas(os.fspath(path))
