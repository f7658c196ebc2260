"""Compiled kernels of chains: segment end frames, rounding floors, joint measures, connectors.

Segments are rows of three arrays (``spiral_cad.core.rows``): ``kind`` (n,),
``geometry`` (n, 4, 3) and ``params`` (n, 3), always with three coordinates
(a plane segment has z = 0), so every formula here is written once, for
3-vectors:

* a line: geometry rows 0 and 1 are its start and end;
* an arc: row 0 its centre, rows 1 and 2 the orthonormal basis (e1, e2) of
  its plane (for a plane arc the x and y axes); params (signed radius, start
  angle, sweep > 0): the point at angle a is centre + |r|·(cos a·e1 + sin a·e2)
  and travel runs from the start angle by sign(r)·sweep;
* a spiral: rows 0–3 its control points.

An end frame is 9 floats: point, unit tangent (travel sense) and the turn
vector ω = κB = T × κN (the tangent turns about it at rate κ). In the plane
ω = (0, 0, κ) with κ the signed curvature, so plane joints are judged on
exactly the numbers they always were; in space |Δω| equals the jump of the
curvature vector κN up to κ × the tangent angle (which is checked too).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .jit import Kernels
from .kinds import ARC, LINE

if TYPE_CHECKING:  # annotations only: the kernels' namespace (what numba compiles against) stays as it is
    from typing import TypeAlias

    import numpy as np
    import numpy.typing as npt

    FloatArray: TypeAlias = npt.NDArray[np.float64]
    KindArray: TypeAlias = npt.NDArray[np.int8]

KERNELS = Kernels(globals())
jit = KERNELS.jit

TAU = 2.0 * math.pi
EPS = 2.220446049250313e-16
#: Rounding allowance (angle, relative curvature) of an arc whose plane basis is not the xy axes.
BASIS_ULPS = 8.0 * EPS
#: Two ends within this many ulps of their coordinates meet: float64 cannot place a line between them.
MEET_ULPS = 8.0


#: Sums of squares between these bounds hold every digit of a length: no square overflowed, and
#: squares that underflowed are below the sum's last digit.
SQUARES_LOW, SQUARES_HIGH = 1e-290, 1e290


@jit
def norm3(x: float, y: float, z: float) -> float:
    """|(x, y, z)| without overflow or underflow, within two units of rounding of the exact length.

    The square root of the sum of squares wherever no square can overflow or lose digits
    (a few nanoseconds; the joints of a million corners measure tens of millions of lengths),
    else ``hypot`` twice (scaled: exact at any magnitude, ten times slower). NaN and inf
    propagate as ``hypot``'s do.
    """
    squares = x * x + y * y + z * z
    if SQUARES_LOW < squares < SQUARES_HIGH:
        return math.sqrt(squares)
    return math.hypot(math.hypot(x, y), z)


@jit
def _max_abs(g: FloatArray, rows: int) -> float:
    """The largest |coordinate| of the first ``rows`` points of ``g`` (4, 3)."""
    big = 0.0
    for i in range(rows):
        for j in range(3):
            big = max(big, abs(g[i, j]))
    return big


@jit
def _line(g: FloatArray, frames: FloatArray, floors: FloatArray) -> float:
    dx, dy, dz = g[1, 0] - g[0, 0], g[1, 1] - g[0, 1], g[1, 2] - g[0, 2]
    length = norm3(dx, dy, dz)
    delta = 4.0 * EPS * _max_abs(g, 2)
    for end in range(2):
        for j in range(3):
            frames[end, j] = g[end, j]
            frames[end, 6 + j] = 0.0
        frames[end, 3], frames[end, 4], frames[end, 5] = dx / length, dy / length, dz / length
        floors[end, 0], floors[end, 1], floors[end, 2] = delta, delta / length, 0.0
    return length


@jit
def _arc(g: FloatArray, p: FloatArray, flat: bool, frames: FloatArray, floors: FloatArray) -> float:
    r: float  # elements of the float64 params row (declarations only: no code)
    sweep: float
    r, a0, sweep = p[0], p[1], p[2]
    rho = abs(r)
    sense = math.copysign(1.0, r)
    # The plane normal e1 × e2 ((0, 0, 1) for a plane arc): ω = n / r.
    nx = g[1, 1] * g[2, 2] - g[1, 2] * g[2, 1]
    ny = g[1, 2] * g[2, 0] - g[1, 0] * g[2, 2]
    nz = g[1, 0] * g[2, 1] - g[1, 1] * g[2, 0]
    k = 1.0 / r
    for end in range(2):
        angle = a0 if end == 0 else a0 + sense * sweep
        c, s = math.cos(angle), math.sin(angle)
        big = 0.0
        for j in range(3):
            frames[end, j] = g[0, j] + rho * (c * g[1, j] + s * g[2, j])
            frames[end, 3 + j] = sense * (-s * g[1, j] + c * g[2, j])
            big = max(big, abs(frames[end, j]))
        frames[end, 6], frames[end, 7], frames[end, 8] = k * nx, k * ny, k * nz
        floors[end, 0] = 4.0 * EPS * big
        # A rotated basis holds its own rounding; the xy axes are exact.
        floors[end, 1] = 0.0 if flat else BASIS_ULPS
        floors[end, 2] = 0.0 if flat else BASIS_ULPS * abs(k)
    return rho * sweep


@jit
def _cross(ax: float, ay: float, az: float, bx: float, by: float, bz: float) -> tuple[float, float, float]:
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@jit
def _spiral(g: FloatArray, frames: FloatArray, floors: FloatArray) -> None:
    """End frames from the legs: tangent a/|a|, ω = (2/3)·(a × b)/|a|³ at the start (c, b at the end)."""
    ux, uy, uz = g[1, 0] - g[0, 0], g[1, 1] - g[0, 1], g[1, 2] - g[0, 2]
    vx, vy, vz = g[2, 0] - g[1, 0], g[2, 1] - g[1, 1], g[2, 2] - g[1, 2]
    wx, wy, wz = g[3, 0] - g[2, 0], g[3, 1] - g[2, 1], g[3, 2] - g[2, 2]
    # Legs divided by their largest component keep |leg|³ in range at any magnitude.
    scale = max(abs(ux), abs(uy), abs(uz), abs(vx), abs(vy), abs(vz), abs(wx), abs(wy), abs(wz))
    ax, ay, az = ux / scale, uy / scale, uz / scale
    bx, by, bz = vx / scale, vy / scale, vz / scale
    cx, cy, cz = wx / scale, wy / scale, wz / scale
    la, lc = norm3(ax, ay, az), norm3(cx, cy, cz)
    w0 = _cross(ax, ay, az, bx, by, bz)
    w1 = _cross(bx, by, bz, cx, cy, cz)
    for j in range(3):
        frames[0, j], frames[1, j] = g[0, j], g[3, j]
        frames[0, 6 + j] = 2.0 / 3.0 * w0[j] / math.pow(la, 3.0) / scale
        frames[1, 6 + j] = 2.0 / 3.0 * w1[j] / math.pow(lc, 3.0) / scale
    frames[0, 3], frames[0, 4], frames[0, 5] = ax / la, ay / la, az / la
    frames[1, 3], frames[1, 4], frames[1, 5] = cx / lc, cy / lc, cz / lc
    # Rounding floors: κ comes from differences of rounded control points,
    # (2/3)(a × b)/|a|³ with a the end leg and b the middle leg. They are
    # evaluated on the legs scaled by a power of two (exact), so a spiral of
    # any magnitude gets the floor of its scaled copy, scaled back.
    two = math.ldexp(1.0, math.frexp(scale)[1] - 1)
    ds = 4.0 * EPS * (_max_abs(g, 4) / two)  # the rounding of the scaled copy (``two``: a power of two)
    middle = norm3(vx / two, vy / two, vz / two)
    for end in range(2):
        if end == 0:
            a = norm3(ux / two, uy / two, uz / two)
        else:
            a = norm3(wx / two, wy / two, wz / two)
        kappa = norm3(frames[end, 6], frames[end, 7], frames[end, 8]) * two
        floors[end, 0] = ds * two
        floors[end, 1] = ds / a
        floors[end, 2] = (2.0 / 3.0 * ds * (a + middle) / math.pow(a, 3.0) + 3.0 * kappa * ds / a) / two


@jit
def segment_ends(
    kind: KindArray, geometry: FloatArray, params: FloatArray, flat: bool, frames: FloatArray, floors: FloatArray, lengths: FloatArray
) -> None:
    """End frames (n, 2, 9), rounding floors (n, 2, 3: gap, angle, curvature) and lengths (n,)
    of segment rows; a spiral's length is left as it was (it needs quadrature)."""
    for i in range(len(kind)):
        if kind[i] == LINE:
            lengths[i] = _line(geometry[i], frames[i], floors[i])
        elif kind[i] == ARC:
            lengths[i] = _arc(geometry[i], params[i], flat, frames[i], floors[i])
        else:
            _spiral(geometry[i], frames[i], floors[i])


