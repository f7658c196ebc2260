"""Refusal advice: the value a refusal names ("radius up to X fits") is found, then built, before it is given.

A fit check finds the limit (bisection on a cheap predicate); the suggestion stays ``ADVICE_MARGIN``
inside it, because near the limit the geometry nears a singularity, and it is built by the caller's
own construction (with its verification) before it is named; when it does not build, smaller values
are tried, and a refusal without one says that no value fits.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..core.errors import NoSolutionError

__all__ = ["ADVICE_MARGIN", "advice", "largest", "refusal"]


def largest(fits: Callable[[float], bool], upper: float) -> float | None:
    """The largest value in (0, upper) for which ``fits`` holds (bisection; it must hold below it), rounded
    down to 6 significant digits and checked itself, or None."""
    low, high = 0.0, upper
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if fits(mid) else (low, mid)
    if not low > 0.0:
        return None
    step = 10.0 ** (math.floor(math.log10(low)) - 5)
    for k in range(3):  # rounding down may still land on a value that fails: a step further
        value = float(f"{(math.floor(low / step) - k) * step:.6g}")
        if value > 0.0 and fits(value):
            return value
    return None


#: A suggested value stays this share inside the limit the fit finds: there the geometry nears a
#: singularity (an inner offset's radius, a wall's height or a line between corners going to zero),
#: where readers measure what our construction does not promise (FreeCAD finds a 2.9e-4 curvature
#: jump on an inner offset of radius 6e-5).
ADVICE_MARGIN = 0.01
#: Values tried, each ``_ADVICE_STEP`` times the last, when a suggestion does not build.
_ADVICE_TRIES = 4
_ADVICE_STEP = 0.9


def advice(fits: Callable[[float], bool], builds: Callable[[float], object], upper: float) -> float | None:
    """The value a refusal may suggest: the largest below ``upper`` that ``fits`` with ``ADVICE_MARGIN`` to
    spare, then built by ``builds`` (which raises when the part is refused or fails its verification);
    stepped down when it does not build, None when nothing tried builds."""
    value = largest(lambda v: fits(v * (1.0 + ADVICE_MARGIN)), upper)
    for _ in range(_ADVICE_TRIES):
        if value is None:
            return None
        try:
            builds(value)
        except ValueError:  # NoSolutionError too: refused or not verified, a step further down
            value = float(f"{value * _ADVICE_STEP:.6g}")
            continue
        return value
    return None


def refusal(problem: str, name: str, fits: float | None) -> NoSolutionError:
    """The refusal of ``problem`` with its advice: "; ``name`` up to ``fits`` fits", or "; no ``name`` fits"."""
    return NoSolutionError(f"{problem}; {name} up to {fits:.6g} fits" if fits is not None else f"{problem}; no {name} fits")
