"""CadQuery plugin: G2 spiral transitions and chains as ``cq.Workplane`` methods.

Importing this module adds these methods to ``cadquery.Workplane``:

* ``spiralLineToCircle(point, direction, center, radius)``
* ``spiralCircleToCircle(c0, r0, c1, r1)``
* ``spiralLineToLine(p0, corner, p1, curvature=None)``
* ``spiralCircleInCircle(c0, r0, c1, r1)``
* ``spiralTransition(transition)`` — an already solved ``Transition``
* ``spiralChain(chain)`` — a whole ``spiral_cad.Chain`` as one wire
* ``g2Polyline(points, radius=None, max_deviation=None)`` — a polyline (2-D or
  3-D points) whose corners are G2 spiral pairs, as one pending wire
* ``g2Fillet(radius, transition=0.5)`` — G2 fillets on every corner of the pending wires, or on the
  selected edges of a solid (``.edges().g2Fillet(r)``: a right prism's side edges and cap rims, holes too)
* ``makeG2(maxDeviation)`` — the pending wires of lines and tangent arcs made G2 within a bound
* ``continuousRect``, ``continuousPolygon``, ``continuousSlot2D`` — shapes with G2 corners

and to ``cadquery.Sketch``: ``g2fillet(radius, transition=0.5)`` on the
selected vertices (like ``Sketch.fillet``), ``makeG2(maxDeviation)`` on its
faces and ``continuousRect``.

All coordinates are local to the workplane (``x`` along its ``xDir``, ``y``
along ``zDir × xDir``, and for ``g2Polyline`` and chains in space ``z`` along
its normal); radii are signed by travel sense as
in the core solvers. Lines become LINE edges, arcs true CIRCLE edges and
spirals BEZIER edges with their exact control points (``spiral_cad.cad.occ``).

Following CadQuery's plugin convention the results are pushed with
``newObject`` and queued as pending edges (transitions) or a pending wire
(chains), so ``.wire()``, ``.sweep(...)`` and — for closed chains —
``.extrude(...)`` work as with the built-in 2-D methods. The transitions sit
where their geometry puts them; they do not start at the current point, but
the last edge's end becomes the current point for ``lineTo`` and friends.

Example:
    >>> import cadquery as cq
    >>> import spiral_cad.cadquery  # registers the methods
    >>> path = cq.Workplane("XY").spiralChain(chain)
    >>> solid = cq.Workplane("YZ").circle(0.1).sweep(path)
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, TypeVar

import cadquery as cq
from OCP.gp import gp_Ax3

from .cad.fillet import fillet_face, fillet_wire
from .cad.g2wire import g2_face, g2_wire
from .cad.occ import chain_wire, segment_edges
from .cad.slabs import continuous_box
from .cad.stack_fillet import fillet_part_edges
from .core.chain import Chain
from .core.segments import Segment
from .core.shapes import DEFAULT_SHAPE
from .core.transitions import Transition, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from .design.fillets import continuous_polygon, continuous_rectangle, continuous_slot
from .design.rounded_paths import curvature_bound, round_corners

if TYPE_CHECKING:
    from cadquery.sketch import Modes

__all__ = [
    "METHODS",
    "SKETCH_METHODS",
    "continuousPolygon",
    "continuousRect",
    "continuousSlot2D",
    "g2Fillet",
    "g2Polyline",
    "makeG2",
    "plane_ax3",
    "spiralChain",
    "spiralCircleInCircle",
    "spiralCircleToCircle",
    "spiralLineToCircle",
    "spiralLineToLine",
    "spiralTransition",
]

W = TypeVar("W", bound=cq.Workplane)
S = TypeVar("S", bound=cq.Sketch)


def plane_ax3(plane: cq.Plane) -> gp_Ax3:
    """The ``gp_Ax3`` of a CadQuery plane: same origin, X direction and normal."""
    return gp_Ax3(plane.origin.toPnt(), plane.zDir.toDir(), plane.xDir.toDir())


def _push_edges(wp: W, segments: Iterable[Segment], make_wire: bool, for_construction: bool) -> W:
    """Place ``segments`` on ``wp``'s plane as edges (or one wire) and queue them as pending."""
    plane = plane_ax3(wp.plane)
    if make_wire:
        wire = cq.Wire(chain_wire(segments, plane))
        if not for_construction:
            wp._addPendingWire(wire)
        return wp.newObject([wire])
    edges = [cq.Edge(e) for e in segment_edges(segments, plane)]
    if not for_construction:
        for edge in edges:
            wp._addPendingEdge(edge)
    return wp.newObject(edges)


