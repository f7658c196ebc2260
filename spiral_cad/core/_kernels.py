"""Compiled kernels: every formula of the spiral and of its five transitions, once.

Each ``*_row`` function solves one problem from plain floats and writes the
control points into ``out`` (shape ``(k, 4, 2)``); it returns
``(status, theta, measure, extra)``.  ``status`` is one of the codes below,
``measure`` is the number that decides feasibility (reported in errors; for
``UNVERIFIED`` the residual that failed) and ``extra`` is case specific (the
contact parameter ``t`` of the nested case). The batch kernels loop over
rows; the scalar API calls the row functions.

Every row works in the same steps:

1. check its inputs (finite, non-zero directions and radii);
2. move to a normalised frame: translated to one input point and scaled by a
   power of two near the problem's natural length, so inputs of magnitude
   1e-300 … 1e300 behave like 1 and the scaling itself is exact;
3. apply the theorem for the canonical left-turning case (a mirrored frame
   when the configuration turns right);
4. map the control points back to world coordinates;
5. verify what is returned: every contact and joint, measured from the world
   control points, must hold to ``VERIFY_TOL`` (relative), else the row
   fails with ``UNVERIFIED`` and the residual as its measure. Non-finite or
   coinciding control points count as an infinite residual.

Kernels use numpy's floating-point error model: a division by zero gives
inf/NaN (caught by step 5) instead of raising, so no input can make a batch
raise.
"""

from __future__ import annotations

import math

from numba import njit, prange

from .errors import Status


def _compile(parallel: bool = False):
    """``njit`` with an on-disk cache where one can be written, else per process.

    Numba refuses to decorate a cached function when it finds no writable
    cache location (a read-only install without a writable home): then the
    kernels compile in memory at first use instead.
    """

    def wrap(function):
        options = dict(nogil=True, error_model="numpy", parallel=parallel)
        try:
            return njit(cache=True, **options)(function)
        except RuntimeError:
            return njit(cache=False, **options)(function)

    return wrap


jit = _compile()

# Row status codes as compile-time ints (meanings: ``errors.Status``).
OK = int(Status.OK)
NOT_FINITE = int(Status.NOT_FINITE)
ZERO_DIRECTION = int(Status.ZERO_DIRECTION)
BAD_RADIUS = int(Status.BAD_RADIUS)
COINCIDENT = int(Status.COINCIDENT)
SIGN_MISMATCH = int(Status.SIGN_MISMATCH)
CIRCLE_MEETS_LINE = int(Status.CIRCLE_MEETS_LINE)
CIRCLES_ENCLOSED = int(Status.CIRCLES_ENCLOSED)
CIRCLES_OVERLAP = int(Status.CIRCLES_OVERLAP)
CORNER_STRAIGHT = int(Status.CORNER_STRAIGHT)
CORNER_REVERSAL = int(Status.CORNER_REVERSAL)
LEGS_TOO_SHORT = int(Status.LEGS_TOO_SHORT)
OUTSIDE_NESTED_BAND = int(Status.OUTSIDE_NESTED_BAND)
EQUAL_RADII = int(Status.EQUAL_RADII)
UNVERIFIED = int(Status.UNVERIFIED)
BAD_CURVATURE = int(Status.BAD_CURVATURE)
BAD_ANGLE = int(Status.BAD_ANGLE)

#: What is returned must reproduce its contacts and joints to this accuracy:
#: gap / L, tangent angle (radians) and curvature error × L, with L the
#: smaller of the spiral's leg at that end and the radius there; the accuracy
#: achieved on well-conditioned input is ~1e-15.
VERIFY_TOL = 1e-9

NAN = math.nan
INF = math.inf


# ---------------------------------------------------------------- shape


@jit
def shape_g1(sin_t, cos_t):
    """g1(θ) = (5/9) tan θ sin θ + cos θ = (5 + 4cos²θ) / (9 cos θ), for θ ≥ 0."""
    return (5.0 + 4.0 * cos_t * cos_t) / (9.0 * cos_t)


@jit
def shape_g2(sin_t, cos_t):
    """g2(θ) = 25 tan θ / (27 cos θ) − (4/9) sin θ, for θ ≥ 0."""
    return sin_t * (25.0 - 12.0 * cos_t * cos_t) / (27.0 * cos_t * cos_t)


@jit
def spiral_legs(sin_t, cos_t, radius):
    """Leg lengths (g, h) of Theorem 3.1 for |θ| and end radius 1/|c|."""
    g = 25.0 * sin_t * radius / (54.0 * cos_t * cos_t)
    h = 5.0 * sin_t * radius / (9.0 * cos_t)
    return g, h


