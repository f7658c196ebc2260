"""Compiled kernels: every formula of the spiral and of its five transitions, once.

Each ``*_row`` function solves one problem from plain floats and writes the
control points into ``out`` (shape ``(k, 4, 2)``); it returns
``(status, theta, measure, extra)``.  ``status`` is one of the codes below,
``measure`` is the number that decides feasibility (reported in errors) and
``extra`` is case specific (the contact parameter ``t`` of the nested case).
The batch kernels loop over rows; the scalar API calls the row functions.

All work is done relative to one input point (survey coordinates stay exact)
and in a mirrored frame when the configuration turns right, so each theorem is
coded for its canonical left-turning case only.
"""

from __future__ import annotations

import math

from numba import njit, prange

from .errors import Status

jit = njit(cache=True, nogil=True)

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

# A returned root must reproduce its joins to this relative accuracy; it
# guards against false roots, the accuracy actually achieved is ~1e-15.
VERIFY_TOL = 1e-9

NAN = math.nan


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


@jit
def end_residual(cp, cx, cy, radius):
    """How far the end of Bézier ``cp`` is from joining circle (c, radius) G2.

    ``radius`` is signed by travel sense (positive: counterclockwise). Returns
    max(|centre error| / |radius|, |κ·radius − 1|) of the osculating circle at
    u = 1, or +inf when the end is degenerate.
    """
    ax = cp[2, 0] - cp[1, 0]
    ay = cp[2, 1] - cp[1, 1]
    bx = cp[3, 0] - cp[2, 0]
    by = cp[3, 1] - cp[2, 1]
    lb2 = bx * bx + by * by
    cross = ax * by - ay * bx
    if not (lb2 > 0.0 and cross != 0.0):
        return math.inf
    # κ = (2/3)·cross/|b|³, so the centre P3 + rot90(b)/(|b|·κ) needs no root.
    to_centre = 1.5 * lb2 / cross
    ox = cp[3, 0] - by * to_centre - cx
    oy = cp[3, 1] + bx * to_centre - cy
    kappa_r = radius / (to_centre * math.sqrt(lb2))
    return max(math.sqrt(ox * ox + oy * oy) / abs(radius), abs(kappa_r - 1.0))


@jit
def reverse_in_place(cp):
    """Reverse the order of the four control points ``cp``."""
    for j in range(2):
        a, b = cp[0, j], cp[1, j]
        cp[0, j], cp[1, j] = cp[3, j], cp[2, j]
        cp[3, j], cp[2, j] = a, b


@jit
def place(out, ox, oy, flip):
    """Map local points (x, flip·y relative to o) back to world coordinates."""
    for i in range(out.shape[0]):
        for k in range(4):
            out[i, k, 0] = ox + out[i, k, 0]
            out[i, k, 1] = oy + flip * out[i, k, 1]


@jit
def norm(x, y):
    """√(x² + y²) (``math.hypot`` is several times slower and its overflow guard is not needed here)."""
    return math.sqrt(x * x + y * y)


@jit
def fill_nan(out):
    for i in range(out.shape[0]):
        for k in range(4):
            out[i, k, 0] = NAN
            out[i, k, 1] = NAN


@jit
def finite(*values):
    for v in values:
        if not math.isfinite(v):
            return False
    return True


# ------------------------------------------------------ line to circle


@jit
def line_to_circle_row(px, py, dx, dy, cx, cy, r, out):
    """Theorem 4.1: spiral from the directed line (p, d) to circle (c, r > 0).

    ``extra`` is the turn side: +1 left, −1 right.
    """
    if not finite(px, py, dx, dy, cx, cy, r):
        return NOT_FINITE, NAN, NAN, NAN
    length = norm(dx, dy)
    if length == 0.0:
        return ZERO_DIRECTION, NAN, NAN, NAN
    if not r > 0.0:
        return BAD_RADIUS, NAN, NAN, NAN
    tx = dx / length
    ty = dy / length
    vx = cx - px
    vy = cy - py
    d = tx * vy - ty * vx
    side = 1.0 if d > 0.0 else -1.0
    measure = abs(d) / r
    if not abs(d) > r:
        return CIRCLE_MEETS_LINE, NAN, measure, NAN
    # cos θ = 10 / (9ρ + √(81ρ² − 80)), with 1 − cos θ formed without cancellation.
    eps = (abs(d) - r) / r
    z = 81.0 * eps * (2.0 + eps)
    s = math.sqrt(1.0 + z)
    den = 9.0 * measure + s
    cos_t = 10.0 / den
    sin_t = math.sqrt((9.0 * eps + z / (s + 1.0)) / den * (1.0 + cos_t))
    a = vx * tx + vy * ty - r * shape_g2(sin_t, cos_t)
    put_spiral(out[0], a * tx, a * ty, tx, ty, -side * ty, side * tx, sin_t, cos_t, r)
    if not end_residual(out[0], vx, vy, side * r) <= VERIFY_TOL:
        return UNVERIFIED, NAN, measure, NAN
    place(out, px, py, 1.0)
    return OK, math.atan2(sin_t, cos_t), measure, side


