"""Samples of a chain for machines: a CSV of station, point, unit tangent and curvature.

A robot or CNC post-processor reads a path as points; this module samples a
chain (in the plane or in space) at a given ``step`` (arc length between
samples at most ``step``) or ``chord_tolerance`` (the path strays at most
that far from the straight chord between neighbouring samples). Every
segment's ends are samples (a joint is never cut), and inside a segment the
samples are evenly spaced in arc length. With a chord tolerance the spacing
comes from the segment's largest curvature κ: a curve whose curvature stays
below κ strays from the chord of an arc length Δs by at most
(1 − cos(κΔs/2))/κ, the circle's sagitta; the samples are then measured
(points between neighbours against their chord) and a segment that strays
further is sampled twice as densely, until every chord holds.

The CSV has one header row with the unit of every column (``s [mm]``,
``x [mm]``, ``y [mm]``, ``z [mm]``, ``tx [1]``, ``ty [1]``, ``tz [1]``,
``curvature [1/mm]``) and one row per sample of plain decimals (the shortest
that read back to the same double). In the plane z and tz are 0 and the
curvature is signed (positive turns left); in space it is κ ≥ 0.

Needs no CAD kernel.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numpy.typing import NDArray

from ..core._inputs import as_float
from ..core.chain import Chain
from ..core.segments import Arc, Line

#: Columns and their dimensions (``L``: the chain's length unit).
COLUMNS = (("s", "L"), ("x", "L"), ("y", "L"), ("z", "L"), ("tx", "1"), ("ty", "1"), ("tz", "1"), ("curvature", "1/L"))
#: At most this many samples are written (a step far below the path's size is an error, not a full disk).
MAX_SAMPLES = 20_000_000
#: Points measured between two neighbouring samples when the chord tolerance is checked.
CHORD_PROBES = 7
#: The curvature of a spiral is taken as its largest at this many parameters, raised by ``CURVATURE_MARGIN``.
CURVATURE_PROBES = 65
CURVATURE_MARGIN = 1.01


def _positive(value: object, name: str) -> float:
    number = as_float(value, name)
    if not (number > 0.0 and math.isfinite(number)):
        raise ValueError(f"{name} must be a positive length; got {number!r}")
    return number


def _largest_curvature(segment) -> float:
    """The segment's largest |κ| (exact for lines and arcs, measured with a margin for spirals)."""
    if isinstance(segment, Line):
        return 0.0
    if isinstance(segment, Arc):
        return 1.0 / abs(segment.radius)
    return float(np.max(np.abs(segment.curvature(np.linspace(0.0, 1.0, CURVATURE_PROBES))))) * CURVATURE_MARGIN


def _spacing(kappa: float, tolerance: float) -> float:
    """The arc length whose circle of curvature ``kappa`` strays ``tolerance`` from its chord."""
    if kappa * tolerance >= 1.0:  # even a half circle stays within it
        return math.pi / kappa
    return 2.0 * math.acos(1.0 - tolerance * kappa) / kappa


def _counts(chain: Chain, step: float | None, chord_tolerance: float | None) -> NDArray:
    """Intervals per segment."""
    lengths = chain.lengths
    if step is not None:
        per = lengths / step
    else:
        spacing = np.array([_spacing(_largest_curvature(s), chord_tolerance) if not isinstance(s, Line) else math.inf for s in chain])
        per = lengths / spacing
    if not np.all(per <= MAX_SAMPLES):
        raise ValueError(f"that would be more than {MAX_SAMPLES:,} samples for a path {chain.length:.6g} {chain.units} long; use a larger step or chord tolerance")
    counts = np.maximum(np.ceil(per), 1).astype(np.int64)
    if counts.sum() > MAX_SAMPLES:
        raise ValueError(f"that would be {int(counts.sum()):,} samples (at most {MAX_SAMPLES:,}); use a larger step or chord tolerance")
    return counts


