"""build123d line objects for G2 spiral transitions and whole chains.

Each object is a ``BaseLineObject`` (a ``Wire``, like build123d's
``Polyline``) because a transition or chain has several edges. Points are
taken in the local coordinates of the active ``BuildLine`` and the result
is placed on its workplane by build123d, exactly as for its own objects;
outside a builder the result lies on ``Plane.XY``. Spirals become exact
``BEZIER`` edges, arcs ``CIRCLE`` and lines ``LINE`` edges, in travel order.

Example:
    >>> with BuildLine(Plane.XZ) as path:
    ...     SpiralChain(chain)
"""

from __future__ import annotations

from collections.abc import Iterable

from build123d import (
    BaseLineObject,
    BuildLine,
    Mode,
    SkipClean,
    Vector,
    VectorLike,
    Wire,
)

from ..core.chain import Chain
from .occ import chain_wire
from ..core.segments import Segment
from ..core.transitions import (
    Transition,
    circle_in_circle,
    circle_to_circle,
    line_to_circle,
    line_to_line,
)

__all__ = ["SpiralChain", "SpiralCircleInCircle", "SpiralCircleToCircle", "SpiralLineToCircle", "SpiralLineToLine"]


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
        mode: Mode = Mode.ADD,
    ):
        transition = line_to_circle(_xy(point, "point"), _xy(direction, "direction"), _xy(center, "center"), radius)
        super().__init__(transition, mode)


class _CirclePairObject(_TransitionObject):
    """A transition between two circles given by centres and signed radii."""

    _solve = staticmethod(circle_to_circle)

    def __init__(
        self,
        center0: VectorLike,
        radius0: float,
        center1: VectorLike,
        radius1: float,
        mode: Mode = Mode.ADD,
    ):
        transition = self._solve(_xy(center0, "center0"), radius0, _xy(center1, "center1"), radius1)
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
        mode: Mode = Mode.ADD,
    ):
        transition = line_to_line(_xy(p0, "p0"), _xy(corner, "corner"), _xy(p1, "p1"), curvature)
        super().__init__(transition, mode)


class SpiralCircleInCircle(_CirclePairObject):
    """Line Object: Spiral Circle In Circle

    One G2 spiral between two nested circles (either way: in or out).

    Args:
        center0 (VectorLike): centre of the circle left
        radius0 (float): its signed radius
        center1 (VectorLike): centre of the circle reached
        radius1 (float): its signed radius (same sign as radius0)
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
