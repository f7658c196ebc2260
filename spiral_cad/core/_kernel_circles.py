"""The transitions between two circles: the C and S pairs (Theorems 4.2, 4.3) and the spiral from a circle
inside another (the nested case), every shape (the steps every row takes: ``spiral_cad.core._kernels``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ._kernel_spiral import (
    C_CASE,
    S_CASE,
    _illinois,
    _secant,
    _solve_offset,
)
from ._kernels import (
    BAD_RADIUS,
    CIRCLES_ENCLOSED,
    CIRCLES_OVERLAP,
    COINCIDENT,
    EQUAL_RADII,
    G2CBS,
    INF,
    NAN,
    NEAR_LINEAR,
    NEAR_LINEAR_MAX_THETA,
    NOT_FINITE,
    OK,
    OUTSIDE_NESTED_BAND,
    OUTSIDE_SHAPE,
    SIGN_MISMATCH,
    UNVERIFIED,
    VERIFY_TOL,
    WALTON_MEEK,
    angle,
    centre_offset,
    curvature_ratio,
    end_fits,
    end_residual,
    fail,
    finite,
    frame_scale,
    leg_factors,
    leg_offsets,
    norm,
    opposite_angle,
    opposite_fits,
    ordinary,
    spiral_in_world,
    start_fits,
    start_residual,
    store,
    to_world,
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


# ---------------------------------------------------- circle to circle


@row_jit
def _frame_vector(dx: float, dy: float, p: float, q: float) -> tuple[float, float]:
    """A vector along T where (dx, dy) = p·T + q·rot90(T), up to scale."""
    return p * dx + q * dy, p * dy - q * dx


@jit
def _frame_from_offset(dx: float, dy: float, p: float, q: float) -> tuple[float, float]:
    """Unit T with (dx, dy) = p·T + q·rot90(T) (up to scale)."""
    fx, fy = _frame_vector(dx, dy, p, q)
    return unit(fx, fy)


@row_jit
def _s_pair_w(eps: float, measure: float) -> float:
    """w = sin²θ of the 1996 S pair, a quadratic in w; eps = D/(r0 + r1) − 1 = measure − 1."""
    gamma = -729.0 * eps * (2.0 + eps)
    beta = 1458.0 * measure * measure - 1208.0
    alpha = 1104.0 - 729.0 * measure * measure
    return -2.0 * gamma / (beta + math.sqrt(beta * beta - 4.0 * alpha * gamma))


@row_jit
def _broken_back_cubic(a_hat: float, delta: float, one_minus_a: float) -> tuple[float, float, float, float]:
    """Coefficients (c0 … c3) of the broken-back C equation in w = sin²θ, scaled by B:

    f(w) = 9Â(1−w)(9−4w)² + w(13+12w)² − 729 D̂²(1−w)², with δ = D̂² − Â > 0,
    so f(0) = −729δ < 0 < f(1) = 625.
    """
    d2 = delta + a_hat
    return -729.0 * delta, 169.0 - 1377.0 * a_hat + 1458.0 * d2, 312.0 + 792.0 * a_hat - 729.0 * d2, 144.0 * one_minus_a


@row_jit
def _broken_back_step(
    c0: float, c1: float, c2: float, c3: float, w: float, lo: float, hi: float, done: bool
) -> tuple[float, float, float, bool]:
    """One safeguarded Halley step for the root of the C cubic in the bracket [lo, hi]:
    (w, lo, hi, done), left as it is once ``done`` (w the root found)."""
    f = ((c3 * w + c2) * w + c1) * w + c0
    below = f < 0.0
    lo_new = w if below else lo
    hi_new = hi if below else w
    df = (3.0 * c3 * w + 2.0 * c2) * w + c1
    ddf = 6.0 * c3 * w + 2.0 * c2
    den = 2.0 * df * df - f * ddf
    new = w - 2.0 * f * df / den if den != 0.0 else 0.5 * (lo_new + hi_new)  # Halley
    new = new if lo_new < new < hi_new else 0.5 * (lo_new + hi_new)
    root = f == 0.0  # w itself
    converged = abs(new - w) <= 1e-15 * new or new == w
    return (w if done or root else new), (lo if done else lo_new), (hi if done else hi_new), done or root or converged


#: Halley steps the vectorised C rows take; a row that needs more is solved by the general row.
FAST_HALLEY_STEPS = 6


@jit
def _broken_back_w(a_hat: float, delta: float, one_minus_a: float) -> float:
    """Root w = sin²θ in (0, 1) of the broken-back C cubic (~3 Halley steps from the secant guess)."""
    c0, c1, c2, c3 = _broken_back_cubic(a_hat, delta, one_minus_a)
    w, lo, hi, done = -c0 / (625.0 - c0), 0.0, 1.0, False
    for _ in range(100):
        w, lo, hi, done = _broken_back_step(c0, c1, c2, c3, w, lo, hi, done)
        if done:
            break
    return w


@row_jit
def _pair_gap(s_shape: bool, dist: float, a0: float, a1: float) -> tuple[float, float]:
    """(gap, D/gap): the centres must lie more than ``gap`` apart (r0 + r1 for an S,
    |r1 − r0| for a C)."""
    gap = a0 + a1 if s_shape else abs(a1 - a0)
    return gap, (dist / gap if gap > 0.0 else INF)


@row_jit
def _pair_spirals(
    dx: float,
    dy: float,
    tx: float,
    ty: float,
    a0: float,
    a1: float,
    sin_t: float,
    cos_t: float,
    shape: int,
    s_shape: bool,
    ox: float,
    oy: float,
    scale: float,
    flip: float,
) -> tuple[float, float, float, float, float, float, float, float, float, float, float, float, float, float]:
    """The C/S pair in world coordinates: Q1 = (s0, s1, s2, s3) and Q0 as built from
    their common start B0 = s0 = C1 − r1·g2·T − r1·g1·N, (s0, u1, u2, u3): Q1 turns
    left towards N, Q0 leaves along −T towards +N (C) or −N (S). Returns s0 … s3, u1 … u3."""
    alpha, beta, gamma = leg_factors(shape, cos_t)
    e1, e2 = leg_offsets(alpha, beta, gamma, cos_t)
    g1, g2 = centre_offset(sin_t, e1, e2)
    nx = -ty
    ny = tx
    bx = dx - a1 * (g2 * tx + g1 * nx)
    by = dy - a1 * (g2 * ty + g1 * ny)
    side0 = -1.0 if s_shape else 1.0
    s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y = spiral_in_world(
        bx, by, tx, ty, nx, ny, sin_t, cos_t, a1, alpha, beta, gamma, ox, oy, scale, flip
    )
    _, _, u1x, u1y, u2x, u2y, u3x, u3y = spiral_in_world(
        bx, by, -tx, -ty, side0 * nx, side0 * ny, sin_t, cos_t, a0, alpha, beta, gamma, ox, oy, scale, flip
    )
    return s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y


@row_jit
def _pair_frame(
    dx: float, dy: float, a0: float, a1: float, sin_t: float, cos_t: float, gap_p: float, gap_q: float, shape: int
) -> tuple[float, float]:
    """The vector along the common start tangent T: circle 1's centre lies at
    P·g2·T + Q·g1·rot90(T) from circle 0's (P, Q = ``gap_p``, ``gap_q``)."""
    alpha, beta, gamma = leg_factors(shape, cos_t)
    e1, e2 = leg_offsets(alpha, beta, gamma, cos_t)
    g1, g2 = centre_offset(sin_t, e1, e2)
    return _frame_vector(dx, dy, gap_p * g2, gap_q * g1)