# ---------------------------------------------------- circle to circle


@jit
def _frame_from_offset(dx, dy, p, q):
    """Unit T with (dx, dy) = p·T + q·rot90(T) (up to scale)."""
    tx = p * dx + q * dy
    ty = p * dy - q * dx
    n = norm(tx, ty)
    return tx / n, ty / n


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
    dx = c1x - c0x
    dy = c1y - c0y
    dist = norm(dx, dy)
    if dist == 0.0:
        return COINCIDENT, NAN, NAN, NAN
    a0 = abs(r0)
    a1 = abs(r1)
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
        measure = dist / gap if gap > 0.0 else math.inf
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
    res0 = end_residual(out[0, ::-1], 0.0, 0.0, -flip * r0)
    res1 = end_residual(out[1], dx, dy, flip * r1)
    if not max(res0, res1) <= VERIFY_TOL:
        return UNVERIFIED, NAN, measure, NAN
    place(out, c0x, c0y, flip)
    return OK, math.atan2(sin_t, cos_t), measure, NAN


# -------------------------------------------------------- line to line


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
    ux = px - p0x
    uy = py - p0y
    vx = px - p1x
    vy = py - p1y
    l0 = norm(ux, uy)
    l1 = norm(vx, vy)
    if l0 == 0.0 or l1 == 0.0:
        return COINCIDENT, NAN, NAN, NAN
    t0x = ux / l0
    t0y = uy / l0
    t1x = vx / l1
    t1y = vy / l1
    bx = t0x - t1x
    by = t0y - t1y
    lb = norm(bx, by)
    if lb == 0.0:
        return CORNER_REVERSAL, math.pi / 2.0, NAN, NAN
    bx /= lb
    by /= lb
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
        a = corner_relation(sin_t, cos_t, curvature, WALTON_MEEK_CORNER)
    measure = a / shortest
    if not measure <= 1.0 + 1e-12:
        return LEGS_TOO_SHORT, math.atan2(sin_t, cos_t), measure, NAN
    radius = 1.0 / corner_relation(sin_t, cos_t, a, WALTON_MEEK_CORNER)
    put_spiral(out[0], -a * t0x, -a * t0y, t0x, t0y, -side * t0y, side * t0x, sin_t, cos_t, radius)
    put_spiral(out[1], -a * t1x, -a * t1y, t1x, t1y, side * t1y, -side * t1x, sin_t, cos_t, radius)
    reverse_in_place(out[1])
    gap = norm(out[0, 3, 0] - out[1, 0, 0], out[0, 3, 1] - out[1, 0, 1])
    if not gap <= VERIFY_TOL * a:
        return UNVERIFIED, NAN, measure, NAN
    place(out, px, py, 1.0)
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
    dx = (c1x - c0x) if inward else (c0x - c1x)
    dy = (c1y - c0y) if inward else (c0y - c1y)
    flip = 1.0 if big_r > 0.0 else -1.0
    piece = out[0]
    status, theta, ratio, t = _nested_canonical(dx, flip * dy, abs(big_r), abs(small_r), piece)
    if status != OK:
        return status, NAN, ratio, NAN
    res0 = end_residual(piece[::-1], 0.0, 0.0, -abs(big_r))
    res1 = end_residual(piece, dx, flip * dy, abs(small_r))
    if not max(res0, res1) <= VERIFY_TOL:
        return UNVERIFIED, NAN, ratio, NAN
    if not inward:
        reverse_in_place(piece)
    place(out, ox, oy, flip)
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


@njit(cache=True, nogil=True, parallel=True)
def line_to_circle_batch(p, d, c, r, out, status, theta, measure):
    for i in prange(p.shape[0]):
        row = line_to_circle_row(p[i, 0], p[i, 1], d[i, 0], d[i, 1], c[i, 0], c[i, 1], r[i], out[i])
        _record(i, row, out, status, theta, measure)


@njit(cache=True, nogil=True, parallel=True)
def circle_to_circle_batch(c0, r0, c1, r1, out, status, theta, measure):
    for i in prange(c0.shape[0]):
        row = circle_to_circle_row(c0[i, 0], c0[i, 1], r0[i], c1[i, 0], c1[i, 1], r1[i], out[i])
        _record(i, row, out, status, theta, measure)


@njit(cache=True, nogil=True, parallel=True)
def line_to_line_batch(p0, p, p1, k, out, status, theta, measure):
    for i in prange(p0.shape[0]):
        row = line_to_line_row(p0[i, 0], p0[i, 1], p[i, 0], p[i, 1], p1[i, 0], p1[i, 1], k[i], out[i])
        _record(i, row, out, status, theta, measure)


@njit(cache=True, nogil=True, parallel=True)
def circle_in_circle_batch(c0, r0, c1, r1, out, status, theta, measure, param):
    for i in prange(c0.shape[0]):
        row = circle_in_circle_row(c0[i, 0], c0[i, 1], r0[i], c1[i, 0], c1[i, 1], r1[i], out[i])
        param[i] = _record(i, row, out, status, theta, measure)
