"""build123d line objects: the transitions, whole chains and G2 polylines as exact wires (``spiral_cad.build123d``)."""

from __future__ import annotations

from collections.abc import Iterable

from build123d import (
    BaseLineObject,
    BuildLine,
    Edge,
    Mode,
    Plane,
    SkipClean,
    Vector,
    VectorLike,
    Wire,
    flatten_sequence,
)
from OCP.gp import gp_Ax3

from ..cad.occ import chain_wire, plane_ax3, segment_edges
from ..core.chain import Chain
from ..core.segments import Segment
from ..core.shapes import DEFAULT_SHAPE
from ..core.transitions import Transition, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from ..design.rounded_paths import curvature_bound, round_corners


def chain_edges(chain: Iterable[Segment], plane: Plane | None = None) -> list[Edge]:
    """The exact build123d edges (LINE, CIRCLE, BEZIER) of a chain, in travel order.

    Args:
        chain: a ``Chain`` (or segments in travel order); its numbers go in as they are (build123d
            works in mm: a chain in another unit keeps its numbers).
        plane: a build123d ``Plane``: the coordinate system of the chain's coordinates
            (x, y[, z]) (None: the global one, ``Plane.XY``).

    Raises:
        ValueError: ``chain`` is not segments, or ``plane`` not a ``Plane`` instance.
    """
    return [Edge(e) for e in segment_edges(_segments(chain), _ax3(plane))]


def chain_to_wire(chain: Iterable[Segment], plane: Plane | None = None) -> Wire:
    """The chain as one build123d ``Wire`` in ``plane``'s coordinates (None: ``Plane.XY``); arguments
    as ``chain_edges``."""
    return Wire(chain_wire(_segments(chain), _ax3(plane)))


def _segments(chain: Iterable[Segment]) -> list[Segment]:
    """``chain`` as a list of segments, or ValueError naming what it is."""
    if isinstance(chain, Chain):
        return list(chain)
    items = list(chain) if isinstance(chain, Iterable) and not isinstance(chain, (str, bytes)) else None
    if not items or not all(isinstance(item, Segment) for item in items):
        raise ValueError(f"chain must be a Chain or segments in travel order; got {type(chain).__name__}")
    return items


def _ax3(plane: Plane | None) -> gp_Ax3 | None:
    """A build123d ``Plane`` instance (or None) as OCP's ``gp_Ax3``."""
    if plane is not None and not isinstance(plane, Plane):
        raise ValueError(f"plane must be a build123d Plane (such as Plane.XZ) or None; got {plane!r:.60}")
    return plane_ax3(plane)


def _xy(value: VectorLike, name: str) -> tuple[float, float]:
    """A build123d point in the local plane as (x, y); a non-zero z is an error, not projected away."""
    vector = Vector(value)
    if vector.Z != 0.0:
        raise ValueError(f"{name} must lie in the line's plane (z = 0); got {tuple(vector)}")
    return vector.X, vector.Y


def _wire(segments: Iterable[Segment]) -> Wire:
    return Wire(chain_wire(segments))


class _ExactLineObject(BaseLineObject):
    """A line object whose edges reach the builder unmerged.

    ``BuildLine`` fuses new edges into its line and then "cleans" it with
    ``ShapeUpgrade_UnifySameDomain``, which concatenates tangent-continuous
    Bézier edges into one B-spline. Publishing inside build123d's
    ``SkipClean`` keeps each spiral its own exact BEZIER edge. (Later objects
    added to the same builder clean the whole line again unless the builder
    itself runs inside ``with SkipClean():``.)
    """

    _applies_to = [BuildLine._tag]

    def _publish_to_context(self, object_scope) -> None:
        previous = SkipClean.clean  # restored as found, so an enclosing SkipClean stays in force
        SkipClean.clean = False
        try:
            super()._publish_to_context(object_scope)
        finally:
            SkipClean.clean = previous


class _TransitionObject(_ExactLineObject):
    """Common base: the spirals of one solved transition, with the solution kept as ``transition``."""

    def __init__(self, transition: Transition, mode: Mode):
        super().__init__(_wire(transition.spirals), mode=mode)
        self.transition = transition


class SpiralLineToCircle(_TransitionObject):
    """Line Object: Spiral Line To Circle

    The G2 Bézier spiral from a directed line onto a circle (Walton–Meek
    Theorem 4.1). Travel follows ``direction`` and turns toward the circle.

    Args:
        point (VectorLike): a point of the line
        direction (VectorLike): travel direction of the line
        center (VectorLike): circle centre, off the line
        radius (float): circle radius (> 0, smaller than the centre's distance to the line)
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        mode (Mode, optional): combination mode. Defaults to Mode.ADD

    Raises:
        NoSolutionError: the circle touches or crosses the line.
    """

    def __init__(
        self,
        point: VectorLike,
        direction: VectorLike,
        center: VectorLike,
        radius: float,
        shape: str = DEFAULT_SHAPE,
        mode: Mode = Mode.ADD,
    ):
        transition = line_to_circle(_xy(point, "point"), _xy(direction, "direction"), _xy(center, "center"), radius, shape)
        super().__init__(transition, mode)