@row_jit
def _pair_fits(
    s0x: float,
    s0y: float,
    s1x: float,
    s1y: float,
    s2x: float,
    s2y: float,
    s3x: float,
    s3y: float,
    u1x: float,
    u1y: float,
    u2x: float,
    u2y: float,
    u3x: float,
    u3y: float,
    wtx: float,
    wty: float,
    c0x: float,
    c0y: float,
    r0: float,
    c1x: float,
    c1y: float,
    r1: float,
    inv: float,
) -> bool:
    """Sufficient tests (``*_fits``) of the pair: Q0 leaves circle 0, Q1 reaches circle 1,
    both leave B0 = s0 along ∓T (world T = (wtx, wty)) with zero curvature, and
    their first legs are opposite there (each within the tolerance of T is not
    enough: the angle between them could be twice it)."""
    return (
        end_fits(u1x, u1y, u2x, u2y, u3x, u3y, c0x, c0y, -r0, inv) & end_fits(s1x, s1y, s2x, s2y, s3x, s3y, c1x, c1y, r1, inv)
        & start_fits(s0x, s0y, s1x, s1y, s2x, s2y, wtx, wty, inv) & start_fits(s0x, s0y, u1x, u1y, u2x, u2y, -wtx, -wty, inv)
        & opposite_fits((s1x - s0x) * inv, (s1y - s0y) * inv, (u1x - s0x) * inv, (u1y - s0y) * inv)
    )  # fmt: skip


