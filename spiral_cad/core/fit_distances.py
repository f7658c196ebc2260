"""Distances from points to a plane chain: ``chain_distances`` (k-d tree, then closed forms on
lines and arcs, Newton's method on Bézier spirals), the measure every fit is checked with."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import bezier
from .chain import Chain
from .segments import Arc, Line, Segment
from .spiral import BezierSpiral

__all__ = ["chain_distances"]

_TAU = 2.0 * math.pi


def _as_points(points: Any) -> NDArray[np.float64]:
    """``points`` as an (N, 2) float array; ValueError naming the first non-finite point."""
    if isinstance(points, (str, bytes)):
        raise ValueError(f"points must be an (N, 2) array of numbers; got {type(points).__name__}")
    try:
        array = np.array(points, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"points must be an (N, 2) array of numbers ({error})") from None
    if array.ndim != 2 or array.shape[1] != 2:
        raise ValueError(f"points must have shape (N, 2); got shape {array.shape}")
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"points[{i}] is not finite: ({float(array[i, 0])!r}, {float(array[i, 1])!r})")
    return array


def _arc_lengths(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """The distance along the points' polyline to each point (0 at the first)."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def _nearest(pieces: list[Segment], points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance of each point to the nearest of ``pieces`` (each tried: few pieces)."""
    best = np.full(len(points), np.inf)
    for piece in pieces:
        np.minimum(best, _piece_distance(piece, points, None, False)[0], out=best)
    return best


