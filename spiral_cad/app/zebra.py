"""Zebra stripes (reflection lines) and curvature maps of a part, drawn with matplotlib.

How surfaces are judged by eye: a part under a room of parallel light tubes. The stripes are
the reflections of the tubes, so they follow the normals: across a G0 edge they break, across a
G1 edge (normals agree, curvature jumps) they stay joined but **kink**, across a G2 edge they
bend smoothly. Here the mesh comes from ``spiral_cad.cad.mesh.face_mesh`` (the surfaces' exact
normals at each vertex, a separate vertex per face along an edge), the view is orthographic, the
reflected view vector r = 2 (n·v) n − v is computed from the surface normals interpolated over
each pixel, and the stripes are bands of ``asin(r·e)`` for a fixed direction e across the tubes.
The triangles are rasterised with a depth buffer into one image of ``spiral_cad.cad.mesh.PIXELS`` pixels a side
(numpy, in passes of bounded size), so time and memory follow the picture, not the mesh; a face
seen from behind (an open shell) is drawn with its normal turned towards the viewer.

Figures are ``matplotlib.figure.Figure`` (Agg, no pyplot state), as ``spiral_cad.app.plots``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap, Normalize, TwoSlopeNorm
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from numpy.typing import NDArray

from ..cad.mesh import PIXELS, FaceMesh, face_mesh

__all__ = ["ACROSS", "VIEW", "plot_curvature_map", "plot_zebra"]

#: Default direction towards the viewer: from the front right, above.
VIEW = (1.0, -1.6, 1.2)
#: Default direction across the light tubes: tilted, so that stripes cross vertical and horizontal faces alike.
ACROSS = (1.0, 0.5, 0.3)


def _frame(view: Sequence[float]) -> tuple[NDArray, NDArray, NDArray]:
    """Unit view vector v (towards the viewer) and the screen's right and up axes (z up where it can be)."""
    v = np.asarray(view, dtype=float)
    if v.shape != (3,) or not np.isfinite(v).all() or not np.linalg.norm(v) > 0:
        raise ValueError(f"view must be a non-zero 3-D direction; got {view!r}")
    v = v / np.linalg.norm(v)
    up = np.array([0.0, 0.0, 1.0]) if abs(v[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    right = np.cross(up, v)
    right /= np.linalg.norm(right)
    return v, right, np.cross(v, right)


#: Candidate pixels tested per rasterising pass: bounds the memory whatever the mesh (~100 MB).
_CHUNK = 1 << 20


@dataclass(frozen=True)
class _Raster:
    """Which triangle is seen at each pixel (-1: none) and where in it (barycentric weights)."""

    owner: NDArray  # (height, width) triangle index
    weights: NDArray  # (height, width, 3)
    extent: tuple[float, float, float, float]  # left, right, bottom, top in screen units


def _raster(mesh: FaceMesh, view: Sequence[float], pixels: int) -> _Raster:
    """Rasterise the projected triangles with a depth buffer (front faces and back faces alike: the
    nearest wins), in passes of at most ``_CHUNK`` candidate pixels so that memory stays bounded."""
    v, right, up = _frame(view)
    xy = np.column_stack([mesh.points @ right, mesh.points @ up])
    depth = mesh.points @ v
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float((hi - lo).max()) or 1.0
    scale = (pixels - 1) / span
    width, height = (int(math.floor(float(d) * scale)) + 1 for d in (hi - lo))
    pix = (xy - lo) * scale  # pixel centres at integer coordinates
    tri = mesh.triangles
    corners = pix[tri]  # (m, 3, 2)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    y0 = np.clip(np.ceil(corners[..., 1].min(axis=1)), 0, height - 1).astype(np.int64)
    y1 = np.clip(np.floor(corners[..., 1].max(axis=1)), -1, height - 1).astype(np.int64)
    rows = np.where(np.abs(area) > 1e-12, np.clip(y1 - y0 + 1, 0, None), 0)  # edge-on triangles show nothing
    zbuffer = np.full(width * height, -np.inf)
    owner = np.full(width * height, -1, dtype=np.int64)
    weights = np.zeros((width * height, 3))
    for batch in _batches(rows):
        # scan lines: each triangle's pixel rows, and the span of pixel centres inside it on each
        t = np.repeat(batch, rows[batch])
        py = y0[t] + np.arange(len(t)) - np.repeat(np.cumsum(rows[batch]) - rows[batch], rows[batch])
        left, right_ = np.full(len(t), np.inf), np.full(len(t), -np.inf)
        for p, q in ((a, b), (b, c), (c, a)):
            dy = q[t, 1] - p[t, 1]
            with np.errstate(all="ignore"):
                x = p[t, 0] + (py - p[t, 1]) * (q[t, 0] - p[t, 0]) / dy
            crosses = (np.minimum(p[t, 1], q[t, 1]) <= py) & (py <= np.maximum(p[t, 1], q[t, 1])) & (dy != 0)
            left, right_ = np.where(crosses, np.minimum(left, x), left), np.where(crosses, np.maximum(right_, x), right_)
        x0 = np.clip(np.ceil(left - 1e-9), 0, width - 1)
        x1 = np.clip(np.floor(right_ + 1e-9), -1, width - 1)
        spans = np.where(np.isfinite(left), np.clip(x1 - x0 + 1, 0, None), 0).astype(np.int64)
        x0 = np.nan_to_num(x0).astype(np.int64)
        for part in _batches(spans):
            n = spans[part]
            r = np.repeat(part, n)
            k, px = t[r], x0[r] + np.arange(len(r)) - np.repeat(np.cumsum(n) - n, n)
            yy = py[r]
            l1 = ((px - a[k, 0]) * (c[k, 1] - a[k, 1]) - (yy - a[k, 1]) * (c[k, 0] - a[k, 0])) / area[k]
            l2 = ((b[k, 0] - a[k, 0]) * (yy - a[k, 1]) - (b[k, 1] - a[k, 1]) * (px - a[k, 0])) / area[k]
            bary = np.clip(np.column_stack([1.0 - l1 - l2, l1, l2]), 0.0, None)  # a centre on an edge: rounding
            bary /= bary.sum(axis=1)[:, None]
            z = np.einsum("kc,kc->k", bary, depth[tri[k]])
            pid = yy * width + px
            order = np.lexsort((z, pid))  # per pixel, the nearest (largest depth towards the viewer) last
            last = np.r_[pid[order][1:] != pid[order][:-1], True]
            keep = order[last]
            keep = keep[z[keep] > zbuffer[pid[keep]]]
            zbuffer[pid[keep]] = z[keep]
            owner[pid[keep]] = k[keep]
            weights[pid[keep]] = bary[keep]
    half = 0.5 / scale
    extent = (float(lo[0]) - half, float(lo[0]) + (width - 0.5) / scale, float(lo[1]) - half,
              float(lo[1]) + (height - 0.5) / scale)  # fmt: skip
    return _Raster(owner.reshape(height, width), weights.reshape(height, width, 3), extent)


def _batches(counts: NDArray) -> Iterator[NDArray]:
    """Indices into ``counts`` in runs whose counts add up to at most ``_CHUNK`` (or one index alone)."""
    ends = np.cumsum(counts)
    first = 0
    while first < len(counts):
        base = int(ends[first - 1]) if first else 0
        last = max(int(np.searchsorted(ends, base + _CHUNK, side="right")), first + 1)
        yield np.arange(first, last)
        first = last


def _draw(mesh: FaceMesh, values: NDArray | Callable[[NDArray], NDArray], view: Sequence[float], ax: Axes | None,
          title: str, pixels: int, **style: Any) -> tuple[Figure, Axes, AxesImage]:  # fmt: skip
    """Draw the part as one image: each pixel takes the nearest triangle's value there.

    A pixel's value is interpolated linearly from the corners' ``values``, or, when ``values`` is
    a function of unit normals, is that function of the normal interpolated to the pixel,
    renormalised and turned towards the viewer (Phong's normals: a stripe border follows the
    surface, not the triangles; a face seen from behind shows its other side).

    Warns:
        UserWarning: no pixel shows a face (a part seen exactly edge-on).
    """
    v = _frame(view)[0]
    if ax is None:
        fig = Figure(figsize=(6.4, 4.8), dpi=100)
        ax = fig.add_subplot()
    else:
        fig = ax.figure.get_figure(root=True)
    raster = _raster(mesh, view, pixels)
    seen = raster.owner >= 0
    corners = mesh.triangles[raster.owner[seen]]  # (k, 3)
    w = raster.weights[seen]
    image = np.full(raster.owner.shape, np.nan)
    if callable(values):
        normals = np.einsum("kc,kcd->kd", w, mesh.normals[corners])
        with np.errstate(all="ignore"):
            normals /= np.linalg.norm(normals, axis=1)[:, None]
            normals *= np.where(normals @ v < 0.0, -1.0, 1.0)[:, None]  # the side facing the viewer
            image[seen] = np.nan_to_num(values(normals))
    else:
        image[seen] = np.einsum("kc,kc->k", w, values[corners])
    if not seen.any():
        warnings.warn("nothing is visible from this view: every face is seen edge-on", stacklevel=3)
    cmap = colormaps[style.pop("cmap")] if isinstance(style.get("cmap"), str) else style.pop("cmap")
    artist = ax.imshow(image, origin="lower", extent=raster.extent, interpolation="nearest",
                       cmap=cmap.with_extremes(bad=(0.0, 0.0, 0.0, 0.0)), **style)  # fmt: skip
    ax.set_aspect("equal")
    ax.set_axis_off()
    if title:
        ax.set_title(title)
    return fig, ax, artist


def _mesh_of(part: Any, units: str | None, pixels: int) -> FaceMesh:
    return part if isinstance(part, FaceMesh) else face_mesh(part, units=units, pixels=pixels)


def _check_pixels(pixels: int) -> None:
    if isinstance(pixels, bool) or not isinstance(pixels, int) or not 16 <= pixels <= 8000:
        raise ValueError(f"pixels must be an integer from 16 to 8000; got {pixels!r:.40}")


def plot_zebra(part: Any, *, view: Sequence[float] = VIEW, stripes: int = 14, across: Sequence[float] = ACROSS,
               ax: Axes | None = None, title: str = "", units: str | None = "mm", pixels: int = PIXELS) -> Figure:  # fmt: skip
    """Zebra stripes (reflection lines of parallel light tubes) on a part, orthographic view.

    Args:
        part: a ``FaceMesh``, a build123d/CadQuery/OCCT shape, or a STEP/IGES path.
        view: direction towards the viewer.
        stripes: stripe pairs over the half-turn of reflected directions.
        across: direction across the light tubes (default vertical: horizontal tubes).
        ax: draw into these axes (default: a new figure).
        title: axes title.
        units: the unit to read a file in (as ``face_mesh``).
        pixels: the raster's longer side (the part's mesh is sized for it too).

    Returns:
        The figure (``fig.savefig("zebra.png")``).

    Raises:
        ValueError: a bad ``view``/``across`` direction, ``stripes`` or ``pixels`` count, or a part without faces.

    Warns:
        UserWarning: nothing is visible from ``view``.
    """
    if isinstance(stripes, bool) or not isinstance(stripes, int) or not 1 <= stripes <= 64:
        raise ValueError(f"stripes must be an integer from 1 to 64; got {stripes!r:.40}")
    _check_pixels(pixels)
    e = np.asarray(across, dtype=float)
    if e.shape != (3,) or not np.isfinite(e).all() or not np.linalg.norm(e) > 0:
        raise ValueError(f"across must be a non-zero 3-D direction; got {across!r}")
    mesh = _mesh_of(part, units, pixels)
    v = _frame(view)[0]
    e = e / np.linalg.norm(e)

    def phase(n: NDArray) -> NDArray:
        """The reflected view vector's elevation above the tubes' plane, cut into 2·stripes bands by the colours."""
        reflected = 2.0 * (n @ v)[:, None] * n - v
        return np.arcsin(np.clip(reflected @ e, -1.0, 1.0))

    bands = ListedColormap(["0.08", "0.97"] * stripes)
    style = dict(cmap=bands, norm=Normalize(-math.pi / 2, math.pi / 2))
    return _draw(mesh, phase, view, ax, title, pixels, **style)[0]


def plot_curvature_map(part: Any, *, view: Sequence[float] = VIEW, kind: str = "mean", ax: Axes | None = None,
                       title: str = "", units: str | None = "mm", pixels: int = PIXELS) -> Figure:  # fmt: skip
    """Mean (or Gaussian) curvature of a part's surfaces as colour: red convex, blue concave.

    A G2 edge shows no colour step; a G1 edge shows one (a fillet's 1/r against a plane's 0).

    Args:
        part: a ``FaceMesh``, a build123d/CadQuery/OCCT shape, or a STEP/IGES path.
        view: direction towards the viewer.
        kind: ``"mean"`` or ``"gaussian"``.
        ax: draw into these axes (default: a new figure).
        title: axes title.
        units: the unit to read a file in (as ``face_mesh``).
        pixels: the raster's longer side (the part's mesh is sized for it too).

    Returns:
        The figure, with a colour bar.

    Raises:
        ValueError: an unknown ``kind``, a bad ``view`` or ``pixels``, or a part without faces.

    Warns:
        UserWarning: nothing is visible from ``view``.
    """
    if kind not in ("mean", "gaussian"):
        raise ValueError(f"kind must be 'mean' or 'gaussian'; got {kind!r}")
    _check_pixels(pixels)
    mesh = _mesh_of(part, units, pixels)
    values = np.nan_to_num(mesh.mean_curvature if kind == "mean" else mesh.gaussian_curvature)
    peak = float(np.abs(values).max()) or 1.0
    fig, axes, artist = _draw(mesh, values, view, ax, title, pixels, cmap="coolwarm", norm=TwoSlopeNorm(0.0, -peak, peak))
    unit = f"1/{mesh.units}" if kind == "mean" else f"1/{mesh.units}²"
    fig.colorbar(artist, ax=axes, shrink=0.7, label=f"{kind} curvature ({unit})")
    return fig
