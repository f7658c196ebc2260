"""Public name of ``spiral_cad.cad.cadquery`` (see there)."""

from .cad.cadquery import *  # noqa: F403
from .cad.cadquery import __all__  # noqa: F401
