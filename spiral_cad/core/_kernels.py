"""Compiled kernels: every formula of the spiral and of its five transitions, once.

Each ``*_row`` function solves one problem from plain floats and writes the
control points into ``out[i]`` (``out`` of shape ``(N, k, 4, 2)``; NaN
where it fails); it returns ``(status, theta, measure, extra)``. ``status``
is one of the codes below, ``measure`` is the number that decides
feasibility (reported in errors; for ``UNVERIFIED`` the residual that
failed) and ``extra`` is case specific (the turn side of line → circle, the
contact parameter ``t`` of the nested case). The batch kernels loop over
rows, with the row functions inlined; the scalar API calls the row
functions with N = 1, so scalar and batch results agree bit for bit.

Every row works in the same steps, in registers (nothing is written before
the row is verified, and nothing is read back):

1. check its inputs (finite, non-zero directions and radii);
2. move to a normalised frame: translated to one input point and scaled by a
   power of two near the problem's natural length, so inputs of magnitude
   1e-300 … 1e300 behave like 1 and the scaling itself is exact;
3. apply the theorem for the canonical left-turning case (a mirrored frame
   when the configuration turns right);
4. map the control points back to world coordinates;
5. verify what is returned: every contact and joint, measured from the world
   control points that are then written, must hold to ``VERIFY_TOL``
   (relative), else the row fails with ``UNVERIFIED`` and the residual as
   its measure. Non-finite or coinciding control points count as an
   infinite residual. The checks need square roots and divisions only.

Kernels use numpy's floating-point error model: a division by zero gives
inf/NaN (caught by step 5) instead of raising, so no input can make a batch
raise.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .errors import Status
from .jit import Kernels

if TYPE_CHECKING:  # annotations only: the kernels' namespace (what numba compiles against) stays as it is
    from typing import TypeAlias

    import numpy.typing as npt

    FloatArray: TypeAlias = npt.NDArray[np.float64]
    StatusArray: TypeAlias = npt.NDArray[np.int8]
    #: What a row returns: (status, θ, measure, extra).
    Row: TypeAlias = tuple[int, float, float, float]
    #: Four control points (x0, y0, …, x3, y3).
    Points8: TypeAlias = tuple[float, float, float, float, float, float, float, float]


KERNELS = Kernels(globals())
jit = KERNELS.jit
#: Row functions are inlined into the batch loops (where the output array
#: then costs no reference counting per row) and compiled on their own for
#: the scalar API.
row_jit = KERNELS.row_jit

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
OUTSIDE_SHAPE = int(Status.OUTSIDE_SHAPE)

#: What is returned must reproduce its contacts and joints to this accuracy:
#: gap / L, tangent angle (radians) and curvature error × L, with L the
#: smaller of the spiral's leg at that end and the radius there; the accuracy
#: achieved on well-conditioned input is ~1e-15.
VERIFY_TOL = 1e-9

#: A bound on the relative rounding of the few float64 operations behind one measure
#: (five units of rounding: a difference, a product, a square root, the unit vector). Two measures cancel large terms: a spiral's end against its circle
#: (||b3 − c| − r| of a leg L ≪ r) and its start against the line's point p far away
#: (|t × (b0 − p)|); their rounding, ROUNDING × r / L and ROUNDING × |b0 − p| / L,
#: is added to the measure, so a row float64 cannot resolve is refused, never passed.
ROUNDING = 5.0 * 2.0**-53

NAN = math.nan
INF = math.inf


# ---------------------------------------------------------------- shapes
# A spiral turning by θ onto end radius R has control points
#   B1 = B0 + a·T,  B2 = B1 + b·T,  B3 = B2 + c·T1   (T1 = T turned by θ),
# with curvature 0 at B0 (B0, B1, B2 collinear) and 1/R at B3 when
# b = 3c²/(2R sin θ). Each shape is a choice of the legs (a, b, c) as a
# function of θ; every formula below (centre offsets, corner distances,
# curvature along the curve) is written once for any legs.

#: Shape codes (names in ``spiral_cad.core.shapes``).
WALTON_MEEK = 0
NEAR_LINEAR = 1
G2CBS = 2

#: Near-linear: the equal-leg member a = b = c = (2/3)·R·sin θ is used while
#: its curvature is monotone (cos θ > 5/6, θ < 33.557°); there κ'(1) = 0, the
#: curvature maximum reaches u = 1, and the family continues through members
#: that keep it there (see ``boundary_ratio``).
EQUAL_LEG_COS = 5.0 / 6.0
#: Largest spiral angle of the near-linear family (50°): its continuation
#: stays monotone to 53.13° and closer to linear than the 1996 spiral.
NEAR_LINEAR_MAX_THETA = 5.0 * math.pi / 18.0
NEAR_LINEAR_MIN_COS = math.cos(NEAR_LINEAR_MAX_THETA)
#: Yang & Sukkarieh's leg ratio a/b = 2(√6 − 1)/5: the smallest for which a
#: member with κ'(1) = 0 is monotone at every θ (Walton, Meek & Ali 2003).
G2CBS_RATIO = 2.0 * (math.sqrt(6.0) - 1.0) / 5.0


@row_jit
def boundary_ratio(shape: int, cos_t: float) -> float:
    """Leg ratio r = a/b of a member whose curvature peaks exactly at u = 1.

    κ'(1) = 0 means c = 6b·cos θ/(r + 4) (Walton, Meek & Ali 2003): the 1996
    spiral is r = 1, G2CBS r = 2(√6 − 1)/5; the near-linear continuation past
    the equal-leg range takes r = 1.8·cos θ − 0.5, which is 1 at cos θ = 5/6
    (where it meets the equal-leg member) and follows the ratio that
    minimises the peak dκ/ds among these members (0.77 at 45°).
    """
    return 1.0 if shape == WALTON_MEEK else (G2CBS_RATIO if shape == G2CBS else 1.8 * cos_t - 0.5)


@row_jit
def leg_factors(shape: int, cos_t: float) -> tuple[float, float, float]:
    """(α, β, γ): the legs (a, b, c) of the spiral turning by θ onto radius R are R·sin θ·(α, β, γ)."""
    r = boundary_ratio(shape, cos_t)
    k = r + 4.0
    beta = k * k / (54.0 * cos_t * cos_t)
    equal = shape == NEAR_LINEAR and cos_t >= EQUAL_LEG_COS  # selects, not branches: rows vectorise
    return (2.0 / 3.0 if equal else r * beta), (2.0 / 3.0 if equal else beta), (2.0 / 3.0 if equal else k / (9.0 * cos_t))


@jit
def in_shape_domain(shape: int, cos_t: float) -> bool:
    """Whether the shape has a spiral of this angle (cos θ > 0; near-linear: θ ≤ 50°)."""
    if shape == NEAR_LINEAR:
        return cos_t >= NEAR_LINEAR_MIN_COS
    return cos_t > 0.0


@row_jit
def leg_offsets(alpha: float, beta: float, gamma: float, cos_t: float) -> tuple[float, float]:
    """(e1, e2) of the spiral with leg factors (α, β, γ) at θ: g1(θ) = 1 + sin²θ·e1, g2(θ) = sin θ·e2.

    The end circle's centre is B0 + R·(g2·T + g1·N) (N the normal towards
    it): g1 − 1 is the circle's shift off the start line over R, and both
    are formed without cancellation as θ → 0.
    """
    return gamma - 1.0 / (1.0 + cos_t), alpha + beta + gamma * cos_t - 1.0


@jit
def shape_offsets(shape: int, sin_t: float, cos_t: float) -> tuple[float, float]:
    """(e1, e2) of ``leg_offsets`` for the shape's spiral of angle θ."""
    alpha, beta, gamma = leg_factors(shape, cos_t)
    return leg_offsets(alpha, beta, gamma, cos_t)


