"""Zebra stripes (reflection lines) and curvature maps of a part, drawn with matplotlib.

How surfaces are judged by eye: a part under a room of parallel light tubes. The stripes are
the reflections of the tubes, so they follow the normals: across a G0 edge they break, across a
G1 edge (normals agree, curvature jumps) they stay joined but **kink**, across a G2 edge they
bend smoothly. Here the mesh comes from ``spiral_cad.cad.mesh.face_mesh`` (the surfaces' exact
normals at each vertex, a separate vertex per face along an edge), the view is orthographic, the
reflected view vector r = 2 (n·v) n − v is computed per vertex, and the stripe pattern is
``sign(sin(stripes · asin(r·e)))`` for a fixed direction e across the tubes, interpolated over
each triangle (gouraud) so stripe borders are sharp even on coarse triangles. Triangles are
drawn back to front, faces turned away are left out.

Figures are ``matplotlib.figure.Figure`` (Agg, no pyplot state), as ``spiral_cad.app.plots``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.colors import ListedColormap, Normalize, TwoSlopeNorm
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ..cad.mesh import FaceMesh, face_mesh

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


def _visible(mesh: FaceMesh, v: NDArray) -> NDArray:
    """Triangles facing the viewer, back to front (painter's order)."""
    tri = mesh.triangles
    facing = (mesh.normals[tri].mean(axis=1) @ v) > -1e-9
    tri = tri[facing]
    depth = mesh.points[tri].mean(axis=1) @ v
    return tri[np.argsort(depth)]


def _template(n: int) -> NDArray:
    """Barycentric weights (n², 3 corners, 3) of the n² small triangles a triangle is cut into."""
    small = []
    for i in range(n):
        for j in range(n - i):
            small.append([(i, j), (i + 1, j), (i, j + 1)])
            if i + j < n - 1:
                small.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    ij = np.array(small, dtype=float) / n
    return np.concatenate([1.0 - ij.sum(axis=2, keepdims=True), ij], axis=2)


def _draw(mesh: FaceMesh, values: NDArray, view: Sequence[float], ax: Axes | None, title: str, subdivide: int,
          **style: Any) -> tuple[Figure, Axes, PolyCollection]:  # fmt: skip
    """Draw the visible triangles back to front, each cut into ``subdivide``² flat-coloured pieces
    whose value is interpolated linearly from the corners (matplotlib's gouraud shading would
    interpolate the corners' *colours*, blurring the stripes)."""
    v, right, up = _frame(view)
    if ax is None:
        fig = Figure(figsize=(6.4, 4.8), dpi=100)
        ax = fig.add_subplot()
    else:
        fig = ax.figure.get_figure(root=True)
    tri = _visible(mesh, v)
    screen = np.column_stack([mesh.points @ right, mesh.points @ up])
    weights = _template(subdivide)
    corners = np.einsum("tkc,mcd->mtkd", weights, screen[tri]).reshape(-1, 3, 2)
    shade = np.einsum("tc,mc->mt", weights.mean(axis=1), values[tri]).ravel()
    artist = PolyCollection(corners, array=shade, edgecolors="face", linewidths=0.4, antialiased=False, **style)
    ax.add_collection(artist)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if title:
        ax.set_title(title)
    ax.autoscale_view()
    return fig, ax, artist


def _mesh_of(part: Any, units: str | None) -> FaceMesh:
    return part if isinstance(part, FaceMesh) else face_mesh(part, units=units)


def plot_zebra(part: Any, *, view: Sequence[float] = VIEW, stripes: int = 14, across: Sequence[float] = ACROSS,
               ax: Axes | None = None, title: str = "", units: str | None = "mm", subdivide: int = 3) -> Figure:  # fmt: skip
    """Zebra stripes (reflection lines of parallel light tubes) on a part, orthographic view.

    Args:
        part: a ``FaceMesh``, a build123d/CadQuery/OCCT shape, or a STEP/IGES path.
        view: direction towards the viewer.
        stripes: stripe pairs over the half-turn of reflected directions.
        across: direction across the light tubes (default vertical: horizontal tubes).
        ax: draw into these axes (default: a new figure).
        title: axes title.
        units: the unit to read a file in (as ``face_mesh``).
        subdivide: each triangle is drawn as subdivide² pieces (sharper stripe borders).

    Returns:
        The figure (``fig.savefig("zebra.png")``).

    Raises:
        ValueError: a bad ``view``/``across`` direction or ``stripes`` count, or a part without faces.
    """
    for name, value in (("stripes", stripes), ("subdivide", subdivide)):
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 64:
            raise ValueError(f"{name} must be an integer from 1 to 64; got {value!r:.40}")
    e = np.asarray(across, dtype=float)
    if e.shape != (3,) or not np.isfinite(e).all() or not np.linalg.norm(e) > 0:
        raise ValueError(f"across must be a non-zero 3-D direction; got {across!r}")
    mesh = _mesh_of(part, units)
    v = _frame(view)[0]
    n = mesh.normals
    reflected = 2.0 * (n @ v)[:, None] * n - v
    # the reflected direction's elevation above the tubes' plane, interpolated over each triangle (not
    # its stripe colour: a triangle may span several stripes) and cut into 2·stripes bands by the colours
    phase = np.arcsin(np.clip(reflected @ (e / np.linalg.norm(e)), -1.0, 1.0))
    bands = ListedColormap(["0.08", "0.97"] * stripes)
    style = dict(cmap=bands, norm=Normalize(-math.pi / 2, math.pi / 2))
    return _draw(mesh, np.nan_to_num(phase), view, ax, title, subdivide, **style)[0]


def plot_curvature_map(part: Any, *, view: Sequence[float] = VIEW, kind: str = "mean", ax: Axes | None = None,
                       title: str = "", units: str | None = "mm") -> Figure:  # fmt: skip
    """Mean (or Gaussian) curvature of a part's surfaces as colour: red convex, blue concave.

    A G2 edge shows no colour step; a G1 edge shows one (a fillet's 1/r against a plane's 0).

    Args:
        part: a ``FaceMesh``, a build123d/CadQuery/OCCT shape, or a STEP/IGES path.
        view: direction towards the viewer.
        kind: ``"mean"`` or ``"gaussian"``.
        ax: draw into these axes (default: a new figure).
        title: axes title.
        units: the unit to read a file in (as ``face_mesh``).

    Returns:
        The figure, with a colour bar.

    Raises:
        ValueError: an unknown ``kind``, a bad ``view``, or a part without faces.
    """
    if kind not in ("mean", "gaussian"):
        raise ValueError(f"kind must be 'mean' or 'gaussian'; got {kind!r}")
    mesh = _mesh_of(part, units)
    values = np.nan_to_num(mesh.mean_curvature if kind == "mean" else mesh.gaussian_curvature)
    peak = float(np.abs(values).max()) or 1.0
    fig, axes, artist = _draw(mesh, values, view, ax, title, 1, cmap="coolwarm", norm=TwoSlopeNorm(0.0, -peak, peak))
    unit = f"1/{mesh.units}" if kind == "mean" else f"1/{mesh.units}²"
    fig.colorbar(artist, ax=axes, shrink=0.7, label=f"{kind} curvature ({unit})")
    return fig