#: Theorem 4.4: a = (40/27)·tan θ/(c cos θ) between corner distance a and joint curvature c.
WALTON_MEEK_CORNER = 40.0 / 27.0


@jit
def corner_relation(sin_t, cos_t, value, factor):
    """factor·sin θ/(value·cos² θ): a spiral pair's corner distance from its joint
    curvature, or the curvature from the distance (the relation is symmetric)."""
    return factor * sin_t / (value * cos_t * cos_t)


@jit
def put_spiral(out, bx, by, tx, ty, nx, ny, sin_t, cos_t, radius):
    """Write the Theorem 3.1 control points into ``out`` (4, 2).

    Starts at (bx, by) along unit (tx, ty) and turns by |θ| towards the unit
    normal (nx, ny), reaching radius ``radius`` at the end.
    """
    g, h = spiral_legs(sin_t, cos_t, radius)
    out[0, 0] = bx
    out[0, 1] = by
    out[1, 0] = bx + g * tx
    out[1, 1] = by + g * ty
    out[2, 0] = bx + 2.0 * g * tx
    out[2, 1] = by + 2.0 * g * ty
    out[3, 0] = out[2, 0] + h * (cos_t * tx + sin_t * nx)
    out[3, 1] = out[2, 1] + h * (cos_t * ty + sin_t * ny)


@jit
def spiral_curvature_ratio(u, cos_t):
    """κ(u)/c of the Theorem 3.1 spiral (the paper's closed form)."""
    c2 = cos_t * cos_t
    u2 = u * u
    base = 25.0 + 10.0 * u2 * (6.0 * c2 - 5.0) + u2 * u2 * (25.0 - 24.0 * c2)
    return 216.0 * u * c2 * cos_t / base**1.5


# ------------------------------------------------- frames and numbers


@jit
def norm(x, y):
    """√(x² + y²) for values of moderate size (normalised frames; ``math.hypot`` is slower)."""
    return math.sqrt(x * x + y * y)


@jit
def power_of_two_near(x):
    """A power of two within a factor 2 of ``x`` > 0: scaling by it is exact."""
    return math.ldexp(1.0, math.frexp(x)[1] - 1)


@jit
def frame_scale(length):
    """The normalising scale for a problem of natural size ``length`` > 0.

    Any power of two scales exactly; 1 is used where squares and cubes of
    lengths cannot overflow or underflow (1e-60 … 1e60), so ordinary inputs
    are solved without any rescaling at all.
    """
    if 1e-60 < length < 1e60:
        return 1.0
    return power_of_two_near(length)


@jit
def unit(x, y):
    """(x, y) / |(x, y)| without overflow or underflow; (0, 0) for a zero or non-finite vector."""
    big = max(abs(x), abs(y))
    if not (big > 0.0 and big < INF):
        return 0.0, 0.0
    if not 1e-60 < big < 1e60:
        s = power_of_two_near(big)
        x /= s
        y /= s
    n = norm(x, y)
    return x / n, y / n


@jit
def finite(*values):
    for v in values:
        if not math.isfinite(v):
            return False
    return True


@jit
def worst(a, b):
    """max(a, b), with NaN counted as infinitely bad."""
    if a != a or b != b:
        return INF
    return a if a > b else b


@jit
def reverse_in_place(cp):
    """Reverse the order of the four control points ``cp``."""
    for j in range(2):
        a, b = cp[0, j], cp[1, j]
        cp[0, j], cp[1, j] = cp[3, j], cp[2, j]
        cp[3, j], cp[2, j] = a, b


@jit
def place(out, ox, oy, scale, flip):
    """Map normalised points (x, flip·y) back to world coordinates o + scale·(x, flip·y)."""
    for i in range(out.shape[0]):
        for k in range(4):
            out[i, k, 0] = ox + scale * out[i, k, 0]
            out[i, k, 1] = oy + scale * flip * out[i, k, 1]


@jit
def fill_nan(out):
    for i in range(out.shape[0]):
        for k in range(4):
            out[i, k, 0] = NAN
            out[i, k, 1] = NAN


# ------------------------------------------- verification (world coordinates)
# A contact or joint is measured like a chain's joint: gap / L, tangent angle
# (radians) and curvature error × L, where L is the smaller of the spiral's
# leg at that end and the radius there (so the curvature error is relative
# to max(|κ|, 1/leg), as in the G2 checker); the residual is the largest. Differences of world
# control points are multiplied by ``inv`` (a power of two, 1/scale of the
# row) before they are squared, so nothing overflows or underflows; the
# residuals are relative and do not depend on ``inv``.


