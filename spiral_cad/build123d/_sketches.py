"""build123d sketch objects with G2 outlines, ``make_g2`` on build123d objects and the curvature comb (``spiral_cad.build123d``)."""

from __future__ import annotations

from build123d import (
    Align,
    BaseSketchObject,
    BuildSketch,
    Compound,
    Curve,
    Face,
    Mode,
    Shape,
    Sketch,
    Wire,
)

from ..cad.fillet import planar_frame
from ..cad.g2wire import g2_face, g2_wire
from ..core.shapes import DEFAULT_SHAPE
from ..design.fillets import continuous_polygon, continuous_rectangle, continuous_slot
from ._lines import chain_to_wire


class _ContinuousSketch(BaseSketchObject):
    """A face bounded by a closed chain with continuous corners (``spiral_cad.design.fillets``)."""

    _applies_to = [BuildSketch._tag]

    def __init__(self, path, rotation: float, align, mode: Mode):
        self.filleted = path  # the chain and the corners (build123d's Shape owns the name "path")
        super().__init__(Face(chain_to_wire(path.chain)), rotation, align, mode)


class ContinuousRectangle(_ContinuousSketch):
    """Sketch Object: Continuous Rectangle

    A rectangle whose corners are G2 ("continuous corners"): spiral → arc of
    ``radius`` → spiral, curvature continuous everywhere.

    Args:
        width (float): rectangle width
        height (float): rectangle height
        radius (float): the smallest radius of curvature of each corner
        transition (float, optional): share of each corner's turn made by the spirals, in (0, 1]. Defaults to 0.5
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        rotation (float, optional): angle to rotate object. Defaults to 0
        align (Align | tuple[Align, Align], optional): align MIN, CENTER, or MAX of object.
            Defaults to (Align.CENTER, Align.CENTER)
        mode (Mode, optional): combination mode. Defaults to Mode.ADD
    """

    def __init__(self, width: float, height: float, radius: float, transition: float = 0.5, rotation: float = 0,
                 align: Align | tuple[Align, Align] | None = (Align.CENTER, Align.CENTER), shape: str = DEFAULT_SHAPE,
                 mode: Mode = Mode.ADD):  # fmt: skip
        super().__init__(continuous_rectangle(width, height, radius, transition, shape=shape), rotation, align, mode)


class ContinuousPolygon(_ContinuousSketch):
    """Sketch Object: Continuous Polygon

    A regular polygon whose corners are G2 fillets.

    Args:
        radius (float): construction radius
        side_count (int): number of sides
        corner_radius (float): the smallest radius of curvature of each corner
        transition (float, optional): share of each corner's turn made by the spirals. Defaults to 0.5
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        major_radius (bool, optional): radius is the circumscribed (True) or inscribed circle's. Defaults to True
        rotation (float, optional): angle to rotate object. Defaults to 0
        align (Align | tuple[Align, Align], optional): align MIN, CENTER, or MAX of object. Defaults to None
        mode (Mode, optional): combination mode. Defaults to Mode.ADD
    """

    def __init__(self, radius: float, side_count: int, corner_radius: float, transition: float = 0.5,
                 major_radius: bool = True, rotation: float = 0, align: Align | tuple[Align, Align] | None = None,
                 shape: str = DEFAULT_SHAPE, mode: Mode = Mode.ADD):  # fmt: skip
        path = continuous_polygon(radius, side_count, corner_radius, transition, major_radius, shape=shape)
        super().__init__(path, rotation, align, mode)


class ContinuousSlot(_ContinuousSketch):
    """Sketch Object: Continuous Slot

    A slot of overall ``width`` and ``height`` whose ends are curvature
    continuous all the way round (each end: two G2 corners meeting in its middle).

    Args:
        width (float): overall width of slot
        height (float): overall height (the width of the ends)
        transition (float, optional): share of each 90° corner made by the spirals. Defaults to 0.5
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        rotation (float, optional): angle to rotate object. Defaults to 0
        align (Align | tuple[Align, Align], optional): align MIN, CENTER, or MAX of object.
            Defaults to (Align.CENTER, Align.CENTER)
        mode (Mode, optional): combination mode. Defaults to Mode.ADD
    """

    def __init__(self, width: float, height: float, transition: float = 0.5, rotation: float = 0,
                 align: Align | tuple[Align, Align] | None = (Align.CENTER, Align.CENTER), shape: str = DEFAULT_SHAPE,
                 mode: Mode = Mode.ADD):  # fmt: skip
        super().__init__(continuous_slot(width, height, transition, shape=shape), rotation, align, mode)


def curvature_comb(shape_or_chain, scale: float | None = None, per_edge: int = 24) -> Compound:
    """The curvature comb (teeth and envelope) of a chain, wire, face or part as a build123d ``Compound`` of edges.

    Show it beside the part (CQ-editor, ``show``) to see where the curvature
    jumps: a circular fillet's comb steps from nothing to 1/r, a G2 corner's
    ramps.
    """
    from ..cad.continuity import curvature_comb as comb

    return Compound(comb(shape_or_chain, scale=scale, per_edge=per_edge))


def make_g2(target: Wire | Face | Sketch | Curve, max_deviation: float, shape: str = "near-linear") -> Wire | Face | Sketch | Curve:
    """Operation: Make G2

    Make a planar outline of lines and tangent arcs curvature-continuous (G2)
    within ``max_deviation`` (``spiral_cad.design.make_g2``): every tangent
    joint gets a spiral transition, its CIRCLE edges stay CIRCLE edges (shrunk
    about their centres by the shift each transition needs), sharp corners
    between lines get a spiral pair, and every point of the result lies within
    ``max_deviation`` of the input and the input within it of the result. A
    ``fillet()``ed rectangle or a ``SlotOverall`` becomes G2 this way.

    Returns the same kind as given, every wire of it made G2 (a face's holes
    included). A wire that reverses is split there into G2 parts that meet.
    BEZIER edges whose joints are G2 (its own spirals, a ``ContinuousRectangle``)
    are kept, so applying it twice changes nothing; near-tangent joints (kinks
    of 1e-7 … 1e-3 rad, as exported drawings have) are made G2 too.

    Args:
        target: a planar ``Wire``, ``Face``, ``Sketch`` or ``Curve``.
        max_deviation (float): the Hausdorff bound, in model units.
        shape (str, optional): "near-linear" or "walton-meek". Defaults to "near-linear"

    Raises:
        ValueError: a solid, non-planar input, or edges other than lines and arcs.
        NoSolutionError: a joint that cannot be made G2 within the bound (named,
            with the smallest bound that works).
    """
    if not isinstance(target, Shape) or target.solids() or target.shells():
        raise ValueError(f"make_g2 takes a planar Wire, Face, Sketch or Curve; got {type(target).__name__}")
    if isinstance(target, Wire):
        return Wire(g2_wire(target.wrapped, max_deviation, shape=shape)[0])
    if isinstance(target, Face) and not isinstance(target, Sketch):
        return Face(g2_face(target.wrapped, max_deviation, shape=shape))
    faces, wires = target.faces(), [] if target.faces() else target.wires()
    if faces:
        return Sketch(Compound([Face(g2_face(f.wrapped, max_deviation, shape=shape)) for f in faces]).wrapped)
    if not wires:
        raise ValueError(f"make_g2 takes a planar Wire, Face, Sketch or Curve; this {type(target).__name__} has no wires")
    frame = planar_frame(target.wrapped)
    return Curve(Compound([Wire(g2_wire(w.wrapped, max_deviation, shape=shape, frame=frame)[0]) for w in wires]).wrapped)
