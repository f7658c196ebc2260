"""The report of a fit to points: every point's residual as CSV, and the fit plot.

``NAME_residuals.csv`` holds one row per input point: its index, x, y, the
station (arc length) of the nearest point of the fitted path and the
distance to it, units in the headers as in the package's other CSV files.
``NAME_fit.png`` shows the residuals against arc length inside the tolerance
band, and the fitted path's curvature against arc length as a line over the
point-wise curvature estimate as dots.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from ..core.chain import Chain
from .plots import MAX_SAMPLES, plot_curvature

__all__ = ["RESIDUAL_COLUMNS", "plot_fit", "shown_points", "write_residuals"]

#: The columns of ``NAME_residuals.csv`` and their dimension (``L`` the length unit).
RESIDUAL_COLUMNS = (("index", ""), ("x", "L"), ("y", "L"), ("station", "L"), ("residual", "L"))


def write_residuals(
    path: str | Path, points: ArrayLike, stations: ArrayLike, residuals: ArrayLike, units: str, vertical: ArrayLike | None = None
) -> Path:
    """Write one row per point (index, x, y, station, residual; full precision, units in the headers) to ``path``;
    with ``vertical`` (a 3-D survey) also z and the vertical residual.

    Args:
        path: the CSV file.
        points: the fitted points (N, 2) or (N, 3); x and y are written.
        stations: the arc length of each point's nearest point on the path (N,).
        residuals: each point's distance to the path (N,).
        units: the unit of every length.
        vertical: each point's |z − profile elevation| (N,), or None.

    Raises:
        ValueError: the arrays do not hold one row per point.
    """
    xy = np.asarray(points, dtype=np.float64)
    s, r = np.asarray(stations, dtype=np.float64), np.asarray(residuals, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] < 2 or s.shape != (len(xy),) or r.shape != (len(xy),):
        raise ValueError(f"points {xy.shape}, stations {s.shape} and residuals {r.shape} must hold one row per point")
    names = RESIDUAL_COLUMNS + ((("z", "L"), ("vertical_residual", "L")) if vertical is not None else ())
    head = ",".join(f"{name} [{dim.replace('L', units)}]" if dim else name for name, dim in names)
    extra = [] if vertical is None else [xy[:, 2], np.asarray(vertical, dtype=np.float64)]
    table = np.column_stack([xy[:, 0], xy[:, 1], s, r, *extra]) + 0.0  # + 0.0: no -0.0
    columns = [map(repr, column) for column in table.T.tolist()]  # repr: the shortest text that reads back exactly
    body = "\n".join(map(",".join, zip(map(str, range(len(table))), *columns)))
    path = Path(path)
    with path.open("w", encoding="utf-8", newline="") as handle:
        handle.write(f"{head}\n{body}\n")
    return path


def shown_points(residuals: ArrayLike, most: int = MAX_SAMPLES) -> NDArray[np.intp]:
    """Indices of at most about ``most`` points to draw: all of them, or the largest |residual| of each run
    of consecutive points, so the plot of a million points still shows the worst."""
    r = np.abs(np.asarray(residuals, dtype=np.float64))
    if len(r) <= most:
        return np.arange(len(r))
    run = math.ceil(len(r) / most)
    padded = np.concatenate([r, np.full(-len(r) % run, -1.0)]).reshape(-1, run)
    return np.arange(0, len(r), run) + padded.argmax(axis=1)


def plot_fit(
    chain: Chain,
    stations: ArrayLike,
    residuals: ArrayLike,
    tolerance: float,
    estimate: ArrayLike | None = None,
    ax: tuple[Axes, Axes] | None = None,
    vertical: ArrayLike | None = None,
) -> Figure:
    """The fit's report plot: residuals and curvature against arc length.

    Top: every point's residual at its station, inside the band ±``tolerance``
    (scatter gid ``residuals``, the band gid ``tolerance``). Bottom: the
    fitted path's curvature as lines (``plot_curvature``), over the point-wise
    curvature ``estimate`` as dots (gid ``estimate``). At most about
    ``MAX_SAMPLES`` points are drawn (see ``shown_points``).

    Args:
        chain: the fitted path.
        stations: each point's station on the path (N,).
        residuals: each point's distance to the path (N,), signed or not.
        tolerance: the fit's tolerance.
        estimate: the curvature estimated at each point (N,), or None.
        ax: a pair of axes (residuals, curvature), or None for a new figure.
        vertical: each point's |z − profile| (N,) of a 3-D survey, drawn beside the plan residuals
            (scatter gid ``vertical``), or None.
    """
    s, r = np.asarray(stations, dtype=np.float64), np.asarray(residuals, dtype=np.float64)
    if ax is None:
        fig = Figure(figsize=(9, 7))
        top, bottom = fig.subplots(2, 1, sharex=True)
    else:
        top, bottom = ax
        fig = top.figure.get_figure(root=True)
    shown = shown_points(r)
    units = chain.units
    top.axhspan(-tolerance, tolerance, color="tab:green", alpha=0.12, lw=0, gid="tolerance", label=f"±{tolerance:g} {units}")
    top.scatter(s[shown], r[shown], s=4, color="tab:blue", gid="residuals", label=f"{len(r):,} points", rasterized=True)
    if vertical is not None:
        v = np.asarray(vertical, dtype=np.float64)
        top.scatter(s[shown], v[shown], s=4, color="tab:orange", gid="vertical", label="vertical (z − profile)", rasterized=True)
    worst = int(np.argmax(np.abs(r))) if len(r) else 0
    top.set_ylabel(f"residual ({units})")
    top.set_title(f"Residuals: worst {abs(r[worst]) if len(r) else 0.0:.3g} {units} of {tolerance:g} {units}")
    top.legend(loc="upper right", fontsize="small")
    top.grid(True, alpha=0.3)
    if estimate is not None:
        k = np.asarray(estimate, dtype=np.float64)
        bottom.scatter(s[shown], k[shown], s=4, color="0.6", zorder=0, gid="estimate", label="point-wise estimate", rasterized=True)
    plot_curvature(chain, ax=bottom)
    bottom.set_title("Curvature: the fitted path over the point-wise estimate")
    return fig