@jit
def _end_frame(cp, inv):
    """At u = 1 of Bézier ``cp``: unit tangent, scaled signed curvature and the
    scaled length of the last leg (NaN where the end is degenerate)."""
    ax = (cp[2, 0] - cp[1, 0]) * inv
    ay = (cp[2, 1] - cp[1, 1]) * inv
    bx = (cp[3, 0] - cp[2, 0]) * inv
    by = (cp[3, 1] - cp[2, 1]) * inv
    lb = norm(bx, by)
    if not lb > 0.0:
        return NAN, NAN, NAN, NAN
    return bx / lb, by / lb, 2.0 / 3.0 * (ax * by - ay * bx) / (lb * lb * lb), lb


@jit
def end_residual(cp, cx, cy, radius, inv):
    """How far the end of Bézier ``cp`` is from joining circle (c, radius) G2.

    ``radius`` is signed by the travel sense of ``cp`` (positive:
    counterclockwise): the end must lie on the circle, run along it in that
    sense and have curvature 1/radius.
    """
    tx, ty, kappa, leg = _end_frame(cp, inv)
    ox = (cp[3, 0] - cx) * inv
    oy = (cp[3, 1] - cy) * inv
    scaled = radius * inv
    # (dx, dy) is the radial direction times the travel sense, so the tangent
    # must be rot90 of it in either sense.
    dx = ox / scaled
    dy = oy / scaled
    distance = norm(dx, dy)
    length = min(leg, abs(scaled))  # the smaller feature sets the scale
    gap = abs(distance - 1.0) * abs(scaled) / length
    angle = abs(tx * dx + ty * dy) / distance + (INF if dx * ty - dy * tx <= 0.0 else 0.0)
    return worst(worst(gap, angle), abs(kappa - 1.0 / scaled) * length)


@jit
def line_residual(cp, px, py, tx, ty, inv):
    """How far the start of spiral ``cp`` is from leaving the line through p along
    unit t with zero curvature (gap, tangent angle, κ(0) × first leg)."""
    ax = (cp[1, 0] - cp[0, 0]) * inv
    ay = (cp[1, 1] - cp[0, 1]) * inv
    bx = (cp[2, 0] - cp[1, 0]) * inv
    by = (cp[2, 1] - cp[1, 1]) * inv
    la = norm(ax, ay)
    if not (la > 0.0 and tx * ax + ty * ay > 0.0):
        return INF
    distance = abs(tx * (cp[0, 1] - py) * inv - ty * (cp[0, 0] - px) * inv) / la
    angle = abs(tx * ay - ty * ax) / la
    kappa0 = abs(2.0 / 3.0 * (ax * by - ay * bx) / (la * la))  # κ(0) × first leg
    return worst(worst(distance, angle), kappa0)


@jit
def joint_residual(cp_a, cp_b, inv):
    """How far two spirals that meet at their ends (u = 1 of both, travelled
    towards each other) are from a G2 joint: gap, tangent angle, curvature jump × leg."""
    tax, tay, ka, la = _end_frame(cp_a, inv)
    tbx, tby, kb, lb = _end_frame(cp_b, inv)
    length = min(min(la, lb), 1.0 / abs(ka))
    gap = norm((cp_a[3, 0] - cp_b[3, 0]) * inv, (cp_a[3, 1] - cp_b[3, 1]) * inv) / length
    # Travelling towards each other, the tangents are opposite and so are the signed curvatures.
    angle = abs(tax * tby - tay * tbx) + (INF if tax * tbx + tay * tby >= 0.0 else 0.0)
    return worst(worst(gap, angle), abs(ka + kb) * length)


# ---------------------------------------------------------- one spiral