class _CirclePairObject(_TransitionObject):
    """A transition between two circles given by centres and signed radii (``_solve``: the subclass's solver)."""

    def __init__(
        self,
        center0: VectorLike,
        radius0: float,
        center1: VectorLike,
        radius1: float,
        shape: str = DEFAULT_SHAPE,
        mode: Mode = Mode.ADD,
    ):
        transition = self._solve(_xy(center0, "center0"), radius0, _xy(center1, "center1"), radius1, shape)
        super().__init__(transition, mode)


class SpiralCircleToCircle(_CirclePairObject):
    """Line Object: Spiral Circle To Circle

    Two G2 spirals from circle 0 to circle 1: a C when the signed radii
    share their sign, an S otherwise (positive radius: counterclockwise).

    Args:
        center0 (VectorLike): centre of the circle left
        radius0 (float): its signed radius
        center1 (VectorLike): centre of the circle reached
        radius1 (float): its signed radius
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        mode (Mode, optional): combination mode. Defaults to Mode.ADD

    Raises:
        NoSolutionError: the circles admit no such transition.
    """

    _solve = staticmethod(circle_to_circle)


class SpiralLineToLine(_TransitionObject):
    """Line Object: Spiral Line To Line

    Two G2 spirals rounding the corner between the lines p0→corner and
    corner→p1.

    Args:
        p0 (VectorLike): a point on the incoming line
        corner (VectorLike): the lines' intersection
        p1 (VectorLike): a point on the outgoing line
        curvature (float, optional): curvature at the joint; None takes the
            largest spirals that fit between p0 and p1. Defaults to None
        shape (str, optional): "walton-meek", "near-linear" or "g2cbs". Defaults to "walton-meek"
        mode (Mode, optional): combination mode. Defaults to Mode.ADD

    Raises:
        NoSolutionError: collinear legs or a curvature too small to fit.
    """

    def __init__(
        self,
        p0: VectorLike,
        corner: VectorLike,
        p1: VectorLike,
        curvature: float | None = None,
        shape: str = DEFAULT_SHAPE,
        mode: Mode = Mode.ADD,
    ):
        transition = line_to_line(_xy(p0, "p0"), _xy(corner, "corner"), _xy(p1, "p1"), curvature, shape)
        super().__init__(transition, mode)


class SpiralCircleInCircle(_CirclePairObject):
    """Line Object: Spiral Circle In Circle

    One G2 spiral between two nested circles (either way: in or out).

    Args:
        center0 (VectorLike): centre of the circle left
        radius0 (float): its signed radius
        center1 (VectorLike): centre of the circle reached
        radius1 (float): its signed radius (same sign as radius0)
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        mode (Mode, optional): combination mode. Defaults to Mode.ADD

    Raises:
        NoSolutionError: the circles lie outside the thin band where a
            single spiral exists.
    """

    _solve = staticmethod(circle_in_circle)


class SpiralChain(_ExactLineObject):
    """Line Object: Spiral Chain

    Every segment of a G2 ``Chain``: lines as LINE, arcs as CIRCLE and
    spirals as BEZIER edges, joined into one wire in travel order.

    Args:
        chain (Chain): the chain, in the builder's local coordinates
        mode (Mode, optional): combination mode. Defaults to Mode.ADD
    """

    def __init__(self, chain: Chain, mode: Mode = Mode.ADD):
        if not isinstance(chain, Chain):
            raise ValueError(f"chain must be a spiral_cad.Chain; got {chain!r}")
        super().__init__(_wire(chain), mode=mode)
        self.chain = chain


class G2Polyline(_ExactLineObject):
    """Line Object: G2 Polyline

    A polyline through ``pts`` whose corners are rounded by G2 spiral pairs
    (``spiral_cad.design.round_corners``), in the plane or in space: each
    pair lies in the plane of its corner's two edges, and between corners the
    path runs straight along the polyline, so the whole wire is curvature
    continuous. Edges: LINE between corners, two BEZIER per corner.

    Args:
        pts (VectorLike | Iterable[VectorLike]): sequence of three or more points
        radius (float, optional): the smallest radius of curvature: every corner
            reaches exactly 1/radius at its middle (the tightest that fits). Defaults to None
        max_deviation (float, optional): the largest distance between a corner
            point and the path (a CNC or robot tolerance): each corner gets the
            largest pair within it; with ``radius`` too, its curvature must stay
            below 1/radius. Defaults to None
        shape (str, optional): "walton-meek", "near-linear" or "g2cbs". Defaults to "walton-meek"
        mode (Mode, optional): combination mode. Defaults to Mode.ADD

    With neither ``radius`` nor ``max_deviation`` each corner uses all of the
    edges it may (half of a shared edge, all of an end edge). The numeric
    result is kept as ``rounded`` (a ``RoundedPath``: chain, corners, deviations).

    Raises:
        ValueError: fewer than three points, repeated points, a polyline that
            folds straight back, a radius or deviation that is not positive.
        NoSolutionError: a corner that cannot be rounded as asked (named, with numbers).
    """

    def __init__(
        self,
        *pts: VectorLike | Iterable[VectorLike],
        radius: float | None = None,
        max_deviation: float | None = None,
        shape: str = DEFAULT_SHAPE,
        mode: Mode = Mode.ADD,
    ):
        points = [tuple(Vector(p)) for p in flatten_sequence(*pts)]
        curvature = curvature_bound(radius)
        path = round_corners(points, max_curvature=curvature, max_deviation=max_deviation, shape=shape)
        super().__init__(_wire(path.chain), mode=mode)
        self.rounded = path  # the numeric result (build123d's Shape owns the name "path")
