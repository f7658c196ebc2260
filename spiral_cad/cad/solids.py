"""G2 solids: a closed planar G2 outline extruded with rolled (curvature-continuous) top and bottom edges.

The roll profile P(v) = (w(v), z(v)) — w measured inward from the outline,
z up — is the exact 2-D G2 corner (line → spiral → arc → spiral → line)
between the vertical wall and the horizontal top (``design.fillets``), or a
quarter circle (``profile="circular"``, the ordinary fillet). It is swept
along the outline C(s) with a vertical binormal::

    S(s, v) = C(s) + w(v) N(s) + z(v) ez        (N: the inward unit normal)

and written as a tensor-product NURBS Σ_i Σ_j B_i(s) R_j(v) (A_i + w_j B_i, z_j)
whose weights are the outline's times the profile's:

* over a line N is constant (an exact extrusion);
* over an arc C + wN is the homothety c + (1 − σκw)(C − c) of the arc about
  its centre (an exact surface of revolution);
* over a spiral N is not rational: it is replaced by a quintic C2 B-spline
  Ñ that matches N, N', N'' exactly at every knot (Hermite), so the patch
  meets its exact neighbours G2; knots are doubled until the patch's
  deviation from the true sweep, max(w)·max|Ñ − N|, is within ``tolerance``.
  That deviation is measured on dense samples and returned.

Each outline piece gives a wall face (the extrusion between the rolls) and
a top and a bottom roll face; the top and bottom are planes bounded by the
rolls' inner boundary curves (the same curves, so faces share edges). The
faces are sewn, made a solid and checked (``BRepCheck_Analyzer``, one
closed solid) before anything is returned.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeSolid,
    BRepBuilderAPI_MakeVertex,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_Sewing,
    BRepBuilderAPI_Transform,
)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln, gp_Pnt, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_SHELL, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shape, TopoDS_Solid
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

from ..core import bezier
from ..core._inputs import as_float, shown
from ..core.chain import JOIN_TOLERANCE, Chain, g2_mismatch
from ..core.errors import NoSolutionError
from ..core.nurbs import chain_to_nurbs
from ..core.segments import Arc, Line, Segment
from ..core.shapes import DEFAULT_SHAPE
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS, length_unit
from ..design.fillets import TANGENT_TOL, continuous_rectangle, corner_distance, fillet_path
from .advice import advice, refusal
from .fillet import wire_path
from .occ import chain_wire

__all__ = [
    "PROFILES",
    "Slab",
    "approximation_note",
    "fillet_prism_edges",
    "forward_solid",
    "g2_slab",
    "outline_segments",
    "expected_level",
    "plan_radius",
    "PLAN_OVER_REACH",
    "recorded_approximation",
    "roll_profile",
    "verify_faces",
    "verify_solid",
]

#: Roll profiles: the G2 corner (line → spiral → arc → spiral → line) or a quarter circle.
PROFILES = ("g2", "circular")
#: Relative slack on "the roll fits" comparisons (equality itself is decided by the construction).
_FIT_SLACK = 1e-12
#: Most Hermite spans over one spiral before the tolerance counts as unreachable.
_MAX_SPANS = 256
#: A joint of the outline turning more than this (radians) is a corner no roll can follow.
_CORNER_TOL = 1e-7
#: Samples per Hermite span when measuring |Ñ − N|.
_SAMPLES = 48
#: Surfaces made here, by their shape's fingerprint (``_fingerprint``): the deviation of each from the exact sweep.
_RECORDED: dict[bytes, float] = {}
#: Most fingerprints kept (the oldest are forgotten first).
_RECORD_LIMIT = 100_000


@dataclass(frozen=True)
class Slab:
    """A G2 slab and what its construction guarantees.

    Attributes:
        shape: the solid (OCP ``TopoDS_Solid``), checked valid and closed.
        approximation: the largest deviation of a non-exact patch (over a
            spiral of the outline) from the true sweep, in the outline's unit;
            0.0 when every patch is exact.
        roll: the horizontal (= vertical) extent of the top and bottom rolls.
        height: the slab's height.
        units: the length unit of the numbers.
    """

    shape: TopoDS_Solid
    approximation: float
    roll: tuple[float, float]
    height: float
    units: str = DEFAULT_UNITS

    @property
    def description(self) -> str:
        """One line for a file header: what is exact and the approximation's tolerance."""
        return approximation_note(self.approximation, self.units)


def approximation_note(approximation: float, units: str = DEFAULT_UNITS) -> str:
    """The STEP description of a G2 solid whose non-exact surfaces deviate ``approximation`` from the exact ones."""
    if approximation == 0.0:
        return "spiral_cad G2 solid: every surface exact (extrusions, surfaces of revolution, planes)"
    return (
        f"spiral_cad G2 solid: sweeps over spirals approximated within {approximation:.3g} {units} "
        "of the exact sweep; all other surfaces exact"
    )