@jit
def spiral_row(bx, by, dx, dy, theta, curvature, out):
    """Theorem 3.1: the spiral from (bx, by) along d turning by θ to curvature c."""
    if not finite(bx, by, dx, dy, theta, curvature):
        return NOT_FINITE, NAN, NAN, NAN
    tx, ty = unit(dx, dy)
    if tx == 0.0 and ty == 0.0:
        return ZERO_DIRECTION, NAN, NAN, NAN
    if not 0.0 < abs(theta) < math.pi / 2.0:
        return BAD_ANGLE, NAN, NAN, NAN
    if curvature == 0.0 or (curvature > 0.0) != (theta > 0.0):
        return BAD_CURVATURE, NAN, NAN, NAN
    side = 1.0 if theta > 0.0 else -1.0
    sin_t = math.sin(abs(theta))
    cos_t = math.cos(theta)
    radius = 1.0 / abs(curvature)
    # The legs set the scale: the spiral's own size, not its end radius.
    g = spiral_legs(sin_t, cos_t, radius)[0]
    if not (g > 0.0 and g < INF):
        return UNVERIFIED, NAN, INF, NAN
    scale = frame_scale(g)
    inv = 1.0 / scale
    nx = -side * ty
    ny = side * tx
    local_radius = radius * inv
    put_spiral(out[0], 0.0, 0.0, tx, ty, nx, ny, sin_t, cos_t, local_radius)
    place(out, bx, by, scale, 1.0)
    # The end circle's centre B0 + r·(g2·T + g1·N) (MATH.md §1).
    g1 = shape_g1(sin_t, cos_t) * local_radius
    g2 = shape_g2(sin_t, cos_t) * local_radius
    cx = bx + scale * (g2 * tx + g1 * nx)
    cy = by + scale * (g2 * ty + g1 * ny)
    res = worst(line_residual(out[0], bx, by, tx, ty, inv), end_residual(out[0], cx, cy, side * radius, inv))
    if not res <= VERIFY_TOL:
        return UNVERIFIED, NAN, res, NAN
    return OK, theta, NAN, NAN


@jit
def unit_spirals_batch(sin_t, cos_t, out):
    """Theorem 3.1 spirals from the origin along +x, turning left by θ to end radius 1 (one per row)."""
    for i in range(sin_t.shape[0]):
        put_spiral(out[i], 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, sin_t[i], cos_t[i], 1.0)


# ------------------------------------------------------ line to circle


@jit
def line_to_circle_row(px, py, dx, dy, cx, cy, r, out):
    """Theorem 4.1: spiral from the directed line (p, d) to circle (c, r > 0).

    ``extra`` is the turn side: +1 left, −1 right.
    """
    if not finite(px, py, dx, dy, cx, cy, r):
        return NOT_FINITE, NAN, NAN, NAN
    tx, ty = unit(dx, dy)
    if tx == 0.0 and ty == 0.0:
        return ZERO_DIRECTION, NAN, NAN, NAN
    if not r > 0.0:
        return BAD_RADIUS, NAN, NAN, NAN
    scale = frame_scale(r)
    inv = 1.0 / scale
    rs = r * inv
    vx = (cx - px) * inv
    vy = (cy - py) * inv
    if not finite(vx, vy):
        return UNVERIFIED, NAN, INF, NAN
    d = tx * vy - ty * vx
    side = 1.0 if d > 0.0 else -1.0
    measure = abs(d) / rs
    if not abs(d) > rs:
        return CIRCLE_MEETS_LINE, NAN, measure, NAN
    # cos θ = 10 / (9ρ + √(81ρ² − 80)), with 1 − cos θ formed without cancellation.
    eps = (abs(d) - rs) / rs
    z = 81.0 * eps * (2.0 + eps)
    s = math.sqrt(1.0 + z)
    den = 9.0 * measure + s
    cos_t = 10.0 / den
    sin_t = math.sqrt((9.0 * eps + z / (s + 1.0)) / den * (1.0 + cos_t))
    a = vx * tx + vy * ty - rs * shape_g2(sin_t, cos_t)
    put_spiral(out[0], a * tx, a * ty, tx, ty, -side * ty, side * tx, sin_t, cos_t, rs)
    place(out, px, py, scale, 1.0)
    res = worst(line_residual(out[0], px, py, tx, ty, inv), end_residual(out[0], cx, cy, side * r, inv))
    if not res <= VERIFY_TOL:
        return UNVERIFIED, NAN, res, NAN
    return OK, math.atan2(sin_t, cos_t), measure, side


# ---------------------------------------------------- circle to circle


@jit
def _frame_from_offset(dx, dy, p, q):
    """Unit T with (dx, dy) = p·T + q·rot90(T) (up to scale)."""
    return unit(p * dx + q * dy, p * dy - q * dx)


@jit
def _broken_back_w(a_hat, delta, one_minus_a):
    """Root w = sin²θ in (0, 1) of the broken-back C equation, scaled by B.

    f(w) = 9Â(1−w)(9−4w)² + w(13+12w)² − 729 D̂²(1−w)², with δ = D̂² − Â > 0.
    Safeguarded Halley iteration (~3 steps) on the bracket f(0) = −729δ < 0 < f(1) = 625.
    """
    d2 = delta + a_hat
    c0 = -729.0 * delta
    c1 = 169.0 - 1377.0 * a_hat + 1458.0 * d2
    c2 = 312.0 + 792.0 * a_hat - 729.0 * d2
    c3 = 144.0 * one_minus_a
    lo = 0.0
    hi = 1.0
    w = -c0 / (625.0 - c0)
    for _ in range(100):
        f = ((c3 * w + c2) * w + c1) * w + c0
        if f == 0.0:
            return w
        if f < 0.0:
            lo = w
        else:
            hi = w
        df = (3.0 * c3 * w + 2.0 * c2) * w + c1
        ddf = 6.0 * c3 * w + 2.0 * c2
        den = 2.0 * df * df - f * ddf
        new = w - 2.0 * f * df / den if den != 0.0 else 0.5 * (lo + hi)  # Halley
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - w) <= 1e-15 * new or new == w:
            return new
        w = new
    return w