@row_jit
def circle_to_circle_fast(
    c0x: float, c0y: float, r0: float, c1x: float, c1y: float, r1: float, shape: int
) -> tuple[bool, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float, float]:
    """``circle_to_circle_row`` in straight-line code for the ordinary row (see
    ``line_to_circle_fast``): finite input, radii within 1e-60 … 1e60, the 1996
    spiral, a C solved within ``FAST_HALLEY_STEPS``. Returns (ok, θ, measure,
    s0 … s3, u1 … u3)."""
    dx = c1x - c0x
    dy = c1y - c0y
    a0 = abs(r0)
    a1 = abs(r1)
    dist = norm(dx, dy)
    s_shape = (r0 > 0.0) != (r1 > 0.0)
    flip = 1.0 if r1 > 0.0 else -1.0
    dy = flip * dy
    gap, measure = _pair_gap(s_shape, dist, a0, a1)
    # Both cases are solved and one is taken (no branches: rows vectorise).
    w_s = _s_pair_w((dist - gap) / gap, measure)
    big = (a0 + a1) * (a0 + a1)
    c0, c1, c2, c3 = _broken_back_cubic(gap * gap / big, (dist - gap) * (dist + gap) / big, 4.0 * a0 * a1 / big)
    w, lo, hi, done = -c0 / (625.0 - c0), 0.0, 1.0, False
    for _ in range(FAST_HALLEY_STEPS):
        w, lo, hi, done = _broken_back_step(c0, c1, c2, c3, w, lo, hi, done)
    w = w_s if s_shape else w
    sin_t = math.sqrt(w)
    cos_t = math.sqrt(1.0 - w)
    fx, fy = _pair_frame(dx, dy, a0, a1, sin_t, cos_t, gap if s_shape else a0 + a1, gap if s_shape else a1 - a0, shape)
    tx, ty = unit_ordinary(fx, fy)
    s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y = _pair_spirals(
        dx, dy, tx, ty, a0, a1, sin_t, cos_t, shape, s_shape, c0x, c0y, 1.0, flip
    )
    ok = (
        math.isfinite(c0x) & math.isfinite(c0y) & math.isfinite(c1x) & math.isfinite(c1y) & math.isfinite(dist)
        & (r0 != 0.0) & (r1 != 0.0) & ordinary(max(a0, a1)) & (dist > gap) & (shape == WALTON_MEEK) & (s_shape or done)
        & ordinary(max(abs(fx), abs(fy)))
        & _pair_fits(s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y, tx, flip * ty,
                     c0x, c0y, r0, c1x, c1y, r1, 1.0)
    )  # fmt: skip
    return ok, angle(sin_t, cos_t), measure, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y


