"""G2 corner rounding of polylines with pairs of Bézier spirals.

Each corner gets a symmetric spiral pair (the ``line_to_line`` transition)
of one of the corner shapes (``spiral_cad.core.shapes``):

* ``"walton-meek"``: Theorem 4.4 of Walton & Meek (1996), peak curvature
  ``(40/27) sin θ / (d cos² θ)``;
* ``"near-linear"``: curvature almost linear in arc length (deflections up
  to 100°);
* ``"g2cbs"``: the curvature-bounded pair of Yang & Sukkarieh (2010) with
  leg ratio g/h = c2 = 2(√6 − 1)/5, the smallest that keeps the curvature
  monotone; peak curvature ``c4 sin θ / (d cos² θ)`` with c4 ≈ 1.12249,
  i.e. about 24 % lower than Walton–Meek for the same corner distance d
  (c4 / (40/27) ≈ 0.758).

Here θ is half the corner's deflection and d the distance from the corner to
where each spiral leaves its leg: d = K(θ)/κ with κ the joint (peak)
curvature and K the shape's corner factor. The array functions
(``corner_legs``, ``round_corners_batch``) handle millions of corners;
``round_corners`` builds a checked :class:`~spiral_cad.Chain` for one polyline.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core import _kernels as K
from ..core import batch
from ..core._inputs import as_float, as_points, as_real_array
from ..core.chain import JOIN_TOLERANCE, Chain, PartCircles, join_rows, join_tolerance
from ..core.errors import JointError, NoSolutionError, Status
from ..core.rows import SegmentRows
from ..core.shapes import CORNER_SHAPES, DEFAULT_SHAPE, SHAPE_CODES, shape_code
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS, length_unit

#: Yang & Sukkarieh's leg ratio g/h: the smallest that keeps κ monotone.
G2CBS_C2 = K.G2CBS_RATIO
#: Exact c1 = (c2 + 1)(c2 + 4) (the paper prints a rounded value that leaves a gap).
G2CBS_C1 = (G2CBS_C2 + 1.0) * (G2CBS_C2 + 4.0)
#: h = c3·d.
G2CBS_C3 = (G2CBS_C2 + 4.0) / (G2CBS_C1 + 6.0)
#: κmax = c4 sin β / (d cos² β): the G2CBS corner factor K(β) = c4·sin β/cos² β.
G2CBS_C4 = (G2CBS_C2 + 4.0) ** 2 / (54.0 * G2CBS_C3)

#: Relative |sin| below which three points count as collinear (passed through).
COLLINEAR_TOL = 1e-12


def corner_scale(theta_sin: ArrayLike, theta_cos: ArrayLike, value: ArrayLike, shape: str) -> NDArray:
    """``K(θ)/value`` of ``shape`` (``K`` its corner factor, ``spiral_cad.core._kernels.corner_factor``).

    The relation between the corner distance d and the peak (joint) curvature κ
    of a spiral pair is symmetric: pass κ to get d, or d to get κ.
    """
    sin_t, cos_t, value = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta_sin, theta_cos, value)))
    factor = np.empty(sin_t.size)
    K.corner_factor_batch(SHAPE_CODES[shape], np.ravel(sin_t), np.ravel(cos_t), factor)
    return factor.reshape(sin_t.shape) / value


def corner_shape(shape: str, method: str | None) -> str:
    """The corner shape from ``shape`` or from ``method`` (its former name), checked."""
    if method is None:
        shape_code(shape, CORNER_SHAPES)
        return shape
    if shape != DEFAULT_SHAPE and shape != method:
        raise ValueError(f"give shape or method (its former name), not both; got shape={shape!r}, method={method!r}")
    shape_code(method, CORNER_SHAPES, "method")
    return method


# ------------------------------------------------------------ array API


@dataclass(frozen=True)
class CornerBatch:
    """Spiral pairs for N corners (one row per corner).

    Attributes:
        shape: ``"walton-meek"``, ``"near-linear"`` or ``"g2cbs"``.
        control_points: (N, 2, 4, 2) the two spirals of each corner in travel
            order; NaN where ``status`` ≠ 0.
        theta: (N,) half the deflection (each spiral's turn), NaN when undefined.
        distance: (N,) corner-to-spiral-start distance used (or required).
        curvature: (N,) peak |κ| of the pair (at its joint), used or required.
        available: (N,) the longest distance the legs allow.
        status: (N,) ``spiral_cad.Status`` codes; 0 where rounded.
        corners: (N, 2) the corner points.
        requested: (N,) the curvature asked for (NaN: as large as fits).
        residual: (N,) for ``UNVERIFIED`` rows, how far the pair's joins are
            off (relative); NaN elsewhere.
    """

    shape: str
    control_points: NDArray
    theta: NDArray
    distance: NDArray
    curvature: NDArray
    available: NDArray
    status: NDArray
    corners: NDArray
    requested: NDArray
    residual: NDArray

    @property
    def ok(self) -> NDArray:
        return self.status == Status.OK

    def __len__(self) -> int:
        return len(self.status)

    def reason(self, i: int, label: str | None = None) -> str:
        """Why corner ``i`` could not be rounded (``"ok"`` if it was)."""
        status = Status(int(self.status[i]))
        name = label or f"corner {i}"
        where = f"{name} at ({self.corners[i, 0]:.10g}, {self.corners[i, 1]:.10g})"
        if status is Status.OK:
            return "ok"
        if status is Status.LEGS_TOO_SHORT:
            return (
                f"{where}: curvature {self.requested[i]:.6g} needs the spirals to start "
                f"{self.distance[i]:.6g} from the corner but only {self.available[i]:.6g} is available "
                f"(each corner may use half of an interior leg); this corner needs curvature "
                f"≥ {self.curvature[i]:.6g} ({self.shape})"
            )
        if status is Status.CORNER_REVERSAL:
            return f"{where}: the path folds back (deflection ≥ 180°); no spiral pair exists"
        if status is Status.CORNER_STRAIGHT:
            return f"{where}: the legs are collinear, there is nothing to round"
        if status is Status.OUTSIDE_SHAPE:
            return (
                f"{where}: deflection {2 * math.degrees(self.theta[i]):.6g}° is beyond what {self.shape} spiral pairs "
                f"round ({2 * math.degrees(K.NEAR_LINEAR_MAX_THETA):g}° at most); use shape='walton-meek'"
            )
        if status is Status.COINCIDENT:
            return f"{where}: a leg has zero length"
        if status is Status.UNVERIFIED:
            return (
                f"{where}: the spiral pair for curvature {self.curvature[i]:.6g} would start "
                f"{self.distance[i]:.3g} from the corner, too small for float64 at these coordinates: its joins "
                f"hold only to {self.residual[i]:.2g} (at most 1e-9 is returned); use a lower curvature"
            )
        return f"{where}: no spiral pair ({status.name})"


def _half_deflection(p0: NDArray, corners: NDArray, p1: NDArray):
    """Leg lengths and sin/cos of half the deflection."""
    vin = corners - p0
    vout = p1 - corners
    lin = np.hypot(vin[:, 0], vin[:, 1])
    lout = np.hypot(vout[:, 0], vout[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        t_in = vin / lin[:, None]
        t_out = vout / lout[:, None]
        joint = t_in + t_out
        joint /= np.hypot(joint[:, 0], joint[:, 1])[:, None]
    sin_t = np.abs(t_in[:, 0] * joint[:, 1] - t_in[:, 1] * joint[:, 0])
    cos_t = np.einsum("ij,ij->i", t_in, joint)
    return lin, lout, sin_t, cos_t


def _requested(curvature: ArrayLike | None, max_curvature: ArrayLike | None, n: int) -> NDArray:
    if curvature is not None and max_curvature is not None:
        raise ValueError("give curvature or max_curvature, not both")
    value = curvature if curvature is not None else max_curvature
    name = "curvature" if curvature is not None else "max_curvature"
    if value is None:
        return np.full(n, np.nan)
    k = as_real_array(value, name)
    if k.ndim > 1 or k.size not in (1, n):
        raise ValueError(f"{name} needs one value or one per corner ({n}); got shape {k.shape}")
    k = np.broadcast_to(k.reshape(-1), (n,))
    bad = ~(np.isfinite(k) & (k > 0.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name} must be positive and finite; got {k[i]} (corner {i})")
    return np.ascontiguousarray(k)


def round_corners_batch(
    p0: ArrayLike,
    corners: ArrayLike,
    p1: ArrayLike,
    *,
    curvature: ArrayLike | None = None,
    max_curvature: ArrayLike | None = None,
    shape: str = DEFAULT_SHAPE,
    method: str | None = None,
) -> CornerBatch:
    """Round N independent corners ``p0 → corner → p1`` with spiral pairs.

    The spirals of a corner must start between ``p0`` and the corner and end
    between the corner and ``p1``: pass the leg ends each corner may use (see
    :func:`corner_legs` for polylines).

    Args:
        p0, corners, p1: (N, 2) arrays (or broadcastable (2,)).
        curvature: joint curvature (scalar or (N,)); the pair peaks there.
        max_curvature: a bound κmax: each corner uses the smallest distance
            that respects it, i.e. its joint curvature equals κmax.
        shape: ``"walton-meek"`` (Theorem 4.4), ``"near-linear"`` or
            ``"g2cbs"`` (Yang & Sukkarieh); every pair is solved and verified
            by ``spiral_cad.batch.line_to_line``.
        method: the former name of ``shape``.

    With neither curvature given, each corner uses all of its shorter leg
    (Corollary 4.5: the lowest curvature that fits). Rows that fail carry a
    status (``CornerBatch.reason`` explains); the others are unaffected.
    """
    shape = corner_shape(shape, method)
    arrays = np.broadcast_arrays(as_points(p0, "p0"), as_points(corners, "corners"), as_points(p1, "p1"))
    p0, corners, p1 = (np.ascontiguousarray(a.reshape(-1, 2)) for a in arrays)
    n = len(corners)
    k = _requested(curvature, max_curvature, n)
    lin, lout, sin_t, cos_t = _half_deflection(p0, corners, p1)
    available = np.minimum(lin, lout)
    fit = np.isnan(k)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # a tiny leg: the curvature it needs overflows
        distance = np.where(fit, available, corner_scale(sin_t, cos_t, k, shape))
        needed = corner_scale(sin_t, cos_t, available, shape)
    result = batch.line_to_line(p0, corners, p1, k, shape=shape)
    control_points = np.stack(result.spirals, axis=1)
    status = result.status.astype(np.int8)
    residual = np.where(status == Status.UNVERIFIED, result.measure, np.nan)
    ok = status == 0
    theta = np.where(sin_t > 0.0, np.arctan2(sin_t, cos_t), np.nan)
    # Failed rows report what they would need: the distance asked for and the
    # curvature that would exactly fit the available legs.
    peak = np.where(ok, np.where(fit, needed, k), needed)
    return CornerBatch(shape, control_points, theta, distance, peak, available, status, corners, k, residual)


def corner_legs(points: ArrayLike) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The leg ends each interior corner of a polyline may use.

    Interior segments are shared half-and-half between their two corners; the
    first and last segments belong wholly to their one corner, so spirals of
    neighbouring corners never overlap. Collinear interior points (forward)
    are dropped: they need no rounding.

    Returns:
        ``(p0, corners, p1, index)``: (M, 2) leg ends and corners, and the
        index of each corner in ``points``.

    Raises:
        ValueError: fewer than 3 points, non-finite or repeated consecutive
            points, or a polyline that folds straight back on itself.
    """
    pts = as_points(points, "points")
    if pts.ndim != 2 or len(pts) < 3:
        raise ValueError(f"points must be an (n ≥ 3, 2) polyline; got shape {pts.shape}")
    if not np.isfinite(pts).all():
        i = int(np.argmax(~np.isfinite(pts).all(axis=1)))
        raise ValueError(f"points must be finite; point {i} is {pts[i].tolist()}")
    seg = np.diff(pts, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    if not (length > 0.0).all():
        i = int(np.argmax(~(length > 0.0)))
        raise ValueError(f"points {i} and {i + 1} coincide at {pts[i].tolist()}")
    unit = seg / length[:, None]
    cross = unit[:-1, 0] * unit[1:, 1] - unit[:-1, 1] * unit[1:, 0]
    dot = np.einsum("ij,ij->i", unit[:-1], unit[1:])
    straight = np.abs(cross) <= COLLINEAR_TOL
    folds = straight & (dot < 0.0)
    if folds.any():
        i = int(np.argmax(folds)) + 1
        raise ValueError(f"the polyline folds straight back at point {i} {pts[i].tolist()}")
    index = np.concatenate([[0], np.flatnonzero(~straight) + 1, [len(pts) - 1]])
    kept = pts[index]
    seg = np.diff(kept, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    unit = seg / length[:, None]
    share = np.full(len(length), 0.5)
    share_in = share[:-1].copy()
    share_out = share[1:].copy()
    if len(share_in):
        share_in[0] = 1.0
        share_out[-1] = 1.0
    corners = kept[1:-1]
    p0 = corners - (share_in * length[:-1])[:, None] * unit[:-1]
    p1 = corners + (share_out * length[1:])[:, None] * unit[1:]
    # Exact leg ends at the polyline's end points (no rounding drift there).
    if len(corners):
        p0[0] = kept[0]
        p1[-1] = kept[-1]
    return p0, corners, p1, index[1:-1]


# ------------------------------------------------------------ chain API


@dataclass(frozen=True)
class RoundedCorner:
    """One rounded corner: its index in the input points and its spiral pair."""

    index: int
    theta: float
    distance: float
    curvature: float
    spirals: tuple[BezierSpiral, BezierSpiral]


@dataclass(frozen=True)
class RoundedPath:
    """A rounded polyline: the G2 chain and the data of every rounded corner."""

    chain: Chain
    corners: list[RoundedCorner]
    shape: str

    @property
    def method(self) -> str:
        """The former name of ``shape``."""
        return self.shape

    @property
    def max_curvature(self) -> float:
        """Largest peak |κ| over the corners (0 for a straight polyline)."""
        return max((c.curvature for c in self.corners), default=0.0)


def round_corners(
    points: ArrayLike,
    *,
    curvature: float | None = None,
    max_curvature: float | None = None,
    shape: str = DEFAULT_SHAPE,
    method: str | None = None,
    tolerance: float = JOIN_TOLERANCE,
    units: str = DEFAULT_UNITS,
) -> RoundedPath:
    """Round every corner of a polyline with a G2 spiral pair.

    Args:
        points: (n ≥ 3, 2) polyline vertices.
        curvature: joint (peak) curvature of every corner's pair.
        max_curvature: bound κmax; each corner uses the smallest distance
            from the corner that respects it (so its peak equals κmax).
        shape: ``"walton-meek"`` (Theorem 4.4), ``"near-linear"`` (curvature
            almost linear in arc length; deflections up to 100°) or ``"g2cbs"``
            (Yang & Sukkarieh: about 24 % lower peak curvature for the same
            corner distance).
        method: the former name of ``shape``.
        tolerance: the chain's relative join tolerance (``Chain``).
        units: length unit of the points (default mm); curvatures are per unit.

    With neither curvature given, each corner uses as much of its legs as it
    may (Corollary 4.5): half of every interior segment, all of the first and
    last. Collinear interior points are passed through.

    Returns:
        A :class:`RoundedPath`: chain from the first to the last point.

    Raises:
        NoSolutionError: a corner's legs are too short for the curvature
            (the message names the corner index and the curvature it needs).
        ValueError: malformed input.
    """
    for name, value in (("curvature", curvature), ("max_curvature", max_curvature)):
        if value is not None:
            as_float(value, name)
    shape = corner_shape(shape, method)
    pts = as_points(points, "points")
    p0, corners, p1, index = corner_legs(pts)
    rounded: list[RoundedCorner] = []
    spirals = np.empty((0, 2, 4, 2))
    if len(corners):
        result = round_corners_batch(p0, corners, p1, curvature=curvature, max_curvature=max_curvature, shape=shape)
        for j in np.flatnonzero(~result.ok):
            message = result.reason(int(j), label=f"corner {index[j]}")
            if result.status[j] in (Status.LEGS_TOO_SHORT, Status.CORNER_REVERSAL, Status.UNVERIFIED, Status.OUTSIDE_SHAPE):
                raise NoSolutionError(message)
            raise ValueError(message)
        spirals = result.control_points
        numbers = zip(index.tolist(), result.theta.tolist(), result.distance.tolist(), result.curvature.tolist())
        for cp, (i, theta, distance, peak) in zip(spirals, numbers):
            pair = (BezierSpiral._wrap(cp[0], shape), BezierSpiral._wrap(cp[1], shape))
            rounded.append(RoundedCorner(i, theta, distance, peak, pair))
    # Each corner's pair is one part; the lines between them follow (``Chain.join`` on arrays).
    rows = SegmentRows.spirals(spirals.reshape(-1, 4, 2), shape)
    objects = [s for corner in rounded for s in corner.spirals]
    try:
        chain = join_rows(rows, np.full(len(rounded), 2), PartCircles(len(rounded)), tuple(pts[0].tolist()),
                          tuple(pts[-1].tolist()), join_tolerance(tolerance), length_unit(units), objects)  # fmt: skip
    except JointError as error:
        raise NoSolutionError(f"corner {index[error.part]}: float64 cannot hold its spirals G2 at these coordinates: {error}") from None
    return RoundedPath(chain, rounded, shape)

