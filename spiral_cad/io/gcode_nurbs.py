"""A LinuxCNC NURBS block (``G5.2`` … ``G5.3``) made G2 within a bound: its points, and a G2 chain along it.

LinuxCNC's definition (``interp_convert.cc``, ``nurbs_additional_functions.cc``): the first control point is where
the tool stands (its weight is the ``P`` of the ``G5.2`` line when that line names no point, else 1); every line of
the block naming both X and Y adds a control point with weight ``P`` (default 1); the order is ``L`` when above 3,
else 3; the knots are clamped and uniform: 0 (order times), 1 … n − order + 1, n − order + 2 (order times), for
control points 0 … n. The curve starts on the first control point and ends on the last.

``nurbs_g2`` approximates the curve by biarcs (``spiral_cad.io.curve_biarcs``, within a share of the bound), makes that G1 path of arcs G2 with ``spiral_cad.design.make_g2`` within the rest (its ends
fixed: a straight step from the block's first point and to its last where the G2 path's ends moved), and
measures the result against dense samples of the NURBS both ways.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BSpline
from scipy.spatial import cKDTree

from ..core.chain import Chain
from ..core.segments import Line, Segment
from .curve_biarcs import BIARC_SHARE, curve_biarcs, rational_spline_at

__all__ = ["NurbsG2", "nurbs_g2", "nurbs_points"]

#: The spacing of the samples the result is measured on, as a share of the bound.
MEASURE_SHARE = 0.05
#: The most samples taken of a block (a longer curve is kept as it is).
MAX_SAMPLES = 400_000


@dataclass
class NurbsG2:
    """A NURBS block made G2.

    Attributes:
        pieces: the G2 chains and the straight steps that fix the ends, in travel order.
        deviation: the measured distance between the NURBS and the result, both ways (an upper bound).
        joints: joints of the biarcs made G2.
    """

    pieces: list[Chain | Segment]
    deviation: float
    joints: int


def _curve(controls: NDArray[np.float64], weights: NDArray[np.float64], order: int) -> BSpline:
    """The NURBS as a B-spline in homogeneous coordinates (w x, w y, w)."""
    p = np.asarray(controls, dtype=float)
    w = np.asarray(weights, dtype=float)
    n = len(p) - 1
    if order < 2 or n + 1 < order:
        raise ValueError(f"a NURBS of order {order} needs at least {order} control points; got {n + 1}")
    if not np.all(w > 0.0):
        raise ValueError(f"NURBS weights must be positive; got {w.min():g}")
    knots = np.array([0.0] * order + list(range(1, n - order + 2)) + [float(n - order + 2)] * order)
    return BSpline(knots, np.column_stack([p * w[:, None], w]), order - 1)


def nurbs_points(
    controls: NDArray[np.float64], weights: NDArray[np.float64], order: int, spacing: float
) -> NDArray[np.float64]:  # fmt: skip
    """Points of a LinuxCNC NURBS (control points (n + 1, 2), their weights, its order), at most about ``spacing``
    apart, first and last on the first and last control points.

    Raises:
        ValueError: fewer control points than the order, a weight that is not positive, a spacing that is not,
            more than ``MAX_SAMPLES`` points.
    """
    if not spacing > 0.0:
        raise ValueError(f"spacing must be positive; got {spacing:g}")
    curve = _curve(controls, weights, order)
    p = np.asarray(controls, dtype=float)
    u = np.linspace(0.0, curve.t[-1], 64 * len(p) + 1)
    rough = curve(u)
    xy = rough[:, :2] / rough[:, 2:]
    length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    count = max(2, math.ceil(length[-1] / spacing) + 1)
    if count > MAX_SAMPLES:
        raise ValueError(f"a NURBS {length[-1]:.6g} long needs {count} samples at spacing {spacing:.3g}; at most {MAX_SAMPLES}")
    dense = curve(np.interp(np.linspace(0.0, length[-1], count), length, u))  # about even in arc length
    out = dense[:, :2] / dense[:, 2:]
    out[0], out[-1] = p[0], p[-1]
    return out


def nurbs_g2(
    controls: NDArray[np.float64], weights: NDArray[np.float64], order: int, bound: float, *, units: str = "mm",
    shape: str = "near-linear",
) -> NurbsG2:  # fmt: skip
    """A LinuxCNC NURBS made G2 within ``bound``, from its first control point to its last.

    Args:
        controls: its control points, (n + 1, 2), the first where the tool stands.
        weights: their weights.
        order: its order (degree + 1).
        bound: the largest distance allowed between the NURBS and the result, both ways.
        units: the length unit.
        shape: the transitions' shape (``make_g2``'s).

    Raises:
        ValueError: a NURBS that cannot be read (``nurbs_points``), biarcs ``make_g2`` refuses, or a result
            measured beyond the bound.
    """
    from ..design.g2 import make_g2

    curve_of = _curve(controls, weights, order)
    biarcs = curve_biarcs(partial(rational_spline_at, curve_of), np.unique(curve_of.t), bound * BIARC_SHARE)
    start, end = np.asarray(controls[0], dtype=float), np.asarray(controls[-1], dtype=float)
    spacing = bound * MEASURE_SHARE
    curve = nurbs_points(controls, weights, order, spacing)
    if len(biarcs) < 2:
        raise ValueError("a NURBS that is one arc or line: nothing to make G2")
    made = make_g2(biarcs, bound * (1.0 - BIARC_SHARE) - spacing, closed=False, shape=shape, units=units)
    pieces: list[Chain | Segment] = []
    position = start
    tiny = 1e-9 * max(1.0, float(np.abs(curve).max()))
    for chain in made.chains:
        if float(np.linalg.norm(np.asarray(chain.start) - position)) > tiny:
            pieces.append(Line(tuple(position), tuple(chain.start)))
        pieces.append(chain)
        position = np.asarray(chain.end)
    if float(np.linalg.norm(end - position)) > tiny:
        pieces.append(Line(tuple(position), tuple(end)))
    # measured both ways on dense samples of each: a point's distance to the other's nearest sample bounds its
    # distance to the other; half the spacing covers the points between samples
    result = np.vstack([_samples(piece, spacing) for piece in pieces])
    deviation = max(float(cKDTree(result).query(curve)[0].max()), float(cKDTree(curve).query(result)[0].max())) + spacing / 2.0
    if deviation > bound:
        raise ValueError(f"the NURBS made G2 measures {deviation:.3g} {units} from it, beyond the bound {bound:g} {units}")
    return NurbsG2(pieces, deviation, sum(j.kind not in ("g2", "split") for j in made.joints))


def _samples(piece: Chain | Segment, spacing: float) -> NDArray[np.float64]:
    """Points of a chain or segment at most ``spacing`` apart along it."""
    segments = list(piece) if isinstance(piece, Chain) else [piece]
    out = [np.asarray(s.point(np.linspace(0.0, 1.0, max(2, math.ceil(s.length / spacing) + 1))))[:, :2] for s in segments]
    return np.vstack(out)
