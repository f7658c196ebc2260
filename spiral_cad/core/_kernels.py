"""Compiled kernels: every formula of the spiral and of its five transitions, once — here what every
solver shares (the status codes, the spiral shapes, frames and numbers, the checks of step 5), and one
module per solver beside it (``_kernel_spiral``, ``_kernel_line_circle``, ``_kernel_circles``,
``_kernel_line_line``, ``_kernel_batches``), each with its own ``Kernels``.

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


KERNELS.seal()
