"""Samples of a chain for machines: a CSV of station, point, unit tangent and curvature.

A robot or CNC post-processor reads a path as points; this module samples a
chain (in the plane or in space) at a given ``step`` (arc length between
samples at most ``step``) or ``chord_tolerance`` (the path strays at most
that far from the straight chord between neighbouring samples). Every
segment's ends are samples (a joint is never cut), and inside a segment the
samples are evenly spaced. With a chord tolerance the spacing
comes from the segment's largest curvature κ: a curve whose curvature stays
below κ strays from the chord of an arc length Δs by at most
(1 − cos(κΔs/2))/κ, the circle's sagitta; the samples are then measured
(points between neighbours against their chord) and a segment that strays
further is sampled twice as densely, until every chord holds. Inside a
spiral the samples are even in its Bézier parameter and their stations are
measured (quadrature); with a ``step`` the measured arc length between
neighbours is what must hold.

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

from ..core import bezier
from ..core.chain import Chain
from ..core.inputs import as_float
from ..core.kinds import ARC, LINE, SPIRAL

#: Columns and their dimensions (``L``: the chain's length unit).
COLUMNS = (("s", "L"), ("x", "L"), ("y", "L"), ("z", "L"), ("tx", "1"), ("ty", "1"), ("tz", "1"), ("curvature", "1/L"))
#: At most this many samples are written (a step far below the path's size is an error, not a full disk).
MAX_SAMPLES = 20_000_000
#: Points measured between two neighbouring samples when the chord tolerance is checked.
CHORD_PROBES = 5
#: A spiral's largest curvature is taken at this many parameters, raised by ``CURVATURE_MARGIN`` (it sets the first
#: spacing only: every chord is then measured).
CURVATURE_PROBES = 5
CURVATURE_MARGIN = 1.05
#: Intervals measured at once (bounded temporaries).
BLOCK = 1 << 17


def _positive(value: object, name: str) -> float:
    number = as_float(value, name)
    if not (number > 0.0 and math.isfinite(number)):
        raise ValueError(f"{name} must be a positive length; got {number!r}")
    return number


class _Rows:
    """Points, tangents and curvatures at parameters u of a chain's rows, vectorised per kind.

    Lines and arcs are parametrised by arc length; a spiral by its Bézier
    parameter, its station found by quadrature (``bezier.arc_lengths_at``).
    """

    def __init__(self, chain: Chain):
        rows = chain.rows
        self.kind, self.geometry, self.params, self.dim = rows.kind, rows.geometry, rows.params, rows.dim
        self.lengths, self.stations = chain.lengths, chain.stations
        d = self.dim
        self.cp = rows.geometry[:, :, :d]
        # A power of two per row near its size: spiral derivatives are formed on exactly scaled copies (any magnitude).
        legs = np.abs(np.diff(self.cp, axis=1)).max(axis=(1, 2))
        self.scale = np.ldexp(1.0, np.frexp(np.where(legs > 0.0, legs, 1.0))[1])
        # Power-basis coefficients of every row once (spirals: the point, and its derivatives scaled), gathered per sample.
        scaled = self.cp / self.scale[:, None, None]
        self.coefficients = [bezier._power_coefficients(self.cp)] + [bezier._power_coefficients(scaled, k) for k in (1, 2)]

    def points(self, owner: NDArray, u: NDArray) -> NDArray:
        out = np.empty((len(owner), self.dim))
        for kind, pick in self._groups(owner):
            i, t = owner[pick], u[pick]
            if kind == LINE:
                a, b = self.cp[i, 0], self.cp[i, 1]
                out[pick] = a + t[:, None] * (b - a)
            elif kind == ARC:
                out[pick] = self._arc(i, t)[0]
            else:
                out[pick] = self._polynomial(0, i, t)
        return out

    def _polynomial(self, order: int, i: NDArray, t: NDArray) -> NDArray:
        """Derivative ``order`` (0: the point; 1, 2 on the scaled copies) of rows ``i`` at ``t``, by Horner."""
        coefficients = self.coefficients[order][i]  # gathered once: (n, k, d)
        acc = coefficients[:, -1]
        for j in range(coefficients.shape[1] - 2, -1, -1):
            acc = acc * t[:, None] + coefficients[:, j]
        return acc

    def frames(self, owner: NDArray, u: NDArray, stations: bool = True) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """(s, points, unit tangents, curvature: signed in the plane, ≥ 0 in space); s is NaN
        on spirals without ``stations`` (their quadrature is the costly part)."""
        n, d = len(owner), self.dim
        s, points, tangents, kappa = np.empty(n), np.empty((n, d)), np.empty((n, d)), np.zeros(n)
        for kind, pick in self._groups(owner):
            i, t = owner[pick], u[pick]
            if kind == LINE:
                a, b = self.cp[i, 0], self.cp[i, 1]
                points[pick] = a + t[:, None] * (b - a)
                tangents[pick] = (b - a) / self.lengths[i, None]
                s[pick] = self.stations[i] + t * self.lengths[i]
            elif kind == ARC:
                points[pick], tangents[pick], kappa[pick] = self._arc(i, t)
                s[pick] = self.stations[i] + t * self.lengths[i]
            else:
                points[pick] = self._polynomial(0, i, t)
                d1, d2 = self._polynomial(1, i, t), self._polynomial(2, i, t)
                speed = np.linalg.norm(d1, axis=1)
                tangents[pick] = d1 / speed[:, None]
                # the multi-curve form of BezierSpiral.curvature: (Q' × Q'')/|Q'|³, signed in the plane
                cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] if d == 2 else np.linalg.norm(np.cross(d1, d2), axis=1)
                kappa[pick] = cross / speed**3 / self.scale[i]
                s[pick] = self.stations[i] + np.minimum(self._arc_lengths(i, t), self.lengths[i]) if stations else np.nan
        return s, points, tangents, kappa

    def _arc_lengths(self, i: NDArray, t: NDArray) -> NDArray:
        """Arc length from 0 to ``t`` on spiral rows ``i`` (``bezier.arc_length``'s rule, one node at a time over all)."""
        return bezier.arc_lengths_at(self.coefficients[1][i], self.scale[i], t)

    def _groups(self, owner: NDArray):
        kinds = self.kind[owner]
        for kind in (LINE, ARC, SPIRAL):
            pick = np.flatnonzero(kinds == kind)
            if len(pick):
                yield kind, pick

    def _arc(self, i: NDArray, t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        g, (r, a0, sweep) = self.geometry[i], self.params[i].T
        sense = np.sign(r)
        angle = a0 + sense * sweep * t
        c, sn = np.cos(angle)[:, None], np.sin(angle)[:, None]
        e1, e2 = g[:, 1, : self.dim], g[:, 2, : self.dim]
        points = g[:, 0, : self.dim] + np.abs(r)[:, None] * (c * e1 + sn * e2)
        tangents = sense[:, None] * (-sn * e1 + c * e2)
        return points, tangents, 1.0 / (r if self.dim == 2 else np.abs(r))

    def largest_curvature(self) -> NDArray:
        """Each row's largest |κ|: 0 on lines, 1/|r| on arcs, measured on spirals with a margin."""
        kappa = np.zeros(len(self.kind))
        arc, spiral = self.kind == ARC, np.flatnonzero(self.kind == SPIRAL)
        kappa[arc] = 1.0 / np.abs(self.params[arc, 0])
        if len(spiral):
            owner = np.repeat(spiral, CURVATURE_PROBES)
            u = np.tile(np.linspace(0.0, 1.0, CURVATURE_PROBES), len(spiral))
            measured = np.abs(self.frames(owner, u, stations=False)[3]).reshape(-1, CURVATURE_PROBES).max(axis=1)
            kappa[spiral] = measured * CURVATURE_MARGIN
        return kappa

    def speed_bound(self) -> NDArray:
        """|Q'(u)| ≤ this on each row: the length of lines and arcs, 3 × the longest leg of a spiral."""
        bound = self.lengths.copy()
        spiral = self.kind == SPIRAL
        bound[spiral] = 3.0 * np.linalg.norm(np.diff(self.cp[spiral], axis=1), axis=2).max(axis=1)
        return bound


def _spacing(kappa: NDArray, tolerance: float) -> NDArray:
    """The arc length whose circle of curvature κ strays ``tolerance`` from its chord ((1 − cos(κΔs/2))/κ)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        half = np.arccos(np.clip(1.0 - tolerance * kappa, -1.0, 1.0))
        return np.where(kappa > 0.0, 2.0 * np.minimum(half, math.pi / 2) / kappa, np.inf)


def _parameters(counts: NDArray) -> tuple[NDArray, NDArray]:
    """Every row's start and ``counts`` even steps in u inside it, plus the end: (owner, u)."""
    owner = np.repeat(np.arange(len(counts)), counts)
    within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    u = within / counts[owner]
    return np.append(owner, len(counts) - 1), np.append(u, 1.0)


def _checked_counts(counts: NDArray, what: str) -> NDArray:
    if not np.all(counts <= MAX_SAMPLES) or counts.sum() > MAX_SAMPLES:
        raise ValueError(f"that would be more than {MAX_SAMPLES:,} samples; use a larger {what}")
    return np.maximum(counts, 1).astype(np.int64)


def chord_deviation(rows: _Rows, owner: NDArray, u: NDArray) -> NDArray:
    """For each pair of neighbouring samples, how far the path between them strays from their chord (measured)."""
    out = np.empty(len(owner) - 1)
    fractions = np.arange(1, CHORD_PROBES + 1) / (CHORD_PROBES + 1)
    for lo in range(0, len(out), BLOCK):
        hi = min(lo + BLOCK, len(out))
        i = owner[lo:hi]
        u0 = u[lo:hi]
        u1 = np.where(owner[lo + 1 : hi + 1] == i, u[lo + 1 : hi + 1], 1.0)  # up to the end of the row
        a, b = rows.points(i, u0), rows.points(i, u1)
        probes = rows.points(np.repeat(i, CHORD_PROBES), (u0[:, None] + (u1 - u0)[:, None] * fractions).ravel())
        offset = probes.reshape(hi - lo, CHORD_PROBES, -1) - a[:, None]
        chord = b - a
        length2 = np.einsum("ij,ij->i", chord, chord)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip(np.einsum("ikj,ij->ik", offset, chord) / length2[:, None], 0.0, 1.0)
        t = np.where(length2[:, None] > 0.0, t, 0.0)
        out[lo:hi] = np.linalg.norm(offset - t[..., None] * chord[:, None], axis=-1).max(axis=1)
    return out


def sample_path(chain: Chain, *, step: float | None = None, chord_tolerance: float | None = None) -> NDArray:
    """(n, 8) samples of ``chain``: s, x, y, z, tx, ty, tz and curvature (see the module docstring).

    Args:
        chain: the path.
        step: the largest arc length between neighbouring samples (measured).
        chord_tolerance: the largest distance between the path and the chord
            of neighbouring samples (measured).

    Raises:
        ValueError: neither or both given, a value that is not a positive
            length, more than ``MAX_SAMPLES`` samples, or values that are not finite.
    """
    if not isinstance(chain, Chain):
        raise ValueError(f"expected a Chain; got {type(chain).__name__}")
    if (step is None) == (chord_tolerance is None):
        raise ValueError("give step or chord_tolerance (one of them)")
    limit = _positive(step if step is not None else chord_tolerance, "step" if step is not None else "chord_tolerance")
    what = "step" if step is not None else "chord tolerance"
    rows = _Rows(chain)
    with np.errstate(over="ignore", invalid="ignore"):
        reach = rows.speed_bound() if step is not None else rows.lengths / _spacing(rows.largest_curvature(), limit) * limit
        counts = _checked_counts(np.ceil(np.nan_to_num(reach / limit, nan=np.inf, posinf=np.inf)), what)
    for _ in range(60):
        owner, u = _parameters(counts)
        s, points, tangents, kappa = rows.frames(owner, u)
        measure = np.diff(s) if step is not None else chord_deviation(rows, owner, u)
        over = ~(measure <= limit)
        if not over.any():
            table = np.zeros((len(s), 8))
            table[:, 0], table[:, 1 : 1 + rows.dim], table[:, 4 : 4 + rows.dim], table[:, 7] = s, points, tangents, kappa
            if not np.isfinite(table).all():
                raise ValueError("the path's samples are not all finite numbers")
            return table
        counts[np.unique(owner[:-1][over])] *= 2
        counts = _checked_counts(counts, what)
    raise ValueError(f"{what} {limit:g} {chain.units} is below what float64 resolves along this path")


def write_samples(chain: Chain, path: str | os.PathLike, *, step: float | None = None, chord_tolerance: float | None = None) -> int:
    """Write the samples of ``chain`` as CSV (see the module docstring); returns the number of samples.

    Raises:
        ValueError: as :func:`sample_path`.
        OSError: the file could not be written.
    """
    table = sample_path(chain, step=step, chord_tolerance=chord_tolerance)
    units = chain.units
    head = ",".join(f"{name} [{dimension.replace('L', units)}]" for name, dimension in COLUMNS)
    cells = map(repr, (table + 0.0).ravel().tolist())  # + 0.0: no -0.0
    body = "\n".join(map(",".join, zip(*[cells] * len(COLUMNS))))  # rows of len(COLUMNS) cells, one join each
    with open(path, "w", encoding="utf-8", newline="") as handle:
        handle.write(f"{head}\n{body}\n")
    return len(table)
