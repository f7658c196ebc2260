"""A DXF drawing's curves as exact OCCT edges, so that the STEP checker judges a drawing as it is drawn.

Read from the model space through ezdxf, every curve exactly as it is stored: ``LINE``, ``ARC`` and
``CIRCLE`` (in their object coordinate system: a mirrored arc stays clockwise), ``ELLIPSE`` (its arc; a
ratio above 1 as the same ellipse with its axes swapped), ``SPLINE`` (its control points, knots and
weights: a B-spline curve as written), ``LWPOLYLINE`` and ``POLYLINE`` (their lines and bulge arcs), and
block references (``INSERT`` and MINSERT grids: their curves placed, nested blocks included). Text,
dimensions, hatches, points and other annotation are left out. The drawing's unit is its ``$INSUNITS``
(``io.dxf_read.DXF_UNITS``); a unitless drawing is in drawing units.

The checker judges joints between edges, so every point where a curve may be less than G2 is made one:
a spline is cut at its inner knots below C2, and a curve that closes on itself is cut in two halves.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.Geom import Geom_BSplineCurve
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Compound, TopoDS_Edge

from ..io.dxf_g2 import open_drawing
from ..io.dxf_read import DXF_UNITS

__all__ = ["DRAWING_UNITS", "MAX_ENTITIES", "dxf_shape"]

#: The unit stated for a drawing whose ``$INSUNITS`` names none.
DRAWING_UNITS = "drawing units"
#: Block references nested deeper than this are refused (a block that contains itself).
_MAX_DEPTH = 32


def _point(v: Any) -> gp_Pnt:
    return gp_Pnt(float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)


def _span(curve: Any, t0: float, t1: float, closed: bool) -> list[TopoDS_Edge]:
    """The curve from ``t0`` to ``t1`` as one edge, or as two halves when it closes on itself (so that its
    closing point is a joint between two edges, judged like any other)."""
    if not closed:
        return [BRepBuilderAPI_MakeEdge(curve, t0, t1).Edge()]
    middle = 0.5 * (t0 + t1)
    return [BRepBuilderAPI_MakeEdge(curve, t0, middle).Edge(), BRepBuilderAPI_MakeEdge(curve, middle, t1).Edge()]


def _arc(entity: Any) -> list[TopoDS_Edge]:
    """An ARC or a CIRCLE on its circle, in its object coordinate system (whose x axis and normal place the
    angles: a mirrored arc, extrusion (0, 0, −1), runs clockwise as seen from +z)."""
    ocs = entity.ocs()
    axis = gp_Ax2(_point(ocs.to_wcs(entity.dxf.center)), gp_Dir(*ocs.uz), gp_Dir(*ocs.ux))
    circle = gp_Circ(axis, float(entity.dxf.radius))
    if entity.dxftype() == "CIRCLE":
        return _span(circle, 0.0, 2.0 * math.pi, True)
    a0 = math.radians(float(entity.dxf.start_angle))
    sweep = math.radians((float(entity.dxf.end_angle) - float(entity.dxf.start_angle)) % 360.0) or 2.0 * math.pi
    return _span(circle, a0, a0 + sweep, sweep == 2.0 * math.pi)


def _ellipse(entity: Any) -> list[TopoDS_Edge]:
    """An ELLIPSE's arc: P(t) = C + cos t · M + sin t · ratio · (N × M), as OCCT's ellipse; a ratio above 1
    (which ezdxf draws) is the same ellipse with its axes swapped, a quarter turn on in t."""
    major, normal = entity.dxf.major_axis, entity.dxf.extrusion
    ratio, t0, t1 = float(entity.dxf.ratio), float(entity.dxf.start_param), float(entity.dxf.end_param)
    span = (t1 - t0) % (2.0 * math.pi) or 2.0 * math.pi
    a = float(major.magnitude)
    if ratio > 1.0:
        major, a, ratio, t0 = normal.cross(major).normalize(a * ratio), a * ratio, 1.0 / ratio, t0 - 0.5 * math.pi
    axis = gp_Ax2(_point(entity.dxf.center), gp_Dir(*normal), gp_Dir(*major.normalize()))
    return _span(gp_Elips(axis, a, a * ratio), t0, t0 + span, span == 2.0 * math.pi)


def _spline(entity: Any) -> list[TopoDS_Edge]:
    """A SPLINE as written (control points, weights, knots; a fit-point spline as ezdxf interpolates it), cut
    at every inner knot where it is less than C2, where a corner or a curvature jump may be (each cut is then
    a joint the checker judges), and in two when it closes on itself."""
    tool = entity.construction_tool()
    degree = tool.order - 1
    points = np.array([tuple(p) for p in tool.control_points], dtype=float).reshape(-1, 3)
    weights = np.array(list(tool.weights()) or [1.0] * len(points), dtype=float)
    pieces = _pieces(np.column_stack([points * weights[:, None], weights]), np.array(list(tool.knots()), dtype=float), degree)
    curves = [_bspline(h, knots, degree) for h, knots in pieces]
    first, last = curves[0].Value(curves[0].FirstParameter()), curves[-1].Value(curves[-1].LastParameter())
    size = float(np.ptp(points, axis=0).max()) if len(points) else 0.0
    closed = len(curves) == 1 and first.Distance(last) <= 1e-12 * max(size, 1e-300)
    return [edge for curve in curves for edge in _span(curve, curve.FirstParameter(), curve.LastParameter(), closed)]


def _inserted(h: NDArray, knots: NDArray, degree: int, value: float) -> tuple[NDArray, NDArray]:
    """The homogeneous poles and knots with ``value`` inserted once (Boehm; the curve unchanged)."""
    k, p = int(np.searchsorted(knots, value, side="right")) - 1, degree
    out = np.empty((len(h) + 1, h.shape[1]))
    out[: k - p + 1] = h[: k - p + 1]
    for i in range(k - p + 1, k + 1):
        a = (value - knots[i]) / (knots[i + p] - knots[i])
        out[i] = a * h[i] + (1.0 - a) * h[i - 1]
    out[k + 1 :] = h[k:]
    return out, np.insert(knots, k + 1, value)


def _pieces(h: NDArray, knots: NDArray, degree: int) -> list[tuple[NDArray, NDArray]]:
    """The spline cut at its inner knots of multiplicity at least ``degree − 1`` (below C2): each such knot
    raised to the degree (the curve passes a pole there), then split into clamped pieces."""
    p = degree
    values, counts = np.unique(knots[p + 1 : len(knots) - p - 1], return_counts=True)
    breaks = [v for v, c in zip(values.tolist(), counts.tolist()) if c >= p - 1]
    for value in breaks:
        while int(np.count_nonzero(knots == value)) < p:
            h, knots = _inserted(h, knots, p, value)
    pieces, pole, head, cursor = [], 0, list(knots[: p + 1]), p + 1
    for value in breaks:
        s, m = int(np.searchsorted(knots, value, side="left")), int(np.count_nonzero(knots == value))
        pieces.append((h[pole:s], np.array(head + list(knots[cursor:s]) + [value] * (p + 1))))
        pole, head, cursor = s + m - p - 1, [value] * (p + 1), s + m
    pieces.append((h[pole:], np.array(head + list(knots[cursor:]))))
    return pieces


def _bspline(h: NDArray, knots: NDArray, degree: int) -> Geom_BSplineCurve:
    """OCCT's B-spline curve of homogeneous poles ``h`` (w·P, w) and the flat knot vector ``knots``."""
    weights = h[:, 3]
    poles = TColgp_Array1OfPnt(1, len(h))
    for k, row in enumerate((h[:, :3] / weights[:, None]).tolist(), start=1):
        poles.SetValue(k, gp_Pnt(*row))
    distinct, copies = np.unique(knots, return_counts=True)
    values, counts = TColStd_Array1OfReal(1, len(distinct)), TColStd_Array1OfInteger(1, len(distinct))
    for k, (value, count) in enumerate(zip(distinct.tolist(), copies.tolist()), start=1):
        values.SetValue(k, value)
        counts.SetValue(k, count)
    if np.all(weights == 1.0):
        return Geom_BSplineCurve(poles, values, counts, degree)
    array = TColStd_Array1OfReal(1, len(weights))
    for k, w in enumerate(weights.tolist(), start=1):
        array.SetValue(k, w)
    return Geom_BSplineCurve(poles, array, values, counts, degree)