@row_jit
def centre_offset(sin_t: float, e1: float, e2: float) -> tuple[float, float]:
    """(g1, g2): the end circle's centre lies R·g1 off the start line and R·g2 along it."""
    return 1.0 + sin_t * sin_t * e1, sin_t * e2


@jit
def shape_g1(shape: int, sin_t: float, cos_t: float) -> float:
    """g1(θ): the end circle's centre lies R·g1 off the start line (1996 spiral: (5 + 4cos²θ)/(9 cos θ))."""
    e1, e2 = shape_offsets(shape, sin_t, cos_t)
    return centre_offset(sin_t, e1, e2)[0]


@jit
def shape_g2(shape: int, sin_t: float, cos_t: float) -> float:
    """g2(θ): the end circle's centre lies R·g2 along the start line (1996 spiral: 25 tan θ/(27 cos θ) − (4/9) sin θ)."""
    e1, e2 = shape_offsets(shape, sin_t, cos_t)
    return centre_offset(sin_t, e1, e2)[1]


@jit
def shape_offsets_batch(shape: int, sin_t: FloatArray, cos_t: FloatArray, e1: FloatArray, e2: FloatArray) -> None:
    """``shape_offsets`` over arrays of sin θ and cos θ, into ``e1`` and ``e2``."""
    for i in range(sin_t.shape[0]):
        e1[i], e2[i] = shape_offsets(shape, sin_t[i], cos_t[i])


@row_jit
def corner_factor(shape: int, sin_t: float, cos_t: float) -> float:
    """K(θ): a symmetric spiral pair at a corner of deflection 2θ starts K/κ from the
    corner, κ its joint curvature (1996 spiral: (40/27)·sin θ/cos²θ, Theorem 4.4).

    The end of each spiral lies on the corner's bisector: d = a + b + c/cos θ.
    """
    alpha, beta, gamma = leg_factors(shape, cos_t)
    return sin_t * (alpha + beta + gamma / cos_t)