@jit
def _capped(floor: float, cap: float) -> float:
    """min(floor, cap), with a floor float64 could not hold (NaN) taken as unbounded."""
    return floor if floor <= cap else cap


@jit
def joint_measures(
    end: FloatArray,
    floor_end: FloatArray,
    length_a: FloatArray,
    start: FloatArray,
    floor_start: FloatArray,
    length_b: FloatArray,
    own: FloatArray,
    tolerance: float,
    cap: float,
    out: FloatArray,
) -> int:
    """Measure and judge m joints: from frames ``end`` (m, 9) of the segments before to ``start``
    (m, 9) of the segments after, with their rounding floors (m, 3) and lengths (m,).

    ``own`` (m,) is the joint's own curvature scale: the largest |κ| either
    segment reaches at any of its ends (0 between lines; a spiral's peak).
    ``out`` (m, 6) receives gap, tangent angle, curvature jump |Δω|, the shorter
    length, the curvature scale max(|κ_a|, |κ_b|, own, 1/L_long) and 1.0 where
    the joint fails (``spiral_cad.core.chain.Chain`` states the rule). Returns
    the index of the first failing joint, or -1.
    """
    first = -1
    for i in range(len(out)):
        a, b = end[i], start[i]
        gap = norm3(b[0] - a[0], b[1] - a[1], b[2] - a[2])
        cx, cy, cz = _cross(a[3], a[4], a[5], b[3], b[4], b[5])
        dot = a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
        angle = math.atan2(norm3(cx, cy, cz), dot)  # in the plane: |atan2(cross, dot)| (atan2 is odd in y)
        jump = norm3(b[6] - a[6], b[7] - a[7], b[8] - a[8])
        la, lb = length_a[i], length_b[i]
        short, long = min(la, lb), max(la, lb)
        at_joint = max(norm3(a[6], a[7], a[8]), norm3(b[6], b[7], b[8]), 1.0 / long)
        kappa = max(at_joint, own[i])
        g_floor = _capped(floor_end[i, 0] + floor_start[i, 0], cap * short)
        a_floor = _capped(floor_end[i, 1] + floor_start[i, 1], cap)
        # The rounding allowance stays capped on the joint's curvatures: a spiral's peak widens
        # the tolerance, never what its rounding may hide.
        k_floor = _capped(floor_end[i, 2] + floor_start[i, 2], cap * at_joint)
        bad = gap > tolerance * short + g_floor or angle > tolerance + a_floor or jump > tolerance * kappa + k_floor
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = gap, angle, jump, short, kappa
        out[i, 5] = 1.0 if bad else 0.0
        if bad and first < 0:
            first = i
    return first


