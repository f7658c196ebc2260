"""The batch kernels: rows of every transition at once, blocks of ordinary rows solved on vectors and the
others by the general row functions (the steps every row takes: ``spiral_cad.core._kernels``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._kernel_circles import (
    circle_in_circle_row,
    circle_to_circle_fast,
    circle_to_circle_general,
)
from ._kernel_line_circle import (
    line_to_circle_fast,
    line_to_circle_general,
)
from ._kernel_line_line import (
    line_to_line_fast,
    line_to_line_general,
)
from ._kernels import (
    OK,
    WALTON_MEEK,
    store,
)
from .jit import Kernels

if TYPE_CHECKING:  # annotations only
    from ._kernels import FloatArray, StatusArray

KERNELS = Kernels(globals())
jit = KERNELS.jit
row_jit = KERNELS.row_jit


# ------------------------------------------------------------ batches
# Each input has one row per problem or one row shared by all (``step`` 0):
# shared rows are read in place, never copied. Every row writes its own slot
# of ``out`` (control points, or NaN where it fails) and its status, θ and
# measure, so a batch may be cut into ranges of rows run on several threads
# (``spiral_cad.core.batch``; the kernels release the GIL).


@jit
def step(a: FloatArray) -> int:
    """1 for an input with a row per problem, 0 for one row shared by all."""
    return 1 if a.shape[0] > 1 else 0


#: Rows per block of a batch: each block's inputs are gathered into columns,
#: the ordinary rows solved on vectors of rows (``*_fast``), the others by the
#: general row functions.
BLOCK = 256


@jit
def line_to_circle_batch(
    p: FloatArray,
    d: FloatArray,
    c: FloatArray,
    r: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    sp, sd, sc, sr = step(p), step(d), step(c), step(r)
    cols = np.empty(7 * BLOCK)  # px, py, dx, dy, cx, cy, r of the block's rows
    res = np.empty(12 * BLOCK)  # ok, θ, measure, x0 … y3
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for k in range(m):
            i = start + k
            ip, id_, ic, ir = i * sp, i * sd, i * sc, i * sr
            cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k] = p[ip, 0], p[ip, 1], d[id_, 0], d[id_, 1]
            cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k] = c[ic, 0], c[ic, 1], r[ir]
        for k in range(m):
            row = line_to_circle_fast(
                cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k],
                cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k], shape,
            )  # fmt: skip
            ok, res[BLOCK + k], res[2 * BLOCK + k], _, x0, y0, x1, y1, x2, y2, x3, y3 = row
            res[k] = 1.0 if ok else 0.0
            res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k] = x0, y0, x1, y1
            res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k], res[11 * BLOCK + k] = x2, y2, x3, y3
        for k in range(m):
            i = start + k
            if res[k] == 1.0:
                store(out, i, 0, res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k],
                      res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k], res[11 * BLOCK + k])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + k], res[2 * BLOCK + k]
            else:
                row = line_to_circle_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k],
                    cols[4 * BLOCK + k], cols[5 * BLOCK + k], cols[6 * BLOCK + k], shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def circle_to_circle_batch(
    c0: FloatArray,
    r0: FloatArray,
    c1: FloatArray,
    r1: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    s0, sr0, s1, sr1 = step(c0), step(r0), step(c1), step(r1)
    cols = np.empty(6 * BLOCK)  # c0x, c0y, r0, c1x, c1y, r1 of the block's rows
    res = np.empty(17 * BLOCK)  # ok, θ, measure, s0 … s3, u1 … u3
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for k in range(m):
            i = start + k
            i0, j0, i1, j1 = i * s0, i * sr0, i * s1, i * sr1
            cols[k], cols[BLOCK + k], cols[2 * BLOCK + k] = c0[i0, 0], c0[i0, 1], r0[j0]
            cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k] = c1[i1, 0], c1[i1, 1], r1[j1]
        for k in range(m if shape == WALTON_MEEK else 0):  # other shapes need the general row's root search
            row = circle_to_circle_fast(
                cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k], shape
            )
            res[k] = 1.0 if row[0] else 0.0
            res[BLOCK + k], res[2 * BLOCK + k] = row[1], row[2]
            _, _, _, s0x, s0y, s1x, s1y, s2x, s2y, s3x, s3y, u1x, u1y, u2x, u2y, u3x, u3y = row
            res[3 * BLOCK + k], res[4 * BLOCK + k], res[5 * BLOCK + k], res[6 * BLOCK + k] = s0x, s0y, s1x, s1y
            res[7 * BLOCK + k], res[8 * BLOCK + k], res[9 * BLOCK + k], res[10 * BLOCK + k] = s2x, s2y, s3x, s3y
            res[11 * BLOCK + k], res[12 * BLOCK + k], res[13 * BLOCK + k] = u1x, u1y, u2x
            res[14 * BLOCK + k], res[15 * BLOCK + k], res[16 * BLOCK + k] = u2y, u3x, u3y
        for k in range(m):
            i = start + k
            if shape == WALTON_MEEK and res[k] == 1.0:
                s0x, s0y = res[3 * BLOCK + k], res[4 * BLOCK + k]
                store(out, i, 0, res[15 * BLOCK + k], res[16 * BLOCK + k], res[13 * BLOCK + k], res[14 * BLOCK + k],
                      res[11 * BLOCK + k], res[12 * BLOCK + k], s0x, s0y)  # fmt: skip
                store(out, i, 1, s0x, s0y, res[5 * BLOCK + k], res[6 * BLOCK + k], res[7 * BLOCK + k], res[8 * BLOCK + k],
                      res[9 * BLOCK + k], res[10 * BLOCK + k])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + k], res[2 * BLOCK + k]
            else:
                row = circle_to_circle_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[k], cols[BLOCK + k], cols[2 * BLOCK + k], cols[3 * BLOCK + k], cols[4 * BLOCK + k], cols[5 * BLOCK + k],
                    shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def line_to_line_batch(
    p0: FloatArray,
    p: FloatArray,
    p1: FloatArray,
    k: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
) -> None:
    s0, sp, s1, sk = step(p0), step(p), step(p1), step(k)
    cols = np.empty(7 * BLOCK)  # p0x, p0y, px, py, p1x, p1y, curvature of the block's rows
    res = np.empty(19 * BLOCK)  # ok, θ, measure, Q0, Q1 as built
    for start in range(0, out.shape[0], BLOCK):
        m = min(BLOCK, out.shape[0] - start)
        for j in range(m):
            i = start + j
            i0, ip, i1, ik = i * s0, i * sp, i * s1, i * sk
            cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j] = p0[i0, 0], p0[i0, 1], p[ip, 0], p[ip, 1]
            cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j] = p1[i1, 0], p1[i1, 1], k[ik]
        for j in range(m):
            row = line_to_line_fast(
                cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j],
                cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j], shape,
            )  # fmt: skip
            ok, res[BLOCK + j], res[2 * BLOCK + j], x0, y0, x1, y1, x2, y2, x3, y3, v0x, v0y, v1x, v1y, v2x, v2y, v3x, v3y = row
            res[j] = 1.0 if ok else 0.0
            res[3 * BLOCK + j], res[4 * BLOCK + j], res[5 * BLOCK + j], res[6 * BLOCK + j] = x0, y0, x1, y1
            res[7 * BLOCK + j], res[8 * BLOCK + j], res[9 * BLOCK + j], res[10 * BLOCK + j] = x2, y2, x3, y3
            res[11 * BLOCK + j], res[12 * BLOCK + j], res[13 * BLOCK + j], res[14 * BLOCK + j] = v3x, v3y, v2x, v2y
            res[15 * BLOCK + j], res[16 * BLOCK + j], res[17 * BLOCK + j], res[18 * BLOCK + j] = v1x, v1y, v0x, v0y
        for j in range(m):
            i = start + j
            if res[j] == 1.0:
                store(out, i, 0, res[3 * BLOCK + j], res[4 * BLOCK + j], res[5 * BLOCK + j], res[6 * BLOCK + j],
                      res[7 * BLOCK + j], res[8 * BLOCK + j], res[9 * BLOCK + j], res[10 * BLOCK + j])  # fmt: skip
                store(out, i, 1, res[11 * BLOCK + j], res[12 * BLOCK + j], res[13 * BLOCK + j], res[14 * BLOCK + j],
                      res[15 * BLOCK + j], res[16 * BLOCK + j], res[17 * BLOCK + j], res[18 * BLOCK + j])  # fmt: skip
                status[i], theta[i], measure[i] = OK, res[BLOCK + j], res[2 * BLOCK + j]
            else:
                row = line_to_line_general(  # type: ignore[assignment]  # numba types each assignment of a name on its own
                    cols[j], cols[BLOCK + j], cols[2 * BLOCK + j], cols[3 * BLOCK + j],
                    cols[4 * BLOCK + j], cols[5 * BLOCK + j], cols[6 * BLOCK + j], shape, out, i,
                )  # fmt: skip
                status[i], theta[i], measure[i] = row[0], row[1], row[2]


@jit
def circle_in_circle_batch(
    c0: FloatArray,
    r0: FloatArray,
    c1: FloatArray,
    r1: FloatArray,
    shape: int,
    out: FloatArray,
    status: StatusArray,
    theta: FloatArray,
    measure: FloatArray,
    param: FloatArray,
) -> None:
    s0, sr0, s1, sr1 = step(c0), step(r0), step(c1), step(r1)
    for i in range(out.shape[0]):
        i0, j0, i1, j1 = i * s0, i * sr0, i * s1, i * sr1
        row = circle_in_circle_row(c0[i0, 0], c0[i0, 1], r0[j0], c1[i1, 0], c1[i1, 1], r1[j1], shape, out, i)
        status[i], theta[i], measure[i], param[i] = row


KERNELS.seal()
