"""spiral_cad: exact curvature-continuous (G2) cubic Bézier spirals for CAD.

This namespace is the numeric core's face: segments, the Bézier spiral, the
five transitions, chains, fitting points (``fit_points``), and ``batch`` (the
same solvers over arrays). It
needs only numpy, scipy and numba. ``export`` and ``read`` (``spiral_cad.app.files``, loaded on first
use) write and read every format, chosen by the file's suffix, and ``check`` judges G0/G1/G2 in any of
them or in a shape; ``make_g2`` and ``round_corners`` (from ``spiral_cad.design``) and ``plot`` (from
``spiral_cad.app.plots``, with the ``cad`` extra's matplotlib) load on first use too. The other design
tools live in ``spiral_cad.design``;
build123d objects in ``spiral_cad.build123d`` and the CadQuery plugin in
``spiral_cad.cadquery`` (these two import OCP).
"""

import sys
from typing import TYPE_CHECKING, Any

from ._version import __version__ as __version__
from .core import batch
from .core.chain import Chain
from .core.errors import NoSolutionError, Status
from .core.fit import PointFit, fit_points
from .core.segments import Arc, Join, Segment
from .core.segments import Circle as Circle  # out of the star import: SHADOWING
from .core.segments import Line as Line
from .core.space import PlaneFrame
from .core.spiral import BezierSpiral
from .core.transitions import Transition as Transition
from .core.transitions import circle_in_circle, circle_to_circle, line_to_circle, line_to_line

if TYPE_CHECKING:
    from .app.files import check, export, read
    from .app.plots import plot
    from .design.g2 import make_g2
    from .design.rounded_paths import round_corners

sys.modules[f"{__name__}.batch"] = batch  # `import spiral_cad.batch` too, as `import os.path`

#: ``Circle``, ``Line`` and ``Transition`` are ours here too (``sc.Line``, ``from spiral_cad import Line``) but
#: stay out of ``from spiral_cad import *``: build123d has its own of those names, with other meanings.
SHADOWING = ("Circle", "Line", "Transition")

__all__ = [
    "Arc",
    "BezierSpiral",
    "Chain",
    "Join",
    "NoSolutionError",
    "PlaneFrame",
    "PointFit",
    "Segment",
    "Status",
    "batch",
    "check",
    "circle_in_circle",
    "circle_to_circle",
    "export",
    "fit_points",
    "line_to_circle",
    "line_to_line",
    "make_g2",
    "plot",
    "read",
    "round_corners",
]
#: The names loaded on first use, and their modules: the file formats' modules, the design tools and the
#: plots load only when used.
_LAZY = {
    "check": "app.files",
    "export": "app.files",
    "read": "app.files",
    "make_g2": "design.g2",
    "round_corners": "design.rounded_paths",
    "plot": "app.plots",
}


def __getattr__(name: str) -> Any:
    """The names of ``_LAZY`` on first use."""
    if name in _LAZY:
        import importlib

        try:
            module = importlib.import_module(f"{__name__}.{_LAZY[name]}")
        except ModuleNotFoundError as missing:
            if missing.name is None or not missing.name.startswith("matplotlib"):
                raise
            raise ModuleNotFoundError(f'spiral_cad.{name} draws with matplotlib: pip install "spiral_cad[cad]"') from None
        return getattr(module, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