@jit
def circle_to_circle_general(
    c0x: float, c0y: float, r0: float, c1x: float, c1y: float, r1: float, shape: int, out: FloatArray, i: int
) -> Row:
    """``circle_to_circle_row`` for any row: checks, scaled frames, every shape."""
    if not finite(c0x, c0y, r0, c1x, c1y, r1):
        return fail(out, i, NOT_FINITE, NAN)
    if r0 == 0.0 or r1 == 0.0:
        return fail(out, i, BAD_RADIUS, NAN)
    if c0x == c1x and c0y == c1y:
        return fail(out, i, COINCIDENT, NAN)
    scale = frame_scale(max(abs(r0), abs(r1)))
    inv = 1.0 / scale
    dx = (c1x - c0x) * inv
    dy = (c1y - c0y) * inv
    a0 = abs(r0) * inv
    a1 = abs(r1) * inv
    dist = norm(dx, dy)
    if not (dist < INF):
        return fail(out, i, UNVERIFIED, INF)
    s_shape = (r0 > 0.0) != (r1 > 0.0)
    # Canonical frames: C with both counterclockwise, S with circle 1 counterclockwise.
    flip = 1.0 if r1 > 0.0 else -1.0
    dy = flip * dy
    gap, measure = _pair_gap(s_shape, dist, a0, a1)
    if not dist > gap:
        return fail(out, i, CIRCLES_OVERLAP if s_shape else CIRCLES_ENCLOSED, measure)
    if s_shape:
        eps = (dist - gap) / gap
        w = _s_pair_w(eps, measure) if shape == WALTON_MEEK else _solve_offset(S_CASE, shape, eps * (2.0 + eps), 0.0)
    else:
        big = (a0 + a1) * (a0 + a1)
        delta = (dist - gap) * (dist + gap) / big
        if shape == WALTON_MEEK:  # a cubic in w = sin²θ
            w = _broken_back_w(gap * gap / big, delta, 4.0 * a0 * a1 / big)
        else:
            w = _solve_offset(C_CASE, shape, delta, gap * gap / big)
    if shape != WALTON_MEEK and not w > 0.0:
        return fail(out, i, OUTSIDE_SHAPE, measure)
    sin_t = math.sqrt(w)
    cos_t = math.sqrt(1.0 - w)
    fx, fy = _pair_frame(dx, dy, a0, a1, sin_t, cos_t, gap if s_shape else a0 + a1, gap if s_shape else a1 - a0, shape)
    tx, ty = unit(fx, fy)
    s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y = _pair_spirals(
        dx, dy, tx, ty, a0, a1, sin_t, cos_t, shape, s_shape, c0x, c0y, scale, flip
    )
    wtx = tx
    wty = flip * ty
    if not _pair_fits(s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y, wtx, wty, c0x, c0y, r0, c1x, c1y, r1, inv):
        res = worst(
            end_residual(u1x, u1y, u2x, u2y, u3x, u3y, c0x, c0y, -r0, inv),
            end_residual(s1x, s1y, s2x, s2y, s3x, s3y, c1x, c1y, r1, inv),
        )
        res = worst(res, start_residual(s0x, s0y, s1x, s1y, s2x, s2y, wtx, wty, inv)[0])
        res = worst(res, start_residual(s0x, s0y, u1x, u1y, u2x, u2y, -wtx, -wty, inv)[0])
        ax, ay, bx, by = (s1x - s0x) * inv, (s1y - s0y) * inv, (u1x - s0x) * inv, (u1y - s0y) * inv
        res = worst(res, opposite_angle(ax, ay, norm(ax, ay), bx, by, norm(bx, by)))
        if not res <= VERIFY_TOL:
            return fail(out, i, UNVERIFIED, res)
    store(out, i, 0, u3x, u3y, u2x, u2y, u1x, u1y, s0x, s0y)
    store(out, i, 1, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y)
    return OK, angle(sin_t, cos_t), measure, NAN


@jit
def circle_to_circle_row(c0x: float, c0y: float, r0: float, c1x: float, c1y: float, r1: float, shape: int, out: FloatArray, i: int) -> Row:
    """Theorems 4.2/4.3: from circle 0 to circle 1, radii signed by travel sense.

    Same signs give a broken-back C, opposite signs an S; the pair is
    returned in travel order (circle 0 → B0 → circle 1).
    """
    row = circle_to_circle_fast(c0x, c0y, r0, c1x, c1y, r1, shape)
    if shape == WALTON_MEEK and row[0]:
        _, theta, measure, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y = row
        store(out, i, 0, u3x, u3y, u2x, u2y, u1x, u1y, s0x, s0y)
        store(out, i, 1, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y)
        return OK, theta, measure, NAN
    return circle_to_circle_general(c0x, c0y, r0, c1x, c1y, r1, shape, out, i)


# --------------------------------------------- circle inside circle


@jit
def shape_max_theta(shape: int) -> float:
    """The largest spiral angle of the shape's family (π/2, exclusive, for the κ'(1) = 0 members)."""
    return NEAR_LINEAR_MAX_THETA if shape == NEAR_LINEAR else math.pi / 2.0


@jit
def nested_band_lower(q: float, shape: int) -> float:
    """Infimum of D/(r0 − r1) for one spiral between nested circles, q = r1/r0.

    The distance between the centres falls as the spiral angle grows, so the
    band ends at the family's largest angle: for the 1996 spiral the limit
    θ → π/2 in closed form, (q^⅓ − q)·√(5/4 + q^−⅔)/(1 − q); for near-linear
    spirals the value at 50°.
    """
    if shape == WALTON_MEEK:
        c: float = q ** (1.0 / 3.0)  # a positive float to a float power (typeshed says Any)
        return (c - q) * math.sqrt(1.25 + 1.0 / (c * c)) / (1.0 - q)
    x, y = nested_center_offset(shape_max_theta(shape), 1.0, q, shape)[:2]
    return norm(x, y) / (1.0 - q)


