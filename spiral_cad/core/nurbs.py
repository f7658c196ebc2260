"""A whole chain as one exact rational cubic B-spline (pure numpy).

Every segment becomes rational cubic Bézier pieces placed on their own
knot spans, joined by interior knots of multiplicity 3:

* a line: a cubic with its control points at thirds (so the parameter is
  still proportional to length),
* a spiral: its own four control points, weights 1,
* an arc: rational quadratic pieces of at most 90° (weights 1, cos(φ/2), 1),
  each degree-elevated exactly to a rational cubic.

Span lengths equal the arc lengths of the pieces, so the curve parameter
runs from 0 to about the chain length.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .segments import Arc, Line, Segment
from .spiral import BezierSpiral

__all__ = ["MAX_ARC_PIECE", "Nurbs", "chain_to_nurbs"]

#: Largest arc piece written as one rational quadratic (keeps weights ≥ cos 45°).
MAX_ARC_PIECE = math.pi / 2


@dataclass(frozen=True, eq=False)
class Nurbs:
    """A planar rational B-spline.

    Attributes:
        degree: polynomial degree (3 for chains).
        knots: distinct knot values, increasing.
        multiplicities: multiplicity of each knot (ends: degree + 1).
        weights: one positive weight per control point.
        control_points: (n, 2) control points.
        segment_index: for each knot span, the chain segment it comes from.
    """

    degree: int
    knots: NDArray[np.float64]
    multiplicities: NDArray[np.int64]
    weights: NDArray[np.float64]
    control_points: NDArray[np.float64]
    segment_index: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        expected = int(np.sum(self.multiplicities)) - self.degree - 1
        if len(self.control_points) != expected or len(self.weights) != expected:
            raise ValueError(
                f"Nurbs needs sum(multiplicities) - degree - 1 = {expected} control points and weights; "
                f"got {len(self.control_points)} points and {len(self.weights)} weights"
            )
        if np.any(np.diff(self.knots) <= 0.0):
            raise ValueError(f"Nurbs knots must be distinct and increasing; got {self.knots.tolist()}")

    @property
    def knot_vector(self) -> NDArray[np.float64]:
        """The full knot vector (each knot repeated by its multiplicity)."""
        return np.repeat(self.knots, self.multiplicities)

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.knots[0]), float(self.knots[-1])

    def point(self, t: ArrayLike) -> NDArray[np.float64]:
        """Points at parameters ``t`` (rational de Boor), shape ``t.shape + (2,)``.

        Raises:
            ValueError: a parameter outside the knot range.
        """
        t = np.asarray(t, dtype=float)
        lo, hi = self.domain
        if np.any((t < lo) | (t > hi)):
            raise ValueError(f"Nurbs parameters must lie in [{lo}, {hi}]; got {t.min()} … {t.max()}")
        p, u = self.degree, self.knot_vector
        flat = t.ravel()
        # Span k with u[k] ≤ t < u[k+1]; the last parameter uses the last non-empty span.
        k = np.clip(np.searchsorted(u, flat, side="right") - 1, p, len(u) - p - 2)
        homogeneous = np.concatenate([self.control_points * self.weights[:, None], self.weights[:, None]], axis=1)
        d = homogeneous[k[:, None] - p + np.arange(p + 1)]  # (m, p+1, 3)
        for r in range(1, p + 1):
            for j in range(p, r - 1, -1):
                i = k - p + j
                left, right = u[i], u[i + p + 1 - r]
                alpha = ((flat - left) / (right - left))[:, None]
                d[:, j] = (1.0 - alpha) * d[:, j - 1] + alpha * d[:, j]
        result = d[:, p, :2] / d[:, p, 2:]
        points: NDArray[np.float64] = result.reshape(t.shape + (2,))
        return points


def _arc_pieces(arc: Arc) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """Rational cubic pieces (points, weights, length) of an arc, each ≤ MAX_ARC_PIECE."""
    count = max(1, math.ceil(arc.sweep / MAX_ARC_PIECE - 1e-12))
    half = 0.5 * arc.sweep / count
    w = math.cos(half)
    sense = math.copysign(1.0, arc.radius)
    r = abs(arc.radius)
    center = arc.center
    pieces = []
    for i in range(count):
        a0 = arc.start_angle + sense * 2.0 * half * i
        mid, a1 = a0 + sense * half, a0 + sense * 2.0 * half
        p0 = center + r * np.array([math.cos(a0), math.sin(a0)])
        p2 = center + r * np.array([math.cos(a1), math.sin(a1)])
        p1 = center + (r / w) * np.array([math.cos(mid), math.sin(mid)])  # where the end tangents meet
        # Exact degree elevation 2 → 3 in homogeneous coordinates.
        weights = np.array([1.0, (1.0 + 2.0 * w) / 3.0, (2.0 * w + 1.0) / 3.0, 1.0])
        points = np.array([p0, (p0 + 2.0 * w * p1) / (1.0 + 2.0 * w), (2.0 * w * p1 + p2) / (2.0 * w + 1.0), p2])
        pieces.append((points, weights, r * 2.0 * half))
    return pieces


def _pieces(segment: Segment) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    ones = np.ones(4)
    if isinstance(segment, BezierSpiral):
        return [(np.array(segment.control_points), ones, segment.length)]
    if isinstance(segment, Line):
        a, b = segment.start, segment.end
        return [(a + np.array([0.0, 1.0, 2.0, 3.0])[:, None] / 3.0 * (b - a), ones, segment.length)]
    if isinstance(segment, Arc):
        return _arc_pieces(segment)
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {segment!r}")


def chain_to_nurbs(chain: Iterable[Segment]) -> Nurbs:
    """The exact rational cubic B-spline of a chain (or any segments in travel order).

    Each joint shares the end point of the piece before it; the chain's own
    gaps (at most its join tolerance) are the only difference.

    Raises:
        ValueError: no segments (segments themselves have positive length by
            construction, so every knot span is non-empty), or a segment in
            space (``Nurbs`` is planar; 3-D chains reach CAD as exact edges).
    """
    points: list[NDArray[np.float64]] = []
    weights: list[NDArray[np.float64]] = []
    spans: list[float] = []
    owners: list[int] = []
    for index, segment in enumerate(chain):
        if getattr(segment, "dim", 2) != 2:
            raise ValueError(
                f"chain_to_nurbs takes plane segments; segment {index} is in space (use exact 3-D edges: spiral_cad.build123d.chain_edges/chain_to_wire)"
            )
        for cp, w, length in _pieces(segment):
            points.append(cp if not points else cp[1:])
            weights.append(w if not weights else w[1:])
            spans.append(length)
            owners.append(index)
    if not spans:
        raise ValueError("chain_to_nurbs needs at least one segment")
    knots = np.concatenate([[0.0], np.cumsum(spans)])
    multiplicities = np.full(len(knots), 3)
    multiplicities[[0, -1]] = 4
    return Nurbs(3, knots, multiplicities, np.concatenate(weights), np.vstack(points), tuple(owners))