def spiralTransition(self: W, transition: Transition, makeWire: bool = False, forConstruction: bool = False) -> W:
    """Place the spirals of a solved ``Transition`` (workplane-local coordinates).

    Args:
        transition: e.g. the result of ``spiral_cad.line_to_circle``.
        makeWire: queue one wire instead of separate edges.
        forConstruction: do not queue anything (reference geometry).

    Returns:
        A new ``Workplane`` whose objects are the BEZIER edges (or the wire).
    """
    if not isinstance(transition, Transition):
        raise ValueError(f"transition must be a spiral_cad.Transition; got {transition!r}")
    return _push_edges(self, transition.spirals, makeWire, forConstruction)


def spiralLineToCircle(
    self: W,
    point: Any,
    direction: Any,
    center: Any,
    radius: float,
    makeWire: bool = False,
    forConstruction: bool = False,
    shape: str = DEFAULT_SHAPE,
) -> W:
    """Spiral from the directed line (``point``, ``direction``) onto a circle (``spiral_cad.line_to_circle``);
    ``shape`` is the spiral shape (``"walton-meek"`` or ``"near-linear"``), as in every method here.

    Raises:
        NoSolutionError: the circle touches or crosses the line.
    """
    return spiralTransition(self, line_to_circle(point, direction, center, radius, shape), makeWire, forConstruction)


def spiralCircleToCircle(
    self: W,
    c0: Any,
    r0: float,
    c1: Any,
    r1: float,
    makeWire: bool = False,
    forConstruction: bool = False,
    shape: str = DEFAULT_SHAPE,
) -> W:
    """Two spirals from circle 0 to circle 1, C or S shaped by the radius signs (``spiral_cad.circle_to_circle``).

    Raises:
        NoSolutionError: no transition of that kind exists for these circles.
    """
    return spiralTransition(self, circle_to_circle(c0, r0, c1, r1, shape), makeWire, forConstruction)


def spiralLineToLine(
    self: W,
    p0: Any,
    corner: Any,
    p1: Any,
    curvature: float | None = None,
    makeWire: bool = False,
    forConstruction: bool = False,
    shape: str = DEFAULT_SHAPE,
) -> W:
    """Two spirals rounding the corner p0 → ``corner`` → p1 (``spiral_cad.line_to_line``; ``shape`` may also be ``"g2cbs"``).

    Raises:
        NoSolutionError: collinear/folded legs or a curvature too small for the legs.
    """
    return spiralTransition(self, line_to_line(p0, corner, p1, curvature, shape), makeWire, forConstruction)


def spiralCircleInCircle(
    self: W,
    c0: Any,
    r0: float,
    c1: Any,
    r1: float,
    makeWire: bool = False,
    forConstruction: bool = False,
    shape: str = DEFAULT_SHAPE,
) -> W:
    """One spiral between nested circles (``spiral_cad.circle_in_circle``).

    Raises:
        NoSolutionError: the circles are outside the solvable nesting band.
    """
    return spiralTransition(self, circle_in_circle(c0, r0, c1, r1, shape), makeWire, forConstruction)


def spiralChain(self: W, chain: Chain, makeWire: bool = True, forConstruction: bool = False) -> W:
    """Place a whole ``Chain`` — LINE, CIRCLE and BEZIER edges — as one wire (workplane-local coordinates).

    A chain whose end meets its start gives a closed wire, ready for ``extrude``.

    Args:
        chain: a ``spiral_cad.Chain``.
        makeWire: True (default) queues one wire; False queues the edges.
        forConstruction: do not queue anything.
    """
    if not isinstance(chain, Chain):
        raise ValueError(f"chain must be a spiral_cad.Chain; got {chain!r}")
    return _push_edges(self, chain.segments, makeWire, forConstruction)


