"""STEP (ISO 10303-21, AP214) for chains, written directly: exact curves, one wire per chain.

Each chain (in the plane or in space) becomes one ``CONNECTED_EDGE_SET`` of
``EDGE_CURVE`` entities in travel order; consecutive edges share their
``VERTEX_POINT`` (a closed chain ends on the vertex it starts from). The sets make one
``EDGE_BASED_WIREFRAME_MODEL`` of an ``EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION``:
the shape of a ``PRODUCT`` named after the design. OCCT's reader, and so
FreeCAD, turns each set into one connected ``TopoDS_Wire`` by adding its
edges in order, in time linear in the edge count.

Why not a ``COMPOSITE_CURVE`` (this module's earlier form, which could carry
G2 transition codes): OCCT translates a composite curve with
``ShapeFix_Wire::FixReorder``, a greedy search over every remaining segment
for each segment (``ShapeAnalysis_WireOrder``, quadratic), and then checks
the order of every wire it read once more (``ShapeFix_Shape`` after the
transfer, the same search). The edge-based form skips the first of the two;
the second runs on every wire OCCT reads, whatever the form, and remains
the cost of one wire of N edges over N loose edges (``benchmarks/bench_step.py``).

The curves (each edge's geometry, bounded by its two vertices, edge and
curve in the same sense):

* ``Line``: a ``LINE`` from the start point along the unit direction;
* ``Arc``: a ``CIRCLE`` whose placement's x axis points at the arc's start,
  its axis the arc's normal (+Z in the plane) for counterclockwise travel
  and the opposite for clockwise;
* ``BezierSpiral``: a ``B_SPLINE_CURVE_WITH_KNOTS`` of degree 3 with the
  spiral's four control points and knots (0, 1) of multiplicity 4
  (``PIECEWISE_BEZIER_KNOTS``): the same polynomial as the Bézier.

Each vertex is the next segment's start point (the point its curve starts
from exactly); the chain's own join tolerance keeps the previous segment's
end within rounding of it.

The length unit is declared in the representation context (an ``SI_UNIT``
with its prefix for mm, cm, m, km; a ``CONVERSION_BASED_UNIT`` of 25.4 mm or
304.8 mm for in and ft), so readers that convert (OCCT reads into mm by
default) get the right size. Every real is the shortest decimal that reads
back to the same double (at most 17 significant digits); every name an
ISO 10303-21 string in pure ASCII (``spiral_cad.io.names.step_string``).

Needs no CAD kernel.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from datetime import UTC, datetime

import numpy as np
from numpy.typing import NDArray

from ..core.chain import Chain
from ..core.segments import Arc, Line, Segment, measure_join
from ..core.spiral import BezierSpiral
from ..core.units import MM_PER_UNIT
from .decimals import shortest_decimal
from .names import step_string

#: STEP's name for each unit: an SI prefix of the metre, or a conversion-based unit.
_SI_PREFIX = {"mm": ".MILLI.", "cm": ".CENTI.", "m": "$", "km": ".KILO."}
_CONVERSION = {"in": "INCH", "ft": "FOOT"}

#: The AP214 schema (what OCCT, FreeCAD and most CAD systems write and read).
SCHEMA = "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"


def real(value: float) -> str:
    """A STEP real: the shortest round-trip decimal, always with a decimal point."""
    text = shortest_decimal(value, "STEP").upper()
    mantissa, _, exponent = text.partition("E")
    if "." not in mantissa:
        mantissa += "."
    return f"{mantissa}E{exponent}" if exponent else mantissa


class _Entities:
    """Numbered DATA-section instances (#1, #2, …)."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def add(self, text: str) -> str:
        self.lines.append(text)
        return f"#{len(self.lines)}"

    def point(self, x: float, y: float, z: float = 0.0) -> str:
        return self.add(f"CARTESIAN_POINT('',({real(x)},{real(y)},{real(z)}))")

    def direction(self, x: float, y: float, z: float = 0.0) -> str:
        return self.add(f"DIRECTION('',({real(x)},{real(y)},{real(z)}))")


def _unit(vector: NDArray) -> list[float]:
    """The direction of ``vector``, scaled first: its squares overflow at 1e155 and vanish at 1e-160."""
    scaled = vector / np.abs(vector).max()
    return (scaled / np.linalg.norm(scaled)).tolist()


def _line(data: _Entities, line: Line, start: str) -> str:
    vector = data.add(f"VECTOR('',{data.direction(*_unit(line.end - line.start))},1.)")
    return data.add(f"LINE('',{start},{vector})")


def _arc(data: _Entities, arc: Arc, start: str) -> str:
    """A circle about the arc's axis (its normal, reversed for clockwise travel) with its x axis at the start."""
    axis = data.direction(*(math.copysign(1.0, arc.radius) * arc.normal).tolist())
    reference = data.direction(*_unit(arc.start - arc.center))
    placement = data.add(f"AXIS2_PLACEMENT_3D('',{data.point(*arc.center.tolist())},{axis},{reference})")
    return data.add(f"CIRCLE('',{placement},{real(abs(arc.radius))})")


def _spiral(data: _Entities, spiral: BezierSpiral, start: str) -> str:
    poles = ",".join([start] + [data.point(*p) for p in spiral.control_points[1:].tolist()])
    return data.add(f"B_SPLINE_CURVE_WITH_KNOTS('',3,({poles}),.UNSPECIFIED.,.F.,.F.,(4,4),(0.,1.),.PIECEWISE_BEZIER_KNOTS.)")


_CURVES = {Line: _line, Arc: _arc, BezierSpiral: _spiral}


def _curve(data: _Entities, segment: Segment, start: str) -> str:
    """The curve of ``segment``, starting at the point ``start`` (an entity already written)."""
    for kind, make in _CURVES.items():
        if isinstance(segment, kind):
            return make(data, segment, start)
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {segment!r}")


def _closes(chain: Chain) -> bool:
    """The chain ends where it starts (within its join tolerance): its last edge ends on its first vertex."""
    return measure_join(chain[-1], chain[0]).gap <= chain.tolerance * chain.size


def _edge_set(data: _Entities, chain: Chain, label: str) -> str:
    """One CONNECTED_EDGE_SET: the chain's edges in travel order, consecutive edges sharing a vertex."""
    starts = [data.point(*segment.start.tolist()) for segment in chain]
    vertices = [data.add(f"VERTEX_POINT('',{point})") for point in starts]
    last = vertices[0] if _closes(chain) else data.add(f"VERTEX_POINT('',{data.point(*chain[-1].end.tolist())})")
    edges = [
        data.add(f"EDGE_CURVE('',{v0},{v1},{_curve(data, segment, start)},.T.)")
        for segment, start, v0, v1 in zip(chain, starts, vertices, vertices[1:] + [last])
    ]
    return data.add(f"CONNECTED_EDGE_SET({step_string(label)},({','.join(edges)}))")


def _units(data: _Entities, units: str, uncertainty: float) -> str:
    """The representation context: length unit, radians, steradians and the uncertainty."""
    if units in _SI_PREFIX:
        length = data.add(f"(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT({_SI_PREFIX[units]},.METRE.))")
    else:
        millimetre = data.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))")
        size = data.add(f"LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE({real(MM_PER_UNIT[units])}),{millimetre})")
        dimensions = data.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)")
        length = data.add(f"(CONVERSION_BASED_UNIT('{_CONVERSION[units]}',{size})LENGTH_UNIT()NAMED_UNIT({dimensions}))")
    angle = data.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))")
    solid = data.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())")
    accuracy = data.add(
        f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({real(uncertainty)}),{length},'distance_accuracy_value','confusion accuracy')"
    )
    return data.add(
        f"(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT(({accuracy}))"
        f"GLOBAL_UNIT_ASSIGNED_CONTEXT(({length},{angle},{solid}))REPRESENTATION_CONTEXT('',''))"
    )


