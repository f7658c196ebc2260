"""Public name of ``spiral_cad.cad.occ`` (see there)."""

from .cad.occ import *  # noqa: F403
from .cad.occ import __all__  # noqa: F401