@jit
def corner_factor_batch(shape: int, sin_t: FloatArray, cos_t: FloatArray, out: FloatArray) -> None:
    """``corner_factor`` over arrays of sin θ and cos θ, into ``out``."""
    for i in range(sin_t.shape[0]):
        out[i] = corner_factor(shape, sin_t[i], cos_t[i])


@row_jit
def corner_relation(shape: int, sin_t: float, cos_t: float, value: float) -> float:
    """K(θ)/value: a spiral pair's corner distance from its joint curvature, or the
    curvature from the distance (the relation is symmetric)."""
    return corner_factor(shape, sin_t, cos_t) / value


@row_jit
def spiral_points(
    bx: float,
    by: float,
    tx: float,
    ty: float,
    nx: float,
    ny: float,
    sin_t: float,
    cos_t: float,
    radius: float,
    alpha: float,
    beta: float,
    gamma: float,
) -> Points8:
    """The spiral's control points (x0, y0, …, x3, y3) from its legs.

    Starts at (bx, by) along unit (tx, ty) and turns by |θ| towards the unit
    normal (nx, ny), reaching radius ``radius`` at the end; (α, β, γ) are the
    shape's leg factors at θ (``leg_factors``).
    """
    size = radius * sin_t
    a = alpha * size
    b = a + beta * size
    c = gamma * size
    x2 = bx + b * tx
    y2 = by + b * ty
    return bx, by, bx + a * tx, by + a * ty, x2, y2, x2 + c * (cos_t * tx + sin_t * nx), y2 + c * (cos_t * ty + sin_t * ny)


@row_jit
def spiral_in_world(
    bx: float,
    by: float,
    tx: float,
    ty: float,
    nx: float,
    ny: float,
    sin_t: float,
    cos_t: float,
    radius: float,
    alpha: float,
    beta: float,
    gamma: float,
    ox: float,
    oy: float,
    scale: float,
    flip: float,
) -> Points8:
    """``spiral_points`` of a normalised frame in world coordinates (``to_world``)."""
    x0, y0, x1, y1, x2, y2, x3, y3 = spiral_points(bx, by, tx, ty, nx, ny, sin_t, cos_t, radius, alpha, beta, gamma)
    return to_world(x0, y0, x1, y1, x2, y2, x3, y3, ox, oy, scale, flip)


@jit
def curvature_ratio(sigma: float, alpha: float, beta: float, gamma: float, sin_t: float, cos_t: float) -> float:
    """κ(u)/κ(1) at u = 1 − σ of the spiral with leg factors (α, β, γ).

    With the legs as vectors, Q' × Q'' = 18·u·c·sin θ·(a(1 − u) + b·u), so
    κ(u)/κ(1) = u·c³·(a(1 − u) + b·u) / (b·|Q'(u)/3|³); written in σ to keep
    1 − u exact near the end.
    """
    u = 1.0 - sigma
    x = sigma * sigma * alpha + 2.0 * u * sigma * beta + u * u * gamma * cos_t
    y = u * u * gamma * sin_t
    speed2 = x * x + y * y
    return u * gamma * gamma * gamma * (alpha * sigma + beta * u) / (beta * speed2 * math.sqrt(speed2))


# ------------------------------------------------- frames and numbers


@row_jit
def norm(x: float, y: float) -> float:
    """√(x² + y²) for values of moderate size (normalised frames; ``math.hypot`` is slower)."""
    return math.sqrt(x * x + y * y)


@jit
def power_of_two_near(x: float) -> float:
    """A power of two within a factor 2 of ``x`` > 0: scaling by it is exact."""
    return math.ldexp(1.0, math.frexp(x)[1] - 1)


@row_jit
def ordinary(v: float) -> bool:
    """Whether a length lies where squares and cubes cannot overflow or underflow (1e-60 … 1e60)."""
    return 1e-60 < v < 1e60


@jit
def frame_scale(length: float) -> float:
    """The normalising scale for a problem of natural size ``length`` > 0.

    Any power of two scales exactly; 1 is used where squares and cubes of
    lengths cannot overflow or underflow (1e-60 … 1e60), so ordinary inputs
    are solved without any rescaling at all.
    """
    if ordinary(length):
        return 1.0
    return power_of_two_near(length)


@jit
def unit(x: float, y: float) -> tuple[float, float]:
    """(x, y) / |(x, y)| without overflow or underflow; (0, 0) for a zero or non-finite vector."""
    big = max(abs(x), abs(y))
    if not (big > 0.0 and big < INF):
        return 0.0, 0.0
    if not ordinary(big):
        s = power_of_two_near(big)
        x /= s
        y /= s
    return unit_ordinary(x, y)


@row_jit
def unit_ordinary(x: float, y: float) -> tuple[float, float]:
    """(x, y) / |(x, y)| for a vector of ordinary length (``unit`` rescales the others first)."""
    n = norm(x, y)
    return x / n, y / n