def _uncertainty(chains: Sequence[Chain], units: str) -> float:
    """1e-7 mm in the file's unit, but at least what float64 can resolve at the largest coordinate."""
    largest = max(float(np.abs(c.segment_ends).max()) for c in chains)
    return max(1e-7 / MM_PER_UNIT[units], 16.0 * math.ulp(largest))


def step_text(chains: Sequence[Chain], name: str, units: str, originating_system: str, timestamp: datetime | None = None) -> str:
    """The whole STEP file for ``chains`` (one product ``name``, one connected edge set per chain)."""
    when = (timestamp or datetime.now(UTC)).strftime("%Y-%m-%dT%H:%M:%S")
    data = _Entities()
    context = data.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
    data.add(f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,{context})")
    product_context = data.add(f"PRODUCT_CONTEXT('',{context},'mechanical')")
    product = data.add(f"PRODUCT({step_string(name)},{step_string(name)},'',({product_context}))")
    data.add(f"PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,({product}))")
    formation = data.add(f"PRODUCT_DEFINITION_FORMATION('','',{product})")
    definition_context = data.add(f"PRODUCT_DEFINITION_CONTEXT('part definition',{context},'design')")
    definition = data.add(f"PRODUCT_DEFINITION('design','',{formation},{definition_context})")
    shape = data.add(f"PRODUCT_DEFINITION_SHAPE('','',{definition})")
    representation_context = _units(data, units, _uncertainty(chains, units))
    origin = data.add(f"AXIS2_PLACEMENT_3D('',{data.point(0.0, 0.0)},{data.direction(0.0, 0.0, 1.0)},{data.direction(1.0, 0.0)})")
    labels = [name] if len(chains) == 1 else [f"{name}-{i + 1}" for i in range(len(chains))]
    sets = [_edge_set(data, chain, label) for chain, label in zip(chains, labels)]
    model = data.add(f"EDGE_BASED_WIREFRAME_MODEL({step_string(name)},({','.join(sets)}))")
    representation = data.add(f"EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION({step_string(name)},({model},{origin}),{representation_context})")
    data.add(f"SHAPE_DEFINITION_REPRESENTATION({shape},{representation})")
    header = [
        "ISO-10303-21;",
        "HEADER;",
        f"FILE_DESCRIPTION(({step_string(f'{name}: exact G2 curves (lines, circles, cubic Bezier spirals)')}),'2;1');",
        f"FILE_NAME({step_string(name)},'{when}',(''),(''),{step_string(originating_system)},{step_string(originating_system)},'');",
        f"FILE_SCHEMA(('{SCHEMA}'));",
        "ENDSEC;",
        "DATA;",
    ]
    body = [f"#{i}={line};" for i, line in enumerate(data.lines, 1)]
    return "\n".join(header + body + ["ENDSEC;", "END-ISO-10303-21;", ""])


def write_step(chains: Sequence[Chain], path: str | os.PathLike, name: str, units: str, originating_system: str) -> None:
    """Write ``chains`` as one STEP file (see the module docstring)."""
    with open(path, "w", encoding="ascii", newline="\n") as handle:
        handle.write(step_text(chains, name, units, originating_system))
