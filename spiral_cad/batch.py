"""Public name of ``spiral_cad.core.batch`` (see there)."""

from .core.batch import *  # noqa: F403
from .core.batch import __all__  # noqa: F401
