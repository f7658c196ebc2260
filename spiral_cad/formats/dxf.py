"""DXF (R2010) through ezdxf: LINE, ARC and exact cubic SPLINE entities on a layer named after the design.

The header declares the unit twice, as readers differ in which they use:
``$INSUNITS`` (4 mm, 5 cm, 6 m, 7 km, 1 in, 2 ft) and ``$MEASUREMENT``
(1 metric, 0 imperial, which Inkscape and LibreCAD use for scaling).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

from ..core.chain import Chain
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..core.units import IMPERIAL

#: ``$INSUNITS`` codes.
INSUNITS = {"in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6, "km": 7}
#: Knot vector of one cubic Bézier written as a B-spline.
BEZIER_KNOTS = (0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)


def _add(msp, seg: Segment, layer: str) -> None:
    attribs = {"layer": layer}
    if isinstance(seg, Line):
        msp.add_line(tuple(seg.start), tuple(seg.end), dxfattribs=attribs)
    elif isinstance(seg, Arc):
        # DXF arcs run counterclockwise: a clockwise arc is written from its end.
        a, b = math.degrees(seg.start_angle), math.degrees(seg.start_angle + math.copysign(seg.sweep, seg.radius))
        start, end = (a, b) if seg.radius > 0 else (b, a)
        msp.add_arc(tuple(seg.center), abs(seg.radius), start, end, dxfattribs=attribs)
    elif isinstance(seg, BezierSpiral):
        points = [(*p, 0.0) for p in seg.control_points.tolist()]
        spline = msp.add_open_spline(points, degree=3, knots=BEZIER_KNOTS, dxfattribs=attribs)
        spline.dxf.flags |= spline.PLANAR
    else:
        raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {seg!r}")


def write_dxf(chains: Sequence[Chain], path: str | os.PathLike, name: str, units: str) -> None:
    """Write ``chains`` in travel order on layer ``name``; a full circle is an ARC from an angle to itself + 360°."""
    import ezdxf

    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = INSUNITS[units]
    doc.header["$MEASUREMENT"] = 0 if units in IMPERIAL else 1
    doc.header["$LUNITS"] = 2  # decimal
    doc.layers.add(name)
    msp = doc.modelspace()
    for chain in chains:
        for seg in chain:
            _add(msp, seg, name)
    doc.saveas(os.fspath(path))