#: fdlibm's arctangent (s_atan.c): atan(t) = t − t·P(t²) for |t| < 7/16, else
#: atan(c) + atan((t − c)/(1 + ct)) with c = 1/2, 1, 3/2, ∞, atan(c) in two parts.
ATAN_HI = (0.4636476090008061, 0.7853981633974483, 0.982793723247329, 1.5707963267948966)
ATAN_LO = (2.2698777452961687e-17, 3.061616997868383e-17, 1.3903311031230998e-17, 6.123233995736766e-17)
ATAN_P = (3.33333333333329318027e-01, -1.99999999998764832476e-01, 1.42857142725034663711e-01,
          -1.11111104054623557880e-01, 9.09088713343650656196e-02, -7.69187620504482999495e-02,
          6.66107313738753120669e-02, -5.83357013379057348645e-02, 4.97687799461593236017e-02,
          -3.65315727442169155270e-02, 1.62858201153657823623e-02)  # fmt: skip
#: Veltkamp's splitter 2^27 + 1: a = hi + lo with 26-bit halves, so products of halves are exact.
SPLIT = 134217729.0


@row_jit
def two_sum(a: float, b: float) -> tuple[float, float]:
    """a + b as s + e exactly (Knuth)."""
    s = a + b
    v = s - a
    return s, (a - (s - v)) + (b - v)


@row_jit
def two_product_error(a: float, b: float, p: float) -> float:
    """a·b − p exactly for p = fl(a·b) (Dekker; |a|, |b| below 2^996)."""
    c = SPLIT * a
    ah = c - (c - a)
    al = a - ah
    c = SPLIT * b
    bh = c - (c - b)
    bl = b - bh
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl


@row_jit
def angle(y: float, x: float) -> float:
    """atan2(y, x) for 0 ≤ y ≤ 1 and 0 < x ≤ 1, the spiral angle θ from its sine and cosine.

    fdlibm's arctangent of the reduced argument t = (n_hi + n_lo)/(d_hi + d_lo),
    with t carried as two doubles (numerator and denominator formed exactly,
    the quotient's remainder by Dekker's product), so the result is as
    accurate as libm's ``atan2`` (about 0.5 ulp) at a third of its cost.
    Scalar and batch results share it bit for bit.
    """
    # Every reduction is formed and one selected (no branches: rows vectorise).
    first = y < 0.4375 * x
    k0 = y < 0.6875 * x  # (t − 1/2)/(1 + t/2) = (2y − x)/(2x + y); 2y − x is exact
    k1 = y < 1.1875 * x  # (t − 1)/(1 + t) = (y − x)/(y + x); y − x is exact
    k2 = y < 2.4375 * x  # (t − 3/2)/(1 + 3t/2) = (y − 3x/2)/(x + 3y/2); y − 3x/2 exact as y − h − l
    d0, e0 = two_sum(2.0 * x, y)
    d1, e1 = two_sum(y, x)
    h, l = two_sum(x, 0.5 * x)
    n2, f2 = two_sum(y - h, -l)
    h, l = two_sum(y, 0.5 * y)
    d2, e2 = two_sum(x, h)
    n_hi = y if first else (2.0 * y - x if k0 else (y - x if k1 else (n2 if k2 else -x)))  # else −1/t
    n_lo = f2 if (k2 and not k1) else 0.0
    d_hi = x if first else (d0 if k0 else (d1 if k1 else (d2 if k2 else y)))
    d_lo = 0.0 if first else (e0 if k0 else (e1 if k1 else (e2 + l if k2 else 0.0)))
    hi = 0.0 if first else (ATAN_HI[0] if k0 else (ATAN_HI[1] if k1 else (ATAN_HI[2] if k2 else ATAN_HI[3])))
    lo = 0.0 if first else (ATAN_LO[0] if k0 else (ATAN_LO[1] if k1 else (ATAN_LO[2] if k2 else ATAN_LO[3])))
    t = n_hi / d_hi
    t_lo = ((n_hi - t * d_hi - two_product_error(t, d_hi, t * d_hi)) + n_lo - t * d_lo) / d_hi
    z = t * t
    w = z * z
    s1 = z * (ATAN_P[0] + w * (ATAN_P[2] + w * (ATAN_P[4] + w * (ATAN_P[6] + w * (ATAN_P[8] + w * ATAN_P[10])))))
    s2 = w * (ATAN_P[1] + w * (ATAN_P[3] + w * (ATAN_P[5] + w * (ATAN_P[7] + w * ATAN_P[9]))))
    small = t_lo - t * (s1 + s2)  # atan(t + t_lo) − t, to first order in t_lo
    return t + small if first else hi + (t + (small + lo))


@jit
def finite(*values: float) -> bool:
    for v in values:
        if not math.isfinite(v):
            return False
    return True