_MAKERS = {"LINE": lambda e: [BRepBuilderAPI_MakeEdge(_point(e.dxf.start), _point(e.dxf.end)).Edge()],
           "ARC": _arc, "CIRCLE": _arc, "ELLIPSE": _ellipse, "SPLINE": _spline, "HELIX": _spline}  # fmt: skip
#: The most entities a drawing may hold with its polylines and blocks taken apart: past it, block references
#: that multiply block by block (a block of 2 references to a block of 2 …, 28 deep) are refused rather than
#: left running.
MAX_ENTITIES = 500_000


def _curves(entities: Any, depth: int = 0, seen: list[int] | None = None) -> Iterator[Any]:
    """The curves of ``entities``, polylines and block references taken apart (placed as drawn; a MINSERT's
    every row and column); ``seen`` counts the entities met, all levels together."""
    seen = [0] if seen is None else seen
    for entity in entities:
        seen[0] += 1
        if seen[0] > MAX_ENTITIES:
            raise ValueError(f"more than {MAX_ENTITIES:,} entities with its polylines and blocks taken apart "
                             "(block references that multiply block by block?); not judged")  # fmt: skip
        kind = entity.dxftype()
        if kind in _MAKERS:
            yield entity
        elif kind in ("LWPOLYLINE", "POLYLINE", "INSERT"):
            if depth >= _MAX_DEPTH:
                raise ValueError(f"block references nested deeper than {_MAX_DEPTH} (a block that contains itself?)")
            copies = entity.multi_insert() if kind == "INSERT" and entity.mcount > 1 else [entity]
            for copy in copies:
                if kind == "INSERT" and copy.dxf.get("zscale", 1.0) == 0.0:
                    copy.dxf.zscale = 1.0  # LibreCAD writes 0 for flat blocks; ezdxf cannot place with it
                yield from _curves(copy.virtual_entities(), depth + 1, seen)