def _piece_distance(
    piece: Segment, points: NDArray[np.float64], u0: NDArray[np.float64] | None, stations: bool = True
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distance of each point to ``piece`` and (``stations``) the arc length of its foot from the
    piece's start (``u0``: a spiral's start guesses)."""
    if isinstance(piece, Line):
        a, b = piece.start, piece.end
        d = b - a
        length2 = float(d @ d)
        t = np.clip(((points - a) @ d) / length2, 0.0, 1.0)
        foot = a + t[:, None] * d
        return np.hypot(*(points - foot).T), t * math.sqrt(length2)
    if isinstance(piece, Arc):
        c, r, a0, sweep = piece.center, piece.radius, piece.start_angle, piece.sweep
        sense = 1.0 if r > 0 else -1.0
        rel = points - c
        phi = np.mod(sense * (np.arctan2(rel[:, 1], rel[:, 0]) - a0), _TAU)
        outside = phi > sweep
        # Beyond the sweep: the nearer end.
        phi = np.where(outside & (phi - sweep > 0.5 * (_TAU - sweep)), 0.0, np.where(outside, sweep, phi))
        angle = a0 + sense * phi
        foot = c + abs(r) * np.stack([np.cos(angle), np.sin(angle)], axis=1)
        return np.hypot(*(points - foot).T), phi * abs(r)
    assert isinstance(piece, BezierSpiral)
    cp = piece.control_points
    # Power basis about B0 (the points moved by −B0 too, so survey coordinates keep their digits); x and y
    # apart, as plain arrays: a sum over a pair of columns costs more than the arithmetic it adds up.
    c1, c2, c3 = 3.0 * (cp[1] - cp[0]), 3.0 * (cp[0] - 2.0 * cp[1] + cp[2]), cp[3] - cp[0] + 3.0 * (cp[1] - cp[2])
    (c1x, c1y), (c2x, c2y), (c3x, c3y) = c1.tolist(), c2.tolist(), c3.tolist()
    rx, ry = points[:, 0] - cp[0, 0], points[:, 1] - cp[0, 1]
    if u0 is None:
        grid = np.linspace(0.0, 1.0, 17)
        sx, sy = ((c3x * grid + c2x) * grid + c1x) * grid, ((c3y * grid + c2y) * grid + c1y) * grid
        gap = (rx[:, None] - sx[None, :]) ** 2 + (ry[:, None] - sy[None, :]) ** 2
        u = grid[np.argmin(gap, axis=1)]
    else:
        u = u0.copy()
    for _ in range(6):  # Newton on (B(u) − p)·B'(u) = 0
        ox, oy = ((c3x * u + c2x) * u + c1x) * u - rx, ((c3y * u + c2y) * u + c1y) * u - ry
        d1x, d1y = (3.0 * c3x * u + 2.0 * c2x) * u + c1x, (3.0 * c3y * u + 2.0 * c2y) * u + c1y
        d2x, d2y = 6.0 * c3x * u + 2.0 * c2x, 6.0 * c3y * u + 2.0 * c2y
        f = ox * d1x + oy * d1y
        df = (d1x * d1x + d1y * d1y) + (ox * d2x + oy * d2y)
        step = np.clip(u - f / np.where(df > 0, df, 1.0), 0.0, 1.0)
        if np.array_equal(step, u):  # every foot settled: the steps left would change nothing
            break
        u = step
    ox, oy = ((c3x * u + c2x) * u + c1x) * u - rx, ((c3y * u + c2y) * u + c1y) * u - ry
    along = _spiral_stations(cp, c1, c2, c3, u) if stations else u
    return np.hypot(ox, oy), along


#: Nodes of the arc length table a spiral's stations are interpolated from.
_NODES = 129


def _spiral_stations(cp: NDArray[np.float64], c1: NDArray[np.float64], c2: NDArray[np.float64], c3: NDArray[np.float64],
                     u: NDArray[np.float64]) -> NDArray[np.float64]:  # fmt: skip
    """Arc length from the spiral's start to each parameter ``u``: few points by quadrature, many
    by cubic Hermite interpolation of a quadrature table with the speed |B'| as its slope (the
    speed is smooth: the error is ~1e-12 of the length at 129 nodes)."""
    if len(u) <= 4 * _NODES:
        return np.asarray(bezier.arc_length(cp, u), dtype=float)
    nodes = np.linspace(0.0, 1.0, _NODES)
    table = np.asarray(bezier.arc_length(cp, nodes), dtype=float)
    speed = np.hypot(*((3.0 * c3 * nodes[:, None] + 2.0 * c2) * nodes[:, None] + c1).T)
    width = 1.0 / (_NODES - 1)
    k = np.minimum((u / width).astype(np.int64), _NODES - 2)
    t = u / width - k
    t2, t3 = t * t, t * t * t
    h00, h10, h01, h11 = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, -2 * t3 + 3 * t2, t3 - t2
    out: NDArray[np.float64] = h00 * table[k] + h10 * width * speed[k] + h01 * table[k + 1] + h11 * width * speed[k + 1]
    return out


#: How many nearest samples chain_distances starts feet from (pieces already tried skipped).
_NEIGHBOURS = 4
#: Most samples chain_distances places along a chain (beside at least 8 per piece).
_SAMPLES = 100_000


def chain_distances(chain: Chain, points: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distance of every point to a plane chain and the station (arc length) of its foot.

    Each point is located at the nearest of samples along every piece (a k-d
    tree, about two per point up to 100 000 samples), then its foot is solved on that piece
    (lines and arcs in closed form, spirals by Newton's method) and on the
    neighbouring pieces.

    Args:
        chain: a 2-D ``Chain``.
        points: (N, 2) points.

    Returns:
        (distances, stations), each (N,).

    Raises:
        ValueError: a chain in space, or malformed points.
    """
    from scipy.spatial import cKDTree

    if chain.dim != 2:
        raise ValueError("chain_distances takes a plane chain")
    p = _as_points(points)
    lengths, stations = chain.lengths, chain.stations
    # Samples enough to tell the pieces apart, not one per point: Newton finds each foot from there.
    spacing = max(chain.length / min(max(2 * len(p), 1), _SAMPLES), 1e-300)
    counts = np.clip(np.ceil(lengths / spacing).astype(np.int64), 8, 1_000_000)
    pieces = list(chain)
    samples = np.concatenate([piece.point(np.linspace(0.0, 1.0, int(m))) for piece, m in zip(pieces, counts.tolist())])
    owner = np.repeat(np.arange(len(pieces)), counts)
    u_of = np.concatenate([np.linspace(0.0, 1.0, int(m)) for m in counts.tolist()])
    if not np.isfinite(samples).all():
        raise ValueError("chain_distances: the chain's points are not finite float64 numbers (coordinates beyond ±1e308)")
    # The nearest few samples: where the chain passes near itself (closer than the samples' spacing)
    # the nearest sample may lie on a piece other than the one that holds the foot.
    _, nearest = cKDTree(samples).query(p, k=min(_NEIGHBOURS, len(samples)))
    nearest = nearest.reshape(len(p), -1)
    best = np.full(len(p), np.inf)
    foot = np.zeros(len(p))
    ring = math.hypot(*(chain.end - chain.start)) <= 1e-9 * chain.size  # a closed chain: the ends are neighbours
    tried = np.full((len(p), 0), -1)
    for column in range(nearest.shape[1]):
        piece_of, u_guess = owner[nearest[:, column]], u_of[nearest[:, column]]
        fresh = np.flatnonzero(~(tried == piece_of[:, None]).any(axis=1))
        tried = np.column_stack([tried, piece_of])
        order = fresh[np.argsort(piece_of[fresh], kind="stable")]
        bounds = np.flatnonzero(np.diff(piece_of[order])) + 1
        for group in np.split(order, bounds):
            if not len(group):
                continue
            k = int(piece_of[group[0]])
            for j in (k - 1, k, k + 1):  # the neighbours too: a foot near a joint may lie on either side
                if ring:
                    j %= len(pieces)
                elif not 0 <= j < len(pieces):
                    continue
                guess = u_guess[group] if j == k else np.full(len(group), 1.0 if j == (k - 1) % len(pieces) else 0.0)
                distance, along = _piece_distance(pieces[j], p[group], guess)
                better = distance < best[group]
                best[group[better]] = distance[better]
                foot[group[better]] = stations[j] + along[better]
    return best, foot
