"""Vectorised transition solvers: N problems per call, one status per row.

Each function broadcasts its inputs to N rows, runs the compiled row kernel
that the scalar API uses (large batches split over threads) and returns a
:class:`BatchResult`. A row that is infeasible or malformed gets a non-zero
``status`` and NaN control points; the other rows are unaffected.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _kernel_batches as KB
from .errors import MALFORMED, NoSolutionError, Status
from .inputs import as_real_array
from .messages import describe
from .shapes import CORNER_SHAPES, DEFAULT_SHAPE, TRANSITION_SHAPES, shape_code
from .threads import run_split

__all__ = ["BatchResult", "circle_in_circle", "circle_to_circle", "line_to_circle", "line_to_line"]


@dataclass(frozen=True)
class BatchResult:
    """Solutions of N problems of one kind.

    Attributes:
        spirals: one (N, 4, 2) control-point array per spiral of the case, in
            travel order (one for line→circle and nested circles, two for
            C, S and line→line).
        theta: (N,) the theorem's θ per row (NaN where not solved).
        status: (N,) ``Status`` codes; 0 where solved.
        measure: (N,) the feasibility number of each row (see ``reason``).
        parameter: (N,) nested case only (else None): t where the spiral
            meets the larger circle.
        shape: the spiral shape of every row.
    """

    case: str
    spirals: tuple[NDArray[np.float64], ...]
    theta: NDArray[np.float64]
    status: NDArray[np.int8]
    measure: NDArray[np.float64]
    parameter: NDArray[np.float64] | None
    inputs: dict[str, NDArray[np.float64]]
    shape: str = DEFAULT_SHAPE

    @property
    def ok(self) -> NDArray[np.bool_]:
        """Boolean mask of solved rows."""
        solved: NDArray[np.bool_] = self.status == Status.OK
        return solved

    def __len__(self) -> int:
        return len(self.status)

    def error(self, i: int) -> ValueError:
        """The exception the scalar API raises for failed row ``i``: ``NoSolutionError``, or
        ``ValueError`` for malformed input; its message is ``reason(i)``."""
        message = self.reason(i)
        return ValueError(message) if Status(int(self.status[i])) in MALFORMED else NoSolutionError(message)

    def reason(self, i: int) -> str:
        """Why row ``i`` failed (the scalar API's error message), or ``"ok"``."""
        if self.status[i] == Status.OK:
            return "ok"
        row: dict[str, Any] = {k: tuple(v[i].tolist()) if v.ndim > 1 else float(v[i]) for k, v in self.inputs.items()}
        if self.case == "line_to_line" and np.isnan(row["curvature"]):
            row["curvature"] = None
        row["shape"] = self.shape
        return describe(self.case, int(self.status[i]), float(self.measure[i]), row)


def _rows(**arrays: tuple[ArrayLike, tuple[int, ...]]) -> tuple[dict[str, NDArray[np.float64]], int]:
    """Named inputs (value, trailing shape) as C-contiguous float64 arrays, and the row count N.

    Each input has N rows or is one row shared by all; a mismatch names both
    arguments. A shared row is handed to the kernels as one row (they read it
    for every problem), so broadcasting copies nothing. The arrays handed to
    the kernels always have the same type (contiguous, writeable, float64),
    so each kernel compiles once.
    """
    parsed = {}
    counts = {}
    for name, (value, trailing) in arrays.items():
        a = as_real_array(value, name)
        if a.shape[a.ndim - len(trailing) :] != trailing or not len(trailing) <= a.ndim <= len(trailing) + 1:
            raise ValueError(f"{name} must have shape (N, {', '.join(map(str, trailing))}) or {trailing}; got {a.shape}")
        if a.ndim > len(trailing):
            counts[name] = len(a)
        parsed[name] = a if a.ndim > len(trailing) else a[None]
    n = max(counts.values(), default=1)
    for name, count in counts.items():
        if count not in (1, n):
            longest = max(counts, key=counts.__getitem__)
            raise ValueError(f"{name} has {count} rows but {longest} has {n}; each input needs N rows or one")
    rows = {}
    for name, a in parsed.items():
        ready = a.flags.c_contiguous and a.flags.writeable and a.flags.aligned and a.dtype == np.float64
        rows[name] = a if ready else np.array(a, dtype=np.float64, order="C")
    return rows, n


def _output(out: NDArray[np.float64] | None, n: int, spirals: int, rows: dict[str, NDArray[np.float64]]) -> NDArray[np.float64]:
    """The (N, k, 4, 2) control-point buffer: ``out`` if given (checked), else new."""
    shape = (n, spirals, 4, 2)
    if out is None:
        return np.empty(shape)
    if not isinstance(out, np.ndarray):
        raise ValueError(f"out must be a numpy array of shape {shape}; got {type(out).__name__}")
    if out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous or not out.flags.writeable:
        raise ValueError(f"out must be a writeable C-contiguous float64 array of shape {shape}; got {out.dtype} {out.shape}")
    for name, values in rows.items():  # rows are read in place while out is written
        if np.may_share_memory(out, values) and np.shares_memory(out, values):
            raise ValueError(f"out must not share memory with an input; it overlaps {name}")
    return out


def _run(case: str, kernel: Callable[..., None], spirals: int, inputs: tuple[dict[str, NDArray[np.float64]], int], out: NDArray[np.float64] | None, shape: str,
         extra: bool = False) -> BatchResult:  # fmt: skip
    rows, n = inputs
    out = _output(out, n, spirals, rows)
    status = np.empty(n, dtype=np.int8)
    theta = np.empty(n)
    measure = np.empty(n)
    parameter = np.empty(n) if extra else None
    code = shape_code(shape, CORNER_SHAPES if case == "line_to_line" else TRANSITION_SHAPES)
    outputs = [out, status, theta, measure] + ([parameter] if extra else [])
    run_split(kernel, [*rows.values(), code, *outputs], n)
    shown = {name: np.broadcast_to(a, (n,) + a.shape[1:]) for name, a in rows.items()}  # N rows each, as views
    return BatchResult(case, tuple(out[:, k] for k in range(spirals)), theta, status, measure, parameter, shown, shape)


def line_to_circle(
    points: ArrayLike,
    directions: ArrayLike,
    centers: ArrayLike,
    radii: ArrayLike,
    out: NDArray[np.float64] | None = None,
    shape: str = DEFAULT_SHAPE,
) -> BatchResult:
    """Theorem 4.1 for N rows: points, directions, centers (N, 2); radii (N,) > 0.

    Every solver accepts inputs of shape (N, …) or a single row that is
    broadcast, ``out``: an optional (N, k, 4, 2) float64 buffer reused for
    the control points (saves the allocation in repeated calls), and
    ``shape``: the spiral shape of every row (as in the scalar solvers).
    Every row of ``out`` is written: solved rows with their control points,
    failed rows with NaN.

    Raises:
        ValueError: an input that is not an array of real numbers (a masked
            array included: numpy would drop its mask), of the wrong shape or
            row count, a bad ``out`` or an unknown shape (the message names
            it). No row's values raise: they become that row's status.
    """
    rows = _rows(point=(points, (2,)), direction=(directions, (2,)), center=(centers, (2,)), radius=(radii, ()))
    return _run("line_to_circle", KB.line_to_circle_batch, 1, rows, out, shape)


def circle_to_circle(
    centers0: ArrayLike,
    radii0: ArrayLike,
    centers1: ArrayLike,
    radii1: ArrayLike,
    out: NDArray[np.float64] | None = None,
    shape: str = DEFAULT_SHAPE,
) -> BatchResult:
    """Theorems 4.2/4.3 for N rows (signed travel-sense radii: C or S per row)."""
    rows = _rows(center0=(centers0, (2,)), radius0=(radii0, ()), center1=(centers1, (2,)), radius1=(radii1, ()))
    return _run("circle_to_circle", KB.circle_to_circle_batch, 2, rows, out, shape)


def line_to_line(
    p0: ArrayLike,
    corners: ArrayLike,
    p1: ArrayLike,
    curvatures: ArrayLike | None = None,
    out: NDArray[np.float64] | None = None,
    shape: str = DEFAULT_SHAPE,
) -> BatchResult:
    """Theorem 4.4 for N corners; ``curvatures`` NaN (or None) applies Corollary 4.5.
    ``shape`` may also be ``"g2cbs"`` (a corner shape)."""
    k = np.nan if curvatures is None else curvatures
    rows = _rows(p0=(p0, (2,)), corner=(corners, (2,)), p1=(p1, (2,)), curvature=(k, ()))
    return _run("line_to_line", KB.line_to_line_batch, 2, rows, out, shape)


def circle_in_circle(
    centers0: ArrayLike,
    radii0: ArrayLike,
    centers1: ArrayLike,
    radii1: ArrayLike,
    out: NDArray[np.float64] | None = None,
    shape: str = DEFAULT_SHAPE,
) -> BatchResult:
    """The fifth case for N rows (nested circles, same-sign radii)."""
    rows = _rows(center0=(centers0, (2,)), radius0=(radii0, ()), center1=(centers1, (2,)), radius1=(radii1, ()))
    return _run("circle_in_circle", KB.circle_in_circle_batch, 1, rows, out, shape, extra=True)
