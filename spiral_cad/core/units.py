"""Length units (every chain's numbers are in one of these, and every file says which) and the
shared tolerances.

The API default is millimetres, as in build123d and CadQuery; design files
name their unit (``"units": "m"``). Each writer declares the unit the way its
readers expect (see ``spiral_cad.cad.export``); nothing is rescaled on the way.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

#: Size of one unit in millimetres, per unit name.
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "km": 1.0e6, "in": 25.4, "ft": 304.8}
UNITS = tuple(MM_PER_UNIT)
DEFAULT_UNITS = "mm"
#: Units of US customary designs (speeds in mph, the US forms of road formulas).
IMPERIAL = frozenset({"in", "ft"})
#: Metres per international foot.
FOOT = MM_PER_UNIT["ft"] / 1000.0
#: |sin| of a turn below which two directions count as one line (before any deviation is measured).
COLLINEAR_TOL = 1e-12


def length_unit(value: Any, name: str = "units") -> str:
    """``value`` as a known unit name, else ValueError naming ``name`` and the choices."""
    if not isinstance(value, str) or value not in MM_PER_UNIT:
        raise ValueError(f"{name} must be one of {', '.join(UNITS)}; got {value!r:.80}")
    return value


def shared_unit(found: Iterable[str], units: str | None = None) -> str:
    """The one length unit of the chains written to one file (``found``: each chain's unit), checked against
    ``units``, which may only confirm it: nothing is rescaled, so another unit would mislabel the file.

    Raises:
        ValueError: chains in different units, or ``units`` another unit than theirs (or not a unit).
    """
    kinds = set(found)
    if len(kinds) != 1:
        raise ValueError(f"chains in one file must share a unit; got {', '.join(sorted(kinds)) or 'none'}")
    (own,) = kinds
    if units is not None and length_unit(units) != own:
        raise ValueError(f"the chains are in {own}; units={units!r} would mislabel them (nothing is rescaled)")
    return own


def to_metres(units: str) -> float:
    """Metres per unit."""
    return MM_PER_UNIT[units] / 1000.0


def speed_unit(units: str) -> str:
    """The speed unit that goes with a length unit: km/h for metric designs, mph for in/ft."""
    return "mph" if units in IMPERIAL else "km/h"