def roll_profile(edge_radius: float, *, profile: str = "g2", transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> list[Segment]:
    """The roll's section in the (w, z) plane: from the wall (0, −d) going up to the top (d, 0) going +w.

    Args:
        edge_radius: the smallest radius of curvature of the section (> 0).
        profile: ``"g2"`` (spiral → arc → spiral, from ``design.fillets``) or
            ``"circular"`` (a quarter circle of ``edge_radius``).
        transition, shape: of the G2 corner's spirals, as in ``fillet_path``.

    Raises:
        ValueError: an unknown profile or a non-positive radius.
    """
    r = as_float(edge_radius, "edge_radius")
    if not r > 0.0:
        raise ValueError(f"edge_radius must be positive; got {shown(edge_radius)}")
    if profile not in PROFILES:
        raise ValueError(f"profile must be one of {', '.join(PROFILES)}; got {profile!r:.40}")
    if profile == "circular":
        return [Arc((r, -r), -r, math.pi, math.pi / 2.0)]
    reach = 2.0 * corner_distance(r, math.pi / 2.0, transition, shape)
    corner = fillet_path([(0.0, -reach), (0.0, 0.0), (reach, 0.0)], r, transition=transition, vertices=[1], shape=shape)
    return [s for s, owner in zip(corner.segments, corner.owners) if owner is not None]


# ------------------------------------------------------------------ the sweep, direction s


@dataclass(frozen=True)
class _Along:
    """One outline piece in the s direction: C(s) + w·N(s) has poles A + w·B with weights W."""

    degree: int
    knots: NDArray[np.float64]
    mults: NDArray[np.int64]
    weights: NDArray[np.float64]
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    deviation: float  # max |Ñ − N| (0 for exact pieces)


def _left_normal_jets(cp: NDArray[np.float64], u: NDArray[np.float64]) -> tuple[NDArray, NDArray, NDArray]:
    """The left unit normal of a cubic Bézier and its first two derivatives in u (dN = −a T, ddN = −a' T − a² N)."""
    q, q2, q3 = (bezier.derivative(cp, u, k) for k in (1, 2, 3))
    g2 = np.einsum("...i,...i", q, q)
    tangent = q / np.sqrt(g2)[..., None]
    normal = np.stack([-tangent[..., 1], tangent[..., 0]], axis=-1)
    cross2 = q[..., 0] * q2[..., 1] - q[..., 1] * q2[..., 0]
    cross3 = q[..., 0] * q3[..., 1] - q[..., 1] * q3[..., 0]
    a = cross2 / g2  # κ·|q|: the normal's turning rate in u
    da = cross3 / g2 - 2.0 * cross2 * np.einsum("...i,...i", q, q2) / g2**2
    return normal, -a[..., None] * tangent, -da[..., None] * tangent - (a**2)[..., None] * normal


def _elevate(points: NDArray[np.float64], times: int) -> NDArray[np.float64]:
    """Bézier control points raised ``times`` degrees (exact)."""
    for _ in range(times):
        n = len(points)  # new degree
        i = np.arange(1, n)[:, None] / n
        points = np.vstack([points[:1], i * points[:-1] + (1.0 - i) * points[1:], points[-1:]])
    return points


#: Degree of Ñ over a spiral: three poles at each end fix N, N', N''; the ones between are fitted.
_DEGREE = 9


def _basis(n: int, t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Bernstein basis of degree n at ``t``: (len(t), n + 1)."""
    return np.stack([math.comb(n, k) * t**k * (1.0 - t) ** (n - k) for k in range(n + 1)], axis=-1)


def _matched(jets: tuple[NDArray, ...], exact: NDArray[np.float64], t: NDArray[np.float64], h: float) -> NDArray[np.float64]:
    """Bézier poles (degree ``_DEGREE``) of the curve with the value, first and second derivative ``jets`` at
    both ends of a span h (Hermite: the end poles), the poles between fitted to ``exact`` at ``t`` by least squares."""
    p = _DEGREE
    (f0, f1), (d0, d1), (s0, s1) = ((x[0], x[1]) for x in jets)
    head = [f0, f0 + h * d0 / p, f0 + 2.0 * h * d0 / p + h * h * s0 / (p * (p - 1))]
    tail = [f1 - 2.0 * h * d1 / p + h * h * s1 / (p * (p - 1)), f1 - h * d1 / p, f1]
    basis = _basis(p, t)
    fixed = np.array(head + tail)
    rest = exact - basis[:, [0, 1, 2, p - 2, p - 1, p]] @ fixed
    inner, *_ = np.linalg.lstsq(basis[:, 3 : p - 2], rest, rcond=None)
    return np.vstack([head, inner, tail])


def _spiral_along(cp: NDArray[np.float64], sigma: float, reach: float, tolerance: float) -> _Along:
    """A spiral piece with Ñ a C2 B-spline (Hermite at every knot), knots doubled until reach·max|Ñ − N| ≤ tolerance."""
    spans = 1
    t = np.linspace(0.0, 1.0, _SAMPLES)
    check = np.linspace(0.0, 1.0, 2 * _SAMPLES + 1)  # judged between the fitted samples too
    while True:
        breaks = np.linspace(0.0, 1.0, spans + 1)
        n, dn, ddn = (sigma * x for x in _left_normal_jets(cp, breaks))
        a_rows, b_rows, worst = [], [], 0.0
        for k in range(spans):
            h = breaks[k + 1] - breaks[k]
            jets = (n[k : k + 2], dn[k : k + 2], ddn[k : k + 2])
            normal_poles = _matched(jets, sigma * _left_normal_jets(cp, breaks[k] + h * t)[0], t, h)
            exact = sigma * _left_normal_jets(cp, breaks[k] + h * check)[0]
            worst = max(worst, float(np.linalg.norm(_basis(_DEGREE, check) @ normal_poles - exact, axis=1).max()))
            curve_poles = _elevate(bezier.split(cp, breaks[k], breaks[k + 1]), _DEGREE - 3)
            a_rows.append(curve_poles if k == 0 else curve_poles[1:])
            b_rows.append(normal_poles if k == 0 else normal_poles[1:])
        if reach * worst <= tolerance or spans >= _MAX_SPANS:
            break
        spans *= 2
    if reach * worst > tolerance:
        raise NoSolutionError(  # pragma: no cover - the fit converges far below float64 noise for any spiral
            f"the sweep over a spiral deviates {reach * worst:.3g} from the exact one with {spans} spans; "
            f"tolerance {tolerance:.3g} is out of reach (give tolerance ≥ {reach * worst:.3g})"
        )
    mults = np.full(spans + 1, _DEGREE)
    mults[[0, -1]] = _DEGREE + 1
    a = np.vstack(a_rows)
    return _Along(_DEGREE, breaks, mults, np.ones(len(a)), a, np.vstack(b_rows), worst)


def _along(segment: Segment, sigma: float, reach: float, tolerance: float) -> _Along:
    if isinstance(segment, BezierSpiral):
        return _spiral_along(np.asarray(segment.control_points, dtype=float), sigma, reach, tolerance)
    curve = chain_to_nurbs([segment])
    poles = curve.control_points
    if isinstance(segment, Line):
        tangent = (segment.end - segment.start)[:2] / segment.length
        b = np.broadcast_to(sigma * np.array([-tangent[1], tangent[0]]), poles.shape).copy()
    elif isinstance(segment, Arc):
        b = -(sigma / segment.radius) * (poles - np.asarray(segment.center)[:2])  # the homothety about the centre
    else:
        raise ValueError(f"outline segments must be lines, arcs or Bézier spirals; got {type(segment).__name__}")
    return _Along(curve.degree, curve.knots, curve.multiplicities, curve.weights, poles, b, 0.0)


# ------------------------------------------------------------------ OCP surfaces and curves


def _reals(values: Iterable[float]) -> TColStd_Array1OfReal:
    values = list(values)
    array = TColStd_Array1OfReal(1, len(values))
    for i, value in enumerate(values, 1):
        array.SetValue(i, float(value))
    return array


def _ints(values: Iterable[int]) -> TColStd_Array1OfInteger:
    values = list(values)
    array = TColStd_Array1OfInteger(1, len(values))
    for i, value in enumerate(values, 1):
        array.SetValue(i, int(value))
    return array


@dataclass(frozen=True)
class _Section:
    """A profile piece in the v direction: poles (w, z), weights, knots."""

    degree: int
    knots: NDArray[np.float64]
    mults: NDArray[np.int64]
    weights: NDArray[np.float64]
    points: NDArray[np.float64]


def _spans(degree: int, weights: NDArray[np.float64], *rows: NDArray[np.float64]) -> list[tuple[NDArray, ...]]:
    """A B-spline whose interior knots all have multiplicity ``degree`` as its Bézier spans: (weights, *rows) each.

    Faces are made one per span pair: OCCT's default area and volume rule does not split a surface at
    its C0 knots (it is ~1e-4 off there), and the checker then judges each joint as an edge."""
    count = (len(weights) - 1) // degree
    return [tuple(x[k * degree : k * degree + degree + 1] for x in (weights, *rows)) for k in range(count)]


def _along_spans(along: _Along) -> list[_Along]:
    return [
        _Along(along.degree, np.array([0.0, 1.0]), np.array([along.degree + 1] * 2), w, a, b, along.deviation)
        for w, a, b in _spans(along.degree, along.weights, along.a, along.b)
    ]


def _sections(roll: list[Segment], top: float, bottom: float, height: float) -> list[_Section]:
    """The Bézier spans of the bottom roll, the wall and the top roll (those of non-zero extent), in the (w, z) plane."""
    curve = chain_to_nurbs(roll) if roll else None
    ends = np.array([0.0, 1.0]), np.array([4, 4])
    sections = []
    if bottom > 0.0 and curve is not None:
        scale = bottom / float(curve.control_points[-1, 0])
        points = curve.control_points * scale * np.array([1.0, -1.0])  # mirrored: the wall at (0, d) down to (d, 0)
        sections += [_Section(3, *ends, w, p) for w, p in _spans(3, curve.weights, points)]
    if height - top - bottom > 0.0:
        wall = np.array([[0.0, bottom], [0.0, height - top]])
        sections.append(_Section(1, np.array([0.0, 1.0]), np.array([2, 2]), np.ones(2), wall))
    if top > 0.0 and curve is not None:
        scale = top / float(curve.control_points[-1, 0])
        points = curve.control_points * scale + np.array([0.0, height])
        sections += [_Section(3, *ends, w, p) for w, p in _spans(3, curve.weights, points)]
    return sections


def _surface_face(along: _Along, section: _Section, degenerate: float) -> tuple[TopoDS_Face, bytes]:
    """The face of the patch and its ``_fingerprint`` (from the same numbers OCCT is given)."""
    rows, cols = len(along.a), len(section.points)
    w, z = section.points[:, 0], section.points[:, 1]
    xy = along.a[:, None, :] + w[None, :, None] * along.b[:, None, :]
    grid = np.concatenate([xy, np.broadcast_to(z[None, :, None], (rows, cols, 1))], axis=2).astype(float)
    products = along.weights[:, None] * section.weights[None, :]
    poles, weights = TColgp_Array2OfPnt(1, rows, 1, cols), TColStd_Array2OfReal(1, rows, 1, cols)
    for i in range(rows):
        for j in range(cols):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*(float(c) for c in grid[i, j])))
            weights.SetValue(i + 1, j + 1, float(products[i, j]))
    surface = Geom_BSplineSurface(
        poles, weights, _reals(along.knots), _reals(section.knots), _ints(along.mults), _ints(section.mults),
        along.degree, section.degree,
    )  # fmt: skip
    key = _fingerprint_of((along.degree, section.degree), grid, products, [*along.knots, *section.knots])
    return BRepBuilderAPI_MakeFace(surface, degenerate).Face(), key


def _boundary_edge(along: _Along, w: float, z: float):
    """The curve C(s) + w·Ñ(s) at height z — the roll's iso-curve, pole for pole — or None if it is a point."""
    points = along.a + w * along.b
    if float(np.ptp(points, axis=0).max()) == 0.0 or np.allclose(points, points[0], rtol=0.0, atol=1e-12 * (1.0 + w)):
        return None
    poles = TColgp_Array1OfPnt(1, len(points))
    for i, (x, y) in enumerate(points, 1):
        poles.SetValue(i, gp_Pnt(float(x), float(y), float(z)))
    curve = Geom_BSplineCurve(poles, _reals(along.weights), _reals(along.knots), _ints(along.mults), along.degree)
    return BRepBuilderAPI_MakeEdge(curve).Edge()


def _cap(alongs: list[_Along], w: float, z: float) -> TopoDS_Face:
    wire = BRepBuilderAPI_MakeWire()
    for along in alongs:
        edge = _boundary_edge(along, w, z)
        if edge is not None:
            wire.Add(edge)
    if not wire.IsDone():
        raise NoSolutionError(f"the cap at z = {z:.6g} has no closed boundary (the roll closes the outline)")
    return BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0.0, 0.0, z), gp_Dir(0.0, 0.0, 1.0)), wire.Wire()).Face()