@jit
def worst(a: float, b: float) -> float:
    """max(a, b), with NaN counted as infinitely bad."""
    if a != a or b != b:
        return INF
    return a if a > b else b


@row_jit
def to_world(
    x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, x3: float, y3: float, ox: float, oy: float, scale: float, flip: float
) -> Points8:
    """Normalised points (x, flip·y) in world coordinates o + scale·(x, flip·y)."""
    sy = scale * flip
    return (ox + scale * x0, oy + sy * y0, ox + scale * x1, oy + sy * y1,
            ox + scale * x2, oy + sy * y2, ox + scale * x3, oy + sy * y3)  # fmt: skip


# Rows write their control points into ``out[i]`` of the (N, k, 4, 2) result
# element by element: an array view per row would cost an atomic reference
# count update that both threads contend for.


@jit
def store(out: FloatArray, i: int, k: int, x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, x3: float, y3: float) -> None:
    """Write four points into ``out[i, k]`` (4, 2)."""
    out[i, k, 0, 0] = x0
    out[i, k, 0, 1] = y0
    out[i, k, 1, 0] = x1
    out[i, k, 1, 1] = y1
    out[i, k, 2, 0] = x2
    out[i, k, 2, 1] = y2
    out[i, k, 3, 0] = x3
    out[i, k, 3, 1] = y3


@jit
def fail(out: FloatArray, i: int, status: int, measure: float) -> Row:
    """A failed row: ``out[i]`` filled with NaN, θ NaN, the status and its measure."""
    for k in range(out.shape[1]):
        store(out, i, k, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN)
    return status, NAN, measure, NAN


# ------------------------------------------- verification (world coordinates)
# A contact or joint is measured like a chain's joint: gap / L, tangent angle
# (radians) and curvature error × L, where L is the smaller of the spiral's
# leg at that end and the radius there (so the curvature error is relative
# to max(|κ|, 1/leg), as in the G2 checker); the residual is the largest.
# Every check reads the world control points that are returned, as plain
# numbers in registers (the points ``b0 … b3`` of a Bézier in the order it
# is checked: a spiral read backwards is passed backwards). Differences of
# world points are multiplied by ``inv`` (a power of two, 1/scale of the row)
# before they are squared, so nothing overflows or underflows; the residuals
# are relative and do not depend on ``inv``.


@jit
def end_leg(x1: float, y1: float, x2: float, y2: float, x3: float, y3: float, inv: float) -> tuple[float, float, float, float]:
    """At u = 1 of the Bézier ending b1, b2, b3: the last leg (bx, by) and its length,
    scaled by ``inv``, and the scaled signed curvature (2/3)(a × b)/|b|³, a = b2 − b1."""
    ax = (x2 - x1) * inv
    ay = (y2 - y1) * inv
    bx = (x3 - x2) * inv
    by = (y3 - y2) * inv
    lb = norm(bx, by)
    return bx, by, lb, 2.0 / 3.0 * (ax * by - ay * bx) / (lb * lb * lb)


@jit
def end_residual(
    x1: float,
    y1: float,
    x2: float,
    y2: float,
    x3: float,
    y3: float,
    cx: float,
    cy: float,
    radius: float,
    inv: float,
    rounding: float = ROUNDING,
) -> float:
    """How far the end (b1, b2, b3) of a Bézier is from joining circle (c, radius) G2.

    ``radius`` is signed by the travel sense of the Bézier (positive:
    counterclockwise): the end must lie on the circle, run along it in that
    sense and have curvature 1/radius. ``rounding`` (ROUNDING for a given
    circle) bounds the relative rounding of |b3 − c|; 0 where the centre is the
    spiral's own, derived from the same closed form (``spiral_row``).
    """
    bx, by, leg, kappa = end_leg(x1, y1, x2, y2, x3, y3, inv)
    if not leg > 0.0:
        return INF
    curvature = 1.0 / (radius * inv)
    # (dx, dy) = (b3 − c)/radius is the radial direction times the travel sense
    # (divided before squaring: the radius may dwarf the legs), so the end
    # leg b must be rot90 of it in either sense.
    dx = (x3 - cx) * inv * curvature
    dy = (y3 - cy) * inv * curvature
    distance = norm(dx, dy)
    size = abs(radius * inv)
    length = min(leg, size)  # the smaller feature sets the scale
    gap = (abs(distance - 1.0) + rounding) * size / length
    angle = abs(bx * dx + by * dy) / (leg * distance) + (INF if dx * by - dy * bx <= 0.0 else 0.0)
    return worst(worst(gap, angle), abs(kappa - curvature) * length)


