"""The rolled edges of G2 solids: the roll profile swept along an outline as NURBS surfaces.

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
closed solid) in ``slabs`` before anything is returned.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
)
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape, TopoDS_Wire

from ..core import bezier
from ..core.errors import NoSolutionError
from ..core.inputs import as_float, shown
from ..core.nurbs import chain_to_nurbs
from ..core.segments import Arc, Line, Segment
from ..core.shapes import DEFAULT_SHAPE
from ..core.spiral import BezierSpiral
from ..design.fillets import corner_distance, fillet_path

__all__ = ["PROFILES", "recorded_approximation", "roll_profile"]

#: Roll profiles: the G2 corner (line → spiral → arc → spiral → line) or a quarter circle.
PROFILES = ("g2", "circular")
#: Most Hermite spans over one spiral before the tolerance counts as unreachable.
_MAX_SPANS = 256
#: Samples per Hermite span when measuring |Ñ − N|.
_SAMPLES = 48
#: Surfaces made here, by their shape's fingerprint (``_fingerprint``): the deviation of each from the exact sweep.
_RECORDED: dict[bytes, float] = {}
#: Most fingerprints kept (the oldest are forgotten first).
_RECORD_LIMIT = 100_000


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


def _sections(roll: list[Segment], top: float, bottom: float, low: float, high: float, *, foot: bool = False,
              head: bool = False) -> list[_Section]:  # fmt: skip
    """The Bézier spans of the bottom roll, the wall and the top roll (those of non-zero extent) of a wall from
    z ``low`` to ``high``, in the (w, z) plane. ``foot``: the bottom is a concave fillet onto a face rising on
    the open side (w < 0: a pocket's floor, the face a boss stands on), the bottom roll turned over; ``head``:
    the top is one onto a face hanging over the open side."""
    curve = chain_to_nurbs(roll) if roll else None
    ends = np.array([0.0, 1.0]), np.array([4, 4])
    sections = []
    if bottom > 0.0 and curve is not None:
        scale = bottom / float(curve.control_points[-1, 0])
        flip = np.array([-1.0 if foot else 1.0, -1.0])  # mirrored: the wall at (0, d) down to (±d, 0)
        points = curve.control_points * scale * flip + np.array([0.0, low])
        sections += [_Section(3, *ends, w, p) for w, p in _spans(3, curve.weights, points)]
    if high - low - top - bottom > 0.0:
        wall = np.array([[0.0, low + bottom], [0.0, high - top]])
        sections.append(_Section(1, np.array([0.0, 1.0]), np.array([2, 2]), np.ones(2), wall))
    if top > 0.0 and curve is not None:
        scale = top / float(curve.control_points[-1, 0])
        points = curve.control_points * scale * np.array([-1.0 if head else 1.0, 1.0]) + np.array([0.0, high])
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
    for i, (pole_row, weight_row) in enumerate(zip(grid.tolist(), products.tolist()), 1):
        for j, ((x, y, z), weight) in enumerate(zip(pole_row, weight_row), 1):
            poles.SetValue(i, j, gp_Pnt(x, y, z))
            weights.SetValue(i, j, weight)
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


def _rim_wire(alongs: Sequence[_Along], w: float, z: float, *, reverse: bool = False) -> TopoDS_Wire:
    """The closed wire of the rim's iso-curves C + w·Ñ at height z (``reverse``: run backwards)."""
    wire = BRepBuilderAPI_MakeWire()
    for along in alongs:
        edge = _boundary_edge(along, w, z)
        if edge is not None:
            wire.Add(edge)
    if not wire.IsDone():
        raise NoSolutionError(f"the face at z = {z:.6g} has no closed boundary (the roll closes the outline)")
    made = wire.Wire()
    return TopoDS.Wire_s(made.Reversed()) if reverse else made


def _plane_face(z: float, outer: TopoDS_Wire, holes: Sequence[TopoDS_Wire] = ()) -> TopoDS_Face:
    """The plane z inside ``outer`` (counterclockwise) and outside each of ``holes`` (clockwise)."""
    face = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0.0, 0.0, z), gp_Dir(0.0, 0.0, 1.0)), outer)
    for hole in holes:
        face.Add(hole)
    return face.Face()


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


def _faces_of(shape: TopoDS_Shape) -> list[TopoDS_Face]:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        found.append(TopoDS.Face_s(explorer.Current()))
        explorer.Next()
    return found
