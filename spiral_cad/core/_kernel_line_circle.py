"""The line → circle transition (Theorem 4.1): the ordinary rows in straight-line code, any row checked,
in scaled frames, for every shape (the steps every row takes: ``spiral_cad.core._kernels``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ._kernel_spiral import (
    _secant,
)
from ._kernels import (
    BAD_RADIUS,
    CIRCLE_MEETS_LINE,
    EQUAL_LEG_COS,
    INF,
    NAN,
    NEAR_LINEAR,
    NEAR_LINEAR_MIN_COS,
    NOT_FINITE,
    OK,
    OUTSIDE_SHAPE,
    UNVERIFIED,
    VERIFY_TOL,
    WALTON_MEEK,
    ZERO_DIRECTION,
    angle,
    centre_offset,
    end_fits,
    end_residual,
    fail,
    finite,
    frame_scale,
    leg_factors,
    leg_offsets,
    line_fits,
    line_residual,
    ordinary,
    spiral_in_world,
    store,
    unit,
    unit_ordinary,
    worst,
)
from .jit import Kernels

if TYPE_CHECKING:  # annotations only
    from ._kernels import FloatArray, Points8, Row

KERNELS = Kernels(globals())
jit = KERNELS.jit
row_jit = KERNELS.row_jit


# ------------------------------------------------------ line to circle


def _near_linear_line_cubic() -> tuple[float, float, float, float]:
    """Taylor coefficients (F0, F1, F2, F3) about c0 = 5/6 of the near-linear
    continuation's shift equation (``_near_linear_line_step``) without its q terms.

    With r = 1.8c − 0.5 the shift g1 − 1 = (1 − c²)·(1.8c + 3.5)/(9c) − (1 − c), so
    9c·(g1 − 1 − q) = −1.8c³ + 5.5c² + (1.8 − 9)c + 3.5 − 9qc. Expanded about c0
    (exactly, from the float constants the legs use) the terms stay small where
    the root lies, so the root keeps the accuracy of the 1996 spiral's closed form.
    """
    from fractions import Fraction

    a, c0 = Fraction(1.8), Fraction(EQUAL_LEG_COS)
    value = ((-a * c0 + Fraction(5.5)) * c0 + (a - 9)) * c0 + Fraction(3.5)
    slope = (-3 * a * c0 + 11) * c0 + (a - 9)
    return float(value), float(slope), float(-3 * a * c0 + Fraction(5.5)), float(-a)


NL_LINE_F0, NL_LINE_F1, NL_LINE_F2, NL_LINE_F3 = _near_linear_line_cubic()


@row_jit
def _near_linear_line_step(q9: float, x: float, lo: float, hi: float, done: bool) -> tuple[float, float, float, bool]:
    """One safeguarded Newton step for cos θ = 5/6 + x of the near-linear continuation
    (33.56° ≤ θ ≤ 50°) that shifts its circle by q = q9/9: the root of
    F = 9c·(g1(θ) − 1 − q), a cubic in x that falls with x (``_near_linear_line_cubic``),
    in the bracket [lo, hi]. Returns (x, lo, hi, done), left as it is once done."""
    f = ((NL_LINE_F3 * x + NL_LINE_F2) * x + (NL_LINE_F1 - q9)) * x + (NL_LINE_F0 - q9 * EQUAL_LEG_COS)
    above = f > 0.0  # the root lies at a larger x
    lo_new = x if above else lo
    hi_new = hi if above else x
    new = x - f / ((3.0 * NL_LINE_F3 * x + 2.0 * NL_LINE_F2) * x + (NL_LINE_F1 - q9))
    new = new if lo_new < new < hi_new else 0.5 * (lo_new + hi_new)
    root = f == 0.0
    converged = abs(new - x) <= 2e-16
    return (x if done or root else new), (lo if done else lo_new), (hi if done else hi_new), done or root or converged


#: Newton steps the vectorised near-linear rows take (from the secant of the bracket, about 4 suffice).
FAST_NEWTON_STEPS = 6


@row_jit
def _near_linear_line_start(q9: float) -> tuple[bool, float, float, float]:
    """The bracket [cos 50° − 5/6, 0] of x = cos θ − 5/6 on the near-linear continuation,
    its secant point and whether the shift is within reach (F > 0 at 50°)."""
    lo = NEAR_LINEAR_MIN_COS - EQUAL_LEG_COS
    f_lo = ((NL_LINE_F3 * lo + NL_LINE_F2) * lo + (NL_LINE_F1 - q9)) * lo + (NL_LINE_F0 - q9 * EQUAL_LEG_COS)
    f_hi = NL_LINE_F0 - q9 * EQUAL_LEG_COS
    return f_lo > 0.0, _secant(lo, f_lo, 0.0, f_hi), lo, 0.0


@row_jit
def line_circle_angle_fast(shape: int, shift: float, measure: float) -> tuple[bool, float, float]:
    """(found, sin θ, cos θ) of the spiral that shifts its circle by ``shift`` = g1(θ) − 1 > 0
    (``measure`` = d/r = 1 + shift) in straight-line code: the 1996 spiral's closed
    form, the near-linear equal-leg closed form (shift < 1/27) or, beyond it,
    ``FAST_NEWTON_STEPS`` Newton steps (``found`` False if they do not settle)."""
    if shape == WALTON_MEEK:
        # cos θ = 10 / (9ρ + √(81ρ² − 80)), with 1 − cos θ formed without cancellation.
        z = 81.0 * shift * (2.0 + shift)
        s = math.sqrt(1.0 + z)
        den = 9.0 * measure + s
        cos_t = 10.0 / den
        return True, math.sqrt((9.0 * shift + z / (s + 1.0)) / den * (1.0 + cos_t)), cos_t
    # Equal legs: 2cos²θ − 3cos θ + 1 + 3q = 0, so 1 − cos θ = 6q / (1 + √(1 − 24q)).
    versine = 6.0 * shift / (1.0 + math.sqrt(1.0 - 24.0 * shift))
    q9 = 9.0 * shift
    reach, x, lo, hi = _near_linear_line_start(q9)
    done = False
    for _ in range(FAST_NEWTON_STEPS):
        x, lo, hi, done = _near_linear_line_step(q9, x, lo, hi, done)
    c = EQUAL_LEG_COS + x
    equal = shift < 1.0 / 27.0
    found = shape == NEAR_LINEAR and (equal or (reach and done))
    return found, (math.sqrt(versine * (2.0 - versine)) if equal else math.sqrt((1.0 - c) * (1.0 + c))), (1.0 - versine if equal else c)


@jit
def line_circle_angle(shape: int, shift: float, measure: float) -> tuple[bool, float, float]:
    """``line_circle_angle_fast`` for any row: (found, sin θ, cos θ); ``found`` False
    beyond the shape's reach."""
    found, sin_t, cos_t = line_circle_angle_fast(shape, shift, measure)
    if found or shape != NEAR_LINEAR:
        return found, sin_t, cos_t
    q9 = 9.0 * shift
    reach, x, lo, hi = _near_linear_line_start(q9)
    if not reach:
        return False, NAN, NAN
    done = False
    for _ in range(100):
        x, lo, hi, done = _near_linear_line_step(q9, x, lo, hi, done)
        if done:
            break
    c = EQUAL_LEG_COS + x
    return True, math.sqrt((1.0 - c) * (1.0 + c)), c