# ------------------------------------------------------------------ what parts made of slabs carry


def _fingerprint(face: TopoDS_Face) -> bytes | None:
    """A B-spline surface's shape, unchanged by rigid motions and copies: degrees, knots, weights and the
    distances of its poles from its two corner poles (relative, 9 digits); None for other surfaces."""
    surface = BRep_Tool.Surface_s(face, TopLoc_Location())  # without the face's placement
    if not isinstance(surface, Geom_BSplineSurface):
        return None
    rows, cols = surface.NbUPoles(), surface.NbVPoles()
    poles = np.array([[surface.Pole(i, j).Coord() for j in range(1, cols + 1)] for i in range(1, rows + 1)])
    weights = [surface.Weight(i, j) for i in range(1, rows + 1) for j in range(1, cols + 1)]
    knots = [surface.UKnot(k) for k in range(1, surface.NbUKnots() + 1)] + [surface.VKnot(k) for k in range(1, surface.NbVKnots() + 1)]
    return _fingerprint_of((surface.UDegree(), surface.VDegree()), poles, np.asarray(weights), knots)


def _fingerprint_of(degrees: tuple[int, int], poles: NDArray[np.float64], weights: NDArray[np.float64],
                    knots: Sequence[float]) -> bytes:  # fmt: skip
    """``_fingerprint`` of a surface given by its numbers: poles (rows, cols, 3), weights in row order, the
    u then v knots (distinct values)."""
    rows, cols = poles.shape[:2]
    flat = poles.reshape(-1, 3)
    distances = np.concatenate([np.linalg.norm(flat - flat[0], axis=1), np.linalg.norm(flat - flat[-1], axis=1)])
    scale = float(distances.max()) or 1.0
    numbers = np.concatenate([[degrees[0], degrees[1], rows, cols], knots, np.ravel(weights), distances / scale])
    return np.round(numbers, 9).tobytes() + np.float64(f"{scale:.9g}").tobytes()


def _record(key: bytes, deviation: float) -> None:
    _RECORDED[key] = max(deviation, _RECORDED.pop(key, 0.0))
    while len(_RECORDED) > _RECORD_LIMIT:
        del _RECORDED[next(iter(_RECORDED))]


def recorded_approximation(shape: TopoDS_Shape) -> float | None:
    """The largest deviation from the exact sweep of the faces of ``shape`` that are surfaces of G2 slabs
    made in this process (``g2_slab``, ``ContinuousBox``, ``g2_fillet`` of cap edges), or None when it
    has none.

    Faces are recognised by their surface's shape (degrees, knots, weights, the poles' distances), so
    they are found in a part the slab was added to in ``BuildPart``, moved, copied or cut by a
    boolean that trims but keeps their surfaces; a scaled copy, or a surface rebuilt by another
    operation, is not recognised.
    """
    found = [_RECORDED.get(key) for face in _faces_of(shape) if (key := _fingerprint(face)) is not None]
    known = [value for value in found if value is not None]
    return max(known) if known else None


# ------------------------------------------------------------------ input and fit


def outline_segments(outline: Any) -> list[Segment]:
    """The plane segments of a closed outline: a ``Chain``, a ``FilletedPath``, an object with ``.filleted``
    (the continuous sketches) or segments in travel order.

    Raises:
        ValueError: anything else, segments in space, or an outline that does not close.
    """
    source = getattr(outline, "filleted", outline)
    source = getattr(source, "segments", source)
    if isinstance(source, Chain):
        source = list(source)
    if not isinstance(source, Sequence) or not source or not all(isinstance(s, Segment) for s in source):
        raise ValueError(f"outline must be a closed Chain, a FilletedPath or segments in travel order; got {type(outline).__name__}")
    segments = list(source)
    if any(s.dim != 2 for s in segments):
        raise ValueError("outline must lie in the plane (2-D segments)")
    size = max(float(np.ptp(np.vstack([s.point(np.linspace(0, 1, 5)) for s in segments]), axis=0).max()), 1e-300)
    gap = math.dist(segments[-1].end[:2], segments[0].start[:2])
    if gap > 1e-9 * size:
        raise ValueError(f"outline must be closed; its end is {gap:.3g} from its start")
    for index, (a, b) in enumerate(zip(segments, [*segments[1:], segments[0]])):
        (x, y, tx0, ty0, _), (_, _, tx1, ty1, _) = a.ends[1], b.ends[0]
        turn = abs(math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1))
        if turn > _CORNER_TOL:
            raise ValueError(
                f"outline must be tangent at every joint (a roll cannot follow a corner); the joint after segment "
                f"{index} at ({x:.6g}, {y:.6g}) turns {turn:.3g} rad: round it first (g2_fillet, fillet_path)"
            )
    return segments


def _samples(segments: list[Segment], count: int = 24) -> tuple[NDArray, NDArray, NDArray]:
    """Points, left normals and curvatures at ``count`` parameters per segment (closing point excluded)."""
    u = np.linspace(0.0, 1.0, count, endpoint=False)
    points = np.vstack([s.point(u)[:, :2] for s in segments])
    tangents = np.vstack([s.tangent(u)[:, :2] for s in segments])
    curvatures = np.concatenate([np.broadcast_to(s.curvature(u), u.shape) for s in segments])
    return points, np.stack([-tangents[:, 1], tangents[:, 0]], axis=1), curvatures


