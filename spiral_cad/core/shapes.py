"""Spiral shapes: the names users pass as ``shape=`` and what each one is.

* ``"walton-meek"`` — the cubic Bézier spiral of Walton & Meek (1996,
  Theorem 3.1): legs a = b = 25 tan θ/(54 κ cos θ), c = 5 tan θ/(9κ). Its
  curvature peaks at the circle (κ'(1) = 0: G3 there), so dκ/ds peaks at
  1.6–1.84× its mean for road-sized angles. Any θ < 90°. The default of the
  core API: the paper's geometry.
* ``"near-linear"`` — the cubic whose curvature grows almost linearly with
  arc length, like a clothoid's (the paper's §5 question): the equal-leg
  member a = b = c = (2/3)·R·sin θ up to θ = 33.56° (peak/mean dκ/ds 1.0009
  at 2°, 1.014 at 8°, 1.050 at 15°), continued to θ = 50° through members
  whose curvature peaks at the circle. G2 at the circle (dκ/ds jumps there,
  as for a clothoid). The default of the road and rail tools.
* ``"g2cbs"`` — Yang & Sukkarieh's curvature-bounded corner pair (leg ratio
  2(√6 − 1)/5): for corners (``line_to_line``, corner rounding) only; about
  24 % lower peak curvature than the 1996 spiral for the same corner distance.
"""

from __future__ import annotations

import math
from typing import Any

from . import _kernels as K

#: Shape name → kernel code.
SHAPE_CODES = {"walton-meek": K.WALTON_MEEK, "near-linear": K.NEAR_LINEAR, "g2cbs": K.G2CBS}
SHAPE_NAMES = {code: name for name, code in SHAPE_CODES.items()}
#: The shapes every transition offers.
TRANSITION_SHAPES = ("walton-meek", "near-linear")
#: The shapes a corner (a spiral pair between two lines) offers.
CORNER_SHAPES = ("walton-meek", "near-linear", "g2cbs")
DEFAULT_SHAPE = "walton-meek"
#: Largest spiral angle of the near-linear family (radians).
NEAR_LINEAR_MAX_THETA = K.NEAR_LINEAR_MAX_THETA


def shape_code(value: Any, allowed: tuple[str, ...] = TRANSITION_SHAPES, name: str = "shape") -> int:
    """The kernel code of shape name ``value``, else ValueError naming ``name`` and the choices."""
    if not isinstance(value, str) or value not in allowed:
        hint = " (g2cbs is a corner shape: line_to_line and corner rounding)" if value == "g2cbs" else ""
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}{hint}; got {value!r:.80}")
    return SHAPE_CODES[value]


def shape_limits(shape: str) -> dict[str, float]:
    """What the shape's largest spiral angle allows, for error messages and documentation.

    Keys: ``theta`` (largest θ, radians; π/2 means any θ < 90°), ``line_circle``
    (largest d/r of line → circle), ``s_pair`` (largest D/(r0 + r1) of an S),
    ``g1`` and ``g2`` at that angle (the C limit is
    √((r0 + r1)²·g2² + (r1 − r0)²·g1²)).
    """
    code = SHAPE_CODES[shape]
    if code != K.NEAR_LINEAR:
        return {"theta": math.pi / 2, "line_circle": math.inf, "s_pair": math.inf, "g1": math.inf, "g2": math.inf}
    theta = K.NEAR_LINEAR_MAX_THETA
    s, c = math.sin(theta), math.cos(theta)
    g1, g2 = K.shape_g1(code, s, c), K.shape_g2(code, s, c)
    return {"theta": theta, "line_circle": g1, "s_pair": math.hypot(g1, g2), "g1": g1, "g2": g2}