@jit
def start_residual(
    x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, tx: float, ty: float, inv: float
) -> tuple[float, float]:
    """How far the start (b0, b1, b2) of a Bézier is from leaving along unit t with
    zero curvature (tangent angle, κ(0) × first leg; b1 − b0 must point along t).
    Also returns 1/|b1 − b0| (scaled)."""
    ax = (x1 - x0) * inv
    ay = (y1 - y0) * inv
    bx = (x2 - x1) * inv
    by = (y2 - y1) * inv
    la = norm(ax, ay)
    if not (la > 0.0 and tx * ax + ty * ay > 0.0):
        return INF, NAN
    inv_la = 1.0 / la
    angle = abs(tx * ay - ty * ax) * inv_la
    kappa0 = abs(2.0 / 3.0 * (ax * by - ay * bx)) * (inv_la * inv_la)  # κ(0) × first leg
    return worst(angle, kappa0), inv_la


@jit
def line_residual(
    x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, px: float, py: float, tx: float, ty: float, inv: float
) -> float:
    """How far the start (b0, b1, b2) of a spiral is from leaving the line through p
    along unit t with zero curvature (gap / first leg, tangent angle, κ(0) × first leg)."""
    res, inv_la = start_residual(x0, y0, x1, y1, x2, y2, tx, ty, inv)
    dx = (x0 - px) * inv
    dy = (y0 - py) * inv
    distance = (abs(tx * dy - ty * dx) + ROUNDING * (abs(dx) + abs(dy))) * inv_la
    return worst(distance, res)


@jit
def opposite_angle(ux: float, uy: float, lu: float, vx: float, vy: float, lv: float) -> float:
    """The tangent angle between u and −v (sine), given their lengths; infinite
    unless they point apart (two spirals' legs at the point they share)."""
    return abs(ux * vy - uy * vx) / (lu * lv) + (INF if ux * vx + uy * vy >= 0.0 else 0.0)


@jit
def joint_residual(
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
    inv: float,
) -> tuple[float, float, float]:
    """How far two spirals that meet at their ends (b3 of both, travelled towards
    each other) are from a G2 joint: gap, tangent angle, curvature jump × leg.
    Also returns the first spiral's scaled end curvature and end leg."""
    ux, uy, la, ka = end_leg(ax1, ay1, ax2, ay2, ax3, ay3, inv)
    vx, vy, lb, kb = end_leg(bx1, by1, bx2, by2, bx3, by3, inv)
    length = min(min(la, lb), 1.0 / abs(ka))
    if not length > 0.0:
        return INF, ka, la
    gap = norm((ax3 - bx3) * inv, (ay3 - by3) * inv) / length
    # Travelling towards each other, the tangents are opposite and so are the signed curvatures.
    angle = opposite_angle(ux, uy, la, vx, vy, lb)
    return worst(worst(gap, angle), abs(ka + kb) * length), ka, la


# Most rows are far inside the tolerance, and for them a sufficient test
# decides without square roots or divisions (the divider is what a row's
# arithmetic waits for): each ratio residual ≤ tol is checked as
# numerator ≤ tol × denominator, squared where the denominator is a length,
# with a margin that covers the rounding of the exact residual. A row that
# this test does not pass has its residuals computed exactly and is judged
# on them, so no row is accepted that the residuals above would refuse.

#: The tolerance of the sufficient tests (a 1e-12 relative margin below VERIFY_TOL).
FIT = VERIFY_TOL * (1.0 - 1e-12)
FIT2 = FIT * FIT


@row_jit
def moderate(v: float) -> bool:
    """Whether a squared length lies where the squared tests cannot overflow or underflow."""
    return 1e-100 < v < 1e100


@row_jit
def start_fits(x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, tx: float, ty: float, inv: float) -> bool:
    """Sufficient for ``start_residual`` ≤ VERIFY_TOL: |t × a| ≤ tol·|a| and
    |(2/3) a × b| ≤ tol·|a|², a = b1 − b0 along t, b = b2 − b1."""
    ax = (x1 - x0) * inv
    ay = (y1 - y0) * inv
    bx = (x2 - x1) * inv
    by = (y2 - y1) * inv
    aa = ax * ax + ay * ay
    cross = tx * ay - ty * ax
    curl = 2.0 / 3.0 * (ax * by - ay * bx)
    return moderate(aa) & (tx * ax + ty * ay > 0.0) & (cross * cross <= FIT2 * aa) & (curl * curl <= FIT2 * (aa * aa))


@row_jit
def line_fits(
    x0: float, y0: float, x1: float, y1: float, x2: float, y2: float, px: float, py: float, tx: float, ty: float, inv: float
) -> bool:
    """Sufficient for ``line_residual`` ≤ VERIFY_TOL: ``start_fits`` and |t × (b0 − p)| plus its
    rounding ≤ tol·|a|."""
    ax = (x1 - x0) * inv
    ay = (y1 - y0) * inv
    dx = (x0 - px) * inv
    dy = (y0 - py) * inv
    gap = abs(tx * dy - ty * dx) + ROUNDING * (abs(dx) + abs(dy))
    return start_fits(x0, y0, x1, y1, x2, y2, tx, ty, inv) & (gap * gap <= FIT2 * (ax * ax + ay * ay))


