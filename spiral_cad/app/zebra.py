"""Zebra stripes (reflection lines) and curvature maps of a part, drawn with matplotlib.

How surfaces are judged by eye: a part under a room of parallel light tubes. The stripes are
the reflections of the tubes, so they follow the normals: across a G0 edge they break, across a
G1 edge (normals agree, curvature jumps) they stay joined but **kink**, across a G2 edge they
bend smoothly. As in CAD zebra tools the tubes hang in the viewer's room (fixed to the view, at
``angle`` in the picture), and the part is seen from a point at a finite ``distance``: each pixel's
ray from the eye is reflected about the surface normal there, r = d − 2 (d·n) n, so a flat face
reflects a fan of directions and carries stripes too, and those stripes run on across its edges
into the fillets — straight on through a G2 edge, with a kink at a G1 one. The stripes are bands
of ``asin(r·e)`` for the direction e across the tubes, their borders smoothed over a pixel
(anti-aliased from the bands' own slope in the picture).

The mesh comes from ``spiral_cad.cad.mesh.face_mesh``: the surfaces' exact normals at each vertex, a
separate vertex per face along an edge, and triangles split where the normal's rate of turn
changes (where a spiral's curvature grows from zero), so that the interpolated normals do not kink
where the surface does not. The image is orthographic: the triangles are rasterised with a depth
buffer into one image of ``spiral_cad.cad.mesh.PIXELS`` pixels a side (numpy, in passes of bounded
size), so time and memory follow the picture, not the mesh; a face seen from behind (an open shell)
is drawn with its normal turned towards the viewer.

Figures are ``matplotlib.figure.Figure`` (Agg, no pyplot state), as ``spiral_cad.app.plots``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap, Normalize, TwoSlopeNorm
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from numpy.typing import NDArray

from ..cad.mesh import PIXELS, FaceMesh, face_mesh

__all__ = ["DISTANCE", "STRIPES", "VIEW", "check_picture_options", "plot_curvature_map", "plot_zebra"]

#: Default direction towards the viewer: from the front right, a little above (low enough that the stripes on
#: the sides run across their vertical edges).
VIEW = (1.0, -0.9, 0.45)
#: Default stripe pairs over the half-turn of reflected directions.
STRIPES = 24
#: Default distance of the eye from the part's centre, in part sizes (bounding-box diagonals): near enough
#: that a flat face reflects a fan of directions (about 45°) and so carries stripes into its fillets.
DISTANCE = 1.2


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


def _draw(mesh: FaceMesh, values: NDArray | Callable[[NDArray, NDArray], NDArray], view: Sequence[float], ax: Axes | None,
          title: str, pixels: int, **style: Any) -> tuple[Figure, Axes, AxesImage]:  # fmt: skip
    """Draw the part as one image: each pixel takes the nearest triangle's value there.

    A pixel's value is interpolated linearly from the corners' ``values``, or, when ``values`` is
    a function of unit normals and points, is that function of the normal interpolated to the pixel,
    renormalised and turned towards the viewer (Phong's normals: a stripe border follows the
    surface, not the triangles; a face seen from behind shows its other side), and of the point
    there, and ``style["finish"]``, if given, maps the whole image of those values to what is shown.

    Warns:
        UserWarning: no pixel shows a face (a part seen exactly edge-on).
    """
    v = _frame(view)[0]
    raster = _raster(mesh, view, pixels)
    if ax is None:  # a figure pixel (at its 100 dpi) per picture pixel, and room above for the title
        inches = np.array(raster.owner.shape[::-1]) / 100.0
        above = 0.4 if title else 0.0
        fig = Figure(figsize=(inches[0], inches[1] + above), dpi=100)
        ax = fig.add_axes((0.0, 0.0, 1.0, inches[1] / (inches[1] + above)))
    else:
        fig = ax.figure.get_figure(root=True)
    seen = raster.owner >= 0
    corners = mesh.triangles[raster.owner[seen]]  # (k, 3)
    w = raster.weights[seen]
    image = np.full(raster.owner.shape, np.nan)
    if callable(values):
        normals = np.einsum("kc,kcd->kd", w, mesh.normals[corners])
        points = np.einsum("kc,kcd->kd", w, mesh.points[corners])
        with np.errstate(all="ignore"):
            normals /= np.linalg.norm(normals, axis=1)[:, None]
            normals *= np.where(normals @ v < 0.0, -1.0, 1.0)[:, None]  # the side facing the viewer
        image[seen] = values(normals, points)
        finish = style.pop("finish", np.nan_to_num)  # the whole picture's values at once (stripes: smoothed borders)
        image = finish(image)
        image[~seen] = np.nan
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


def check_picture_options(*, view: Sequence[float] = VIEW, stripes: int = STRIPES, pixels: int = PIXELS) -> None:
    """Refuse a picture's options before anything is drawn.

    Raises:
        ValueError: ``view`` not a non-zero 3-D direction, ``stripes`` not an integer from 1 to 200, or
            ``pixels`` not an integer from 16 to 8000 (each named with the value given).
    """
    _frame(view)
    if isinstance(stripes, bool) or not isinstance(stripes, int) or not 1 <= stripes <= 200:
        raise ValueError(f"stripes must be an integer from 1 to 200; got {stripes!r:.40}")
    if isinstance(pixels, bool) or not isinstance(pixels, int) or not 16 <= pixels <= 8000:
        raise ValueError(f"pixels must be an integer from 16 to 8000; got {pixels!r:.40}")


def _stripes(phase: NDArray, dark: float) -> NDArray:
    """Grey levels in [0, 1] of stripes at ``phase`` (in periods; the first ``dark`` share of each period
    dark), each border ramped over one pixel by the phase's own slope in the picture (as a shader's
    ``fwidth``): anti-aliased without drawing the picture larger."""
    with np.errstate(all="ignore"):
        # (a picture one pixel thin, a face seen edge-on: no slope, hard borders)
        slope = np.nan_to_num(np.hypot(*np.gradient(phase)), nan=0.0, posinf=0.0) if min(phase.shape) > 1 else np.zeros_like(phase)
        fraction = phase - np.floor(phase)
        # signed distance (in periods) to the nearer border of the dark band: positive inside it
        distance = np.where(fraction < dark, np.minimum(fraction, dark - fraction), -np.minimum(fraction - dark, 1.0 - fraction))
        shade = np.clip(0.5 + distance / np.maximum(slope, 1e-12), 0.0, 1.0)
    return np.nan_to_num(1.0 - shade)


def plot_zebra(part: Any, *, view: Sequence[float] = VIEW, stripes: int = STRIPES, width: float = 0.5,
               angle: float = 0.0, distance: float = DISTANCE, across: Sequence[float] | None = None,
               ax: Axes | None = None, title: str = "", units: str | None = "mm", pixels: int = PIXELS) -> Figure:  # fmt: skip
    """Zebra stripes (reflection lines of parallel light tubes) on a part: they kink at a G1 edge and
    run smoothly through a G2 one.

    Args:
        part: a ``FaceMesh``, a build123d/CadQuery/OCCT shape, or a STEP/IGES path.
        view: direction towards the viewer (the picture is an orthographic view along it).
        stripes: dark-and-light stripe pairs over the half-turn of reflected directions.
        width: the dark share of each pair, in (0, 1).
        angle: the tubes' direction in the picture, degrees counter-clockwise from horizontal.
        distance: how far the eye is from the part's centre, in part sizes (bounding-box diagonals);
            ``math.inf`` reflects parallel rays (a flat face then shows one colour).
        across: a direction across the tubes fixed to the part instead of the view (overrides ``angle``).
        ax: draw into these axes (default: a new figure).
        title: axes title.
        units: the unit to read a file in (as ``face_mesh``).
        pixels: the raster's longer side (the part's mesh is sized for it too).

    Returns:
        The figure (``fig.savefig("zebra.png")``).

    Raises:
        ValueError: a bad ``view``/``across`` direction, ``stripes``, ``width``, ``angle``, ``distance`` or
            ``pixels``, or a part without faces.

    Warns:
        UserWarning: nothing is visible from ``view``.
    """
    check_picture_options(view=view, stripes=stripes, pixels=pixels)
    for name, value, ok in (("width", width, lambda x: 0.0 < x < 1.0), ("angle", angle, math.isfinite),
                            ("distance", distance, lambda x: x > 0.0)):  # fmt: skip
        if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value) or not ok(value):
            raise ValueError(f"{name} must be {'in (0, 1)' if name == 'width' else 'a positive number' if name == 'distance' else 'a finite number'}; "
                             f"got {value!r:.40}")  # fmt: skip
    v, right, up = _frame(view)
    if across is None:
        e = math.cos(math.radians(angle)) * up - math.sin(math.radians(angle)) * right
    else:
        e = np.asarray(across, dtype=float)
        if e.shape != (3,) or not np.isfinite(e).all() or not np.linalg.norm(e) > 0:
            raise ValueError(f"across must be a non-zero 3-D direction; got {across!r}")
        e = e / np.linalg.norm(e)
    mesh = _mesh_of(part, units, pixels)
    centre = 0.5 * (mesh.points.min(axis=0) + mesh.points.max(axis=0))
    eye = centre + distance * max(mesh.size, 1e-300) * v if math.isfinite(distance) else None

    def phase(n: NDArray, p: NDArray) -> NDArray:
        """Stripe periods of the reflected ray's elevation above the tubes' plane (the dark band first)."""
        if eye is None:
            d = np.broadcast_to(-v, n.shape)
        else:
            d = p - eye
            d = d / np.linalg.norm(d, axis=1)[:, None]
        reflected = d - 2.0 * np.einsum("ij,ij->i", d, n)[:, None] * n
        elevation = np.arcsin(np.clip(reflected @ e, -1.0, 1.0))
        return (elevation / math.pi + 0.5) * stripes

    grey = ListedColormap(np.linspace(0.08, 0.97, 256)[:, None].repeat(3, axis=1))
    style = dict(cmap=grey, norm=Normalize(0.0, 1.0), finish=partial(_stripes, dark=width))
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
    check_picture_options(view=view, pixels=pixels)
    mesh = _mesh_of(part, units, pixels)
    values = np.nan_to_num(mesh.mean_curvature if kind == "mean" else mesh.gaussian_curvature)
    peak = float(np.abs(values).max()) or 1.0
    fig, axes, artist = _draw(mesh, values, view, ax, title, pixels, cmap="coolwarm", norm=TwoSlopeNorm(0.0, -peak, peak))
    unit = f"1/{mesh.units}" if kind == "mean" else f"1/{mesh.units}²"
    fig.colorbar(artist, ax=axes, shrink=0.7, label=f"{kind} curvature ({unit})")
    return fig