def g2Polyline(
    self: W,
    points: Iterable[Any],
    radius: float | None = None,
    max_deviation: float | None = None,
    shape: str = DEFAULT_SHAPE,
    forConstruction: bool = False,
) -> W:
    """A polyline through ``points`` (2-D or 3-D, workplane-local) with every corner rounded by a
    G2 spiral pair in the plane of its two edges (``spiral_cad.design.round_corners``), as one wire.

    Args:
        points: three or more points, like ``polyline``'s.
        radius: the smallest radius of curvature: every corner reaches exactly 1/radius.
        max_deviation: the largest distance between a corner point and the path
            (each corner gets the largest pair within it; with ``radius`` its
            curvature must also stay below 1/radius).
        shape: "walton-meek", "near-linear" or "g2cbs".
        forConstruction: do not queue the wire.

    Raises:
        ValueError: malformed points, a radius or deviation that is not positive.
        NoSolutionError: a corner that cannot be rounded as asked (named, with numbers).
    """
    curvature = curvature_bound(radius)
    path = round_corners([tuple(cq.Vector(p).toTuple()) for p in points], max_curvature=curvature,
                         max_deviation=max_deviation, shape=shape)  # fmt: skip
    return _push_edges(self, path.chain.segments, True, forConstruction)


def g2Fillet(self: W, radius: float, transition: float = 0.5, same_sense: str = "nested", shape: str = DEFAULT_SHAPE) -> W:
    """Round every corner of the pending wires with G2 fillets (``spiral_cad.design.fillets``).

    Each corner becomes transition → arc of ``radius`` → transition, curvature
    continuous; the wires stay pending (e.g. for ``.extrude``). With no pending
    wires and edges of a solid selected (``.edges()``, as CadQuery's ``fillet``
    takes them), the solid is rounded as ``spiral_cad.build123d.g2_fillet``
    rounds a part's edges (``fillet_part_edges``: prisms and 2.5-D parts) and replaces it on the stack.

    Raises:
        ValueError: no pending wires and no selected edges of a solid, non-planar wires or edges other than
            lines and arcs.
        NoSolutionError: a corner or edge that cannot be rounded (named, with numbers).
    """
    wires = list(self.ctx.pendingWires)
    edges = [e for e in self.objects if isinstance(e, cq.Edge)]
    if not wires and edges:
        solid = self.findSolid()
        slab = fillet_part_edges(solid.wrapped, [e.wrapped for e in edges], radius, transition=transition,
                                  same_sense=same_sense, shape=shape)  # fmt: skip
        return self.newObject([cq.Solid(slab.shape)])
    if not wires:
        raise ValueError("g2Fillet rounds the pending wires; there are none (draw a closed wire first)")
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape)
    rounded = [cq.Wire(fillet_wire(w.wrapped, radius, **options)[0]) for w in wires]
    self.ctx.pendingWires = []
    result = self.newObject(rounded)
    for wire in rounded:
        result._addPendingWire(wire)
    return result


def makeG2(self: W, maxDeviation: float, shape: str = "near-linear") -> W:
    """Make the pending wires G2 within ``maxDeviation`` (``spiral_cad.design.make_g2``).

    Lines and tangent arcs (e.g. a ``rect`` after ``.vertices().fillet2D``, or a
    ``slot2D``) get spiral transitions at every tangent joint, their arcs kept
    CIRCLE edges (shrunk about their centres by the shift each transition
    needs), sharp corners between lines a spiral pair; every point moves by at
    most ``maxDeviation``. The wires stay pending (e.g. for ``.extrude``).

    Raises:
        ValueError: no pending wires, non-planar wires or edges other than lines and arcs.
        NoSolutionError: a joint that cannot be made G2 within the bound (named, with a bound that works).
    """
    wires = list(self.ctx.pendingWires)
    if not wires:
        raise ValueError("makeG2 makes the pending wires G2; there are none (draw a wire first)")
    made = [cq.Wire(g2_wire(w.wrapped, maxDeviation, shape=shape)[0]) for w in wires]
    self.ctx.pendingWires = []
    result = self.newObject(made)
    for wire in made:
        result._addPendingWire(wire)
    return result


def _place_closed(self: W, path) -> W:
    """A closed chain built at the workplane origin, placed at every point on the stack (as ``rect``)."""
    wire = cq.Wire(chain_wire(path.segments))
    return self.eachpoint(lambda loc: wire.moved(loc), True)