def _stations(chain: Chain, counts: NDArray) -> NDArray:
    """Every segment's start and ``counts`` even intervals inside it, plus the end."""
    starts, lengths = chain.stations[:-1], chain.lengths
    owner = np.repeat(np.arange(len(counts)), counts)
    within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    s = starts[owner] + lengths[owner] * within / counts[owner]
    return np.append(s, chain.length), owner


def chord_deviation(chain: Chain, s: NDArray) -> NDArray:
    """For each pair of neighbouring stations, how far the path between them strays from their chord (measured)."""
    a, b = chain.point_at(s[:-1]), chain.point_at(s[1:])
    fractions = np.arange(1, CHORD_PROBES + 1) / (CHORD_PROBES + 1)
    inner = chain.point_at(s[:-1, None] + np.diff(s)[:, None] * fractions)
    chord = b - a
    length2 = np.einsum("ij,ij->i", chord, chord)
    offset = inner - a[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ikj,ij->ik", offset, chord) / length2[:, None], 0.0, 1.0)
    t = np.where(length2[:, None] > 0.0, t, 0.0)
    return np.linalg.norm(offset - t[..., None] * chord[:, None], axis=-1).max(axis=1)


def sample_stations(chain: Chain, *, step: float | None = None, chord_tolerance: float | None = None) -> NDArray:
    """Stations along ``chain``: every segment's ends and evenly spaced ones inside (see the module docstring).

    Args:
        chain: the path.
        step: the largest arc length between neighbouring samples.
        chord_tolerance: the largest distance between the path and the chord
            of neighbouring samples (measured).

    Raises:
        ValueError: neither or both given, a value that is not a positive
            length, or more than ``MAX_SAMPLES`` samples.
    """
    if not isinstance(chain, Chain):
        raise ValueError(f"expected a Chain; got {type(chain).__name__}")
    if (step is None) == (chord_tolerance is None):
        raise ValueError("give step or chord_tolerance (one of them)")
    step = None if step is None else _positive(step, "step")
    chord_tolerance = None if chord_tolerance is None else _positive(chord_tolerance, "chord_tolerance")
    counts = _counts(chain, step, chord_tolerance)
    s, owner = _stations(chain, counts)
    if chord_tolerance is None:
        return s
    for _ in range(60):
        over = chord_deviation(chain, s) > chord_tolerance
        if not over.any():
            return s
        counts[np.unique(owner[over])] *= 2
        if counts.sum() > MAX_SAMPLES:
            raise ValueError(f"that would be {int(counts.sum()):,} samples (at most {MAX_SAMPLES:,}); use a larger chord tolerance")
        s, owner = _stations(chain, counts)
    raise ValueError(f"chord_tolerance {chord_tolerance:g} {chain.units} is below what float64 resolves along this path")


def sample_table(chain: Chain, s: NDArray) -> NDArray:
    """(n, 8) rows of s, x, y, z, tx, ty, tz and curvature at stations ``s``."""
    rows = np.zeros((len(s), 8))
    rows[:, 0] = s
    rows[:, 1 : 1 + chain.dim] = chain.point_at(s)
    rows[:, 4 : 4 + chain.dim] = chain.tangent_at(s)
    rows[:, 7] = chain.curvature_at(s)
    return rows


def write_samples(chain: Chain, path: str | os.PathLike, *, step: float | None = None, chord_tolerance: float | None = None) -> int:
    """Write the samples of ``chain`` as CSV (see the module docstring); returns the number of samples.

    Raises:
        ValueError: as :func:`sample_stations`, or a sample that is not a finite number.
        OSError: the file could not be written.
    """
    rows = sample_table(chain, sample_stations(chain, step=step, chord_tolerance=chord_tolerance))
    if not np.isfinite(rows).all():
        raise ValueError("the path's samples are not all finite numbers")
    units = chain.units
    head = ",".join(f"{name} [{dimension.replace('L', units)}]" for name, dimension in COLUMNS)
    body = "\n".join(",".join(map(repr, row)) for row in (rows + 0.0).tolist())  # + 0.0: no -0.0
    with open(path, "w", encoding="utf-8", newline="") as handle:
        handle.write(f"{head}\n{body}\n")
    return len(rows)
