"""G2 corner rounding of polylines, in the plane or in space, with pairs of Bézier spirals.

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
curvature and K the shape's corner factor; the path passes h = D(θ)/κ from
the corner (its deviation, ``deviation_factor``). A corner of a polyline in
space lies in the plane of its two legs: it is solved in that plane
(``spiral_cad.core.space.corner_frames``) by the same batch kernel as a plane
corner and placed back; between corners the path is straight (κ = 0), so
corners in different planes still join G2. The array functions
(``corner_legs``, ``round_corners_batch``) handle millions of corners;
``spiral_cad.design.rounded_paths.round_corners`` builds a checked :class:`~spiral_cad.Chain` for one polyline on them.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core import _chain_kernels as CK
from ..core import _kernel_spiral as KS
from ..core import _kernels as K
from ..core import batch
from ..core.chain import JOIN_TOLERANCE, ROUNDING_CAP, join_tolerance
from ..core.errors import Status
from ..core.factors import length_factor
from ..core.inputs import as_real_array
from ..core.jit import Kernels
from ..core.shapes import CORNER_SHAPES, DEFAULT_SHAPE, SHAPE_CODES, shape_code
from ..core.space import corner_frames, norms, place, placed_pair_residuals
from ..core.threads import run_split

#: Yang & Sukkarieh's leg ratio g/h: the smallest that keeps κ monotone.
G2CBS_C2 = K.G2CBS_RATIO
#: Exact c1 = (c2 + 1)(c2 + 4) (the paper prints a rounded value that leaves a gap).
G2CBS_C1 = (G2CBS_C2 + 1.0) * (G2CBS_C2 + 4.0)
#: h = c3·d.
G2CBS_C3 = (G2CBS_C2 + 4.0) / (G2CBS_C1 + 6.0)
#: κmax = c4 sin β / (d cos² β): the G2CBS corner factor K(β) = c4·sin β/cos² β.
G2CBS_C4 = (G2CBS_C2 + 4.0) ** 2 / (54.0 * G2CBS_C3)

#: A ``max_deviation`` pair is aimed this much (relative) inside its bound, and
#: further by the rounding of the corner's coordinates (``ROUNDING_ULPS`` ulp of
#: the largest), so that its measured deviation never exceeds the bound.
DEVIATION_MARGIN = 1e-12
ROUNDING_ULPS = 8.0
EPS = float(np.finfo(float).eps)

#: This module's kernel (the joints of corner pairs), compiled into this module.
KERNELS = Kernels(globals())
jit = KERNELS.jit


def corner_scale(theta_sin: ArrayLike, theta_cos: ArrayLike, value: ArrayLike, shape: str) -> NDArray:
    """``K(θ)/value`` of ``shape`` (``K`` its corner factor, ``spiral_cad.core._kernels.corner_factor``).

    The relation between the corner distance d and the peak (joint) curvature κ
    of a spiral pair is symmetric: pass κ to get d, or d to get κ.
    """
    sin_t, cos_t, value = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta_sin, theta_cos, value)))
    factor = np.empty(sin_t.size)
    K.corner_factor_batch(SHAPE_CODES[shape], np.ravel(sin_t), np.ravel(cos_t), factor)
    return factor.reshape(sin_t.shape) / value


def deviation_factor(theta_sin: ArrayLike, theta_cos: ArrayLike, shape: str) -> NDArray:
    """D(θ): a spiral pair of joint curvature κ passes D/κ from its corner point.

    The pair is symmetric about the corner's bisector and meets on it, and
    the distance to the corner falls all along the first spiral (tested by
    dense sampling), so the joint is the path's nearest point to the corner.
    The first spiral's end leg c runs from B2 on the incoming leg, at c/cos θ
    from the corner, to the joint at angle θ to the leg; so the joint lies
    h = c·tan θ from the corner. With c = γ(θ)·sin θ/κ (the shape's end leg
    on the unit spiral), D = c_unit·tan θ, and the corner distance is
    d = h·K(θ)/D(θ).
    """
    sin_t, cos_t = np.broadcast_arrays(np.asarray(theta_sin, dtype=float), np.asarray(theta_cos, dtype=float))
    unit = np.empty((sin_t.size, 4, 2))
    KS.unit_spirals_batch(np.ascontiguousarray(sin_t.ravel()), np.ascontiguousarray(cos_t.ravel()), SHAPE_CODES[shape], unit)
    end_leg = norms(unit[:, 3] - unit[:, 2]).reshape(sin_t.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        return end_leg * sin_t / cos_t


def corner_shape(shape: str | None, method: str | None) -> str:
    """The corner shape from ``shape`` (None: ``DEFAULT_SHAPE``) or from ``method`` (its former name,
    deprecated: it warns), checked; both given and different is refused."""
    if method is None:
        shape = DEFAULT_SHAPE if shape is None else shape
        shape_code(shape, CORNER_SHAPES)
        return shape
    warnings.warn("method= is deprecated and will be removed: the same choice is shape=", DeprecationWarning, stacklevel=3)
    if shape is not None and shape != method:
        raise ValueError(f"give shape or method (its former name), not both; got shape={shape!r}, method={method!r}")
    shape_code(method, CORNER_SHAPES, "method")
    return method


def _sin_turn(u: NDArray, v: NDArray) -> NDArray:
    """|u × v| of unit vectors (N, 2) or (N, 3): the sine of the turn between them."""
    if u.shape[-1] == 2:
        return np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
    return norms(np.cross(u, v))


def straight_points(before: NDArray, corner: NDArray, after: NDArray) -> tuple[NDArray, NDArray]:
    """Which corners (N, d) are no corners: ``(straight, folds)``, each (N,) bool.

    A corner is straight when it lies within what float64 resolves at its coordinates
    (``ROUNDING_ULPS`` ulp of the largest) of the chord ``before`` → ``after``: dropping it
    moves the path by no more than rounding. The turn's angle alone never decides: a point
    0.4 off a line between points 1e12 apart turns by 1e-12 rad but is a real corner.
    It folds when the path turns back and the shorter leg lies that close to the other's line.
    """
    vin, vout = corner - before, after - corner
    lin, lout = norms(vin), norms(vout)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sin_t = _sin_turn(vin / lin[:, None], vout / lout[:, None])
        chord = norms(after - before)
        size = np.maximum(np.maximum(np.abs(before).max(axis=1), np.abs(corner).max(axis=1)), np.abs(after).max(axis=1))
        resolution = ROUNDING_ULPS * EPS * size
        ahead = np.einsum("ij,ij->i", vin, vout) > 0.0
        # The corner's distance from the chord (the path's deviation if it were dropped).
        straight = ahead & (lin * (lout / chord) * sin_t <= resolution)
        folds = ~ahead & (np.minimum(lin, lout) * sin_t <= resolution)
    return straight, folds


def _coordinates(value: ArrayLike, name: str) -> NDArray:
    """Points (..., 2) or (..., 3) as float64, refused by name otherwise."""
    array = as_real_array(value, name)
    if array.ndim == 0 or array.shape[-1] not in (2, 3):
        raise ValueError(f"{name} must have 2 or 3 coordinates per point; got shape {array.shape}")
    return array


def _plane_if_flat(*arrays: NDArray) -> tuple[NDArray, ...]:
    """Drop z when every z is 0: points whose z is 0 are plane points, as everywhere in the API."""
    if arrays[0].shape[-1] == 3 and all(np.all(a[..., 2] == 0.0) for a in arrays):
        return tuple(a[..., :2] for a in arrays)
    return arrays


# ------------------------------------------------------------ array API


@dataclass(frozen=True)
class CornerBatch:
    """Spiral pairs for N corners (one row per corner), in the plane (d = 2) or in space (d = 3).

    Attributes:
        shape: ``"walton-meek"``, ``"near-linear"`` or ``"g2cbs"``.
        control_points: (N, 2, 4, d) the two spirals of each corner in travel
            order; NaN where ``status`` ≠ 0.
        theta: (N,) half the deflection (each spiral's turn), NaN when undefined.
        distance: (N,) corner-to-spiral-start distance used (or required).
        curvature: (N,) peak |κ| of the pair (at its joint), used or required.
        available: (N,) the longest distance the legs allow.
        status: (N,) ``spiral_cad.Status`` codes; 0 where rounded.
        corners: (N, d) the corner points.
        requested: (N,) the joint curvature asked for (NaN: as large as fits).
        residual: (N,) for ``UNVERIFIED`` rows, how far the pair is off
            (relative); NaN elsewhere.
        deviation: (N,) the distance from each corner to its path (to the
            pair's joint), measured on the returned control points; NaN
            where not rounded.
        max_deviation, max_curvature, spiral_length: (N,) the bounds and
            lengths asked for (NaN where not given).
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
    deviation: NDArray
    max_deviation: NDArray
    max_curvature: NDArray
    spiral_length: NDArray

    @property
    def ok(self) -> NDArray:
        return self.status == Status.OK

    @property
    def dim(self) -> int:
        """2 for plane corners, 3 for corners in space."""
        return self.corners.shape[1]

    def __len__(self) -> int:
        return len(self.status)

    def reason(self, i: int, label: str | None = None) -> str:
        """Why corner ``i`` could not be rounded (``"ok"`` if it was)."""
        status = Status(int(self.status[i]))
        name = label or f"corner {i}"
        where = f"{name} at ({', '.join(f'{v:.10g}' for v in self.corners[i].tolist())})"
        if status is Status.OK:
            return "ok"
        if status is Status.LEGS_TOO_SHORT:
            return f"{where}: {self._too_short(i)}"
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
            bound = self.max_deviation[i]
            steepest = _steepest_deflection(self.shape) if self.theta[i] == self.theta[i] else math.nan
            if 2.0 * self.theta[i] > steepest:
                # Scale-free: the same turn fails with unit legs at the origin, so no size or tolerance helps.
                return (
                    f"{where}: deflection {2 * math.degrees(self.theta[i]):.6g}° is too close to a reversal for a "
                    f"{self.shape} spiral pair: its peak curvature is {float(corner_scale(math.sin(self.theta[i]), math.cos(self.theta[i]), 1.0, self.shape)):.3g} "
                    f"/ d (d its distance from the corner), beyond what float64 holds to 1e-9 at any size or max_deviation "
                    f"(at most {math.degrees(steepest):.6g}° holds); replace the corner by two corners that each turn "
                    "about half as much (e.g. a short flat across its tip), each rounded by its own pair"
                )
            if bound == bound and not self.residual[i] < math.inf:
                return (
                    f"{where}: max_deviation {bound:.6g} is below what float64 resolves at these coordinates "
                    f"({ROUNDING_ULPS:g} ulp of the largest is {ROUNDING_ULPS * EPS * np.abs(self.corners[i]).max():.3g}); "
                    "use a larger max_deviation, or coordinates nearer the origin"
                )
            held = (f"it holds only to {self.residual[i]:.2g} (at most 1e-9 is returned)" if self.residual[i] < math.inf
                    else "its control points cannot be told apart")  # fmt: skip
            advice = "a larger max_deviation" if bound == bound else "a lower curvature"
            return (
                f"{where}: the spiral pair would start {self.distance[i]:.3g} from the corner, too small for "
                f"float64 at these coordinates: {held}; use {advice}"
            )
        if status is Status.NOT_FINITE:
            return f"{where}: its points must be finite"
        return f"{where}: no spiral pair ({status.name})"

    def _too_short(self, i: int) -> str:
        """The reason of a ``LEGS_TOO_SHORT`` row, in the terms it was asked in."""
        available = f"only {self.available[i]:.6g} is available (each corner may use half of an interior leg)"
        largest = f"this corner needs curvature ≥ {self.curvature[i]:.6g} ({self.shape})"
        length, bound, kmax = self.spiral_length[i], self.max_deviation[i], self.max_curvature[i]
        if bound == bound and kmax == kmax and self.curvature[i] > kmax:
            return (
                f"within max_deviation {bound:.6g} and its legs the spiral pair may start at most "
                f"{self.distance[i]:.6g} from the corner, which needs curvature {self.curvature[i]:.6g}, above "
                f"max_curvature {kmax:.6g}; allow a larger deviation or curvature"
            )
        if self.distance[i] <= self.available[i]:  # the legs allow it: the plane solver could not hold the sizes
            return (
                f"float64 cannot round it at these magnitudes: the spirals would start {self.distance[i]:.6g} from the "
                f"corner and the legs allow {self.available[i]:.6g}, but the legs differ in size by more than float64 "
                "can hold in one corner; bring the points to a common scale"
            )
        if length == length:
            longest = float(length_factor(self.theta[i], self.shape) / self.curvature[i])
            return (
                f"spirals {length:.6g} long need to start {self.distance[i]:.6g} from the corner but {available}; "
                f"its spirals may be at most {longest:.6g} long ({self.shape})"
            )
        return (
            f"curvature {self.requested[i]:.6g} needs the spirals to start {self.distance[i]:.6g} from the corner "
            f"but {available}; {largest}"
        )


_STEEPEST: dict[str, float] = {}


def _steepest_deflection(shape: str) -> float:
    """The largest deflection (radians) whose ``shape`` spiral pair float64 holds (to
    ``VERIFY_TOL``) for a corner with unit legs at the origin: beyond it a corner is too
    close to a reversal at any size. Bisected once per shape on the plane kernel."""
    if shape not in _STEEPEST:

        def holds(deflection: float) -> bool:
            end = (math.cos(deflection), math.sin(deflection))
            return bool(batch.line_to_line([(-1.0, 0.0)], [(0.0, 0.0)], [end], shape=shape).status[0] == Status.OK)

        lo, hi = math.radians(90.0), math.pi
        if not holds(lo):
            _STEEPEST[shape] = math.nan
            return math.nan
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if holds(mid) else (lo, mid)
        _STEEPEST[shape] = lo
    return _STEEPEST[shape]


def _half_deflection(p0: NDArray, corners: NDArray, p1: NDArray):
    """Leg lengths, sin/cos of half the deflection and the legs' unit directions (plane points)."""
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
    return lin, lout, sin_t, cos_t, t_in, t_out


def _per_corner(value: ArrayLike | None, name: str, n: int, first: int = 0) -> NDArray | None:
    """One positive finite value, or one per corner, as (n,); None stays None. Errors name
    the corner by its number, ``first`` for the first value (a polyline's corners are its
    interior points, numbered from 1)."""
    if value is None:
        return None
    v = as_real_array(value, name)
    if v.ndim > 1 or v.size not in (1, n):
        raise ValueError(f"{name} needs one value or one per corner ({n}); got shape {v.shape}")
    v = np.broadcast_to(v.reshape(-1), (n,))
    bad = ~(np.isfinite(v) & (v > 0.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name} must be positive and finite; got {v[i]} (corner {i + first})")
    return np.ascontiguousarray(v)


def _exclusive(curvature, max_curvature, max_deviation, spiral_lengths) -> None:
    """``curvature`` and ``spiral_lengths`` fix each pair; the two bounds may be combined."""
    given = [name for name, v in (("curvature", curvature), ("spiral_lengths", spiral_lengths)) if v is not None]
    bounds = [name for name, v in (("max_curvature", max_curvature), ("max_deviation", max_deviation)) if v is not None]
    if len(given) > 1 or (given and bounds):
        raise ValueError(
            f"give curvature, spiral_lengths or the bounds (max_curvature, max_deviation), not both; got {', '.join(given + bounds)}"
        )


def _corner_rows(p0: ArrayLike, corners: ArrayLike, p1: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
    """The three point arrays as contiguous (N, d) rows: d = 3 when a z is not 0, else 2."""
    named = (("p0", p0), ("corners", corners), ("p1", p1))
    arrays = [_coordinates(v, name) for name, v in named]
    dims = {a.shape[-1] for a in arrays}
    if len(dims) > 1:
        raise ValueError(
            "p0, corners and p1 must all be 2-D or all 3-D points; got " + ", ".join(f"{n} {a.shape}" for (n, _), a in zip(named, arrays))
        )
    try:
        arrays = list(np.broadcast_arrays(*arrays))
    except ValueError:
        raise ValueError(
            "p0, corners and p1 need N rows each (or one); got " + ", ".join(f"{n} {a.shape}" for (n, _), a in zip(named, arrays))
        ) from None
    d = arrays[0].shape[-1]
    a, b, c = _plane_if_flat(*(np.ascontiguousarray(a.reshape(-1, d)) for a in arrays))
    return a, b, c


def _in_corner_planes(p0: NDArray, corners: NDArray, p1: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Plane coordinates of corners in space: (p0, p1) local (N, 2) with the corner at the origin,
    and each corner's frame (x_dir, y_dir) (N, 3).

    p0 lies on the x axis; p1 at its distance along the turn (cos, sin) = (t_in·t_out,
    |t_in × t_out|): legs that are collinear to the last bit stay exactly collinear.
    """
    x_dir, y_dir = corner_frames(p0, corners, p1)
    local_p0 = np.zeros((len(corners), 2))
    local_p0[:, 0] = -norms(corners - p0)
    out = p1 - corners
    length = norms(out)
    with np.errstate(invalid="ignore", divide="ignore"):
        t_out = out / length[:, None]
    turn = np.stack([np.einsum("ij,ij->i", x_dir, t_out), norms(np.cross(x_dir, t_out))], axis=1)
    return local_p0, length[:, None] * turn, x_dir, y_dir


def round_corners_batch(
    p0: ArrayLike,
    corners: ArrayLike,
    p1: ArrayLike,
    *,
    curvature: ArrayLike | None = None,
    max_curvature: ArrayLike | None = None,
    max_deviation: ArrayLike | None = None,
    spiral_lengths: ArrayLike | None = None,
    shape: str | None = None,
    method: str | None = None,
    tolerance: float = JOIN_TOLERANCE,
) -> CornerBatch:
    """Round N independent corners ``p0 → corner → p1`` with spiral pairs, in the plane or in space.

    The spirals of a corner must start between ``p0`` and the corner and end
    between the corner and ``p1``: pass the leg ends each corner may use (see
    :func:`corner_legs` for polylines). A corner in space is solved in the
    plane of its legs by the plane kernel (``spiral_cad.core.batch.line_to_line``),
    placed back with ``spiral_cad.core.space.place`` and verified in space:
    each spiral leaves its leg G2, the two meet G2 (curvature vector κN), at
    the pair's curvature, else the row is ``UNVERIFIED``.

    Args:
        p0, corners, p1: (N, 2) or (N, 3) arrays (or broadcastable rows); 3-D
            points whose z are all 0 are plane points.
        curvature: joint curvature (scalar or (N,)); the pair peaks there.
        max_curvature: a bound κmax: each corner uses the smallest distance
            that respects it, i.e. its joint curvature equals κmax.
        max_deviation: the largest distance allowed between each corner point
            and the path (the CNC or robot tolerance, scalar or (N,)): each
            corner gets the largest pair that stays within it (and within its
            legs); its deviation is measured (``deviation``) and never exceeds
            the bound. With ``max_curvature`` as well, that pair's curvature
            must respect κmax, else the row fails (``LEGS_TOO_SHORT``).
        spiral_lengths: the arc length of each spiral (scalar or (N,)).
        shape: ``"walton-meek"`` (Theorem 4.4; the default), ``"near-linear"`` or
            ``"g2cbs"`` (Yang & Sukkarieh).
        method: the former name of ``shape`` (deprecated: it warns; refused when it differs from ``shape``).
        tolerance: the relative join tolerance of the chains the corners will be
            part of: each corner's joints must pass ``Chain``'s joint test with it
            (else ``UNVERIFIED``), so ``round_corners`` refuses exactly what this refuses.

    With none of curvature, spiral_lengths or max_* given, each corner uses
    all of its shorter leg (Corollary 4.5: the lowest curvature that fits).
    Rows that fail carry a status (``CornerBatch.reason`` explains); the
    others are unaffected.

    Raises:
        ValueError: malformed arguments (shapes, signs, conflicting options).
    """
    shape = corner_shape(shape, method)
    _exclusive(curvature, max_curvature, max_deviation, spiral_lengths)
    p0, corners, p1 = _corner_rows(p0, corners, p1)
    n, dim = corners.shape
    values = {name: _per_corner(v, name, n) for name, v in
              (("curvature", curvature), ("max_curvature", max_curvature), ("max_deviation", max_deviation), ("spiral_lengths", spiral_lengths))}  # fmt: skip
    if dim == 3:
        local_p0, local_p1, x_dir, y_dir = _in_corner_planes(p0, corners, p1)
        local_corners = np.zeros((n, 2))
    else:
        local_p0, local_corners, local_p1 = p0, corners, p1
    lin, lout, sin_t, cos_t, t_in, t_out = _half_deflection(local_p0, local_corners, local_p1)
    theta = np.where(sin_t > 0.0, np.arctan2(sin_t, cos_t), np.nan)
    available = np.minimum(lin, lout)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # a tiny leg: the curvature it needs overflows
        factor = corner_scale(sin_t, cos_t, 1.0, shape)
        needed = factor / available
        k = np.full(n, np.nan)
        too_fine = np.zeros(n, dtype=bool)
        if values["curvature"] is not None:
            k = values["curvature"]
        elif values["spiral_lengths"] is not None:
            k = length_factor(np.nan_to_num(theta), shape) / values["spiral_lengths"]
        elif values["max_deviation"] is not None:
            # The largest pair within the bound, aimed inside it by the rounding of the coordinates.
            size = np.abs(corners).max(axis=1)
            target = values["max_deviation"] * (1.0 - DEVIATION_MARGIN) - ROUNDING_ULPS * EPS * size
            too_fine = ~(target > 0.0)  # refused below, after the plane solve (as UNVERIFIED)
            reach = target * factor / deviation_factor(sin_t, cos_t, shape)
            k = np.where((reach < available) & ~too_fine, factor / reach, np.nan)
        elif values["max_curvature"] is not None:
            k = values["max_curvature"]
        fit = np.isnan(k)
        distance = np.where(fit, available, corner_scale(sin_t, cos_t, k, shape))
    pairs = np.empty((n, 2, 4, 2))
    result = batch.line_to_line(local_p0, local_corners, local_p1, k, shape=shape, out=pairs)
    status = result.status.astype(np.int8)
    residual = np.where(status == Status.UNVERIFIED, result.measure, np.nan)
    if dim == 2:
        # The kernel verifies world control points to 1e-9 with no allowance for their rounding; a
        # small pair far from the origin can miss that by its last bits alone. Such a pair is solved
        # about its corner (where float64 holds it), placed by translation, and judged below as
        # the chain judges it (``_joints_hold``: with the rounding floors of its stored points).
        again = np.flatnonzero(status == Status.UNVERIFIED)
        if len(again):
            origin = corners[again]
            local = batch.line_to_line(p0[again] - origin, np.zeros_like(origin), p1[again] - origin, k[again], shape=shape)
            held = local.status == Status.OK
            rows = again[held]
            pairs[rows] = np.stack(local.spirals, axis=1)[held] + origin[held][:, None, None]
            status[rows] = Status.OK
            residual[rows] = np.nan
    ok = status == Status.OK
    # Failed rows report what they would need: the distance asked for and the
    # curvature that would exactly fit the available legs.
    peak = np.where(ok, np.where(fit, needed, k), needed)
    if values["max_deviation"] is not None:
        status[ok & too_fine] = Status.UNVERIFIED
        residual[ok & too_fine] = np.inf
        if values["max_curvature"] is not None:  # both bounds: the pair within the deviation must respect κmax
            status[ok & ~(peak <= values["max_curvature"] * (1.0 + DEVIATION_MARGIN))] = Status.LEGS_TOO_SHORT
    if dim == 3:
        pairs = place(pairs, corners[:, None, None], x_dir[:, None, None], y_dir[:, None, None])
        off, deviation = np.empty(n), np.empty(n)
        placed_pair_residuals(pairs, corners, x_dir, y_dir, local_p1, peak, off, deviation)
        failed = (status == Status.OK) & ~(off <= K.VERIFY_TOL)
        status[failed] = Status.UNVERIFIED
        residual[failed] = off[failed]
    else:
        deviation = norms(pairs[:, 0, 3] - corners)
    legs = (lin, lout, t_in, t_out) if dim == 2 else None  # the plane's legs as measured above
    joined, off = _joints_hold(pairs, p0, corners, p1, status == Status.OK, shape, tolerance, legs)
    status[~joined] = Status.UNVERIFIED
    residual[~joined] = off[~joined]
    if values["max_deviation"] is not None:
        over = (status == Status.OK) & ~(deviation <= values["max_deviation"])
        status[over] = Status.UNVERIFIED
        residual[over] = np.inf
    ok = status == Status.OK
    pairs[~ok] = np.nan
    deviation[~ok] = np.nan
    unset = np.full(n, np.nan)
    given = {name: unset if v is None else v for name, v in values.items()}
    return CornerBatch(shape, pairs, theta, distance, peak, available, status, corners, k, residual, deviation,
                       given["max_deviation"], given["max_curvature"], given["spiral_lengths"])  # fmt: skip


@jit
def _pair_joints(cp, ok, t_in, t_out, line_in, line_out, tolerance, cap, held, off):  # pragma: no cover - compiled
    """``_joints_hold`` per row: the spirals' end frames and floors (``_chain_kernels._spiral``), the
    legs' lines, and the three joints judged by ``_chain_kernels.joint_measures``."""
    dim = cp.shape[3]
    g = np.zeros((4, 3))
    frames = np.zeros((2, 2, 9))
    floors = np.zeros((2, 2, 3))
    ends, starts = np.zeros((3, 9)), np.zeros((3, 9))
    end_floors, start_floors = np.zeros((3, 3)), np.zeros((3, 3))
    end_lengths, start_lengths = np.zeros(3), np.zeros(3)
    own = np.zeros(3)
    out = np.zeros((3, 6))
    chord, polygon = np.zeros(2), np.zeros(2)
    for i in range(cp.shape[0]):
        if not ok[i]:
            continue
        polygon[0] = polygon[1] = 0.0
        big = 0.0
        for s in range(2):
            for r in range(4):
                for j in range(dim):
                    g[r, j] = cp[i, s, r, j]
                    big = max(big, abs(g[r, j]))
            CK._spiral(g, frames[s], floors[s])
            # norm3: lengths of any magnitude, no square under- or overflows.
            chord[s] = CK.norm3(g[3, 0] - g[0, 0], g[3, 1] - g[0, 1], g[3, 2] - g[0, 2])
            for r in range(3):
                polygon[s] += CK.norm3(g[r + 1, 0] - g[r, 0], g[r + 1, 1] - g[r, 1], g[r + 1, 2] - g[r, 2])
        peak = 0.0
        for s in range(2):
            for e in range(2):
                peak = max(peak, CK.norm3(frames[s, e, 6], frames[s, e, 7], frames[s, e, 8]))
        gap = 4.0 * EPS * big
        for k in range(3):
            own[k] = peak
            for j in range(9):
                ends[k, j] = 0.0
                starts[k, j] = 0.0
            for j in range(3):
                end_floors[k, j] = 0.0
                start_floors[k, j] = 0.0
        # line in → spiral 0; spiral 0 → spiral 1 (chord below, polygon above the quadrature); spiral 1 → line out.
        for j in range(3):
            ends[0, j] = frames[0, 0, j]
            starts[2, j] = frames[1, 1, j]
        for j in range(dim):
            ends[0, 3 + j] = t_in[i, j]
            starts[2, 3 + j] = t_out[i, j]
        end_floors[0, 0], end_floors[0, 1] = gap, gap / line_in[i]
        start_floors[2, 0], start_floors[2, 1] = gap, gap / line_out[i]
        end_lengths[0], start_lengths[2] = line_in[i], line_out[i]
        for j in range(9):
            starts[0, j] = frames[0, 0, j]
            ends[1, j] = frames[0, 1, j]
            starts[1, j] = frames[1, 0, j]
            ends[2, j] = frames[1, 1, j]
        for j in range(3):
            start_floors[0, j] = floors[0, 0, j]
            end_floors[1, j] = floors[0, 1, j]
            start_floors[1, j] = floors[1, 0, j]
            end_floors[2, j] = floors[1, 1, j]
        start_lengths[0], end_lengths[1], start_lengths[1], end_lengths[2] = chord[0], chord[0], polygon[1], polygon[1]
        first = CK.joint_measures(ends, end_floors, end_lengths, starts, start_floors, start_lengths, own, tolerance, cap, out)
        held[i] = first < 0
        worst = 0.0
        for k in range(3):
            worst = max(worst, out[k, 0] / out[k, 3], out[k, 1], out[k, 2] / out[k, 4])
        off[i] = worst if worst == worst else math.inf


#: Corners per thread from which the joint check splits over threads (about a millisecond of work).
JOINTS_PER_THREAD = 4_096


def _joints_hold(
    pairs: NDArray,
    p0: NDArray,
    corners: NDArray,
    p1: NDArray,
    ok: NDArray,
    shape: str,
    tolerance: float,
    legs: tuple[NDArray, NDArray, NDArray, NDArray] | None = None,
) -> tuple[NDArray, NDArray]:
    """Whether each OK corner's three joints (line → spiral → spiral → line) pass the ``Chain``'s own
    joint test (``joint_table``'s kernel), so that a corner the batch returns is one a chain accepts.

    The lines run along the legs and are taken as long as a polyline's segment can be around the
    corner (twice its leg); each spiral's length is bounded by its chord (below) and control polygon
    (above) instead of its quadrature, the shorter taken below and the longer above: the test is
    never more lenient than the chain's. Returns whether each row holds and, for the rows judged,
    its largest relative mismatch (NaN elsewhere). ``legs``: the legs' lengths and unit directions
    (len_in, len_out, t_in, t_out) when already measured (``_half_deflection``).
    """
    del shape  # the frames come from the control points alone
    held = np.ones(len(ok), dtype=np.bool_)
    off = np.full(len(ok), np.nan)
    if legs is None:
        with np.errstate(invalid="ignore", divide="ignore"):
            leg_in, leg_out = corners - p0, p1 - corners
            len_in, len_out = norms(leg_in), norms(leg_out)
            legs = (len_in, len_out, leg_in / len_in[:, None], leg_out / len_out[:, None])
    len_in, len_out, t_in, t_out = legs
    args = [np.ascontiguousarray(pairs), np.ascontiguousarray(ok, dtype=np.bool_), np.ascontiguousarray(t_in), np.ascontiguousarray(t_out),
            2.0 * len_in, 2.0 * len_out, join_tolerance(tolerance), ROUNDING_CAP, held, off]  # fmt: skip
    run_split(_pair_joints, args, len(ok), JOINTS_PER_THREAD)
    return held, off


def _polyline(points: ArrayLike) -> NDArray:
    """(n ≥ 3, d) polyline vertices: d = 3 when a z is not 0, else 2."""
    pts = _coordinates(points, "points")
    if pts.ndim != 2 or len(pts) < 3:
        raise ValueError(f"points must be an (n ≥ 3, 2) or (n ≥ 3, 3) polyline; got shape {pts.shape}")
    return _plane_if_flat(pts)[0]


def corner_legs(points: ArrayLike) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The leg ends each interior corner of a polyline (in the plane or in space) may use.

    Interior segments are shared half-and-half between their two corners; the
    first and last segments belong wholly to their one corner, so spirals of
    neighbouring corners never overlap. Collinear interior points (forward, within
    float64's resolution of the chord of their neighbours: ``straight_points``)
    are dropped: they need no rounding.

    Returns:
        ``(p0, corners, p1, index)``: (M, d) leg ends and corners, and the
        index of each corner in ``points``.

    Raises:
        ValueError: fewer than 3 points, non-finite or repeated consecutive
            points, or a polyline that folds straight back on itself.
    """
    pts = _polyline(points)
    if not np.isfinite(pts).all():
        i = int(np.argmax(~np.isfinite(pts).all(axis=1)))
        raise ValueError(f"points must be finite; point {i} is {pts[i].tolist()}")
    with np.errstate(over="ignore"):  # legs wider than float64: refused below by name
        seg = np.diff(pts, axis=0)
    length = norms(seg)
    if not (length > 0.0).all():
        i = int(np.argmax(~(length > 0.0)))
        raise ValueError(f"points {i} and {i + 1} coincide at {pts[i].tolist()}")
    if not np.isfinite(length).all():
        i = int(np.argmax(~np.isfinite(length)))
        raise ValueError(f"points {i} and {i + 1} are too far apart for float64: {pts[i].tolist()} and {pts[i + 1].tolist()}")
    straight, folds = straight_points(pts[:-2], pts[1:-1], pts[2:])
    if folds.any():
        i = int(np.argmax(folds)) + 1
        raise ValueError(f"the polyline folds straight back at point {i} {pts[i].tolist()}")
    index = np.concatenate([[0], np.flatnonzero(~straight) + 1, [len(pts) - 1]])
    kept = pts[index]
    seg = np.diff(kept, axis=0)
    length = norms(seg)
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


KERNELS.seal()
