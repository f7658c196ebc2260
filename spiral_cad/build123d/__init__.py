"""build123d line objects for G2 spiral transitions and whole chains.

Each object is a ``BaseLineObject`` (a ``Wire``, like build123d's
``Polyline``) because a transition or chain has several edges. Points are
taken in the local coordinates of the active ``BuildLine`` and the result
is placed on its workplane by build123d, exactly as for its own objects;
outside a builder the result lies on ``Plane.XY``. Spirals become exact
``BEZIER`` edges, arcs ``CIRCLE`` and lines ``LINE`` edges, in travel order.

``G2Polyline`` is build123d's ``Polyline`` with every corner rounded by a
G2 spiral pair, in the plane or in space (robot and CNC paths, handrails,
cable and pipe runs), and ``g2_fillet`` also rounds a 3-D wire of lines,
each corner in the plane of its two edges. ``show_continuity`` shows what the
face checker finds in OCP CAD Viewer or CQ-editor.

Example:
    >>> with BuildLine(Plane.XZ) as path:
    ...     SpiralChain(chain)
"""

from __future__ import annotations

from ..cad.corridor import Corridor, centerline_wire, corridor
from ._lines import (
    G2Polyline,
    SpiralChain,
    SpiralCircleInCircle,
    SpiralCircleToCircle,
    SpiralLineToCircle,
    SpiralLineToLine,
    chain_edges,
    chain_to_wire,
)
from ._parts import ContinuousBox, g2_fillet, g2_slab
from ._sketches import ContinuousPolygon, ContinuousRectangle, ContinuousSlot, curvature_comb, make_g2
from ._viewer import show_continuity

__all__ = [
    "chain_edges",
    "chain_to_wire",
    "ContinuousBox",
    "ContinuousPolygon",
    "ContinuousRectangle",
    "ContinuousSlot",
    "Corridor",
    "G2Polyline",
    "SpiralChain",
    "SpiralCircleInCircle",
    "SpiralCircleToCircle",
    "SpiralLineToCircle",
    "SpiralLineToLine",
    "centerline_wire",
    "corridor",
    "curvature_comb",
    "g2_fillet",
    "g2_slab",
    "make_g2",
    "show_continuity",
]
