"""Public name of ``spiral_cad.core.nurbs`` (see there)."""

from .core.nurbs import *  # noqa: F403
from .core.nurbs import __all__  # noqa: F401