def _crossing(polygon: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """A point where the closed polygon crosses itself (non-adjacent edges), or None."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    d = b - a
    n = len(a)
    i, j = np.triu_indices(n, 2)
    keep = (j - i) < n - 1  # the last edge is adjacent to the first
    i, j = i[keep], j[keep]
    denom = d[i, 0] * d[j, 1] - d[i, 1] * d[j, 0]
    diff = a[j] - a[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (diff[:, 0] * d[j, 1] - diff[:, 1] * d[j, 0]) / denom
        u = (diff[:, 0] * d[i, 1] - diff[:, 1] * d[i, 0]) / denom
    hit = (denom != 0.0) & (t > 0.0) & (t < 1.0) & (u > 0.0) & (u < 1.0)
    if not hit.any():
        return None
    k = int(np.argmax(hit))
    result: NDArray[np.float64] = a[i[k]] + t[k] * d[i[k]]
    return result


def _fit_problem(segments: list[Segment], sigma: float, roll: float, given: Any, name: str) -> str | None:
    """Why a roll ``roll`` wide does not fit inside the outline, or None: it must stay below every convex
    radius of curvature (equal only on arcs: a clean pole) and its inner offset must not cross itself."""
    for index, segment in enumerate(segments):
        u = np.linspace(0.0, 1.0, 65)
        bend = float(np.max(sigma * np.broadcast_to(segment.curvature(u), u.shape)))
        if bend <= 0.0:
            continue
        product = roll * bend
        exact_pole = isinstance(segment, Arc) and abs(product - 1.0) <= 1e-12
        if product > 1.0 - _FIT_SLACK and not exact_pole:
            return (
                f"{name} {shown(given)} gives a roll {roll:.6g} wide, not below the outline's smallest convex radius "
                f"of curvature {1.0 / bend:.6g} (segment {index}, a {type(segment).__name__}): the inner offset "
                "would fold"
            )
    points, normals, _ = _samples(segments)
    place = _crossing(points + sigma * roll * normals)
    if place is not None:
        return (
            f"{name} {shown(given)} gives a roll {roll:.6g} wide whose inner offset crosses itself near "
            f"({place[0]:.6g}, {place[1]:.6g}): the outline is too narrow there"
        )
    return None


def _inward(segments: list[Segment]) -> float:
    """+1 when the outline runs counterclockwise (its inward normal is the left one), else −1."""
    points, _, _ = _samples(segments)
    area = 0.5 * float(np.sum(points[:, 0] * np.roll(points[:, 1], -1) - np.roll(points[:, 0], -1) * points[:, 1]))
    return 1.0 if area > 0.0 else -1.0


def _roll_problem(segments: list[Segment], height: float, edge_radius: Any, given_height: Any, name: str,
                  **options: Any) -> str | None:  # fmt: skip
    """Why rolls of ``edge_radius`` (``options``: top, bottom, profile, transition, shape) do not fit the
    outline and the height, or None."""
    top, bottom = options.pop("top"), options.pop("bottom")
    reach = float(roll_profile(float(edge_radius), **options)[-1].end[0])
    d_top, d_bottom = (reach if top else 0.0), (reach if bottom else 0.0)
    if d_top + d_bottom > height * (1.0 + _FIT_SLACK):
        return (
            f"{name} {shown(edge_radius)} gives rolls {reach:.6g} high; {'together they' if top and bottom else 'it'} "
            f"exceed height {shown(given_height)}"
        )
    if max(d_top, d_bottom) == 0.0:
        return None
    return _fit_problem(segments, _inward(segments), min(max(d_top, d_bottom), height), edge_radius, name)


# ------------------------------------------------------------------ the solid


def _solid(faces: list[TopoDS_Face], tolerance: float, top: TopoDS_Face) -> TopoDS_Solid:
    """The faces sewn into one closed shell and made a FORWARD solid facing out: the shell faces out
    when the top cap (``top``, a plane z = height) does, as the construction knows (no volume needed)."""
    sewing = BRepBuilderAPI_Sewing(tolerance)
    for face in faces:
        sewing.Add(face)
    sewing.Perform()
    sewn = sewing.SewedShape()
    shells = TopExp_Explorer(sewn, TopAbs_SHELL)
    count = 0
    shell = None
    while shells.More():
        count += 1
        shell = TopoDS.Shell_s(shells.Current())
        shells.Next()
    if count != 1 or shell is None or not BRep_Tool.IsClosed_s(shell):
        raise NoSolutionError(f"the slab's {len(faces)} faces did not sew into one closed shell ({count} shell(s))")
    sewn_top = sewing.Modified(top)
    cap = next((f for f in _faces_of(shell) if f.IsSame(sewn_top)), None)
    if cap is None or (plane := _plane(cap)) is None:
        raise NoSolutionError("the slab's top cap is not a plane of the sewn shell")
    up = plane.Axis().Direction().Z() * (-1.0 if cap.Orientation() == TopAbs_REVERSED else 1.0)
    if up < 0.0:  # the shell faces in: the solid of the turned shell (a fresh solid is FORWARD)
        shell = TopoDS.Shell_s(shell.Reversed())
    return BRepBuilderAPI_MakeSolid(shell).Solid()


def forward_solid(solid: TopoDS_Shape) -> TopoDS_Solid:
    """The solid FORWARD: the same volume, usable in booleans.

    ``BRepLib.OrientClosedSolid`` and ``Reversed`` may leave a solid REVERSED with a positive
    volume; a fuse of a compound holding such a solid drops it (CadQuery's ``combine``). The
    solid is made again from its shells as they face (orientations composed down from it)."""
    if solid.Orientation() == TopAbs_FORWARD:
        return TopoDS.Solid_s(solid)
    maker = BRepBuilderAPI_MakeSolid()
    shells = TopExp_Explorer(solid, TopAbs_SHELL)
    while shells.More():
        maker.Add(TopoDS.Shell_s(shells.Current()))
        shells.Next()
    return maker.Solid()


def verify_solid(shape: TopoDS_Shape, what: str = "slab", facing_out: bool = False) -> None:
    """NoSolutionError unless ``shape`` is one valid, closed, FORWARD solid with positive volume
    (``BRepCheck_Analyzer``, which also finds a shell whose faces do not all face the same way;
    ``facing_out``: the caller knows the shell faces out, so its volume is positive, unmeasured)."""
    solids = TopExp_Explorer(shape, TopAbs_SOLID)
    count = 0
    while solids.More():
        count += 1
        solids.Next()
    if count != 1:
        raise NoSolutionError(f"the {what} is {count} solids, not one")
    if _first_solid(shape).Orientation() != TopAbs_FORWARD:
        raise NoSolutionError(f"the {what} is a {_first_solid(shape).Orientation().name} solid, not FORWARD (booleans drop it)")
    if not BRepCheck_Analyzer(shape).IsValid():
        raise NoSolutionError(f"the {what} is not a valid solid (BRepCheck_Analyzer)")
    volume = 1.0 if facing_out else _volume(shape)
    if not volume > 0.0:
        raise NoSolutionError(f"the {what} encloses no volume ({volume:.3g})")


def continuous_box(
    length: float,
    width: float,
    height: float,
    radius: float,
    edge_radius: float | None = None,
    *,
    transition: float = 0.5,
    shape: str = DEFAULT_SHAPE,
    profile: str = "g2",
    top: bool = True,
    bottom: bool = True,
    tolerance: float | None = None,
    units: str = DEFAULT_UNITS,
    _advise: bool = True,
) -> Slab:
    """A box with every edge and corner G2: ``g2_slab`` of a ``continuous_rectangle`` (centred on the origin,
    z from 0 to ``height``). ``edge_radius`` None: the roll half as wide as the smaller of ``radius`` and
    ``height``/2 allows. Other arguments and errors as ``g2_slab`` and ``continuous_rectangle``."""
    for value, name in ((length, "length"), (width, "width"), (height, "height")):
        if not as_float(value, name) > 0.0:
            raise ValueError(f"{name} must be positive; got {shown(value)}")
    try:
        plan = continuous_rectangle(length, width, radius, transition, units=units, shape=shape)
    except NoSolutionError as error:
        if not _advise:
            raise
        raise _plan_refusal(error, length, width, height, as_float(radius, "radius"), edge_radius,
                            dict(transition=transition, shape=shape, profile=profile, top=top, bottom=bottom),
                            tolerance, units) from None  # fmt: skip
    if edge_radius is None:  # the roll's extent is proportional to its radius
        unit = float(roll_profile(1.0, profile=profile, transition=transition, shape=shape)[-1].end[0])
        edge_radius = 0.5 * min(as_float(radius, "radius"), as_float(height, "height") / 2.0) / unit
    return g2_slab(plan, height, edge_radius, top=top, bottom=bottom, profile=profile, transition=transition,
                   shape=shape, tolerance=tolerance, units=units, _advise=_advise)  # fmt: skip


def _plan_refusal(error: NoSolutionError, length: float, width: float, height: float, radius: float,
                  edge_radius: float | None, options: dict[str, Any], tolerance: float | None,
                  units: str) -> NoSolutionError:  # fmt: skip
    """The refusal of plan corners too large for the box, with the largest ``radius`` that fits and builds
    (with the given ``edge_radius``); when that roll fits no plan radius that fits, the largest plan radius
    and the largest roll it holds, built together."""
    transition, shape = options["transition"], options["shape"]

    def plan_fits(r: float) -> bool:  # shrinking corners only ever fit better
        try:
            continuous_rectangle(length, width, r, transition, shape=shape)
        except NoSolutionError:
            return False
        return True

    def box(r: float) -> Slab:
        return continuous_box(length, width, height, r, edge_radius, **options, tolerance=tolerance, units=units,
                              _advise=False)  # fmt: skip

    problem = f"{error} (the plan corners)"
    fits = advice(plan_fits, box, radius)
    if fits is not None or edge_radius is None:
        return refusal(problem, "radius", fits)
    corner = advice(plan_fits, lambda r: continuous_rectangle(length, width, r, transition, shape=shape), radius)
    problem += f"; no radius fits with edge_radius {shown(edge_radius)}"
    if corner is None:
        return refusal(problem, "radius", None)
    plan = outline_segments(continuous_rectangle(length, width, corner, transition, shape=shape))
    slab_options = dict(options, profile=options["profile"])
    roll = _slab_advice(plan, height, as_float(edge_radius, "edge_radius"), height, "edge_radius", slab_options,
                        tolerance, units)  # fmt: skip
    if roll is None:
        return refusal(problem, "radius", None)
    return NoSolutionError(f"{problem}; with radius {corner:.6g}, edge_radius up to {roll:.6g} fits")


def expected_level(segments: Sequence[Segment], profile: str = "g2") -> str:
    """The continuity the construction promises for tangent edges: ``"G2"`` for a G2 profile along an
    outline whose tangent joints are all G2, else ``"G1"`` (circular profiles, circularly filleted outlines)."""
    if profile != "g2":
        return "G1"
    for index, (a, b) in enumerate(zip(segments, [*segments[1:], segments[0]])):
        if not _turns(a, b) and g2_mismatch(a, b, JOIN_TOLERANCE, index=index) is not None:
            return "G1"
    return "G2"


def verify_faces(shape: TopoDS_Shape, level: str, what: str = "slab", units: str = DEFAULT_UNITS) -> None:
    """NoSolutionError unless the face checker (``spiral_cad.cad.faces.check_faces``, default tolerances:
    normals ≤ 1e-7 rad, normal-curvature jump ≤ 1e-4 relative, gaps ≤ 1e-7 × size) finds every tangent
    edge at least ``level`` and no gap; sharp edges are features, listed there and not failed."""
    from .faces import check_faces  # late: the checker reads files through this layer's readers

    report = check_faces(shape, units=units)
    if report.passes(level):
        return
    worst = min(report.edges, key=lambda e: (e.level == "sharp", e.level == level, -e.jump, -e.angle))
    raise NoSolutionError(
        f"the {what} is refused: the face checker finds edge {worst.index} ({worst.surfaces[0]}–{worst.surfaces[1]}) "
        f"{worst.level}, not {level} (gap {worst.gap:.3g}, normal angle {worst.angle:.3g} rad, relative curvature "
        f"jump {worst.jump:.3g} at {worst.jump_at}); {report.describe()}"
    )


def g2_slab(
    outline: Any,
    height: float,
    edge_radius: float,
    *,
    top: bool = True,
    bottom: bool = True,
    profile: str = "g2",
    transition: float = 0.5,
    shape: str = DEFAULT_SHAPE,
    tolerance: float | None = None,
    units: str = DEFAULT_UNITS,
    _name: str = "edge_radius",
    _advise: bool = True,
) -> Slab:
    """A closed planar outline extruded by ``height`` with its top and bottom edges rolled (see the module docstring).

    Args:
        outline: a closed plane ``Chain`` of lines, arcs and spirals (G2 for a
            G2 solid; tangent joints are swept as they are), a ``FilletedPath``
            (``continuous_rectangle`` …) or its segments; convex or concave,
            either sense. It lies in z = 0; the slab rises to z = ``height``.
        height: the slab's height (> 0).
        edge_radius: the roll profile's smallest radius of curvature (> 0).
        top, bottom: roll the top / bottom edge (else the edge stays sharp).
        profile: ``"g2"`` or ``"circular"`` (``roll_profile``).
        transition, shape: of the G2 profile's spirals.
        tolerance: the largest deviation allowed for the sweep over a spiral
            (default 1e-7 × the outline's size).
        units: the unit of the numbers (kept for the files written).

    Returns:
        The ``Slab``: the solid and the measured approximation. It is verified as returned: one valid
        closed solid (``BRepCheck_Analyzer``), and the face checker finds every edge G2 (G1 for a
        circular profile or an outline with G1 joints) or a sharp feature (unrolled edges).

    Raises:
        ValueError: malformed input.
        NoSolutionError: the roll does not fit (it is as wide as it is high:
            wider than the outline's smallest convex radius of curvature, an
            inner offset that crosses itself, or both rolls higher than
            ``height``) — the message names the value and what would fit.
    """
    units = length_unit(units)
    segments = outline_segments(outline)
    given_height, height = height, as_float(height, "height")
    if not height > 0.0:
        raise ValueError(f"height must be positive; got {shown(height)}")
    options = dict(top=top, bottom=bottom, profile=profile, transition=transition, shape=shape)
    radius = as_float(edge_radius, "edge_radius")
    problem = _roll_problem(segments, height, edge_radius, given_height, _name, **options)
    if problem is not None:
        if not _advise:
            raise NoSolutionError(problem)
        raise refusal(problem, _name, _slab_advice(segments, height, radius, given_height, _name, options, tolerance, units))
    try:
        return _built_slab(segments, height, edge_radius, options, tolerance, units)
    except NoSolutionError as error:  # fits, yet does not build: nearly singular (rolls meeting, an offset folding)
        if not _advise:
            raise
        raise refusal(str(error), _name, _slab_advice(segments, height, radius, given_height, _name, options, tolerance, units)) from None


def _slab_advice(segments: list[Segment], height: float, radius: float, given_height: Any, name: str,
                 options: dict[str, Any], tolerance: float | None, units: str) -> float | None:  # fmt: skip
    """The largest roll radius below ``radius`` a refusal may name: it fits with a margin and builds."""
    return advice(
        lambda r: _roll_problem(segments, height, r, given_height, name, **options) is None,
        lambda r: g2_slab(segments, height, r, **options, tolerance=tolerance, units=units, _advise=False),
        radius,
    )


def _built_slab(segments: list[Segment], height: float, edge_radius: float, options: dict[str, Any],
                tolerance: float | None, units: str) -> Slab:  # fmt: skip
    """The slab of rolls that fit, verified (``g2_slab`` after its fit checks)."""
    top, bottom, profile, transition, shape = (options[k] for k in ("top", "bottom", "profile", "transition", "shape"))
    roll = roll_profile(edge_radius, profile=profile, transition=transition, shape=shape)
    reach = float(roll[-1].end[0])
    d_top, d_bottom = (reach if top else 0.0), (reach if bottom else 0.0)
    points, _, _ = _samples(segments)
    size = float(np.ptp(points, axis=0).max())
    if d_top + d_bottom > height - 1e-7 * size:  # a wall thinner than the sewing tolerance: the rolls meet
        d_top, d_bottom = (height / 2.0, height / 2.0) if top and bottom else (d_top and height, d_bottom and height)
    sigma = _inward(segments)
    reach_max = max(d_top, d_bottom)
    tol = 1e-7 * size if tolerance is None else as_float(tolerance, "tolerance")
    if not tol > 0.0:
        raise ValueError(f"tolerance must be positive; got {shown(tolerance)}")
    alongs = [span for s in segments for span in _along_spans(_along(s, sigma, reach_max, tol))]
    sections = _sections(roll, d_top, d_bottom, height)
    degenerate = 1e-9 * size
    made = [_surface_face(a, sec, degenerate) for a in alongs for sec in sections]
    faces = [face for face, _ in made]
    for k, (_, key) in enumerate(made):  # so export_step finds the note on parts built from this solid
        _record(key, reach_max * alongs[k // len(sections)].deviation)
    top_cap = _cap(alongs, d_top, height)
    faces += [top_cap, _cap(alongs, d_bottom, 0.0)]
    solid = _solid(faces, 1e-7 * size, top_cap)
    verify_solid(solid, facing_out=True)
    verify_faces(solid, expected_level(segments, profile), units=units)
    approximation = reach_max * max(a.deviation for a in alongs)
    return Slab(solid, approximation, (d_top, d_bottom), height, units)


# ------------------------------------------------------------------ solid edges of prisms


@dataclass(frozen=True)
class _Prism:
    """A solid that is a right prism: two parallel planar caps, the bottom one framed with z into the solid."""

    frame: gp_Ax3
    bottom: TopoDS_Face
    top: TopoDS_Face
    height: float


def _faces_of(shape: TopoDS_Shape) -> list[TopoDS_Face]:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        found.append(TopoDS.Face_s(explorer.Current()))
        explorer.Next()
    return found


def _edges_of(shape: TopoDS_Shape) -> list[TopoDS_Edge]:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        found.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    return found


def _plane(face: TopoDS_Face) -> gp_Pln | None:
    surface = GeomAdaptor_Surface(BRep_Tool.Surface_s(face))
    return surface.Plane() if surface.GetType() == GeomAbs_SurfaceType.GeomAbs_Plane else None


def _line_direction(edge: TopoDS_Edge) -> tuple[gp_Pnt, gp_Pnt, gp_Dir] | None:
    curve = BRepAdaptor_Curve(edge)
    if curve.GetType() != GeomAbs_CurveType.GeomAbs_Line:
        return None
    return curve.Value(curve.FirstParameter()), curve.Value(curve.LastParameter()), curve.Line().Direction()


def _where(point: gp_Pnt) -> str:
    return f"({point.X():.6g}, {point.Y():.6g}, {point.Z():.6g})"


def _volume(shape: TopoDS_Shape) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def _area(shape: TopoDS_Shape) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    return props.Mass()


def _prism(solid: TopoDS_Shape, direction: gp_Dir, edge_name: str) -> _Prism:
    """The solid as a right prism along ``direction``, or NoSolutionError naming what is not."""
    caps = [f for f in _faces_of(solid) if (p := _plane(f)) is not None and p.Axis().Direction().IsParallel(direction, 1e-12)]
    if len(caps) != 2:
        raise NoSolutionError(
            f"g2_fillet rounds solid edges of right prisms (two parallel planar caps, side faces along the edges); "
            f"{edge_name}: the part has {len(caps)} planar face(s) perpendicular to it, not 2 (a vertex blend is a later step)"
        )
    for index, face in enumerate(_faces_of(solid)):
        if any(face.IsSame(cap) for cap in caps):
            continue
        lean = _lean(face, direction)
        if lean > _SIDE_TOL:
            surface = BRepAdaptor_Surface(face)
            u, v = (
                0.5 * (surface.FirstUParameter() + surface.LastUParameter()),
                0.5 * (surface.FirstVParameter() + surface.LastVParameter()),
            )
            raise NoSolutionError(
                f"g2_fillet rounds solid edges of right prisms (side faces perpendicular to the caps); {edge_name}: "
                f"side face {index} near {_where(surface.Value(u, v))} leans {math.degrees(lean):.6g}° from the caps' "
                "normal: the part is no right prism (an oblique prism, a taper), which g2_fillet does not round"
            )
    origins = [_plane(f).Location() for f in caps]  # type: ignore[union-attr]
    offsets = [gp_Vec(direction).Dot(gp_Vec(o.XYZ())) for o in origins]
    low, high = (0, 1) if offsets[0] < offsets[1] else (1, 0)
    height = offsets[high] - offsets[low]
    if not abs(_volume(solid) - _area(caps[low]) * height) <= 1e-9 * abs(_volume(solid)):
        raise NoSolutionError(
            f"g2_fillet rounds solid edges of right prisms; {edge_name}: the part is not its cap extruded by "
            f"{height:.6g} (volume {_volume(solid):.9g}, cap area × height {_area(caps[low]) * height:.9g})"
        )
    plane = _plane(caps[low])
    assert plane is not None
    frame = gp_Ax3(plane.Location(), direction, plane.Position().XDirection())
    if frame.XDirection().IsParallel(direction, 1e-9):
        frame = gp_Ax3(plane.Location(), direction)
    return _Prism(frame, caps[low], caps[high], height)


#: Most angle (radians) a prism's side face may lean from the caps' normal.
_SIDE_TOL = 1e-9
#: Samples per parameter direction when a side face's surface gives no direction of its own.
_SIDE_SAMPLES = 9


def _lean(face: TopoDS_Face, axis: gp_Dir) -> float:
    """How far (radians) the face leans from containing the direction ``axis`` everywhere: from its
    surface's own direction (plane normal, cylinder axis, extrusion direction) where it has one, else
    the largest over a grid of its normals (a face perpendicular to the caps has every normal ⟂ axis)."""
    surface = BRepAdaptor_Surface(face)
    kind = surface.GetType()
    if kind == GeomAbs_SurfaceType.GeomAbs_Plane:
        return abs(math.asin(max(-1.0, min(1.0, surface.Plane().Axis().Direction().Dot(axis)))))
    along = {GeomAbs_SurfaceType.GeomAbs_Cylinder: lambda: surface.Cylinder().Axis().Direction(),
             GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion: surface.Direction}.get(kind)  # fmt: skip
    if along is not None:
        angle = along().Angle(axis)
        return min(angle, math.pi - angle)
    u0, u1, v0, v1 = surface.FirstUParameter(), surface.LastUParameter(), surface.FirstVParameter(), surface.LastVParameter()
    worst = 0.0
    for u in np.linspace(u0, u1, _SIDE_SAMPLES):
        for v in np.linspace(v0, v1, _SIDE_SAMPLES):
            point, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
            surface.D1(float(u), float(v), point, du, dv)
            normal = du.Crossed(dv)
            if normal.Magnitude() > 1e-12 * (1.0 + du.Magnitude() * dv.Magnitude()):
                worst = max(worst, abs(math.asin(max(-1.0, min(1.0, normal.Normalized().Dot(gp_Vec(axis)))))))
    return worst


def _on(face: TopoDS_Face, point: gp_Pnt, size: float) -> bool:
    return BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(point).Vertex(), face).Value() <= 1e-9 * size


def fillet_prism_edges(
    solid: TopoDS_Shape,
    edges: Sequence[TopoDS_Edge],
    radius: float,
    *,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
    tolerance: float | None = None,
    _advise: bool = True,
) -> Slab:
    """Round straight edges of a right prism with G2 fillets, exactly.

    Side edges (along the prism's axis, between two planar faces, any
    dihedral angle, convex or concave) become exact extrusions of the 2-D G2
    corner of the cap's outline; when every edge of a cap is chosen too, the
    cap's edge is rolled by the G2 profile of the same radius (``g2_slab``),
    and the chosen side corners are rounded with ``plan_radius(radius)`` so
    the roll fits inside them (``radius`` stays the smallest radius of
    curvature of every rounded edge).

    Args:
        solid: one solid, a right prism (two parallel planar caps; the part's
            volume is its cap's area times its height).
        edges: the edges to round (all side edges, or side edges and every edge of
            one or both caps).
        radius: the smallest radius of curvature of each rounded edge.
        transition, same_sense, shape: as in ``design.fillets.fillet_path``.
        tolerance: for a slab's sweep over spirals, as in ``g2_slab``.

    Raises:
        NoSolutionError: an edge that is not straight, not between planar faces, a part that
            is no right prism, or a cap partly chosen — named by edge index and point;
            side corners, rolls and height that do not fit together — with the largest radius that does.
    """
    if not edges:
        raise ValueError("g2_fillet needs at least one edge")
    all_edges = _edges_of(solid)
    index = {i: e for i, e in enumerate(all_edges)}
    position = {}
    for k, edge in enumerate(edges):
        match = next((i for i, e in index.items() if e.IsSame(edge)), None)
        if match is None:
            raise ValueError(f"edge {k} of the selection is not an edge of the part")
        position[k] = match
    size = max(BRepAdaptor_Curve(e).Value(BRepAdaptor_Curve(e).FirstParameter()).Distance(gp_Pnt()) for e in all_edges) + 1.0
    neighbours = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid, TopAbs_EDGE, TopAbs_FACE, neighbours)
    named = []
    candidates: list[gp_Dir] = []  # prism axes: chosen straight edges meeting perpendicular faces at both ends,
    for k, edge in enumerate(edges):  # and the normals of planar faces holding chosen edges
        curve = BRepAdaptor_Curve(edge)
        named.append(f"edge {position[k]} at {_where(curve.Value(curve.FirstParameter()))}")
        line = _line_direction(edge)
        if line is not None:
            ends = [f for f in _faces_of(solid) if (p := _plane(f)) is not None and p.Axis().Direction().IsParallel(line[2], 1e-12)]
            if all(any(_on(f, end, size) for f in ends) for end in line[:2]):
                candidates.append(line[2])
    for face in _faces_of(solid):
        plane = _plane(face)
        if plane is not None and any(any(e.IsSame(h) for h in _edges_of(face)) for e in edges):
            candidates.append(plane.Axis().Direction())
    ranked, leaning = [], []
    for candidate in candidates:
        try:
            ranked.append((_fit(solid, edges, candidate, named), candidate))
        except NoSolutionError as error:
            leaning += [error] if " leans " in str(error) else []
    if not ranked and leaning:
        raise leaning[0]
    if not ranked:
        raise NoSolutionError(
            f"g2_fillet rounds a solid's straight edges when each end meets a face perpendicular to it (prism side "
            f"edges) and whole caps of right prisms; {named[0]} is neither (a vertex blend is a later step)"
        )
    axis = min(ranked, key=lambda row: row[0])[1]
    sides, caps, side_names = [], [], []
    for k, edge in enumerate(edges):
        line = _line_direction(edge)
        if line is not None and line[2].IsParallel(axis, 1e-12):
            sides.append(edge)
            side_names.append(named[k])
        else:
            caps.append((k, edge, named[k]))
    prism = _prism(solid, axis, f"edge {position[0]}")
    by_cap = {"bottom": _edges_of(prism.bottom), "top": _edges_of(prism.top)}
    chosen_caps = {}
    for which, cap_edges in by_cap.items():
        picked = [c for c in caps if any(c[1].IsSame(e) for e in cap_edges)]
        if picked and len(picked) != len(cap_edges):
            missing = next(e for e in cap_edges if not any(c[1].IsSame(e) for c in picked))
            where = _where(BRepAdaptor_Curve(missing).Value(BRepAdaptor_Curve(missing).FirstParameter()))
            raise NoSolutionError(
                f"g2_fillet rounds a prism's {which} edges all together (a slab); the {which} cap's edge at {where} "
                "is not chosen, and a vertex blend where rounded and sharp edges meet is a later step"
            )
        chosen_caps[which] = bool(picked)
        for c in picked:
            caps.remove(c)
    if caps:
        raise NoSolutionError(f"g2_fillet cannot round {caps[0][2]}: neither a side edge nor a cap edge of the prism")
    frame = prism.frame
    if BRepTools.OuterWire_s(prism.bottom).IsNull() or len(_wires_of(prism.bottom)) != 1:
        raise NoSolutionError("g2_fillet rounds prisms whose caps have one boundary (no holes)")
    segments, _ = wire_path(BRepTools.OuterWire_s(prism.bottom), frame, spirals=True)
    feet = [BRepAdaptor_Curve(e).Value(BRepAdaptor_Curve(e).FirstParameter()) for e in sides]
    feet += [BRepAdaptor_Curve(e).Value(BRepAdaptor_Curve(e).LastParameter()) for e in sides]
    for name, edge in zip(side_names, sides):
        ends = [BRepAdaptor_Curve(edge).Value(BRepAdaptor_Curve(edge).FirstParameter()),
                BRepAdaptor_Curve(edge).Value(BRepAdaptor_Curve(edge).LastParameter())]  # fmt: skip
        for i in _corner_vertices(segments, frame, ends, size):
            before, after = segments[i - 1], segments[i]
            mismatch = None if _turns(before, after) else g2_mismatch(before, after, JOIN_TOLERANCE, index=i)
            if mismatch is not None:
                jump = (float(np.ravel(before.curvature(1.0))[0]), float(np.ravel(after.curvature(0.0))[0]))
                raise NoSolutionError(
                    f"g2_fillet rounds corners; {name} is a tangent joint, not a corner: the outline's curvature "
                    f"jumps from {jump[0]:.6g} to {jump[1]:.6g} there, so its faces meet G1; making tangent joints G2 "
                    "is a separate feature: leave the edge out of the selection"
                )
    chosen = [i for i in _corner_vertices(segments, frame, feet, size) if _turns(segments[i - 1], segments[i])]
    rolled = any(chosen_caps.values())
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape, tolerance=tolerance)

    def builds(r: float) -> Slab:  # the same edges rounded with ``r``: what a refusal may suggest
        return fillet_prism_edges(solid, edges, r, **options, _advise=False)

    outline = segments
    if chosen and rolled:  # one radius for all: the roll's, the plan corners wide enough to hold it
        segments = _rolled_plan(outline, chosen, prism.height, radius, chosen_caps, transition, same_sense, shape,
                                builds if _advise else None)  # fmt: skip
    elif chosen:
        plan_options = dict(transition=transition, vertices=chosen, closed=True, same_sense=same_sense, shape=shape)
        try:
            path = fillet_path(segments, radius, **plan_options)  # type: ignore[arg-type]
        except NoSolutionError as error:
            if not _advise:
                raise
            fits = advice(lambda r: _succeeds(lambda: fillet_path(segments, r, **plan_options)), builds, as_float(radius, "radius"))  # type: ignore[arg-type]
            raise refusal(str(error), "radius", fits) from None
        segments = list(path.segments)
    if not rolled:
        local = _extrusion(segments, prism.height)
        approximation = 0.0
        roll = (0.0, 0.0)
    else:
        for a, b in zip(segments, segments[1:] + segments[:1]):
            if _turns(a, b):
                corner = gp_Pnt(*a.end[:2], 0.0).Transformed(_to_global(frame))
                raise NoSolutionError(
                    f"g2_fillet rolls the cap edges along a smooth outline; the side edge at {_where(corner)} is sharp "
                    "and not chosen (choose it too: a vertex blend of sharp and rounded edges is a later step)"
                )
        try:  # with chosen side edges the plan changes with the radius: a suggestion is built from the start
            slab = g2_slab(segments, prism.height, radius, top=chosen_caps["top"], bottom=chosen_caps["bottom"],
                           transition=transition, shape=shape, tolerance=tolerance, _name="radius",
                           _advise=_advise and not chosen)  # fmt: skip
        except NoSolutionError as error:
            if not (_advise and chosen):
                raise
            plan_fits = lambda r: _succeeds(  # noqa: E731
                lambda: _rolled_plan(outline, chosen, prism.height, r, chosen_caps, transition, same_sense, shape, None)
            )
            raise refusal(str(error), "radius", advice(plan_fits, builds, as_float(radius, "radius"))) from None
        local, approximation, roll = slab.shape, slab.approximation, slab.roll
    placed = BRepBuilderAPI_Transform(local, _to_global(frame), True).Shape()
    result = forward_solid(TopoDS.Solid_s(placed) if placed.ShapeType() == TopAbs_SOLID else _first_solid(placed))
    verify_solid(result, "rounded part")
    verify_faces(result, expected_level(segments), "rounded part")
    return Slab(result, approximation, roll, prism.height)


#: Side edges chosen with the cap edges: their plan corners' radius over the roll's reach into the part.
PLAN_OVER_REACH = 1.25


def plan_radius(radius: float, *, transition: float = 0.5, shape: str = DEFAULT_SHAPE) -> float:
    """The plan corner radius ``fillet_prism_edges`` gives side edges chosen together with the cap edges
    and one ``radius``: ``PLAN_OVER_REACH`` × the G2 roll's reach (1.25 × 1.257 × radius = 1.571 × radius
    with the default transition), so the roll fits inside every plan corner and ``radius`` stays the
    smallest radius of curvature of every rounded edge.

    Args:
        radius: the roll's smallest radius of curvature (> 0).
        transition, shape: of the roll's spirals, as in ``roll_profile``.

    Raises:
        ValueError: a non-positive radius.
    """
    return PLAN_OVER_REACH * float(roll_profile(radius, transition=transition, shape=shape)[-1].end[0])


def _succeeds(make: Callable[[], object]) -> bool:
    """Whether ``make()`` returns rather than refusing (NoSolutionError)."""
    try:
        make()
    except NoSolutionError:
        return False
    return True


def _rolled_plan(segments: list[Segment], chosen: list[int], height: float, radius: float, caps: dict[str, bool],
                 transition: float, same_sense: str, shape: str,
                 builds: Callable[[float], object] | None) -> list[Segment]:  # fmt: skip
    """The cap outline with the chosen corners rounded by ``plan_radius(radius)``, or NoSolutionError naming
    what does not fit and the largest radius that does (side corners, rolls and height together)."""
    options = dict(top=caps["top"], bottom=caps["bottom"], profile="g2", transition=transition, shape=shape)

    def attempt(r: float) -> tuple[list[Segment] | None, str | None]:
        corner = plan_radius(r, transition=transition, shape=shape)
        try:
            path = fillet_path(segments, corner, transition=transition, vertices=chosen, closed=True,
                               same_sense=same_sense, shape=shape)  # fmt: skip
        except NoSolutionError as error:
            return None, f"radius {shown(r)} rounds the side edges with the plan radius {corner:.6g} ({error})"
        plan = list(path.segments)
        return plan, _roll_problem(plan, height, r, height, "radius", **dict(options))

    plan, problem = attempt(radius)
    if problem is None and plan is not None:
        return plan
    if builds is None:
        raise NoSolutionError(str(problem))
    fits = advice(lambda r: attempt(r)[1] is None, builds, radius)
    raise refusal(
        f"{problem} (side and cap edges chosen together: the side edges get the plan radius {PLAN_OVER_REACH:g} × the roll's reach)",
        "radius",
        fits,
    )


def _fit(solid: TopoDS_Shape, edges: Sequence[TopoDS_Edge], axis: gp_Dir, named: list[str]) -> tuple:
    """How well the chosen edges fit a prism along ``axis`` (smaller is better; NoSolutionError: no prism):
    edges left unexplained, caps chosen in part, then the axis nearest z, y."""
    prism = _prism(solid, axis, named[0])
    caps = [_edges_of(prism.bottom), _edges_of(prism.top)]
    unexplained, partial = 0, 0
    for edge in edges:
        line = _line_direction(edge)
        if not (line is not None and line[2].IsParallel(axis, 1e-12)) and not any(any(edge.IsSame(e) for e in c) for c in caps):
            unexplained += 1
    for cap in caps:
        count = sum(any(edge.IsSame(e) for edge in edges) for e in cap)
        partial += 0 < count < len(cap)
    return unexplained, partial, -abs(axis.Z()), -abs(axis.Y())


def _turns(before: Segment, after: Segment) -> bool:
    """Whether the outline turns (a sharp corner) from ``before`` into ``after`` (tangent joints are left alone)."""
    (tx0, ty0), (tx1, ty1) = before.ends[1][2:4], after.ends[0][2:4]
    return abs(math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1)) > TANGENT_TOL


def _wires_of(face: TopoDS_Face) -> list[TopoDS_Shape]:
    found, explorer = [], TopExp_Explorer(face, TopAbs_WIRE)
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def _first_solid(shape: TopoDS_Shape) -> TopoDS_Solid:
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    return TopoDS.Solid_s(explorer.Current())


def _to_global(frame: gp_Ax3) -> gp_Trsf:
    trsf = gp_Trsf()
    trsf.SetTransformation(frame)  # global → local
    return trsf.Inverted()


def _corner_vertices(segments: list[Segment], frame: gp_Ax3, feet: list[gp_Pnt], size: float) -> list[int]:
    """Indices of the outline vertices under the chosen side edges' ends."""
    back = gp_Trsf()
    back.SetTransformation(frame)
    local = [p.Transformed(back) for p in feet]
    chosen = []
    for i, segment in enumerate(segments):
        x, y = segment.start[:2]
        if any(abs(p.X() - x) <= 1e-9 * size and abs(p.Y() - y) <= 1e-9 * size and abs(p.Z()) <= 1e-9 * size for p in local):
            chosen.append(i)
    return chosen


def _extrusion(segments: list[Segment], height: float) -> TopoDS_Shape:
    face = BRepBuilderAPI_MakeFace(chain_wire(segments), True).Face()
    solid = BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, height)).Shape()
    explorer = TopExp_Explorer(solid, TopAbs_SOLID)
    result = TopoDS.Solid_s(explorer.Current())
    return forward_solid(TopoDS.Solid_s(result.Reversed()) if _volume(result) < 0.0 else result)
