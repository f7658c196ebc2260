"""Public name of ``spiral_cad.cad.continuity`` (see there)."""

from .cad.continuity import *  # noqa: F403
from .cad.continuity import __all__  # noqa: F401