@row_jit
def opposite_fits(ux: float, uy: float, vx: float, vy: float) -> bool:
    """Sufficient for ``opposite_angle`` ≤ VERIFY_TOL: u·v < 0 and |u × v| ≤ tol·|u||v|."""
    uu = ux * ux + uy * uy
    vv = vx * vx + vy * vy
    cross = ux * vy - uy * vx
    return moderate(uu) & moderate(vv) & (ux * vx + uy * vy < 0.0) & (cross * cross <= FIT2 * (uu * vv))


@row_jit
def end_fits(
    x1: float,
    y1: float,
    x2: float,
    y2: float,
    x3: float,
    y3: float,
    cx: float,
    cy: float,
    radius: float,
    inv: float,
    rounding: float = ROUNDING,
) -> bool:
    """Sufficient for ``end_residual`` ≤ VERIFY_TOL, with o = b3 − c, b the end leg,
    r = radius and L = min(|b|, |r|): |o·o − r²| plus its rounding ≤ tol·|r|·L (then ||o| − |r|| ≤ tol·L),
    |b·o| ≤ tol·|b||o| with o × b of the sign of r, and |K·r − |b|³|·L ≤ tol·|b|³·|r|
    for the end curvature κ = K/|b|³ (one square root, for |b|)."""
    ax = (x2 - x1) * inv
    ay = (y2 - y1) * inv
    bx = (x3 - x2) * inv
    by = (y3 - y2) * inv
    ox = (x3 - cx) * inv
    oy = (y3 - cy) * inv
    rs = radius * inv
    bb = bx * bx + by * by
    oo = ox * ox + oy * oy
    rr = rs * rs
    leg = math.sqrt(bb)
    length = min(leg, abs(rs))
    off = oo - rr
    dot = bx * ox + by * oy
    cube = bb * leg
    return (
        moderate(bb)
        & moderate(oo)
        & moderate(rr)
        & ((ox * by - oy * bx) * rs > 0.0)
        & (abs(off) + rounding * (oo + rr) <= FIT * abs(rs) * length)
        & (dot * dot <= FIT2 * (bb * oo))
        & (abs(2.0 / 3.0 * (ax * by - ay * bx) * rs - cube) * length <= FIT * cube * abs(rs))
    )


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


# ------------------------------------------------------------ batches
# Each input has one row per problem or one row shared by all (``step`` 0):
# shared rows are read in place, never copied. Every row writes its own slot
# of ``out`` (control points, or NaN where it fails) and its status, θ and
# measure, so a batch may be cut into ranges of rows run on several threads
# (``spiral_cad.core.batch``; the kernels release the GIL).


@jit
def step(a: FloatArray) -> int:
    """1 for an input with a row per problem, 0 for one row shared by all."""
    return 1 if a.shape[0] > 1 else 0


#: Rows per block of a batch: each block's inputs are gathered into columns,
#: the ordinary rows solved on vectors of rows (``*_fast``), the others by the
#: general row functions.
BLOCK = 256