@jit
def _two_spirals(out, ox, oy, tx, ty, r0, r1, sin_t, cos_t, s_shape):
    """Write Q0 (reversed) and Q1 leaving their common start of the C/S pair.

    (ox, oy) is circle 1's centre relative to circle 0's; the common start is
    B0 = C1 − r1·g2·T − r1·g1·N.  Q1 turns left towards N; Q0 leaves along −T
    and turns towards +N (C) or −N (S).
    """
    nx = -ty
    ny = tx
    g1 = shape_g1(sin_t, cos_t)
    g2 = shape_g2(sin_t, cos_t)
    bx = ox - r1 * (g2 * tx + g1 * nx)
    by = oy - r1 * (g2 * ty + g1 * ny)
    side0 = -1.0 if s_shape else 1.0
    put_spiral(out[1], bx, by, tx, ty, nx, ny, sin_t, cos_t, r1)
    put_spiral(out[0], bx, by, -tx, -ty, side0 * nx, side0 * ny, sin_t, cos_t, r0)
    reverse_in_place(out[0])


@jit
def circle_to_circle_row(c0x, c0y, r0, c1x, c1y, r1, out):
    """Theorems 4.2/4.3: from circle 0 to circle 1, radii signed by travel sense.

    Same signs give a broken-back C, opposite signs an S.
    """
    if not finite(c0x, c0y, r0, c1x, c1y, r1):
        return NOT_FINITE, NAN, NAN, NAN
    if r0 == 0.0 or r1 == 0.0:
        return BAD_RADIUS, NAN, NAN, NAN
    if c0x == c1x and c0y == c1y:
        return COINCIDENT, NAN, NAN, NAN
    scale = frame_scale(max(abs(r0), abs(r1)))
    inv = 1.0 / scale
    dx = (c1x - c0x) * inv
    dy = (c1y - c0y) * inv
    a0 = abs(r0) * inv
    a1 = abs(r1) * inv
    dist = norm(dx, dy)
    if not (dist < INF):
        return UNVERIFIED, NAN, INF, NAN
    s_shape = (r0 > 0.0) != (r1 > 0.0)
    # Canonical frames: C with both counterclockwise, S with circle 1 counterclockwise.
    flip = 1.0 if r1 > 0.0 else -1.0
    dy = flip * dy
    if s_shape:
        gap = a0 + a1
        measure = dist / gap
        if not dist > gap:
            return CIRCLES_OVERLAP, NAN, measure, NAN
        eps = (dist - gap) / gap
        gamma = -729.0 * eps * (2.0 + eps)
        beta = 1458.0 * measure * measure - 1208.0
        alpha = 1104.0 - 729.0 * measure * measure
        w = -2.0 * gamma / (beta + math.sqrt(beta * beta - 4.0 * alpha * gamma))
        sin_t = math.sqrt(w)
        cos_t = math.sqrt(1.0 - w)
        p = gap * shape_g2(sin_t, cos_t)
        q = gap * shape_g1(sin_t, cos_t)
    else:
        gap = abs(a1 - a0)
        measure = dist / gap if gap > 0.0 else INF
        if not dist > gap:
            return CIRCLES_ENCLOSED, NAN, measure, NAN
        big = (a0 + a1) * (a0 + a1)
        delta = (dist - gap) * (dist + gap) / big
        w = _broken_back_w(gap * gap / big, delta, 4.0 * a0 * a1 / big)
        sin_t = math.sqrt(w)
        cos_t = math.sqrt(1.0 - w)
        p = (a0 + a1) * shape_g2(sin_t, cos_t)
        q = (a1 - a0) * shape_g1(sin_t, cos_t)
    tx, ty = _frame_from_offset(dx, dy, p, q)
    _two_spirals(out, dx, dy, tx, ty, a0, a1, sin_t, cos_t, s_shape)
    place(out, c0x, c0y, scale, flip)
    # In world coordinates: Q0 leaves circle 0, Q1 reaches circle 1, and both
    # leave their common start B0 along ∓T with zero curvature.
    wtx = tx
    wty = flip * ty
    res = worst(end_residual(out[0, ::-1], c0x, c0y, -r0, inv), end_residual(out[1], c1x, c1y, r1, inv))
    res = worst(res, line_residual(out[1], out[1, 0, 0], out[1, 0, 1], wtx, wty, inv))
    res = worst(res, line_residual(out[0, ::-1], out[1, 0, 0], out[1, 0, 1], -wtx, -wty, inv))
    if not res <= VERIFY_TOL:
        return UNVERIFIED, NAN, res, NAN
    return OK, math.atan2(sin_t, cos_t), measure, NAN