def dxf_shape(path: str | os.PathLike) -> tuple[TopoDS_Compound, str, list[str]]:
    """The curves of the DXF file ``path`` as one compound of exact edges, the drawing's unit
    (``DRAWING_UNITS`` when it states none) and notes for the reader (curves of no length left out,
    ezdxf's recover mode).

    Raises:
        ValueError: a file neither of ezdxf's readers reads (``io.dxf_g2.open_drawing``), no curve in the
            model space, or a curve OCCT cannot build (naming its entity type and handle).
    """
    source = Path(path)
    doc, recovered = open_drawing(source)
    compound, builder, count, empty = TopoDS_Compound(), BRep_Builder(), 0, Counter[str]()
    builder.MakeCompound(compound)
    curves = _curves(doc.modelspace())
    while True:
        try:
            entity = next(curves, None)
        except ValueError as error:
            raise ValueError(f"{source.name}: {error}") from None
        except Exception as error:  # noqa: BLE001 - ezdxf placing a block or a polyline it cannot: named, never a crash
            raise ValueError(
                f"{source.name}: a polyline or block reference ezdxf cannot take apart: {error or type(error).__name__}"
            ) from None
        if entity is None:
            break
        kind = entity.dxftype()
        try:
            edges = _MAKERS[kind](entity)
        except Exception as error:  # noqa: BLE001 - OCCT's Standard_Failure or a malformed entity: named, never a crash
            if _no_length(entity):
                empty[kind] += 1
                continue
            handle = entity.dxf.get("handle") or "(in a polyline or block)"
            raise ValueError(f"{source.name}: {kind} {handle} cannot be built as a curve: {error or type(error).__name__}") from None
        for edge in edges:
            builder.Add(compound, edge)
        count += 1
    if not count:
        raise ValueError(f"{source.name}: the drawing's model space holds no curve (lines, arcs, circles, ellipses, splines, polylines)")
    notes = [f"{n} {kind}(s) of no length left out" for kind, n in sorted(empty.items())]
    notes += [recovered] if recovered else []
    return compound, DXF_UNITS.get(int(doc.header.get("$INSUNITS", 0) or 0), DRAWING_UNITS), notes


def _no_length(entity: Any) -> bool:
    """A LINE whose ends coincide, or an ARC or CIRCLE of no radius."""
    if entity.dxftype() == "LINE":
        return bool(entity.dxf.start.isclose(entity.dxf.end, abs_tol=0.0))
    return entity.dxftype() in ("ARC", "CIRCLE") and float(entity.dxf.radius) <= 0.0
