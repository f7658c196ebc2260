"""Segments as arrays: the storage of chains.

A chain of 40 000 segments is four arrays, not 40 000 objects: ``kind``
(n,), ``geometry`` (n, 4, 3), ``params`` (n, 3) and ``shapes`` (n,), in the
layout of ``spiral_cad.core._chain_kernels`` (always three coordinates; a
plane chain has z = 0 and ``dim`` 2). ``Line``, ``Arc`` and ``BezierSpiral``
objects are made from rows only when asked for (``segment``), and rows are
made from objects or from batch results (``spirals``: no object per segment).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import bezier
from .kinds import ARC, LINE, SPIRAL
from .segments import _XY_BASIS, Arc, Line, Segment, row_frames
from .shapes import SHAPE_CODES, SHAPE_NAMES
from .space import place
from .spiral import BezierSpiral

#: ``shapes`` entry of rows whose shape is not stated (lines, arcs, spirals without one).
NO_SHAPE = -1


def shape_number(shape: str | None) -> int:
    return NO_SHAPE if shape is None else SHAPE_CODES[shape]


@dataclass(frozen=True, eq=False)
class SegmentRows:
    """n segments as arrays (see the module docstring).

    Attributes:
        kind: (n,) int8: ``LINE``, ``ARC`` or ``SPIRAL``.
        geometry: (n, 4, 3) points of each row (line ends; arc centre and plane basis; control points).
        params: (n, 3) arc (signed radius, start angle, sweep); zeros otherwise.
        shapes: (n,) int8 spiral shape codes (``NO_SHAPE`` where not stated).
        dim: 2 (every z is 0, arcs in the XY plane) or 3.
        lengths: (n,) known arc lengths, NaN where not yet measured (spirals).
    """

    kind: NDArray[np.int8]
    geometry: NDArray[np.float64]
    params: NDArray[np.float64]
    shapes: NDArray[np.int8]
    dim: int
    lengths: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.kind)

    # ------------------------------------------------------- building

    @classmethod
    def empty(cls, n: int, dim: int) -> SegmentRows:
        return cls(np.zeros(n, np.int8), np.zeros((n, 4, 3)), np.zeros((n, 3)), np.full(n, NO_SHAPE, np.int8), dim,
                   np.full(n, np.nan))  # fmt: skip

    @classmethod
    def spirals(cls, control_points: ArrayLike, shape: str | None = None) -> SegmentRows:
        """Rows of spirals from (n, 4, 2) or (n, 4, 3) control points (solver output, e.g. ``spiral_cad.core.batch``
        rows placed by ``space.place``: no checks)."""
        cp = np.asarray(control_points, dtype=float)
        rows = cls.empty(len(cp), cp.shape[2])
        rows.kind[:] = SPIRAL
        rows.geometry[:, :, : cp.shape[2]] = cp
        rows.shapes[:] = shape_number(shape)
        return rows

    @classmethod
    def of_segments(cls, segments: Sequence[Segment]) -> SegmentRows:
        """Rows of segment objects (any mix of kinds and dimensions; plane ones in the XY plane).

        Spiral lengths are measured here where the objects have not yet
        (one quadrature for all), and cached in the objects as well.
        """
        dims = [s._dim for s in segments]
        rows = cls.empty(len(segments), max(dims, default=2))
        kinds = (Line, Arc, BezierSpiral)
        groups: dict[type, list[int]] = {k: [] for k in kinds}
        for i, s in enumerate(segments):
            kind = type(s)
            (groups[kind] if kind in groups else groups[next(k for k in kinds if isinstance(s, k))]).append(i)  # subclasses too
        for kind, index in groups.items():
            for dim in (2, 3):  # one array per kind and dimension
                rows._fill(kind, [i for i in index if dims[i] == dim], [segments[i] for i in index if dims[i] == dim], dim)
        for dim in (2, 3):  # spirals not yet measured: one quadrature for all (in their own dimension)
            todo = [i for i in groups[BezierSpiral] if dims[i] == dim and cast(BezierSpiral, segments[i])._length is None]
            if todo:
                rows.lengths[todo] = bezier.arc_length(rows.geometry[todo, :, :dim])
                for i, length in zip(todo, rows.lengths[todo].tolist()):
                    cast(BezierSpiral, segments[i])._length = length
        return rows

    def _fill(self, kind: type, index: list[int], items: list[Segment], dim: int) -> None:
        if not index:
            return
        g = self.geometry
        if kind is Line:
            lines = cast("list[Line]", items)
            self.kind[index] = LINE
            g[index, 0, :dim] = [s._a for s in lines]
            g[index, 1, :dim] = [s._b for s in lines]
        elif kind is Arc:
            arcs = cast("list[Arc]", items)
            self.kind[index] = ARC
            self.params[index] = [(s._r, s._a0, s._sweep) for s in arcs]
            g[index, 0, :dim] = [s._c for s in arcs]
            g[index, 1:3] = _XY_BASIS if dim == 2 else [s._basis for s in arcs]
        else:
            spirals = cast("list[BezierSpiral]", items)
            self.kind[index] = SPIRAL
            self.shapes[index] = [shape_number(s._shape) for s in spirals]
            self.lengths[index] = [np.nan if s._length is None else s._length for s in spirals]
            g[index, :, :dim] = [s._cp for s in spirals]

    @classmethod
    def concatenate(cls, parts: Sequence[SegmentRows]) -> SegmentRows:
        def joined(name: str) -> NDArray[Any]:
            return np.concatenate([getattr(p, name) for p in parts])

        return cls(joined("kind"), joined("geometry"), joined("params"), joined("shapes"), max(p.dim for p in parts),
                   np.concatenate([p.lengths for p in parts]))  # fmt: skip

    def take(self, index: NDArray[np.intp]) -> SegmentRows:
        """The rows at ``index`` (in that order)."""
        return SegmentRows(self.kind[index], self.geometry[index], self.params[index], self.shapes[index], self.dim, self.lengths[index])

    # ------------------------------------------------------- measuring

    def measure(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """End frames (n, 2, 9), rounding floors (n, 2, 3) and lengths (n,) of every row in one pass;
        spiral lengths not yet known by one vectorised quadrature (``bezier.arc_length``)."""
        frames, floors, lengths = row_frames(self.kind, self.geometry, self.params, self.dim)
        spiral = self.kind == SPIRAL
        lengths[spiral] = self.lengths[spiral]
        todo = np.flatnonzero(spiral & np.isnan(lengths))
        if len(todo):
            lengths[todo] = bezier.arc_length(self.geometry[todo, :, : self.dim])
            self.lengths[todo] = lengths[todo]
        return frames, floors, lengths

    # ------------------------------------------------------- objects

    def segment(self, i: int) -> Segment:
        """Row ``i`` as a ``Line``, ``Arc`` or ``BezierSpiral`` of ``dim`` coordinates."""
        g, dim = self.geometry[i], self.dim
        kind = self.kind[i]
        if kind == LINE:
            return Line._of(g[0, :dim].copy(), g[1, :dim].copy())
        if kind == ARC:
            r, a0, sweep = self.params[i].tolist()
            return Arc._of(g[0, :dim].copy(), r, a0, sweep, None if dim == 2 else g[1:3].copy())
        shape = int(self.shapes[i])
        length = float(self.lengths[i])
        return BezierSpiral._wrap(g[:, :dim].copy(), None if shape == -1 else SHAPE_NAMES[shape], None if length != length else length)

    # ------------------------------------------------------- transforms

    def reversed(self) -> SegmentRows:
        """The rows of the same path travelled the other way (spiral lengths to be measured again)."""
        rows = self.take(np.arange(len(self))[::-1])
        g, p = rows.geometry, rows.params
        line, arc, spiral = (rows.kind == k for k in (LINE, ARC, SPIRAL))
        g[line, :2] = g[line, 1::-1]
        g[spiral] = g[spiral, ::-1]
        p[arc, 1] += np.copysign(p[arc, 2], p[arc, 0])  # the end angle (``Arc.reversed``)
        p[arc, 0] *= -1.0
        rows.lengths[spiral] = np.nan
        return rows

    def placed(self, origin: ArrayLike, x_dir: ArrayLike, y_dir: ArrayLike) -> SegmentRows:
        """Plane rows placed in space by the frame (origin, x_dir, y_dir) (lengths to be measured again)."""
        rows = self.take(np.arange(len(self)))
        g = rows.geometry
        line, arc, spiral = (rows.kind == k for k in (LINE, ARC, SPIRAL))
        g[line, :2] = place(g[line, :2, :2], origin, x_dir, y_dir)
        g[spiral] = place(g[spiral, :, :2], origin, x_dir, y_dir)
        g[arc, 0] = place(g[arc, 0, :2], origin, x_dir, y_dir)
        g[arc, 1], g[arc, 2] = x_dir, y_dir
        return SegmentRows(rows.kind, g, rows.params, rows.shapes, 3, np.where(arc, rows.lengths, np.nan))