# -------------------------------------------------------- line to line


@jit
def corner_residual(out, px, py, t0x, t0y, t1x, t1y, joint_curvature, inv):
    """Verification of a corner's spiral pair ``out`` (2, 4, 2) in travel order.

    The first spiral must leave the line through corner p along t0, the second
    (read backwards) the line through p along t1 (pointing at the corner);
    they must share the osculating circle where they meet, with curvature
    ``joint_curvature`` (magnitude, scaled by ``inv``).
    """
    second = out[1, ::-1]
    res = worst(line_residual(out[0], px, py, t0x, t0y, inv), line_residual(second, px, py, t1x, t1y, inv))
    res = worst(res, joint_residual(out[0], second, inv))
    _, _, kappa, leg = _end_frame(out[0], inv)
    return worst(res, abs(abs(kappa) - joint_curvature) * min(leg, 1.0 / joint_curvature))


@jit
def line_to_line_row(p0x, p0y, px, py, p1x, p1y, curvature, out):
    """Theorem 4.4: two spirals from line p0→p to line p→p1.

    ``curvature`` > 0 is the joint curvature magnitude; NaN applies Corollary
    4.5 (the larger spiral pair that fits the shorter leg).
    """
    if not finite(p0x, p0y, px, py, p1x, p1y):
        return NOT_FINITE, NAN, NAN, NAN
    if not (math.isnan(curvature) or (curvature > 0.0 and math.isfinite(curvature))):
        return BAD_CURVATURE, NAN, NAN, NAN
    if (p0x == px and p0y == py) or (p1x == px and p1y == py):
        return COINCIDENT, NAN, NAN, NAN
    ux = px - p0x
    uy = py - p0y
    vx = px - p1x
    vy = py - p1y
    if not finite(ux, uy, vx, vy):
        return UNVERIFIED, NAN, INF, NAN
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
        return CORNER_REVERSAL, math.pi / 2.0, NAN, NAN
    cross = t0x * by - t0y * bx
    sin_t = abs(cross)
    cos_t = t0x * bx + t0y * by
    if sin_t == 0.0:
        return CORNER_STRAIGHT, 0.0, NAN, NAN
    if not cos_t > 0.0:
        return CORNER_REVERSAL, math.pi / 2.0, NAN, NAN
    side = 1.0 if cross > 0.0 else -1.0
    shortest = min(l0, l1)
    if math.isnan(curvature):
        a = shortest
    else:
        a = corner_relation(sin_t, cos_t, curvature * scale, WALTON_MEEK_CORNER)
    measure = a / shortest
    if not measure <= 1.0 + 1e-12:
        return LEGS_TOO_SHORT, math.atan2(sin_t, cos_t), measure, NAN
    joint = corner_relation(sin_t, cos_t, a, WALTON_MEEK_CORNER)
    radius = 1.0 / joint
    put_spiral(out[0], -a * t0x, -a * t0y, t0x, t0y, -side * t0y, side * t0x, sin_t, cos_t, radius)
    put_spiral(out[1], -a * t1x, -a * t1y, t1x, t1y, side * t1y, -side * t1x, sin_t, cos_t, radius)
    reverse_in_place(out[1])
    place(out, px, py, scale, 1.0)
    res = corner_residual(out, px, py, t0x, t0y, t1x, t1y, joint, inv)
    if not res <= VERIFY_TOL:
        return UNVERIFIED, NAN, res, NAN
    return OK, math.atan2(sin_t, cos_t), measure, NAN


# --------------------------------------------- circle inside circle


@jit
def nested_band_lower(q):
    """Infimum of D/(r0 − r1) for one spiral between nested circles, q = r1/r0.

    The limit θ → π/2 of the fifth case: (q^⅓ − q)·√(5/4 + q^−⅔)/(1 − q).
    """
    c = q ** (1.0 / 3.0)
    return (c - q) * math.sqrt(1.25 + 1.0 / (c * c)) / (1.0 - q)


