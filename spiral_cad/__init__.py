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