@jit
def _nested_sigma(q: float, alpha: float, beta: float, gamma: float, sin_t: float, cos_t: float) -> float:
    """σ = 1 − t where κ(t) = q·κ(1): κ grows along the spiral, so an Illinois
    search on σ ∈ (0, 1) of q − κ(1 − σ)/κ(1) (increasing in σ)."""
    lo = 0.0
    f_lo = q - 1.0
    hi = 1.0
    f_hi = q
    side = 0
    sigma = 0.5
    for _ in range(200):
        sigma = _secant(lo, f_lo, hi, f_hi)
        f = q - curvature_ratio(sigma, alpha, beta, gamma, sin_t, cos_t)
        if f == 0.0 or hi - lo <= 2e-16 * sigma:
            break
        lo, f_lo, hi, f_hi, side = _illinois(lo, f_lo, hi, f_hi, side, sigma, f)
    return sigma


@jit
def nested_center_offset(
    theta: float, r0: float, r1: float, shape: int
) -> tuple[float, float, float, float, float, float, float, float, float, float, float]:
    """The fifth case for spiral angle θ: circle 1's centre relative to circle 0's.

    The spiral of ``shape`` turning by θ onto r1 meets the larger circle r0
    at u = t = 1 − σ (where κ(t) = 1/r0). Returns (x, y) in the frame (T, N)
    of the spiral's start, σ, sin θ, cos θ and the piece [t, 1] as control
    points relative to the spiral's end B3 (first three; the fourth is 0).
    The piece is de Casteljau's, each step written as Y + σ(X − Y) relative
    to B3 so that short pieces keep their digits.
    """
    sin_t = math.sin(theta)
    cos_t = math.cos(theta)
    alpha, beta, gamma = leg_factors(shape, cos_t)
    sigma = _nested_sigma(r1 / r0, alpha, beta, gamma, sin_t, cos_t)
    size = r1 * sin_t
    a = alpha * size
    b = beta * size
    c = gamma * size
    d2x = -c * cos_t  # B2 − B3
    d2y = -c * sin_t
    d1x = d2x - b  # B1 − B3
    d0x = d1x - a  # B0 − B3
    e0x = d1x + sigma * (d0x - d1x)
    e0y = d2y
    e1x = d2x + sigma * (d1x - d2x)
    e1y = d2y
    e2x = sigma * d2x
    e2y = sigma * d2y
    f0x = e1x + sigma * (e0x - e1x)
    f0y = e1y + sigma * (e0y - e1y)
    f1x = e2x + sigma * (e1x - e2x)
    f1y = e2y + sigma * (e1y - e2y)
    gx = f1x + sigma * (f0x - f1x)  # Q(t) − B3
    gy = f1y + sigma * (f0y - f1y)
    tx, ty = unit(f1x - f0x, f1y - f0y)  # tangent at t
    # C1 − C0 = (B3 + r1·N1) − (Q(t) + r0·N(t)), N = the left normal.
    x = -gx - r1 * sin_t + r0 * ty
    y = -gy + r1 * cos_t - r0 * tx
    return x, y, sigma, sin_t, cos_t, gx, gy, f1x, f1y, e2x, e2y


