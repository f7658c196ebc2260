"""``make_g2`` on OCCT wires and faces: planar lines and arcs in, exact LINE/CIRCLE/BEZIER edges out.

The numeric work is ``spiral_cad.design.g2.make_g2``; this module reads a
planar OCCT wire into lines and arcs in its plane (``wire_path``), makes the
path G2 within the bound (its arcs stay CIRCLE edges, shrunk about their
centres by the shift each transition needs) and builds the wire again with
shared vertices, closing joint included. A face is rebuilt from its made
wires, holes included. build123d's ``make_g2`` and the CadQuery plugin call it.
"""

from __future__ import annotations

import math

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepTools import BRepTools
from OCP.gp import gp_Ax3
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape, TopoDS_Wire
from OCP.TopTools import TopTools_HSequenceOfShape, TopTools_IndexedMapOfShape

from ..core.segments import Segment
from ..core.units import DEFAULT_UNITS
from ..design.g2 import G2Path, make_g2, smallest_max_deviation
from .fillet import _wires, planar_frame, wire_path
from .occ import chain_wire

__all__ = ["g2_advice", "g2_face", "g2_wire"]


def g2_wire(
    wire: TopoDS_Wire, max_deviation: float, *, shape: str = "near-linear", frame: gp_Ax3 | None = None, units: str = DEFAULT_UNITS
) -> tuple[TopoDS_Wire, G2Path]:
    """The wire made G2 within ``max_deviation`` (``make_g2``), and the numeric result (``units``: the wire's length unit,
    for the result and make_g2's messages).

    A wire split at reversals stays one wire: its parts meet there (G0 at the
    split, G2 everywhere else). Cubic Bézier edges (make_g2's own spirals, and a
    builder's B-spline merges of them) are kept as they are: a wire made G2 is
    returned unchanged by a second call.

    Raises:
        ValueError: a non-planar wire, an edge that is not a line, arc or cubic
            Bézier span, or a kept Bézier edge whose joints are not G2.
        NoSolutionError: a joint that cannot be made G2 within the bound (named,
            with a bound that works).
    """
    frame = planar_frame(wire) if frame is None else frame
    segments, closed = wire_path(wire, frame, spirals=True)  # spirals (BEZIER edges, their B-spline merges) are kept
    result = make_g2(segments, max_deviation, closed=closed, shape=shape, units=units)
    pieces: list[Segment] = [s for chain in result.chains for s in chain]
    return chain_wire(pieces, frame), result


def g2_face(face: TopoDS_Face, max_deviation: float, *, shape: str = "near-linear") -> TopoDS_Face:
    """The planar face with every wire (outer and holes) made G2 within ``max_deviation``.

    Raises:
        ValueError, NoSolutionError: as ``g2_wire``; the face is rebuilt on its
        own plane and keeps its orientation.
    """
    frame = planar_frame(face)
    outer = BRepTools.OuterWire_s(face)
    wires = [outer] + [w for w in _wires(face) if not w.IsSame(outer)]
    made = [g2_wire(w, max_deviation, shape=shape, frame=frame)[0] for w in wires]
    maker = BRepBuilderAPI_MakeFace(BRep_Tool.Surface_s(face), made[0], True)
    for inner in made[1:]:
        maker.Add(inner)
    if not maker.IsDone():
        raise ValueError(f"the G2 wires do not make a face ({maker.Error().name})")
    result = maker.Face()
    return TopoDS.Face_s(result.Reversed()) if face.Orientation() != result.Orientation() else result


def _all_wires(shape: TopoDS_Shape) -> list[TopoDS_Wire]:
    """The shape's wires, then its loose edges (a STEP file's curves often are) joined end to end into wires."""
    wires, held = [], TopTools_IndexedMapOfShape()
    explorer = TopExp_Explorer(shape, TopAbs_WIRE)
    while explorer.More():
        wire = TopoDS.Wire_s(explorer.Current())
        wires.append(wire)
        TopExp.MapShapes_s(wire, TopAbs_EDGE, held)
        explorer.Next()
    loose = TopTools_HSequenceOfShape()
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        if not held.Contains(explorer.Current()):
            loose.Append(explorer.Current())
        explorer.Next()
    if loose.Length():
        joined = TopTools_HSequenceOfShape()
        ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(loose, 1e-7, False, joined)
        wires += [TopoDS.Wire_s(joined.Value(i)) for i in range(1, joined.Length() + 1)]
    return wires


def g2_advice(shape: TopoDS_Shape, units: str = "mm", shape_name: str = "near-linear") -> list[str]:
    """What ``make_g2`` would do for each wire of ``shape`` that is not G2: one line per wire of planar
    lines and arcs with the smallest ``max_deviation`` that makes it G2 (built and checked), or why not."""
    lines = []
    for index, wire in enumerate(_all_wires(shape)):
        try:
            frame = planar_frame(wire)
            segments, closed = wire_path(wire, frame)
        except ValueError:
            continue  # not planar lines and arcs: not make_g2's input
        try:
            works = smallest_max_deviation(segments, closed=closed, shape=shape_name, units=units)
            made = make_g2(segments, works, closed=closed, shape=shape_name, units=units)
        except ValueError as error:
            lines.append(f"make_g2: piece {index} cannot be made G2: {error}")
            continue
        kinds = [j.kind for j in made.joints]
        if all(kind == "g2" for kind in kinds):
            continue
        tangent = sum(kind.startswith(("line-arc", "arc-arc")) for kind in kinds)
        corners = kinds.count("corner")
        use = _suggested(segments, closed, works, shape_name, units, made.chains[0].size)
        lines.append(
            f"make_g2: piece {index} ({len(segments)} lines and arcs; {tangent} tangent joints, {corners} corners) becomes G2 "
            f"with max_deviation {use:.3g} {units} (built and checked; any bound from {works:.3g} {units} works, a larger one "
            "gives gentler transitions)"
        )
    return lines


#: The bound ``g2_advice`` suggests: this share of the piece's size, when it builds (else the smallest that works).
SUGGESTED_SHARE = 1e-3


def _suggested(segments: list, closed: bool, works: float, shape: str, units: str, size: float) -> float:
    """A bound to use: ``SUGGESTED_SHARE`` of the piece's size, rounded down to one significant figure,
    if it builds (checked here), else ``works`` (the smallest that works)."""
    share = SUGGESTED_SHARE * size
    if not (math.isfinite(share) and share > works):
        return works
    rounded = float(f"{share:.0e}")
    try:
        make_g2(segments, rounded, closed=closed, shape=shape, units=units)
    except ValueError:
        return works
    return rounded
