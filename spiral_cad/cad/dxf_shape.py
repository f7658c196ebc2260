"""A DXF drawing's curves as exact OCCT edges, so that the STEP checker judges a drawing as it is drawn.

Read from the model space through ezdxf, every curve exactly as it is stored: ``LINE``, ``ARC`` and
``CIRCLE`` (in their object coordinate system: a mirrored arc stays clockwise), ``ELLIPSE`` (its arc),
``SPLINE`` (its control points, knots and weights: a B-spline curve as written), ``LWPOLYLINE`` and
``POLYLINE`` (their lines and bulge arcs), and block references (``INSERT``: their curves placed, nested
blocks included). Text, dimensions, hatches, points and other annotation are left out. The drawing's
unit is its ``$INSUNITS`` (``io.dxf_read.DXF_UNITS``); a unitless drawing is in drawing units.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.GC import GC_MakeArcOfCircle
from OCP.Geom import Geom_BSplineCurve
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Compound, TopoDS_Edge

from ..io.dxf_g2 import open_drawing
from ..io.dxf_read import DXF_UNITS

__all__ = ["DRAWING_UNITS", "dxf_shape"]

#: The unit stated for a drawing whose ``$INSUNITS`` names none.
DRAWING_UNITS = "drawing units"
#: Block references nested deeper than this are refused (a block that contains itself).
_MAX_DEPTH = 32


def _point(v: Any) -> gp_Pnt:
    return gp_Pnt(float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)


def _arc(entity: Any) -> TopoDS_Edge:
    """An ARC through its start, middle and end, each placed from its object coordinate system."""
    ocs, center, radius = entity.ocs(), entity.dxf.center, float(entity.dxf.radius)
    a0 = math.radians(float(entity.dxf.start_angle))
    sweep = math.radians((float(entity.dxf.end_angle) - float(entity.dxf.start_angle)) % 360.0) or 2.0 * math.pi
    points = [ocs.to_wcs((center.x + radius * math.cos(t), center.y + radius * math.sin(t), center.z))
              for t in (a0, a0 + 0.5 * sweep, a0 + sweep)]  # fmt: skip
    return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(*(_point(p) for p in points)).Value()).Edge()


def _circle(entity: Any) -> TopoDS_Edge:
    center = entity.ocs().to_wcs(entity.dxf.center)
    axis = gp_Ax2(_point(center), gp_Dir(*entity.dxf.extrusion))
    return BRepBuilderAPI_MakeEdge(gp_Circ(axis, float(entity.dxf.radius))).Edge()


def _ellipse(entity: Any) -> TopoDS_Edge:
    """An ELLIPSE's arc: P(t) = C + cos t · major + sin t · ratio · (N × major), as OCCT's ellipse."""
    major = entity.dxf.major_axis
    a = float(major.magnitude)
    axis = gp_Ax2(_point(entity.dxf.center), gp_Dir(*entity.dxf.extrusion), gp_Dir(*major.normalize()))
    ellipse = gp_Elips(axis, a, a * float(entity.dxf.ratio))
    t0, t1 = float(entity.dxf.start_param), float(entity.dxf.end_param)
    span = (t1 - t0) % (2.0 * math.pi) or 2.0 * math.pi
    return BRepBuilderAPI_MakeEdge(ellipse, t0, t0 + span).Edge()


def _spline(entity: Any) -> TopoDS_Edge:
    """A SPLINE as written: its control points, weights and knots (a fit-point spline as ezdxf interpolates it)."""
    tool = entity.construction_tool()
    controls, weights, knots, degree = list(tool.control_points), list(tool.weights()), list(tool.knots()), tool.order - 1
    poles = TColgp_Array1OfPnt(1, len(controls))
    for k, p in enumerate(controls, start=1):
        poles.SetValue(k, _point(p))
    distinct = sorted(Counter(knots).items())
    values, counts = TColStd_Array1OfReal(1, len(distinct)), TColStd_Array1OfInteger(1, len(distinct))
    for k, (value, count) in enumerate(distinct, start=1):
        values.SetValue(k, float(value))
        counts.SetValue(k, count)
    if weights:
        array = TColStd_Array1OfReal(1, len(weights))
        for k, w in enumerate(weights, start=1):
            array.SetValue(k, float(w))
        curve = Geom_BSplineCurve(poles, array, values, counts, degree)
    else:
        curve = Geom_BSplineCurve(poles, values, counts, degree)
    return BRepBuilderAPI_MakeEdge(curve).Edge()


_MAKERS = {"LINE": lambda e: BRepBuilderAPI_MakeEdge(_point(e.dxf.start), _point(e.dxf.end)).Edge(),
           "ARC": _arc, "CIRCLE": _circle, "ELLIPSE": _ellipse, "SPLINE": _spline, "HELIX": _spline}  # fmt: skip


def _curves(entities: Any, depth: int = 0) -> Iterator[Any]:
    """The curves of ``entities``, polylines and block references taken apart (placed as drawn)."""
    for entity in entities:
        kind = entity.dxftype()
        if kind in _MAKERS:
            yield entity
        elif kind in ("LWPOLYLINE", "POLYLINE", "INSERT"):
            if depth >= _MAX_DEPTH:
                raise ValueError(f"block references nested deeper than {_MAX_DEPTH} (a block that contains itself?)")
            yield from _curves(entity.virtual_entities(), depth + 1)


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
    for entity in _curves(doc.modelspace()):
        kind = entity.dxftype()
        try:
            edge = _MAKERS[kind](entity)
        except Exception as error:  # noqa: BLE001 - OCCT's Standard_Failure or a malformed entity: named, never a crash
            if _no_length(entity):
                empty[kind] += 1
                continue
            handle = entity.dxf.get("handle") or "(in a polyline or block)"
            raise ValueError(f"{source.name}: {kind} {handle} cannot be built as a curve: {error or type(error).__name__}") from None
        builder.Add(compound, edge)
        count += 1
    if not count:
        raise ValueError(f"{source.name}: the drawing's model space holds no curve (lines, arcs, circles, ellipses, splines, polylines)")
    notes = [f"{n} {kind}(s) of no length left out" for kind, n in sorted(empty.items())]
    notes += [recovered] if recovered else []
    return compound, DXF_UNITS.get(int(doc.header.get("$INSUNITS", 0) or 0), DRAWING_UNITS), notes


def _no_length(entity: Any) -> bool:
    """A LINE whose ends coincide, or an ARC or CIRCLE of radius 0."""
    if entity.dxftype() == "LINE":
        return bool(entity.dxf.start.isclose(entity.dxf.end, abs_tol=0.0))
    return entity.dxftype() in ("ARC", "CIRCLE") and float(entity.dxf.radius) == 0.0