@row_jit
def line_circle_spiral(
    px: float,
    py: float,
    tx: float,
    ty: float,
    vx: float,
    vy: float,
    rs: float,
    sin_t: float,
    cos_t: float,
    side: float,
    shape: int,
    scale: float,
) -> Points8:
    """Theorem 4.1's spiral in world coordinates: it leaves the line through p along
    t and reaches radius ``rs`` (normalised) on the side ``side`` of the line, the
    circle's centre at v from p (normalised)."""
    alpha, beta, gamma = leg_factors(shape, cos_t)
    e1, e2 = leg_offsets(alpha, beta, gamma, cos_t)
    g2 = centre_offset(sin_t, e1, e2)[1]
    a = vx * tx + vy * ty - rs * g2  # B0 = p + a·T lies r·g2 before the centre's foot
    return spiral_in_world(a * tx, a * ty, tx, ty, -side * ty, side * tx, sin_t, cos_t, rs, alpha, beta, gamma, px, py, scale, 1.0)


@row_jit
def line_to_circle_fast(
    px: float, py: float, dx: float, dy: float, cx: float, cy: float, r: float, shape: int
) -> tuple[bool, float, float, float, float, float, float, float, float, float, float, float]:
    """``line_to_circle_row`` in straight-line code for the ordinary row: every number
    finite, the direction's and the radius's size within 1e-60 … 1e60 (a frame of
    scale 1), the circle clear of the line, an angle the shape reaches and a verification
    that the sufficient tests pass. Returns (ok, θ, measure, side, x0, y0, …, x3, y3);
    where ``ok`` is False the row is left to ``line_to_circle_general``. The same
    arithmetic as that path, so the two agree bit for bit; no branches, so the
    batch runs it on vectors of rows.
    """
    tx, ty = unit_ordinary(dx, dy)
    vx = cx - px
    vy = cy - py
    d = tx * vy - ty * vx
    side = 1.0 if d > 0.0 else -1.0
    measure = abs(d) / r
    found, sin_t, cos_t = line_circle_angle_fast(shape, (abs(d) - r) / r, measure)
    x0, y0, x1, y1, x2, y2, x3, y3 = line_circle_spiral(px, py, tx, ty, vx, vy, r, sin_t, cos_t, side, shape, 1.0)
    ok = (
        math.isfinite(px) & math.isfinite(py) & math.isfinite(cx) & math.isfinite(cy) & math.isfinite(vx) & math.isfinite(vy)
        & ordinary(max(abs(dx), abs(dy))) & ordinary(r) & (abs(d) > r) & found
        & line_fits(x0, y0, x1, y1, x2, y2, px, py, tx, ty, 1.0)
        & end_fits(x1, y1, x2, y2, x3, y3, cx, cy, side * r, 1.0)
    )  # fmt: skip
    return ok, angle(sin_t, cos_t), measure, side, x0, y0, x1, y1, x2, y2, x3, y3