@jit
def line_to_circle_batch(
    p: FloatArray,
    d: FloatArray,
    c: FloatArray,
    r: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    sp, sd, sc, sr = step(p), step(d), step(c), step(r)
    cols = np.empty(7 * BLOCK)  # px, py, dx, dy, cx, cy, r of the block's rows
    res = np.empty(12 * BLOCK)  # ok, θ, measure, x0 … y3
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for k in range(m):
            i = start + k
            ip, id_, ic, ir = i * sp, i * sd, i * sc, i * sr
            cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k] = p[ip, 0], p[ip, 1], d[id_, 0], d[id_, 1]
            cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k] = c[ic, 0], c[ic, 1], r[ir]
        for k in range(m):
            row = line_to_circle_fast(
                cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k],
                cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k], shape,
            )  # fmt: skip
            ok, res[BLOCK + k], res[2 * BLOCK + k], _, x0, y0, x1, y1, x2, y2, x3, y3 = row
            res[k] = 1.0 if ok else 0.0
            res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k] = x0, y0, x1, y1
            res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k], res[11 * BLOCK + k] = x2, y2, x3, y3
        for k in range(m):
            i = start + k
            if res[k] == 1.0:
                store(out, i, 0, res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k],
                      res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k], res[11 * BLOCK + k])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + k], res[2 * BLOCK + k]
            else:
                row = line_to_circle_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k],
                    cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k], shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def circle_to_circle_batch(
    c0: FloatArray,
    r0: FloatArray,
    c1: FloatArray,
    r1: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    s0, sr0, s1, sr1 = step(c0), step(r0), step(c1), step(r1)
    cols = np.empty(6 * BLOCK)  # c0x, c0y, r0, c1x, c1y, r1 of the block's rows
    res = np.empty(17 * BLOCK)  # ok, θ, measure, s0 … s3, u1 … u3
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for k in range(m):
            i = start + k
            i0, j0, i1, j1 = i * s0, i * sr0, i * s1, i * sr1
            cols[k], cols[BLOCK + k], cols[2 * BLOCK + k] = c0[i0, 0], c0[i0, 1], r0[j0]
            cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k] = c1[i1, 0], c1[i1, 1], r1[j1]
        for k in range(m if shape == WALTON_MEEK else 0):  # other shapes need the general row's root search
            row = circle_to_circle_fast(
                cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k], shape
            )
            res[k] = 1.0 if row[0] else 0.0
            res[BLOCK + k], res[2 * BLOCK + k] = row[1], row[2]
            _, _, _, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y = row
            res[3 * BLOCK + k], res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k] = s0x, s0y, s1x, s1y
            res[7 * BLOCK + k], res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k] = s2x, s2y, s3x, s3y
            res[11 * BLOCK + k], res[12 * BLOCK + k], res[13 * BLOCK + k] = u1x, u1y, u2x
            res[14 * BLOCK + k], res[15 * BLOCK + k], res[16 * BLOCK + k] = u2y, u3x, u3y
        for k in range(m):
            i = start + k
            if shape == WALTON_MEEK and res[k] == 1.0:
                s0x, s0y = res[3 * BLOCK + k], res[4 * BLOCK + k]
                store(out, i, 0, res[15 * BLOCK + k], res[16 * BLOCK + k], res[13 * BLOCK + k], res[14 * BLOCK + k],
                      res[11 * BLOCK + k], res[12 * BLOCK + k], s0x, s0y)  # fmt: skip
                store(out, i, 1, s0x, s0y, res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k], res[8 * BLOCK + k],
                      res[9 * BLOCK + k], res[10 * BLOCK + k])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + k], res[2 * BLOCK + k]
            else:
                row = circle_to_circle_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k],
                    shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def line_to_line_batch(
    p0: FloatArray,
    p: FloatArray,
    p1: FloatArray,
    k: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    s0, sp, s1, sk = step(p0), step(p), step(p1), step(k)
    cols = np.empty(7 * BLOCK)  # p0x, p0y, px, py, p1x, p1y, curvature of the block's rows
    res = np.empty(19 * BLOCK)  # ok, θ, measure, Q0, Q1 as built
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for j in range(m):
            i = start + j
            i0, ip, i1, ik = i * s0, i * sp, i * s1, i * sk
            cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j] = p0[i0, 0], p0[i0, 1], p[ip, 0], p[ip, 1]
            cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j] = p1[i1, 0], p1[i1, 1], k[ik]
        for j in range(m):
            row = line_to_line_fast(
                cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j],
                cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j], shape,
            )  # fmt: skip
            ok, res[BLOCK + j], res[2 * BLOCK + j], x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = row
            res[j] = 1.0 if ok else 0.0
            res[3 * BLOCK + j], res[4 * BLOCK + j], res[5 * BLOCK + j], res[6 * BLOCK + j] = x0, y0, x1, y1
            res[7 * BLOCK + j], res[8 * BLOCK + j], res[9 * BLOCK + j], res[10 * BLOCK + j] = x2, y2, x3, y3
            res[11 * BLOCK + j], res[12 * BLOCK + j], res[13 * BLOCK + j], res[14 * BLOCK + j] = v3x, v3y, v2x, v2y
            res[15 * BLOCK + j], res[16 * BLOCK + j], res[17 * BLOCK + j], res[18 * BLOCK + j] = v1x, v1y, v0x, v0y
        for j in range(m):
            i = start + j
            if res[j] == 1.0:
                store(out, i, 0, res[3 * BLOCK + j], res[4 * BLOCK + j], res[5 * BLOCK + j], res[6 * BLOCK + j],
                      res[7 * BLOCK + j], res[8 * BLOCK + j], res[9 * BLOCK + j], res[10 * BLOCK + j])  # fmt: skip
                store(out, i, 1, res[11 * BLOCK + j], res[12 * BLOCK + j], res[13 * BLOCK + j], res[14 * BLOCK + j],
                      res[15 * BLOCK + j], res[16 * BLOCK + j], res[17 * BLOCK + j], res[18 * BLOCK + j])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + j], res[2 * BLOCK + j]
            else:
                row = line_to_line_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j],
                    cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j], shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def circle_in_circle_batch(
    c0: FloatArray,
    r0: FloatArray,
    c1: FloatArray,
    r1: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
    param: FloatArray,
) -> None:
    s0, sr0, s1, sr1 = step(c0), step(r0), step(c1), step(r1)
    for i in range(out.shape[0]):
        i0, j0, i1, j1 = i * s0, i * sr0, i * s1, i * sr1
        row = circle_in_circle_row(c0[i0, 0], c0[i0, 1], r0[j0], c1[i1, 0], c1[i1, 1], r1[j1], shape, out, i)
        status[i], theta[i], measure[i], param[i] = row


KERNELS.seal()