def continuousRect(self: W, xLen: float, yLen: float, radius: float, transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> W:
    """A centred rectangle with G2 corners ("continuous corners") at each point on the stack, as a pending wire."""
    return _place_closed(self, continuous_rectangle(xLen, yLen, radius, transition, shape=shape))


def continuousPolygon(self: W, nSides: int, diameter: float, radius: float, transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> W:
    """A regular polygon (circumscribed ``diameter``) with G2 corners, as a pending wire."""
    return _place_closed(self, continuous_polygon(diameter / 2.0, nSides, radius, transition, shape=shape))


def continuousSlot2D(self: W, length: float, diameter: float, transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> W:
    """A slot of overall ``length`` and width ``diameter`` whose ends are G2 all round, as a pending wire."""
    return _place_closed(self, continuous_slot(length, diameter, transition, shape=shape))


def continuousBox(self: W, length: float, width: float, height: float, radius: float, edgeRadius: float | None = None,
                  transition: float = 0.5, shape: str = DEFAULT_SHAPE, profile: str = "g2",
                  centered: bool | tuple[bool, bool, bool] = True, combine: Any = True, clean: bool = True) -> W:  # fmt: skip
    """A box with every edge and corner G2 at each point on the stack (as ``box``): a continuous rectangle
    in plan, its top and bottom edges rolled by a G2 profile (``spiral_cad.build123d.ContinuousBox``).

    Args:
        length, width, height: the box's size.
        radius: the plan corners' smallest radius of curvature.
        edgeRadius: the rolled edges' smallest radius of curvature (None: a roll half as wide as
            the smaller of ``radius`` and ``height``/2 allows).
        transition, shape, profile: of the spirals and the roll (``"g2"`` or ``"circular"``).
        centered, combine, clean: as for ``box``.

    Raises:
        NoSolutionError: corners or rolls that do not fit (named, with what would fit).
    """
    slab = continuous_box(length, width, height, radius, edgeRadius, transition=transition, shape=shape, profile=profile)
    flags = (centered,) * 3 if isinstance(centered, bool) else tuple(centered)
    offset = cq.Vector(0 if flags[0] else length / 2, 0 if flags[1] else width / 2, -height / 2 if flags[2] else 0)
    box = cq.Solid(slab.shape).moved(cq.Location(offset))  # built centred in x, y; z from 0 to height
    return self.eachpoint(lambda loc: box.moved(loc), True, combine, clean)


METHODS = (
    spiralTransition,
    spiralLineToCircle,
    spiralCircleToCircle,
    spiralLineToLine,
    spiralCircleInCircle,
    spiralChain,
    g2Polyline,
    g2Fillet,
    makeG2,
    continuousRect,
    continuousPolygon,
    continuousSlot2D,
    continuousBox,
)

for _method in METHODS:
    setattr(cq.Workplane, _method.__name__, _method)


# ------------------------------------------------------------------ cq.Sketch


def sketch_g2fillet(self: S, radius: float, transition: float = 0.5, same_sense: str = "nested", shape: str = DEFAULT_SHAPE) -> S:
    """``cq.Sketch.g2fillet``: round the selected vertices with G2 fillets, as ``Sketch.fillet`` does with arcs."""
    faces = self._matchFacesToVertices()
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape)
    self._faces = cq.Compound.makeCompound(
        cq.Face(fillet_face(face.wrapped, radius, [v.toTuple() for v in vertices], **options))
        if vertices else face
        for face, vertices in faces.items()
    )  # fmt: skip
    return self


def sketch_continuous_rect(self: S, w: float, h: float, radius: float, transition: float = 0.5, angle: float = 0,
                           mode: Modes = "a", tag: str | None = None, shape: str = DEFAULT_SHAPE) -> S:  # fmt: skip
    """``cq.Sketch.continuousRect``: a rectangular face with G2 corners (as ``Sketch.rect``)."""
    path = continuous_rectangle(w, h, radius, transition, shape=shape)
    face = cq.Face.makeFromWires(cq.Wire(chain_wire(path.segments)))
    face = face.rotate(cq.Vector(), cq.Vector(0, 0, 1), angle)
    return self.each(lambda location: face.located(location), mode, tag)


def sketch_make_g2(self: S, maxDeviation: float, shape: str = "near-linear") -> S:
    """``cq.Sketch.makeG2``: every face of the sketch (holes included) made G2 within ``maxDeviation``."""
    self._faces = cq.Compound.makeCompound(cq.Face(g2_face(face.wrapped, maxDeviation, shape=shape)) for face in self._faces.Faces())
    return self


SKETCH_METHODS = {"g2fillet": sketch_g2fillet, "makeG2": sketch_make_g2, "continuousRect": sketch_continuous_rect}

for _name, _sketch_method in SKETCH_METHODS.items():
    setattr(cq.Sketch, _name, _sketch_method)
