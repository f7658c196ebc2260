"""Matplotlib views of chains and spirals: plan with curvature comb, curvature plots.

Figures are built with ``matplotlib.figure.Figure`` (Agg canvas, no pyplot
state, nothing is shown); every function takes an optional ``ax`` and
returns the figure so callers can ``fig.savefig(...)``.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from numpy.typing import NDArray
from scipy.special import fresnel

from ..core import bezier
from ..core.chain import Chain
from ..core.factors import length_factor, peak_rate_factor, search_range
from ..core.namespaces import lazy_names
from ..core.shapes import shape_limits
from ..core.spiral import BezierSpiral

#: Colour per segment type (plan, comb and curvature plots).
SEGMENT_COLORS = {"Line": "0.35", "Arc": "tab:blue", "BezierSpiral": "tab:red"}


def _axes(ax: Axes | None, **figure_kw) -> tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure.get_figure(root=True), ax  # the root: an Axes in a SubFigure too gives a savable Figure
    fig = Figure(**figure_kw)
    return fig, fig.add_subplot()


def _axes_pair(ax: Sequence[Axes] | None) -> tuple[Figure, tuple[Axes, Axes]]:
    """The given pair of axes, or a new two-panel figure."""
    if ax is not None:
        return ax[0].figure.get_figure(root=True), cast("tuple[Axes, Axes]", tuple(ax))
    fig = Figure(figsize=(11, 4.5))
    return fig, cast("tuple[Axes, Axes]", tuple(fig.subplots(1, 2)))


def _kind(segment) -> str:
    return type(segment).__name__


@dataclass(frozen=True)
class Comb:
    """Curvature comb samples of a chain: teeth from ``points`` to ``tips``.

    ``tips = points − scale · curvature · normals`` (normals point left of
    travel, so teeth stand on the convex side). ``segment`` is the index of
    the segment each sample belongs to.
    """

    stations: NDArray
    points: NDArray
    normals: NDArray
    curvature: NDArray
    tips: NDArray
    segment: NDArray
    scale: float


def comb_samples(chain: Chain, per_segment: int = 24, scale: float | None = None) -> Comb:
    """Comb samples, ``per_segment`` per segment (ends included); in space the teeth
    stand against the curvature vector κN, in the osculating plane.

    Args:
        chain: the path.
        per_segment: samples per segment.
        scale: tooth length per unit curvature; by default the longest tooth
            is a fifth of the chain's size.
    """
    u = np.linspace(0.0, 1.0, per_segment)
    starts = chain.stations
    stations, points, normals, kappa, owner = [], [], [], [], []
    for i, seg in enumerate(chain.segments):
        # Stations from the segment's own arc-length parametrisation.
        s = starts[i] + (bezier.arc_length(seg.control_points, u) if isinstance(seg, BezierSpiral) else u * seg.length)
        stations.append(s)
        points.append(seg.point(u))
        k = np.broadcast_to(seg.curvature(u), u.shape)
        if chain.dim == 2:  # the left normal: signed curvature times it is the curvature vector
            t = seg.tangent(u)
            normals.append(np.stack([-t[:, 1], t[:, 0]], axis=1))
        else:  # in space the principal normal (κ ≥ 0); none on straight stretches
            vector = seg.curvature_vector(u)
            with np.errstate(invalid="ignore", divide="ignore"):
                normals.append(np.nan_to_num(vector / k[:, None]))
        kappa.append(k)
        owner.append(np.full(per_segment, i))
    kappa_all = np.concatenate(kappa)
    if scale is None:
        peak = float(np.abs(kappa_all).max())
        scale = 0.2 * chain.size / peak if peak > 0.0 else 0.0
    pts, nrm = np.vstack(points), np.vstack(normals)
    tips = pts - scale * kappa_all[:, None] * nrm  # teeth on the convex side, against the curvature vector
    return Comb(np.concatenate(stations), pts, nrm, kappa_all, tips, np.concatenate(owner), float(scale))


def _by_kind(chain: Chain) -> dict[str, NDArray]:
    """Segment indices per segment type, in order of first appearance."""
    kinds = np.array([_kind(seg) for seg in chain.segments])
    return {kind: np.flatnonzero(kinds == kind) for kind in dict.fromkeys(kinds.tolist())}


#: Samples drawn per figure at most: long chains get fewer per segment, so a
#: 40 000-segment alignment plots in seconds, not minutes.
MAX_SAMPLES = 100_000


def _samples(chain: Chain, per_segment: int | None, most: int) -> int:
    return per_segment if per_segment is not None else max(4, min(most, MAX_SAMPLES // len(chain)))


def plot_plan(chain: Chain, comb: bool = True, ax: Axes | None = None, per_segment: int | None = None) -> Figure:
    """Plan view of ``chain``, coloured by segment type, with an optional curvature comb
    (a chain in space is drawn projected onto its XY plane, comb teeth included).

    Artists (one set per segment type; at most ``MAX_SAMPLES`` points unless
    ``per_segment`` is given, so long chains draw in seconds): a ``LineCollection`` of the segments (gid
    ``plan-KIND``), and with ``comb`` one of teeth (``comb-KIND``) and one of
    the envelopes through the tips (``envelope-KIND``), each holding one
    polyline per segment in chain order.
    """
    fig, ax = _axes(ax, figsize=(8, 5))
    per_segment = _samples(chain, per_segment, 48)
    data = comb_samples(chain, per_segment) if comb else None
    u = np.linspace(0.0, 1.0, per_segment)
    for kind, index in _by_kind(chain).items():
        color = SEGMENT_COLORS.get(kind, "k")
        plan = [chain.segments[i].point(u)[:, :2] for i in index]
        ax.add_collection(LineCollection(plan, colors=color, linewidths=2.0, label=kind, gid=f"plan-{kind}"))
        if data is not None:
            rows = (index[:, None] * per_segment + np.arange(per_segment)).ravel()
            teeth = np.stack([data.points[rows, :2], data.tips[rows, :2]], axis=1)
            # ignores: matplotlib's stub takes only a Sequence, but an (n, m, 2) array is a documented list of lines
            ax.add_collection(LineCollection(teeth, colors=color, linewidths=0.6, alpha=0.5, gid=f"comb-{kind}"))  # type: ignore[arg-type]
            envelopes = data.tips[rows, :2].reshape(len(index), per_segment, 2)
            ax.add_collection(LineCollection(envelopes, colors=color, linewidths=0.8, alpha=0.8, gid=f"envelope-{kind}"))  # type: ignore[arg-type]
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    unit = f" ({chain.units})"
    ax.set_xlabel("x" + unit)
    ax.set_ylabel("y" + unit)
    count = f"{len(chain)} segment{'s' * (len(chain) != 1)}"
    title = f"{'Plan' if chain.dim == 2 else 'Plan (projected onto XY)'}: {count}, length {chain.length:.6g} {chain.units}"
    if data is not None:
        title += f" (comb: {data.scale:.3g} {chain.units}² per unit curvature)"
    ax.set_title(title)
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


def plot_curvature(chain: Chain, ax: Axes | None = None, per_segment: int | None = None) -> Figure:
    """Curvature against arc length (signed in the plane, κ ≥ 0 in space): one
    ``LineCollection`` per segment type (gid ``curvature-KIND``, one polyline per segment)."""
    fig, ax = _axes(ax, figsize=(8, 4))
    per_segment = _samples(chain, per_segment, 64)
    data = comb_samples(chain, per_segment, scale=0.0)
    profile = np.stack([data.stations, data.curvature], axis=1).reshape(len(chain), per_segment, 2)
    for kind, index in _by_kind(chain).items():
        ax.add_collection(
            LineCollection(profile[index], colors=SEGMENT_COLORS.get(kind, "k"), linewidths=1.8, label=kind, gid=f"curvature-{kind}")
        )
    ax.autoscale_view()
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel(f"arc length s ({chain.units})")
    ax.set_ylabel(f"curvature {'κ' if chain.dim == 2 else '|κ|'} (1/{chain.units})")
    ax.set_title("Curvature profile")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


def plot(obj: Any, path: str | os.PathLike | None = None, *, comb: bool = True) -> Figure:
    """The plan (with its curvature comb) and the curvature profile of a chain, side by side.

    Args:
        obj: a ``Chain``, a ``Transition`` (its spirals), or what holds one chain: ``.chain`` (an
            ``Alignment``, a rounded path) or ``.chains`` with one (``make_g2``'s result).
        path: also save the figure there (any format matplotlib writes, by suffix: .png, .svg, .pdf).
        comb: draw the curvature comb on the plan.

    Returns:
        The figure (``plot_plan`` beside ``plot_curvature``).

    Raises:
        ValueError: ``obj`` holds no chain, or several; a ``path`` matplotlib cannot write.
    """
    from ..core.transitions import Transition

    chain = obj
    if isinstance(obj, Transition):
        chain = Chain(obj.spirals)
    elif not isinstance(obj, Chain) and isinstance(getattr(obj, "chain", None), Chain):
        chain = obj.chain
    elif not isinstance(obj, Chain) and isinstance(getattr(obj, "chains", None), list):
        if len(obj.chains) != 1:
            raise ValueError(f"plot: the {type(obj).__name__} holds {len(obj.chains)} chains; plot each of .chains")
        chain = obj.chains[0]
    if not isinstance(chain, Chain):
        raise ValueError(f"plot: expected a Chain, a Transition or what holds one chain (.chain, .chains); got {type(obj).__name__}")
    fig, (plan, profile) = _axes_pair(None)
    plot_plan(chain, comb=comb, ax=plan)
    plan.set_title(plan.get_title().replace(" (comb:", "\n(comb:"), fontsize="medium")  # two lines: it fits its half
    plot_curvature(chain, ax=profile)
    fig.tight_layout()
    if path is not None:
        try:
            fig.savefig(os.fspath(path))
        except ValueError as error:  # "Format 'xyz' is not supported"
            raise ValueError(f"plot: cannot save {os.fspath(path)!r}: {error}") from None
    return fig


#: Line colour of each spiral shape in the comparison plots.
SHAPE_COLORS = {"walton-meek": "tab:red", "near-linear": "tab:green"}


def plot_fig6(ax: Axes | None = None, samples: int = 200, shape: str = "walton-meek") -> Figure:
    """Walton & Meek's Fig. 6: curvature against arc length for θ = 10°, 20°, …, 80°.

    As in the paper, each spiral has unit curvature at u = 1 and its arc
    length is scaled to the total length of the θ = 10° spiral; the dashed
    line is the clothoid's linear profile. ``shape="near-linear"`` draws the
    near-linear family instead (θ = 10° … 50°, its range).
    """
    fig, ax = _axes(ax, figsize=(7, 5))
    u = np.linspace(0.0, 1.0, samples)
    reference = BezierSpiral((0.0, 0.0), (1.0, 0.0), math.radians(10.0), 1.0, shape=shape).length
    largest = math.degrees(shape_limits(shape)["theta"])
    for k, degrees in enumerate(d for d in range(10, 90, 10) if d <= largest + 1e-9):
        spiral = BezierSpiral((0.0, 0.0), (1.0, 0.0), math.radians(degrees), 1.0, shape=shape)
        s = bezier.arc_length(spiral.control_points, u) * reference / spiral.length
        ax.plot(s, spiral.curvature(u), color=f"C{k}", lw=1.4, label=f"θ = {degrees}°")
    ax.plot([0.0, reference], [0.0, 1.0], "k--", lw=1.0, label="clothoid")
    ax.set_xlabel("arc length (scaled to the θ = 10° spiral)")
    ax.set_ylabel("curvature")
    name = "Cubic Bézier spiral (Walton & Meek, Fig. 6)" if shape == "walton-meek" else f"{shape} cubic spiral"
    ax.set_title(f"{name}: curvature vs arc length")
    ax.legend(loc="lower right", fontsize="small", ncol=2)
    ax.grid(True, alpha=0.3)
    return fig


def plot_fig6_shapes(samples: int = 200) -> Figure:
    """Fig. 6 extended: the 1996 spiral's family (left) beside the near-linear one (right)."""
    fig = Figure(figsize=(13, 5))
    left, right = fig.subplots(1, 2, sharey=True)
    plot_fig6(left, samples, "walton-meek")
    plot_fig6(right, samples, "near-linear")
    return fig


def clothoid_points(theta: float, curvature: float, s: NDArray) -> NDArray:
    """Points of the clothoid from the origin along +x with turn ``theta`` and end curvature.

    Length L = 2θ/c and heading φ(s) = c s²/(2L); with a = √(πL/c),
    (x, y) = a·(C(s/a), S(s/a)) in Fresnel integrals. Negative θ mirrors.
    """
    c, th = abs(curvature), abs(theta)
    length = 2.0 * th / c
    a = math.sqrt(math.pi * length / c)
    fs, fc = fresnel(np.asarray(s) / a)
    return np.stack([a * fc, math.copysign(1.0, theta) * a * fs], axis=-1)


def plot_vs_clothoid(
    theta: float,
    curvature: float,
    ax: Sequence[Axes] | None = None,
    samples: int = 200,
    shapes: Sequence[str] = ("walton-meek",),
) -> Figure:
    """Bézier spirals of ``shapes`` against the clothoid with the same turn ``theta`` and end ``curvature``.

    Left: curvature against arc length (the clothoid's is linear). Right:
    both curves from the origin along +x, with their end circles; the legend
    gives each curve's length and its circle's offset p from the start
    tangent (the "shift" of highway design).

    Args:
        theta: turn angle (radians, 0 < |θ| < π/2).
        curvature: end curvature (same sign as θ).
        ax: a pair of axes, or None for a new two-panel figure.
        shapes: the spiral shapes drawn (``"walton-meek"``, ``"near-linear"``).
    """
    fig, (left, right) = _axes_pair(ax)
    spirals = {shape: BezierSpiral((0.0, 0.0), (1.0, 0.0), theta, curvature, shape=shape) for shape in shapes}
    u = np.linspace(0.0, 1.0, samples)
    length_clo = 2.0 * abs(theta) / abs(curvature)
    s_clo = np.linspace(0.0, length_clo, samples)
    for shape, spiral in spirals.items():
        s_bez = bezier.arc_length(spiral.control_points, u)
        left.plot(s_bez, spiral.curvature(u), color=SHAPE_COLORS[shape], lw=1.8, label=f"{shape} (L = {spiral.length:.4g})")
    left.plot(s_clo, curvature * s_clo / length_clo, "k--", lw=1.4, label=f"clothoid (L = {length_clo:.4g})")
    left.set_xlabel("arc length s")
    left.set_ylabel("curvature κ")
    left.set_title(f"θ = {math.degrees(theta):.4g}°, end curvature {curvature:.4g}")
    left.legend(loc="best", fontsize="small")
    left.grid(True, alpha=0.3)

    radius = 1.0 / curvature
    xy_clo = clothoid_points(theta, curvature, s_clo)
    end_normal = np.array([-math.sin(theta), math.cos(theta)])  # both curves end with heading θ
    curves = [(spiral.point(u), SHAPE_COLORS[shape], "-", shape) for shape, spiral in spirals.items()]
    for xy, color, style, name in (*curves, (xy_clo, "k", "--", "clothoid")):
        center = xy[-1] + radius * end_normal
        shift = abs(center[1]) - abs(radius)
        right.plot(xy[:, 0], xy[:, 1], color=color, ls=style, lw=1.6, label=f"{name}: shift p = {shift:.4g}")
        phi = np.linspace(0.0, 2.0 * math.pi, 4000)  # smooth when zoomed onto the spirals
        right.plot(center[0] + abs(radius) * np.cos(phi), center[1] + abs(radius) * np.sin(phi), color=color, ls=":", lw=0.8)
    right.axhline(0.0, color="0.6", lw=0.6)
    # Frame the spirals (the full end circles would dwarf them).
    both = np.vstack([*(xy for xy, *_ in curves), xy_clo])
    low, high = both.min(axis=0), both.max(axis=0)
    width, height = high - low
    flat = height < 0.2 * width  # small turns: stretch y so the shifts can be told apart
    pad = 0.15 * (max(width, height) if not flat else 0.0)
    right.set_xlim(low[0] - pad - 0.05 * width * flat, high[0] + pad + 0.05 * width * flat)
    right.set_ylim(low[1] - pad - 0.3 * height * flat, high[1] + pad + 0.3 * height * flat)
    right.set_aspect("auto" if flat else "equal", adjustable="box")
    right.set_xlabel("x")
    right.set_ylabel("y")
    right.set_title("Plan (end circles dotted" + ("; y stretched)" if flat else ")"))
    right.legend(loc="best", fontsize="small")
    right.grid(True, alpha=0.3)
    return fig


def plot_jerk_length(
    design_speed: float = 80.0,
    max_jerk: float = 0.6,
    ax: Sequence[Axes] | None = None,
    shapes: Sequence[str] = ("walton-meek",),
) -> Figure:
    """How much longer a Bézier spiral must be than the clothoid rule for the same lateral jerk.

    Left: the ratio L_Bézier / L_clothoid against the spiral angle θ, where
    the spiral's *peak* jerk v³·max dκ/ds equals the clothoid's constant
    v³/(R·L): it is ℓ(θ)·F(θ) (unit spiral's length × peak dκ/ds), 1.84 for
    the 1996 spiral at small θ and 1.0009 for the near-linear one. Right: the
    lengths against the radius at ``design_speed`` (km/h) and ``max_jerk``
    (m/s³), metric units, one line per shape in ``shapes``.
    """
    from ..design.criteria import RoadCriteria

    fig, (left, right) = _axes_pair(ax)
    radii = np.linspace(150.0, 3000.0, 120)
    criteria = RoadCriteria(design_speed, max_jerk, shift_min=0.0, shift_max=1e9)
    v = criteria.speed("m")
    for shape in shapes:
        theta = np.radians(np.linspace(0.5, min(60.0, math.degrees(search_range(shape)[1])), 400))
        ratio = length_factor(theta, shape) * peak_rate_factor(theta, shape)
        left.plot(np.degrees(theta), ratio, color=SHAPE_COLORS[shape], lw=1.8, label=shape)
        shortest, _ = criteria.choose(radii, "m", shape)
        right.plot(radii, length_factor(shortest, shape) * radii, color=SHAPE_COLORS[shape], lw=1.8, label=f"{shape} (peak jerk = C)")
    left.axhline(1.0, color="k", ls="--", lw=1.0, label="clothoid (dκ/ds constant)")
    left.set_xlabel("spiral angle θ (°)")
    left.set_ylabel("L_spiral / L_clothoid at equal peak jerk")
    left.set_title("Length needed for the same peak lateral jerk")
    left.legend(loc="best", fontsize="small")
    left.grid(True, alpha=0.3)
    right.plot(radii, v**3 / (radii * max_jerk), "k--", lw=1.4, label="clothoid rule L = v³/(R·C)")
    right.set_xlabel("radius R (m)")
    right.set_ylabel("spiral length L (m)")
    right.set_title(f"V = {design_speed:g} km/h, C = {max_jerk:g} m/s³")
    right.legend(loc="best", fontsize="small")
    right.grid(True, alpha=0.3)
    return fig


#: ``curvature_comb`` is ``comb_samples``'s old name (the comb as edges is ``spiral_cad.cad.curvature_comb``).
__getattr__, _ = lazy_names(__name__, {}, renamed={"curvature_comb": "comb_samples"})
