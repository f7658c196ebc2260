"""Public name of ``spiral_cad.cad.build123d`` (see there)."""

from .cad.build123d import *  # noqa: F403
from .cad.build123d import __all__  # noqa: F401