@jit
def connectors(
    a: FloatArray,
    b: FloatArray,
    scale: FloatArray,
    circle: npt.NDArray[np.bool_],
    center: FloatArray,
    radius: FloatArray,
    basis: FloatArray,
    flat: bool,
    tolerance: float,
    kind: KindArray,
    geometry: FloatArray,
    params: FloatArray,
) -> None:
    """The segment bridging each of m gaps from point ``a`` to ``b`` (m, 3).

    ``kind`` receives -1 where the points meet (|b − a| ≤ tolerance·scale, or
    within ``MEET_ULPS`` of the coordinates' rounding: a line there would point
    anywhere), else LINE, or ARC where ``circle`` is set: the arc of that circle
    (``center``, signed ``radius``, plane ``basis`` (m, 2, 3)) from the polar
    angle of ``a`` to that of ``b`` in the radius's travel sense, sweep in
    [0, 2π) (``Arc.between``). ``geometry``/``params`` receive the rows.
    """
    for i in range(len(kind)):
        dx, dy, dz = b[i, 0] - a[i, 0], b[i, 1] - a[i, 1], b[i, 2] - a[i, 2]
        for r in range(4):
            for j in range(3):
                geometry[i, r, j] = 0.0
        params[i, 0], params[i, 1], params[i, 2] = 0.0, 0.0, 0.0
        magnitude = max(abs(a[i, 0]), abs(a[i, 1]), abs(a[i, 2]), abs(b[i, 0]), abs(b[i, 1]), abs(b[i, 2]))
        if norm3(dx, dy, dz) <= max(tolerance * scale[i], MEET_ULPS * EPS * magnitude):
            kind[i] = -1
        elif not circle[i]:
            kind[i] = LINE
            for j in range(3):
                geometry[i, 0, j], geometry[i, 1, j] = a[i, j], b[i, j]
        else:
            kind[i] = ARC
            angles = [0.0, 0.0]
            for k in range(2):
                p = a[i] if k == 0 else b[i]
                if flat:
                    u, v = p[0] - center[i, 0], p[1] - center[i, 1]
                else:
                    u = v = 0.0
                    for j in range(3):
                        d = p[j] - center[i, j]
                        u += d * basis[i, 0, j]
                        v += d * basis[i, 1, j]
                angles[k] = math.atan2(v, u)
            for j in range(3):
                geometry[i, 0, j] = center[i, j]
                geometry[i, 1, j], geometry[i, 2, j] = basis[i, 0, j], basis[i, 1, j]
            params[i, 0], params[i, 1] = radius[i], angles[0]
            params[i, 2] = math.copysign(1.0, radius[i]) * (angles[1] - angles[0]) % TAU  # Python's float %


KERNELS.seal()
