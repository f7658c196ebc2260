"""Planes in space: where plane geometry goes when a path leaves the plane.

Every spiral is planar (Walton & Meek §5), and so is every corner of a
polyline: the two legs span a plane. Plane geometry is solved in plane
coordinates (x, y) — the transitions and batch solvers as they are — and
then placed: a ``PlaneFrame`` maps (x, y) to origin + x·x_dir + y·y_dir.
``place`` does the same for arrays of points in arrays of frames (the
spirals of a million corners, each in its own plane) in one pass, and
``corner_frames`` gives the planes of arrays of polyline corners.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _kernel_line_line as KLL
from . import _kernels as K
from .inputs import as_float, as_real_array
from .jit import Kernels
from .threads import run_split
from .units import COLLINEAR_TOL

#: This module's kernels (placing and verifying points in their planes), compiled into this module.
KERNELS = Kernels(globals())
jit = KERNELS.jit

#: Legs whose |sin(turn)| is at most this span no plane.


def place(points: ArrayLike, origin: ArrayLike, x_dir: ArrayLike, y_dir: ArrayLike) -> NDArray[np.float64]:
    """Plane points (..., 2) in space: origin + x·x_dir + y·y_dir, shape (..., 3).

    ``origin``, ``x_dir`` and ``y_dir`` are (..., 3) and broadcast against the
    points' leading shape, so N frames place (N, k, 2) points as
    ``place(points, origin[:, None], x_dir[:, None], y_dir[:, None])``. One
    compiled pass over the frames (the spirals of a million corners in tens
    of milliseconds, where numpy's broadcasting takes ten times longer).
    """
    p = np.asarray(points, dtype=float)
    frames = [np.asarray(v, dtype=float) for v in (origin, x_dir, y_dir)]
    lead = np.broadcast_shapes(p.shape[:-1], *(f.shape[:-1] for f in frames))
    varying = np.broadcast_shapes(*(f.shape[:-1] for f in frames))
    varying = (1,) * (len(lead) - len(varying)) + varying
    split = max((i + 1 for i, d in enumerate(varying) if d != 1), default=0)  # frames are constant after this axis
    rows, count, inner = lead[:split], math.prod(lead[:split]), math.prod(lead[split:])
    drop = (slice(None),) * split + (0,) * (len(lead) - split)  # the axes frames are constant along
    frames = [np.broadcast_to(f.reshape((1,) * (len(lead) + 1 - f.ndim) + f.shape)[drop], rows + (3,)).reshape(count, 3) for f in frames]
    flat = np.broadcast_to(p, lead + (2,)).reshape(count, inner, 2)
    # Writeable C arrays: numba dispatches read-only views (what broadcast_to gives) in milliseconds, not microseconds.
    frames = [np.require(f, np.float64, ["C", "W", "A"]) for f in frames]
    flat = np.require(flat, np.float64, ["C", "W", "A"])
    out = np.empty((count, inner, 3))
    run_split(_place_rows, [flat, *frames, out], count, max(1, POINTS_PER_THREAD // max(inner, 1)))
    return out.reshape(lead + (3,))


#: Points per thread from which ``place`` and the pair check split over threads.
POINTS_PER_THREAD = 100_000


@jit
def _place_row(
    points: NDArray[np.float64],
    origin: NDArray[np.float64],
    x_dir: NDArray[np.float64],
    y_dir: NDArray[np.float64],
    out: NDArray[np.float64],
    i: int,
) -> None:
    """out[i, k] = origin[i] + points[i, k, 0]·x_dir[i] + points[i, k, 1]·y_dir[i]."""
    for k in range(points.shape[1]):
        u, v = points[i, k, 0], points[i, k, 1]
        for j in range(3):
            out[i, k, j] = origin[i, j] + u * x_dir[i, j] + v * y_dir[i, j]


@jit
def _place_rows(
    points: NDArray[np.float64],
    origin: NDArray[np.float64],
    x_dir: NDArray[np.float64],
    y_dir: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    for i in range(points.shape[0]):
        _place_row(points, origin, x_dir, y_dir, out, i)


def norms(vectors: ArrayLike) -> NDArray[np.float64]:
    """|v| of (..., 2) or (..., 3) vectors without overflow or underflow (``math.hypot`` per row)."""
    v = np.asarray(vectors, dtype=float)
    if v.shape[-1] == 2:
        plane: NDArray[np.float64] = np.hypot(v[..., 0], v[..., 1])
        return plane
    with np.errstate(over="ignore", under="ignore"):
        length: NDArray[np.float64] = np.sqrt(np.einsum("...i,...i->...", v, v))  # 6x faster than hypot, within an ulp or two
    unsafe = ~((length > 1e-150) & (length < 1e150))  # squares that may have overflowed or underflowed
    if unsafe.any():
        length[unsafe] = np.hypot(np.hypot(v[unsafe][..., 0], v[unsafe][..., 1]), v[unsafe][..., 2])
    return length


def corner_frames(before: ArrayLike, corners: ArrayLike, after: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The planes of N corners before → corner → after, points (N, 3): unit x_dir (N, 3) along the
    incoming leg and unit y_dir (N, 3) perpendicular to it, towards the outgoing leg.

    y_dir is the outgoing direction with its x_dir part removed twice
    (Gram–Schmidt with one re-orthogonalisation): the outgoing leg then lies
    in the plane to rounding even when the corner turns by 1e-9, and x_dir ⟂
    y_dir to rounding, where a normalised cross product would lose both.
    Collinear legs span no plane: there y_dir is some unit vector
    perpendicular to x_dir. Zero or non-finite legs give NaN frames.
    """
    c = np.asarray(corners, dtype=float)
    incoming = c - np.asarray(before, dtype=float)
    outgoing = np.asarray(after, dtype=float) - c
    with np.errstate(invalid="ignore", divide="ignore"):
        x = incoming / norms(incoming)[..., None]
        y = outgoing / norms(outgoing)[..., None]
        for _ in range(2):
            y = y - np.einsum("...i,...i->...", y, x)[..., None] * x
        length = norms(y)
        straight = length == 0.0
        if straight.any():  # any perpendicular: x × the axis x leans on least
            axis = np.eye(3)[np.argmin(np.abs(x[straight]), axis=-1)]
            y[straight] = np.cross(x[straight], axis)
            length[straight] = norms(y[straight])
        y = y / length[..., None]
    return x, y


def placed_pair_residuals(pairs: NDArray[np.float64], corners: NDArray[np.float64], x_dir: NDArray[np.float64],
                          y_dir: NDArray[np.float64], outgoing: NDArray[np.float64], peak: NDArray[np.float64],
                          residual: NDArray[np.float64], deviation: NDArray[np.float64]) -> None:  # fmt: skip
    """Verify N corners' spiral pairs placed in space, measured on the placed control points.

    ``pairs`` (N, 2, 4, 3) were solved in the planes (``x_dir``, ``y_dir``)
    (N, 3) of ``corners`` (N, 3), with the incoming leg along x_dir and the
    outgoing leg along ``outgoing`` (N, 2, plane coordinates), joint curvature
    ``peak`` (N,). Each placed point's offset from its corner is split into
    plane coordinates and its distance off the plane; the pair must lie in
    the plane (distance / L, added to the in-plane residual) and round the corner G2 in it (the plane
    kernel's own ``corner_residual``: gap / L, tangent angle, curvature error
    × L, L the smaller of the spiral's leg and the radius). ``residual`` (N,)
    receives the worst of these (NaN counted infinite), ``deviation`` (N,)
    the distance from each corner to its pair's joint.
    """
    args = [pairs, corners, x_dir, y_dir, outgoing, peak, residual, deviation]
    run_split(_pair_residuals, args, len(corners), POINTS_PER_THREAD // 8)


@jit
def _pair_residual(
    pairs: NDArray[np.float64],
    corners: NDArray[np.float64],
    x_dir: NDArray[np.float64],
    y_dir: NDArray[np.float64],
    outgoing: NDArray[np.float64],
    peak: NDArray[np.float64],
    residual: NDArray[np.float64],
    deviation: NDArray[np.float64],
    i: int,
    local: NDArray[np.float64],
) -> None:
    """Row ``i`` of ``placed_pair_residuals`` (``local`` (2, 4, 2): room for the pair in plane coordinates)."""
    x, y = x_dir[i], y_dir[i]
    nx, ny, nz = x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]
    off = 0.0
    for k in range(2):
        for m in range(4):
            dx, dy, dz = pairs[i, k, m, 0] - corners[i, 0], pairs[i, k, m, 1] - corners[i, 1], pairs[i, k, m, 2] - corners[i, 2]
            local[k, m, 0] = dx * x[0] + dy * x[1] + dz * x[2]
            local[k, m, 1] = dx * y[0] + dy * y[1] + dz * y[2]
            off = K.worst(off, abs(dx * nx + dy * ny + dz * nz))
    scale = K.frame_scale(max(abs(local[0, 0, 0]), abs(outgoing[i, 0]), abs(outgoing[i, 1])))
    inv = 1.0 / scale
    t1x, t1y = K.unit(-outgoing[i, 0], -outgoing[i, 1])  # along the outgoing leg, towards the corner
    res = KLL.corner_residual(local, 0.0, 0.0, 1.0, 0.0, t1x, t1y, peak[i] * scale, inv)
    leg = K.norm((local[0, 1, 0] - local[0, 0, 0]) * inv, (local[0, 1, 1] - local[0, 0, 1]) * inv)
    length = min(leg, 1.0 / (peak[i] * scale))
    # Off the plane, each leg may tilt by up to 2 × off / L beside its in-plane angle: the sum bounds the angle in space.
    residual[i] = K.worst(res + 2.0 * off * inv / length, res)
    jx, jy, jz = (
        (pairs[i, 0, 3, 0] - corners[i, 0]) * inv,
        (pairs[i, 0, 3, 1] - corners[i, 1]) * inv,
        (pairs[i, 0, 3, 2] - corners[i, 2]) * inv,
    )
    deviation[i] = math.sqrt(jx * jx + jy * jy + jz * jz) * scale


@jit
def _pair_residuals(
    pairs: NDArray[np.float64],
    corners: NDArray[np.float64],
    x_dir: NDArray[np.float64],
    y_dir: NDArray[np.float64],
    outgoing: NDArray[np.float64],
    peak: NDArray[np.float64],
    residual: NDArray[np.float64],
    deviation: NDArray[np.float64],
) -> None:
    local = np.empty((2, 4, 2))  # once per call: an allocation per row would cost as much as the row
    for i in range(corners.shape[0]):
        _pair_residual(pairs, corners, x_dir, y_dir, outgoing, peak, residual, deviation, i, local)


def _vector3(value: Any, name: str) -> NDArray[np.float64]:
    v = as_real_array(value, name)
    if v.shape not in ((2,), (3,)):
        raise ValueError(f"{name} must have 2 or 3 coordinates; got shape {v.shape}")
    out = np.zeros(3)
    out[: len(v)] = [as_float(c, f"{name}[{i}]") for i, c in enumerate(v.tolist())]
    return out


def _unit(v: NDArray[np.float64], name: str) -> NDArray[np.float64]:
    length = math.hypot(*v.tolist())
    if not length > 0.0 or not math.isfinite(length):
        raise ValueError(f"{name} must be a non-zero finite vector; got {tuple(v.tolist())}")
    return v / length


@dataclass(frozen=True, init=False)
class PlaneFrame:
    """An orthonormal frame of a plane in space, like build123d's ``Plane(origin, x_dir, z_dir)``.

    Plane coordinates (x, y) lie at origin + x·x_dir + y·y_dir; ``normal`` =
    x_dir × y_dir, so a counterclockwise (positive) plane turn is
    counterclockwise about ``normal``.

    Args:
        origin: where (0, 0) lies (2 or 3 coordinates; default the origin).
        x_dir: the direction of the x axis (made perpendicular to ``normal``).
        normal: the plane's normal (default +z: the XY plane).

    Raises:
        ValueError: non-finite values, a zero ``normal``, or an ``x_dir`` along ``normal``.
    """

    origin: tuple[float, float, float]
    x_dir: tuple[float, float, float]
    y_dir: tuple[float, float, float]
    normal: tuple[float, float, float]

    def __init__(self, origin: Any = (0.0, 0.0, 0.0), x_dir: Any = (1.0, 0.0, 0.0), normal: Any = (0.0, 0.0, 1.0)):
        o = _vector3(origin, "origin")
        n = _unit(_vector3(normal, "normal"), "normal")
        x = _vector3(x_dir, "x_dir")
        x = _unit(x - float(np.dot(x, n)) * n, "x_dir off the normal")
        y = np.cross(n, x)
        for name, value in (("origin", o), ("x_dir", x), ("y_dir", y), ("normal", np.cross(x, y))):
            object.__setattr__(self, name, tuple(value.tolist()))

    @classmethod
    def of_corner(cls, before: Any, corner: Any, after: Any) -> PlaneFrame:
        """The plane of the corner before → corner → after: origin at ``corner``, x_dir along the
        incoming leg, normal along d_in × d_out, so the corner turns left (counterclockwise) in it.

        Raises:
            ValueError: a zero leg, or legs that are collinear (|sin| ≤ 1e-12) and span no plane.
        """
        a, p, b = (_vector3(v, name) for v, name in ((before, "before"), (corner, "corner"), (after, "after")))
        d_in = _unit(p - a, "the incoming leg")
        d_out = _unit(b - p, "the outgoing leg")
        if not math.hypot(*np.cross(d_in, d_out).tolist()) > COLLINEAR_TOL:
            raise ValueError(f"the corner at {tuple(p.tolist())} has collinear legs: they span no plane")
        x, y = corner_frames(a, p, b)
        return cls(p, x, np.cross(x, y))

    @property
    def basis(self) -> NDArray[np.float64]:
        """(2, 3): x_dir and y_dir."""
        return np.array([self.x_dir, self.y_dir])

    def point(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Plane points (..., 2) in space (..., 3)."""
        return place(xy, self.origin, self.x_dir, self.y_dir)

    def vector(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Plane vectors (..., 2) in space (..., 3) (directions: no origin)."""
        return place(xy, (0.0, 0.0, 0.0), self.x_dir, self.y_dir)

    def local(self, xyz: ArrayLike) -> NDArray[np.float64]:
        """Plane coordinates (..., 2) of points (..., 3): their projection onto the plane."""
        d = np.asarray(xyz, dtype=float) - self.origin
        return np.stack([d @ self.x_dir, d @ self.y_dir], axis=-1)


KERNELS.seal()
