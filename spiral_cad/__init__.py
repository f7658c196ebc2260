"""spiral_cad: exact curvature-continuous (G2) cubic Bézier spirals for CAD.

The numeric core (this namespace and ``spiral_cad.batch``) needs only numpy,
scipy and numba; the CAD adapters import OCP when they are used.
"""

from .core.chain import Chain, Join
from .core.errors import NoSolutionError, Status
from .core.segments import Arc, Circle, Line, Segment
from .core.space import PlaneFrame
from .core.spiral import BezierSpiral
from .core.transitions import (
    Transition,
    circle_in_circle,
    circle_to_circle,
    line_to_circle,
    line_to_line,
)

__all__ = [
    "Arc",
    "BezierSpiral",
    "Chain",
    "Circle",
    "Join",
    "Line",
    "NoSolutionError",
    "PlaneFrame",
    "Segment",
    "Status",
    "Transition",
    "circle_in_circle",
    "circle_to_circle",
    "line_to_circle",
    "line_to_line",
]
__version__ = "0.2.0"


def _cad_method(name: str, adapter: str, doc: str):
    """A ``Chain`` method that imports the CAD adapter (and OCP) only when it is called."""

    def method(self, plane=None):
        from .cad import occ

        return getattr(occ, adapter)(self, plane)

    method.__name__, method.__qualname__, method.__doc__ = name, f"Chain.{name}", doc
    return method


# The numeric core knows no CAD kernel: its chains get their CAD methods here, one layer up.
Chain.to_edges = _cad_method("to_edges", "chain_edges", "The exact build123d edges (LINE, CIRCLE, BEZIER) in travel order "
                             "(``spiral_cad.cad.occ.chain_edges``; ``plane``: a build123d Plane, None for Plane.XY).")
Chain.to_wire = _cad_method("to_wire", "chain_to_wire", "The chain as one build123d Wire in ``plane``'s coordinates "
                            "(``spiral_cad.cad.occ.chain_to_wire``; None: Plane.XY).")
