"""One spiral (Theorem 3.1 and the shapes' own legs), the 1-D root finders the transitions share, and
Bézier evaluation at many parameters: kernels on ``spiral_cad.core._kernels``'s (its docstring tells the steps
every row takes).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ._kernels import (
    BAD_ANGLE,
    BAD_CURVATURE,
    INF,
    NAN,
    NEAR_LINEAR,
    NEAR_LINEAR_MIN_COS,
    NOT_FINITE,
    OK,
    OUTSIDE_SHAPE,
    UNVERIFIED,
    VERIFY_TOL,
    ZERO_DIRECTION,
    centre_offset,
    end_fits,
    end_residual,
    fail,
    finite,
    frame_scale,
    in_shape_domain,
    leg_factors,
    leg_offsets,
    line_fits,
    line_residual,
    shape_offsets,
    spiral_in_world,
    spiral_points,
    store,
    unit,
    worst,
)
from .jit import Kernels

if TYPE_CHECKING:  # annotations only
    from ._kernels import FloatArray, Row

KERNELS = Kernels(globals())
jit = KERNELS.jit
row_jit = KERNELS.row_jit


# ---------------------------------------------------------- one spiral


@jit
def spiral_row(bx: float, by: float, dx: float, dy: float, theta: float, curvature: float, shape: int, out: FloatArray, i: int) -> Row:
    """Theorem 3.1 (or the shape's own legs): the spiral from (bx, by) along d turning by θ to curvature c."""
    if not finite(bx, by, dx, dy, theta, curvature):
        return fail(out, i, NOT_FINITE, NAN)
    tx, ty = unit(dx, dy)
    if tx == 0.0 and ty == 0.0:
        return fail(out, i, ZERO_DIRECTION, NAN)
    if not 0.0 < abs(theta) < math.pi / 2.0:
        return fail(out, i, BAD_ANGLE, NAN)
    if curvature == 0.0 or (curvature > 0.0) != (theta > 0.0):
        return fail(out, i, BAD_CURVATURE, NAN)
    side = 1.0 if theta > 0.0 else -1.0
    sin_t = math.sin(abs(theta))
    cos_t = math.cos(theta)
    if not in_shape_domain(shape, cos_t):
        return fail(out, i, OUTSIDE_SHAPE, abs(theta))
    radius = 1.0 / abs(curvature)
    alpha, beta, gamma = leg_factors(shape, cos_t)
    # The legs set the scale: the spiral's own size, not its end radius.
    size = beta * sin_t * radius
    if not (size > 0.0 and size < INF):
        return fail(out, i, UNVERIFIED, INF)
    scale = frame_scale(size)
    inv = 1.0 / scale
    nx = -side * ty
    ny = side * tx
    local_radius = radius * inv
    x0, y0, x1, y1, x2, y2, x3, y3 = spiral_in_world(
        0.0, 0.0, tx, ty, nx, ny, sin_t, cos_t, local_radius, alpha, beta, gamma, bx, by, scale, 1.0
    )
    # The end circle's centre B0 + r·(g2·T + g1·N).
    e1, e2 = leg_offsets(alpha, beta, gamma, cos_t)
    g1, g2 = centre_offset(sin_t, e1, e2)
    g1 *= local_radius
    g2 *= local_radius
    cx = bx + scale * (g2 * tx + g1 * nx)
    cy = by + scale * (g2 * ty + g1 * ny)
    fits = line_fits(x0, y0, x1, y1, x2, y2, bx, by, tx, ty, inv)
    # The centre is the spiral's own (not given): its check carries no rounding of a far circle.
    if not (fits and end_fits(x1, y1, x2, y2, x3, y3, cx, cy, side * radius, inv, 0.0)):
        res = worst(
            line_residual(x0, y0, x1, y1, x2, y2, bx, by, tx, ty, inv),
            end_residual(x1, y1, x2, y2, x3, y3, cx, cy, side * radius, inv, 0.0),
        )
        if not res <= VERIFY_TOL:
            return fail(out, i, UNVERIFIED, res)
    store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
    return OK, theta, NAN, NAN


@jit
def unit_spirals_batch(sin_t: FloatArray, cos_t: FloatArray, shape: int, out: FloatArray) -> None:
    """Spirals of ``shape`` from the origin along +x, turning left by θ to end radius 1 (one per row)."""
    rows = out.reshape((out.shape[0], 1, 4, 2))
    for i in range(sin_t.shape[0]):
        alpha, beta, gamma = leg_factors(shape, cos_t[i])
        x0, y0, x1, y1, x2, y2, x3, y3 = spiral_points(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, sin_t[i], cos_t[i], 1.0, alpha, beta, gamma)
        store(rows, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)


# ------------------------------------------------------------ 1-D roots


@jit
def _secant(lo: float, f_lo: float, hi: float, f_hi: float) -> float:
    """The regula falsi point of the bracket [lo, hi] (its middle if that falls outside)."""
    x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
    return x if lo < x < hi else 0.5 * (lo + hi)


@jit
def _illinois(lo: float, f_lo: float, hi: float, f_hi: float, side: int, x: float, f: float) -> tuple[float, float, float, float, int]:
    """Bracket [lo, hi] of an increasing function updated with the new point (x, f).

    The Illinois rule halves the value kept at an end that stays twice in a
    row, so regula falsi converges superlinearly from both sides.
    """
    if f < 0.0:
        if side == -1:
            f_hi *= 0.5
        return x, f, hi, f_hi, -1
    if side == 1:
        f_lo *= 0.5
    return lo, f_lo, x, f, 1


# Which circle-pair equation ``_offset_measure`` evaluates.
S_CASE = 1
C_CASE = 2


@jit
def shape_max_w(shape: int) -> float:
    """The largest sin²θ of the shape's family (1: any θ < π/2)."""
    if shape == NEAR_LINEAR:
        return 1.0 - NEAR_LINEAR_MIN_COS * NEAR_LINEAR_MIN_COS
    return 1.0


@jit
def _offset_measure(case: int, shape: int, w: float, a_hat: float) -> float:
    """The left-hand side of a circle pair's equation in w = sin²θ, increasing from 0.

    S: g1² + g2² − 1. C: Â·(g1² − 1) + g2² with Â = (r1 − r0)²/(r1 + r0)².
    """
    sin_t = math.sqrt(w)
    cos_t = math.sqrt(1.0 - w)
    e1, e2 = shape_offsets(shape, sin_t, cos_t)
    g1_squared_less_one = e1 * (2.0 + w * e1)
    if case == S_CASE:
        return w * (g1_squared_less_one + e2 * e2)
    return w * (a_hat * g1_squared_less_one + e2 * e2)


@jit
def _solve_offset(case: int, shape: int, target: float, a_hat: float) -> float:
    """w = sin²θ where ``_offset_measure`` reaches ``target`` > 0; NaN beyond the shape's range."""
    hi = shape_max_w(shape)
    f_hi = _offset_measure(case, shape, hi, a_hat) - target
    if not f_hi > 0.0:
        return NAN
    lo = 0.0
    f_lo = -target
    side = 0
    w = hi
    for _ in range(200):
        w = _secant(lo, f_lo, hi, f_hi)
        f = _offset_measure(case, shape, w, a_hat) - target
        if f == 0.0 or hi - lo <= 4e-16 * w:
            break
        lo, f_lo, hi, f_hi, side = _illinois(lo, f_lo, hi, f_hi, side, w, f)
    return w


# ---------------------------------------------------- Bézier evaluation
# One curve at many parameters (``spiral_cad.core.bezier``): numpy's
# operations in numpy's order, so the values are those of the array formulas
# bit for bit, but each in registers and written once. The loops vectorise;
# a million parameters take about a millisecond, so they run in the calling
# thread (starting threads would cost more than it saves).


@jit
def polynomial_values(coefficients: FloatArray, u: FloatArray, out: FloatArray) -> None:
    """``out[i, j]``: coordinate j of the polynomial at ``u[i]``, by Horner's rule.

    ``coefficients`` (k, d), lowest first, with k ≤ 4 (a cubic Bézier and its
    derivatives).
    """
    k = coefficients.shape[0]
    for j in range(out.shape[1]):
        c3 = coefficients[k - 1, j]
        c2 = coefficients[k - 2, j] if k > 1 else 0.0
        c1 = coefficients[k - 3, j] if k > 2 else 0.0
        c0 = coefficients[k - 4, j] if k > 3 else 0.0
        for i in range(u.shape[0]):
            t = u[i]
            acc = c3
            if k > 1:
                acc = acc * t + c2
            if k > 2:
                acc = acc * t + c1
            if k > 3:
                acc = acc * t + c0
            out[i, j] = acc


@jit
def plane_curvatures(first: FloatArray, second: FloatArray, scale: float, u: FloatArray, out: FloatArray) -> None:
    """``out[i]``: signed curvature (Q' × Q'')/|Q'|³ at ``u[i]`` of a plane curve, from
    the power coefficients of Q' (3, 2) and Q'' (2, 2) divided by ``scale``."""
    for i in range(u.shape[0]):
        t = u[i]
        t2 = t * t
        dx = first[2, 0] * t2 + first[1, 0] * t + first[0, 0]
        dy = first[2, 1] * t2 + first[1, 1] * t + first[0, 1]
        cross = dx * (second[1, 1] * t + second[0, 1]) - dy * (second[1, 0] * t + second[0, 0])
        speed2 = dx * dx + dy * dy
        out[i] = cross / (speed2 * math.sqrt(speed2) * scale)


KERNELS.seal()