@jit
def _nested_sigma(cos_t, q):
    """σ = 1 − t where κ(t) = q·c on the spiral of angle θ (safeguarded Newton).

    Solves H(σ) = B^{3/2} − 216·t·cos³θ/q = 0 with B the denominator base of
    κ(u) (``spiral_curvature_ratio``), written in σ to keep 1 − t exact.
    """
    e2 = cos_t * cos_t
    k = 216.0 * e2 * cos_t / q
    lam = 1.2 * math.sqrt(q ** (-2.0 / 3.0) - 1.0)
    sigma = min(0.5 * lam * cos_t, 0.5)
    lo = 0.0
    hi = 1.0
    for _ in range(200):
        t = 1.0 - sigma
        w2 = sigma * (2.0 - sigma)
        t2 = t * t
        base = 25.0 * w2 * w2 + e2 * t2 * (60.0 - 24.0 * t2)
        root = math.sqrt(base)
        f = base * root - k * t
        if f == 0.0:
            return sigma
        if f < 0.0:
            lo = sigma
        else:
            hi = sigma
        dbase_dt = -100.0 * t * w2 + e2 * (120.0 * t - 96.0 * t2 * t)
        df = -(1.5 * root * dbase_dt - k)
        new = sigma - f / df if df != 0.0 else 0.5 * (lo + hi)
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - sigma) <= 1e-16 * new:
            return new
        sigma = new
    return sigma


@jit
def _nested_geometry(theta, r0, r1):
    """Centre offset (x, y) in the (T, N) frame for spiral angle θ, plus σ and sin/cos."""
    sin_t = math.sin(theta)
    cos_t = math.cos(theta)
    sigma = _nested_sigma(cos_t, r1 / r0)
    t = 1.0 - sigma
    g, h = spiral_legs(sin_t, cos_t, r1)
    num = 6.0 * t * t * sin_t * cos_t
    den = 5.0 * sigma * (2.0 - sigma) + 6.0 * t * t * cos_t * cos_t
    n = norm(num, den)
    sin_p = num / n
    cos_p = den / n
    tail = h * sigma * (3.0 - 3.0 * sigma + sigma * sigma)
    x = g * sigma * sigma * (3.0 - sigma) + tail * cos_t - r1 * sin_t + r0 * sin_p
    y = tail * sin_t + r1 * cos_t - r0 * cos_p
    return x, y, sigma, sin_t, cos_t


@jit
def _nested_canonical(dx, dy, r0, r1, out):
    """Fifth case, r0 > r1 > 0: the spiral piece [t, 1] from Ω0 to Ω1.

    Solves |C1 − C0|(θ) = D by Illinois regula falsi on θ ∈ (0, π/2), where
    the distance falls from r0 − r1 (θ → 0) to the band's lower end (θ → π/2).
    Writes the piece relative to C0 and returns (status, θ, D/(r0 − r1), t).
    """
    dist = norm(dx, dy)
    ratio = dist / (r0 - r1)
    if not (nested_band_lower(r1 / r0) < ratio < 1.0):
        return OUTSIDE_NESTED_BAND, NAN, ratio, NAN
    lo = 0.0
    hi = math.pi / 2.0
    f_lo = (r0 - r1) - dist
    f_hi = nested_band_lower(r1 / r0) * (r0 - r1) - dist
    theta = 0.5 * hi
    side = 0
    for _ in range(200):
        theta = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        if not (lo < theta < hi):
            theta = 0.5 * (lo + hi)
        x, y, sigma, sin_t, cos_t = _nested_geometry(theta, r0, r1)
        f = norm(x, y) - dist
        if f == 0.0 or hi - lo <= 4e-16 * theta:
            break
        if f > 0.0:
            lo = theta
            f_lo = f
            if side == 1:
                f_hi *= 0.5
            side = 1
        else:
            hi = theta
            f_hi = f
            if side == -1:
                f_lo *= 0.5
            side = -1
    x, y, sigma, sin_t, cos_t = _nested_geometry(theta, r0, r1)
    g, h = spiral_legs(sin_t, cos_t, r1)
    tx, ty = _frame_from_offset(dx, dy, x, y)
    nx = -ty
    ny = tx
    # Local (T, N) coordinates of the piece relative to Q(1), then moved to
    # world axes relative to C0 in place.
    e1x = cos_t
    e1y = sin_t
    locs = out
    tail = h * sigma * (3.0 - 3.0 * sigma + sigma * sigma)
    locs[3, 0] = 0.0
    locs[3, 1] = 0.0
    locs[2, 0] = -sigma * h * e1x
    locs[2, 1] = -sigma * h * e1y
    locs[0, 0] = -g * sigma * sigma * (3.0 - sigma) - tail * e1x
    locs[0, 1] = -tail * e1y
    lead = (1.0 - sigma) * (1.0 - sigma)
    locs[1, 0] = locs[0, 0] + sigma * (g * sigma * (2.0 - sigma) + h * lead * e1x)
    locs[1, 1] = locs[0, 1] + sigma * h * lead * e1y
    # C1 = Q(1) + r1·N1 with N1 = (−sin θ, cos θ) in the local frame.
    for k in range(4):
        lx = locs[k, 0] + r1 * sin_t
        ly = locs[k, 1] - r1 * cos_t
        out[k, 0] = dx + lx * tx + ly * nx
        out[k, 1] = dy + lx * ty + ly * ny
    return OK, theta, ratio, 1.0 - sigma