@jit
def _nested_canonical(
    dx: float, dy: float, r0: float, r1: float, shape: int
) -> tuple[int, float, float, float, float, float, float, float, float, float, float, float]:
    """Fifth case, r0 > r1 > 0: the spiral piece [t, 1] from Ω0 to Ω1.

    Solves |C1 − C0|(θ) = D by Illinois regula falsi on θ between 0 and the
    family's largest angle, where the distance falls from r0 − r1 to the
    band's lower end. Returns (status, θ, D/(r0 − r1), t) and the piece's
    control points relative to C0 (x0, y0, …, x3, y3).
    """
    dist = norm(dx, dy)
    ratio = dist / (r0 - r1)
    lower = nested_band_lower(r1 / r0, shape)
    if not (lower < ratio < 1.0):
        return OUTSIDE_NESTED_BAND, NAN, ratio, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    lo = 0.0
    hi = shape_max_theta(shape)
    f_lo = dist - (r0 - r1)  # dist − |C1 − C0|(θ), increasing in θ
    f_hi = dist - lower * (r0 - r1)
    theta = 0.5 * hi
    side = 0
    for _ in range(200):
        theta = _secant(lo, f_lo, hi, f_hi)
        x, y = nested_center_offset(theta, r0, r1, shape)[:2]
        f = dist - norm(x, y)
        if f == 0.0 or hi - lo <= 4e-16 * theta:
            break
        lo, f_lo, hi, f_hi, side = _illinois(lo, f_lo, hi, f_hi, side, theta, f)
    x, y, sigma, sin_t, cos_t, p0x, p0y, p1x, p1y, p2x, p2y = nested_center_offset(theta, r0, r1, shape)
    tx, ty = _frame_from_offset(dx, dy, x, y)
    # Relative to C1 = B3 + r1·N1 with N1 = (−sin θ, cos θ), then to world axes relative to C0.
    sx = r1 * sin_t
    sy = r1 * cos_t
    return (OK, theta, ratio, 1.0 - sigma,
            dx + (p0x + sx) * tx - (p0y - sy) * ty, dy + (p0x + sx) * ty + (p0y - sy) * tx,
            dx + (p1x + sx) * tx - (p1y - sy) * ty, dy + (p1x + sx) * ty + (p1y - sy) * tx,
            dx + (p2x + sx) * tx - (p2y - sy) * ty, dy + (p2x + sx) * ty + (p2y - sy) * tx,
            dx + (0.0 + sx) * tx - (0.0 - sy) * ty, dy + (0.0 + sx) * ty + (0.0 - sy) * tx)  # fmt: skip


@row_jit
def circle_in_circle_row(c0x: float, c0y: float, r0: float, c1x: float, c1y: float, r1: float, shape: int, out: FloatArray, i: int) -> Row:
    """Fifth case: one spiral from circle 0 to the nested circle 1 (or out of it).

    Radii are signed by travel sense and must share the sign.
    """
    if not finite(c0x, c0y, r0, c1x, c1y, r1):
        return fail(out, i, NOT_FINITE, NAN)
    if r0 == 0.0 or r1 == 0.0:
        return fail(out, i, BAD_RADIUS, NAN)
    if (r0 > 0.0) != (r1 > 0.0):
        return fail(out, i, SIGN_MISMATCH, NAN)
    if abs(r0) == abs(r1):
        return fail(out, i, EQUAL_RADII, NAN)
    if shape == G2CBS:
        return fail(out, i, OUTSIDE_SHAPE, NAN)
    inward = abs(r0) > abs(r1)
    # Outward travel is the reverse of inward travel with both senses flipped.
    big_r = r0 if inward else -r1
    small_r = r1 if inward else -r0
    ox = c0x if inward else c1x
    oy = c0y if inward else c1y
    scale = frame_scale(abs(big_r))
    inv = 1.0 / scale
    dx = ((c1x - c0x) if inward else (c0x - c1x)) * inv
    dy = ((c1y - c0y) if inward else (c0y - c1y)) * inv
    if not finite(dx, dy):
        return fail(out, i, UNVERIFIED, INF)
    flip = 1.0 if big_r > 0.0 else -1.0
    status, theta, ratio, t, x0, y0, x1, y1, x2, y2, x3, y3 = _nested_canonical(dx, flip * dy, abs(big_r) * inv, abs(small_r) * inv, shape)
    if status != OK:
        return fail(out, i, status, ratio)
    if not inward:
        x0, y0, x1, y1, x2, y2, x3, y3 = x3, y3, x2, y2, x1, y1, x0, y0
    x0, y0, x1, y1, x2, y2, x3, y3 = to_world(x0, y0, x1, y1, x2, y2, x3, y3, ox, oy, scale, flip)
    fits = end_fits(x2, y2, x1, y1, x0, y0, c0x, c0y, -r0, inv)
    if not (fits and end_fits(x1, y1, x2, y2, x3, y3, c1x, c1y, r1, inv)):
        res = worst(
            end_residual(x2, y2, x1, y1, x0, y0, c0x, c0y, -r0, inv),
            end_residual(x1, y1, x2, y2, x3, y3, c1x, c1y, r1, inv),
        )
        if not res <= VERIFY_TOL:
            return fail(out, i, UNVERIFIED, res)
    store(out, i, 0, x0, y0, x1, y1, x2, y2, x3, y3)
    return OK, theta, ratio, t


KERNELS.seal()