@jit
def line_to_circle_general(
    px: float, py: float, dx: float, dy: float, cx: float, cy: float, r: float, shape: int, out: FloatArray, i: int
) -> Row:
    """``line_to_circle_row`` for any row: checks, scaled frames, every shape."""
    if not finite(px, py, dx, dy, cx, cy, r):
        return fail(out, i, NOT_FINITE, NAN)
    tx, ty = unit(dx, dy)
    if tx == 0.0 and ty == 0.0:
        return fail(out, i, ZERO_DIRECTION, NAN)
    if not r > 0.0:
        return fail(out, i, BAD_RADIUS, NAN)
    scale = frame_scale(r)
    inv = 1.0 / scale
    rs = r * inv
    vx = (cx - px) * inv
    vy = (cy - py) * inv
    if not finite(vx, vy):
        return fail(out, i, UNVERIFIED, INF)
    d = tx * vy - ty * vx
    side = 1.0 if d > 0.0 else -1.0
    measure = abs(d) / rs
    if not abs(d) > rs:
        return fail(out, i, CIRCLE_MEETS_LINE, measure)
    found, sin_t, cos_t = line_circle_angle(shape, (abs(d) - rs) / rs, measure)
    if not found:
        return fail(out, i, OUTSIDE_SHAPE, measure)
    x0, y0, x1, y1, x2, y2, x3, y3 = line_circle_spiral(px, py, tx, ty, vx, vy, rs, sin_t, cos_t, side, shape, scale)
    fits = line_fits(x0, y0, x1, y1, x2, y2, px, py, tx, ty, inv)
    if not (fits and end_fits(x1, y1, x2, y2, x3, y3, cx, cy, side * r, inv)):
        res = worst(
            line_residual(x0, y0, x1, y1, x2, y2, px, py, tx, ty, inv),
            end_residual(x1, y1, x2, y2, x3, y3, cx, cy, side * r, inv),
        )
        if not res <= VERIFY_TOL:
            return fail(out, i, UNVERIFIED, res)
    store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
    return OK, angle(sin_t, cos_t), measure, side


@jit
def line_to_circle_row(
    px: float, py: float, dx: float, dy: float, cx: float, cy: float, r: float, shape: int, out: FloatArray, i: int
) -> Row:
    """Theorem 4.1: spiral from the directed line (p, d) to circle (c, r > 0).

    ``extra`` is the turn side: +1 left, −1 right.
    """
    ok, theta, measure, side, x0, y0, x1, y1, x2, y2, x3, y3 = line_to_circle_fast(px, py, dx, dy, cx, cy, r, shape)
    if ok:
        store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
        return OK, theta, measure, side
    return line_to_circle_general(px, py, dx, dy, cx, cy, r, shape, out, i)


KERNELS.seal()