@jit
def circle_in_circle_row(c0x, c0y, r0, c1x, c1y, r1, out):
    """Fifth case: one spiral from circle 0 to the nested circle 1 (or out of it).

    Radii are signed by travel sense and must share the sign.
    """
    if not finite(c0x, c0y, r0, c1x, c1y, r1):
        return NOT_FINITE, NAN, NAN, NAN
    if r0 == 0.0 or r1 == 0.0:
        return BAD_RADIUS, NAN, NAN, NAN
    if (r0 > 0.0) != (r1 > 0.0):
        return SIGN_MISMATCH, NAN, NAN, NAN
    if abs(r0) == abs(r1):
        return EQUAL_RADII, NAN, NAN, NAN
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
        return UNVERIFIED, NAN, INF, NAN
    flip = 1.0 if big_r > 0.0 else -1.0
    piece = out[0]
    status, theta, ratio, t = _nested_canonical(dx, flip * dy, abs(big_r) * inv, abs(small_r) * inv, piece)
    if status != OK:
        return status, NAN, ratio, NAN
    if not inward:
        reverse_in_place(piece)
    place(out, ox, oy, scale, flip)
    res = worst(end_residual(piece[::-1], c0x, c0y, -r0, inv), end_residual(piece, c1x, c1y, r1, inv))
    if not res <= VERIFY_TOL:
        return UNVERIFIED, NAN, res, NAN
    return OK, theta, ratio, t


# ------------------------------------------------------------ batches


@jit
def _record(i, result, out, status, theta, measure):
    status[i] = result[0]
    theta[i] = result[1]
    measure[i] = result[2]
    if result[0] != OK:
        fill_nan(out[i])
        theta[i] = NAN
    return result[3]


@_compile(parallel=True)
def line_to_circle_batch(p, d, c, r, out, status, theta, measure):
    for i in prange(p.shape[0]):
        row = line_to_circle_row(p[i, 0], p[i, 1], d[i, 0], d[i, 1], c[i, 0], c[i, 1], r[i], out[i])
        _record(i, row, out, status, theta, measure)


@_compile(parallel=True)
def circle_to_circle_batch(c0, r0, c1, r1, out, status, theta, measure):
    for i in prange(c0.shape[0]):
        row = circle_to_circle_row(c0[i, 0], c0[i, 1], r0[i], c1[i, 0], c1[i, 1], r1[i], out[i])
        _record(i, row, out, status, theta, measure)


@_compile(parallel=True)
def line_to_line_batch(p0, p, p1, k, out, status, theta, measure):
    for i in prange(p0.shape[0]):
        row = line_to_line_row(p0[i, 0], p0[i, 1], p[i, 0], p[i, 1], p1[i, 0], p1[i, 1], k[i], out[i])
        _record(i, row, out, status, theta, measure)


@_compile(parallel=True)
def circle_in_circle_batch(c0, r0, c1, r1, out, status, theta, measure, param):
    for i in prange(c0.shape[0]):
        row = circle_in_circle_row(c0[i, 0], c0[i, 1], r0[i], c1[i, 0], c1[i, 1], r1[i], out[i])
        param[i] = _record(i, row, out, status, theta, measure)


@_compile(parallel=True)
def verify_corners_batch(out, corners, t_in, t_out, curvature, status, measure):
    """``corner_residual`` for spiral pairs made elsewhere (e.g. G2CBS): rows
    with status OK that fail become ``UNVERIFIED`` (NaN control points)."""
    for i in prange(out.shape[0]):
        if status[i] != OK:
            continue
        scale = frame_scale(1.0 / abs(curvature[i]))
        inv = 1.0 / scale
        res = corner_residual(
            out[i], corners[i, 0], corners[i, 1], t_in[i, 0], t_in[i, 1], -t_out[i, 0], -t_out[i, 1], curvature[i] * scale, inv
        )
        if not res <= VERIFY_TOL:
            status[i] = UNVERIFIED
            measure[i] = res
            fill_nan(out[i])
