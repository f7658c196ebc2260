"""The corner between two lines (Theorem 4.4 and the shapes' own pairs): the ordinary rows in straight-line
code, any row in scaled frames (the steps every row takes: ``spiral_cad.core._kernels``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ._kernels import (
    BAD_CURVATURE,
    COINCIDENT,
    CORNER_REVERSAL,
    CORNER_STRAIGHT,
    FIT,
    FIT2,
    INF,
    LEGS_TOO_SHORT,
    NAN,
    NOT_FINITE,
    OK,
    OUTSIDE_SHAPE,
    UNVERIFIED,
    VERIFY_TOL,
    angle,
    corner_relation,
    fail,
    finite,
    frame_scale,
    in_shape_domain,
    joint_residual,
    leg_factors,
    line_fits,
    line_residual,
    moderate,
    norm,
    ordinary,
    spiral_in_world,
    store,
    unit,
    unit_ordinary,
    worst,
)
from .jit import Kernels

if TYPE_CHECKING:  # annotations only
    from ._kernels import FloatArray, Row

KERNELS = Kernels(globals())
jit = KERNELS.jit
row_jit = KERNELS.row_jit


# -------------------------------------------------------- line to line


@row_jit
def joint_fits(
    ax1: float,
    ay1: float,
    ax2: float,
    ay2: float,
    ax3: float,
    ay3: float,
    bx1: float,
    by1: float,
    bx2: float,
    by2: float,
    bx3: float,
    by3: float,
    joint: float,
    inv: float,
) -> bool:
    """Sufficient for ``joint_residual`` ≤ VERIFY_TOL and for the first spiral's end
    curvature to be ``joint`` (a corner's check): with end legs u, v, κ = K/|u|³ and
    L = min(|u|, |v|, 1/|κa|): |b3a − b3b| ≤ tol·L, |u × v| ≤ tol·|u||v| with u·v < 0,
    |Ka·|v|³ + Kb·|u|³|·L ≤ tol·|u|³|v|³ and |(|Ka| − joint·|u|³)|·min(|u|·joint, 1) ≤
    tol·|u|³·joint. Two square roots and one division."""
    ux = (ax3 - ax2) * inv
    uy = (ay3 - ay2) * inv
    vx = (bx3 - bx2) * inv
    vy = (by3 - by2) * inv
    uu = ux * ux + uy * uy
    vv = vx * vx + vy * vy
    la = math.sqrt(uu)
    lb = math.sqrt(vv)
    ka = 2.0 / 3.0 * ((ax2 - ax1) * inv * uy - (ay2 - ay1) * inv * ux)  # κ·|u|³
    kb = 2.0 / 3.0 * ((bx2 - bx1) * inv * vy - (by2 - by1) * inv * vx)
    cube_a = uu * la
    cube_b = vv * lb
    length = min(min(la, lb), cube_a / abs(ka))
    gx = (ax3 - bx3) * inv
    gy = (ay3 - by3) * inv
    cross = ux * vy - uy * vx
    return (
        moderate(uu) & moderate(vv) & (ux * vx + uy * vy < 0.0)
        & (gx * gx + gy * gy <= FIT2 * (length * length))
        & (cross * cross <= FIT2 * (uu * vv))
        & (abs(ka * cube_b + kb * cube_a) * length <= FIT * (cube_a * cube_b))
        & (abs(abs(ka) - joint * cube_a) * min(la * joint, 1.0) <= FIT * cube_a * joint)
    )  # fmt: skip


@row_jit
def _corner_pair(
    px: float,
    py: float,
    t0x: float,
    t0y: float,
    t1x: float,
    t1y: float,
    a: float,
    sin_t: float,
    cos_t: float,
    side: float,
    shape: int,
    scale: float,
) -> tuple[float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float]:
    """Theorem 4.4's pair, its starts ``a`` before the corner p along each line: the
    joint curvature (normalised) and Q0 (from the first line) and Q1 (built from the
    second line, travelled backwards) in world coordinates."""
    alpha, beta, gamma = leg_factors(shape, cos_t)
    joint = corner_relation(shape, sin_t, cos_t, a)
    radius = 1.0 / joint
    x0, y0, x1, y1, x2, y2, x3, y3 = spiral_in_world(
        -a * t0x, -a * t0y, t0x, t0y, -side * t0y, side * t0x, sin_t, cos_t, radius, alpha, beta, gamma, px, py, scale, 1.0
    )
    v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = spiral_in_world(
        -a * t1x, -a * t1y, t1x, t1y, side * t1y, -side * t1x, sin_t, cos_t, radius, alpha, beta, gamma, px, py, scale, 1.0
    )
    return joint, x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y


@row_jit
def _corner_turn(t0x: float, t0y: float, bx: float, by: float) -> tuple[float, float, float]:
    """(cross, sin θ, cos θ) of the corner from the first leg's direction and the unit bisector."""
    cross = t0x * by - t0y * bx
    return cross, abs(cross), t0x * bx + t0y * by


@row_jit
def _corner_start(shape: int, sin_t: float, cos_t: float, shortest: float, curvature: float, scale: float) -> float:
    """How far before the corner the pair starts: the shorter leg (curvature NaN,
    Corollary 4.5) or K(θ)/κ."""
    return shortest if math.isnan(curvature) else corner_relation(shape, sin_t, cos_t, curvature * scale)


@row_jit
def line_to_line_fast(
    p0x: float, p0y: float, px: float, py: float, p1x: float, p1y: float, curvature: float, shape: int
) -> tuple[
    bool, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float
]:
    """``line_to_line_row`` in straight-line code for the ordinary row (see
    ``line_to_circle_fast``): legs and their difference of ordinary size, a turn
    inside the shape's range, legs long enough. Returns (ok, θ, measure, Q0, Q1 as built)."""
    ux = px - p0x
    uy = py - p0y
    vx = px - p1x
    vy = py - p1y
    l0 = norm(ux, uy)
    l1 = norm(vx, vy)
    t0x, t0y = unit_ordinary(ux, uy)
    t1x, t1y = unit_ordinary(vx, vy)
    bx, by = unit_ordinary(t0x - t1x, t0y - t1y)
    cross, sin_t, cos_t = _corner_turn(t0x, t0y, bx, by)
    side = 1.0 if cross > 0.0 else -1.0
    shortest = min(l0, l1)
    a = _corner_start(shape, sin_t, cos_t, shortest, curvature, 1.0)
    measure = a / shortest
    joint, x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = _corner_pair(
        px, py, t0x, t0y, t1x, t1y, a, sin_t, cos_t, side, shape, 1.0
    )
    ok = (
        math.isfinite(p0x) & math.isfinite(p0y) & math.isfinite(px) & math.isfinite(py) & math.isfinite(p1x)
        & math.isfinite(p1y) & (math.isnan(curvature) | ((curvature > 0.0) & (curvature < INF)))
        & ordinary(max(abs(ux), abs(uy))) & ordinary(max(abs(vx), abs(vy)))
        & ordinary(max(max(abs(ux), abs(uy)), max(abs(vx), abs(vy))))
        & ordinary(max(abs(t0x - t1x), abs(t0y - t1y))) & (sin_t > 0.0) & (cos_t > 0.0) & in_shape_domain(shape, cos_t)
        & (measure <= 1.0 + 1e-12)
        & line_fits(x0, y0, x1, y1, x2, y2, px, py, t0x, t0y, 1.0)
        & line_fits(v0x, v0y, v1x, v1y, v2x, v2y, px, py, t1x, t1y, 1.0)
        & joint_fits(x1, y1, x2, y2, x3, y3, v1x, v1y, v2x, v2y, v3x, v3y, joint, 1.0)
    )  # fmt: skip
    return ok, angle(sin_t, cos_t), measure, x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y


@jit
def pair_residual(
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    x2: float,
    y2: float,
    x3: float,
    y3: float,
    v0x: float,
    v0y: float,
    v1x: float,
    v1y: float,
    v2x: float,
    v2y: float,
    v3x: float,
    v3y: float,
    px: float,
    py: float,
    t0x: float,
    t0y: float,
    t1x: float,
    t1y: float,
    joint: float,
    inv: float,
) -> float:
    """How far a corner's spiral pair is from rounding it G2: the first spiral (x, y)
    must leave the line through corner p along unit t0, the second (v, read
    backwards from its end) the line through p along unit t1 (pointing at the
    corner); they must share the osculating circle where they meet, with
    curvature ``joint`` (magnitude, scaled by ``inv``)."""
    res = worst(
        line_residual(x0, y0, x1, y1, x2, y2, px, py, t0x, t0y, inv),
        line_residual(v0x, v0y, v1x, v1y, v2x, v2y, px, py, t1x, t1y, inv),
    )
    joint_res, kappa, leg = joint_residual(x1, y1, x2, y2, x3, y3, v1x, v1y, v2x, v2y, v3x, v3y, inv)
    res = worst(res, joint_res)
    return worst(res, abs(abs(kappa) - joint) * min(leg, 1.0 / joint))


@jit
def corner_residual(
    pair: FloatArray, px: float, py: float, t0x: float, t0y: float, t1x: float, t1y: float, joint: float, inv: float
) -> float:
    """``pair_residual`` of a pair stored in travel order, ``pair`` (2, 4, 2)."""
    a, b = pair[0], pair[1]
    return pair_residual(
        a[0, 0], a[0, 1], a[1, 0], a[1, 1], a[2, 0], a[2, 1], a[3, 0], a[3, 1],
        b[3, 0], b[3, 1], b[2, 0], b[2, 1], b[1, 0], b[1, 1], b[0, 0], b[0, 1],
        px, py, t0x, t0y, t1x, t1y, joint, inv,
    )  # fmt: skip


@jit
def line_to_line_general(
    p0x: float, p0y: float, px: float, py: float, p1x: float, p1y: float, curvature: float, shape: int, out: FloatArray, i: int
) -> Row:
    """``line_to_line_row`` for any row: checks, scaled frames, every shape."""
    if not finite(p0x, p0y, px, py, p1x, p1y):
        return fail(out, i, NOT_FINITE, NAN)
    if not (math.isnan(curvature) or (curvature > 0.0 and math.isfinite(curvature))):
        return fail(out, i, BAD_CURVATURE, NAN)
    if (p0x == px and p0y == py) or (p1x == px and p1y == py):
        return fail(out, i, COINCIDENT, NAN)
    ux = px - p0x
    uy = py - p0y
    vx = px - p1x
    vy = py - p1y
    if not finite(ux, uy, vx, vy):
        return fail(out, i, UNVERIFIED, INF)
    scale = frame_scale(max(max(abs(ux), abs(uy)), max(abs(vx), abs(vy))))
    inv = 1.0 / scale
    ux *= inv
    uy *= inv
    vx *= inv
    vy *= inv
    l0 = norm(ux, uy)
    l1 = norm(vx, vy)
    t0x, t0y = unit(ux, uy)
    t1x, t1y = unit(vx, vy)
    bx, by = unit(t0x - t1x, t0y - t1y)
    if bx == 0.0 and by == 0.0:
        return fail(out, i, CORNER_REVERSAL, NAN)
    cross, sin_t, cos_t = _corner_turn(t0x, t0y, bx, by)
    if sin_t == 0.0:
        return fail(out, i, CORNER_STRAIGHT, NAN)
    if not cos_t > 0.0:
        return fail(out, i, CORNER_REVERSAL, NAN)
    if not in_shape_domain(shape, cos_t):
        return fail(out, i, OUTSIDE_SHAPE, angle(sin_t, cos_t))
    side = 1.0 if cross > 0.0 else -1.0
    shortest = min(l0, l1)
    a = _corner_start(shape, sin_t, cos_t, shortest, curvature, scale)
    measure = a / shortest
    if not measure <= 1.0 + 1e-12:
        return fail(out, i, LEGS_TOO_SHORT, measure)
    joint, x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = _corner_pair(
        px, py, t0x, t0y, t1x, t1y, a, sin_t, cos_t, side, shape, scale
    )
    fits = line_fits(x0, y0, x1, y1, x2, y2, px, py, t0x, t0y, inv)
    fits = fits and line_fits(v0x, v0y, v1x, v1y, v2x, v2y, px, py, t1x, t1y, inv)
    if not (fits and joint_fits(x1, y1, x2, y2, x3, y3, v1x, v1y, v2x, v2y, v3x, v3y, joint, inv)):
        res = pair_residual(x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y, px, py, t0x, t0y, t1x, t1y, joint, inv)
        if not res <= VERIFY_TOL:
            return fail(out, i, UNVERIFIED, res)
    store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
    store(out, i, 1, v3x, v3y, v2x, v2y, v1x, v1y, v0x, v0y)
    return OK, angle(sin_t, cos_t), measure, NAN


@jit
def line_to_line_row(
    p0x: float, p0y: float, px: float, py: float, p1x: float, p1y: float, curvature: float, shape: int, out: FloatArray, i: int
) -> Row:
    """Theorem 4.4: two spirals from line p0→p to line p→p1.

    ``curvature`` > 0 is the joint curvature magnitude; NaN applies Corollary
    4.5 (the larger spiral pair that fits the shorter leg).

    Verification: the first spiral must leave the line through corner p along
    t0, the second (read backwards) the line through p along t1 (pointing at
    the corner); they must share the osculating circle where they meet, with
    the joint curvature.
    """
    row = line_to_line_fast(p0x, p0y, px, py, p1x, p1y, curvature, shape)
    if row[0]:
        _, theta, measure, x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = row
        store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
        store(out, i, 1, v3x, v3y, v2x, v2y, v1x, v1y, v0x, v0y)
        return OK, theta, measure, NAN
    return line_to_line_general(p0x, p0y, px, py, p1x, p1y, curvature, shape, out, i)


KERNELS.seal()
