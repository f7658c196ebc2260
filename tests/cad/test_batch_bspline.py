"""B-spline surfaces and curves evaluated in batches agree with OCCT's own evaluation (``D2``, ``D1``), one by one."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("build123d")
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface, Geom_RectangularTrimmedSurface
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal

from spiral_cad.cad.batch_bspline import bspline_curve_points, bspline_curves, bspline_derivatives, bspline_surfaces

pytestmark = pytest.mark.cad


def _occt(surface, uvs: np.ndarray) -> np.ndarray:
    p, vs, rows = gp_Pnt(), [gp_Vec() for _ in range(5)], []
    for u, v in uvs.tolist():
        surface.D2(u, v, p, *vs)
        rows.append([*p.Coord(), *(c for w in vs for c in w.Coord())])
    return np.array(rows)


def _random_surface(rng: np.random.Generator) -> Geom_BSplineSurface:
    """A random B-spline surface: degrees 1–5, inner knots of any multiplicity up to the degree, weights or none."""
    arrays = []
    for _ in range(2):
        degree = int(rng.integers(1, 6))
        inner = int(rng.integers(0, 4))
        values = np.sort(rng.uniform(-3.0, 7.0, inner + 2))
        multiplicities = [degree + 1] + [int(rng.integers(1, degree + 1)) for _ in range(inner)] + [degree + 1]
        arrays.append((degree, values, multiplicities, sum(multiplicities) - degree - 1))
    (p, ku, mu, nu), (q, kv, mv, nv) = arrays
    poles, weights = TColgp_Array2OfPnt(1, nu, 1, nv), TColStd_Array2OfReal(1, nu, 1, nv)
    for i in range(1, nu + 1):
        for j in range(1, nv + 1):
            poles.SetValue(i, j, gp_Pnt(*rng.uniform(-50.0, 50.0, 3)))
            weights.SetValue(i, j, float(rng.uniform(0.3, 3.0)))
    knots = []
    for values, multiplicities in ((ku, mu), (kv, mv)):
        k, m = TColStd_Array1OfReal(1, len(values)), TColStd_Array1OfInteger(1, len(values))
        for i, (value, count) in enumerate(zip(values, multiplicities), start=1):
            k.SetValue(i, float(value))
            m.SetValue(i, count)
        knots.append((k, m))
    (uk, um), (vk, vm) = knots
    if rng.random() < 0.5:
        return Geom_BSplineSurface(poles, weights, uk, vk, um, vm, p, q)
    return Geom_BSplineSurface(poles, uk, vk, um, vm, p, q)


def _away_from_knots(surface: Geom_BSplineSurface, uvs: np.ndarray) -> np.ndarray:
    """The rows not within 1e-9 of the range of a knot (where OCCT and the batches may pick either span)."""
    keep = np.ones(len(uvs), dtype=bool)
    for axis, (count, knot) in enumerate(((surface.NbUKnots(), surface.UKnot), (surface.NbVKnots(), surface.VKnot))):
        knots = np.array([knot(i) for i in range(1, count + 1)])
        keep &= np.abs(uvs[:, axis, None] - knots[None]).min(axis=1) > 1e-9 * (knots[-1] - knots[0])
    return uvs[keep]


def test_random_surfaces_of_every_degree_agree_with_occt():
    """60 random surfaces (rational or not, degrees 1–5, knots of every multiplicity) in one batch per degree
    pair, each sample on its own surface: the same point and derivatives as OCCT's D2, to rounding."""
    rng = np.random.default_rng(11)
    surfaces = [_random_surface(rng) for _ in range(60)]
    groups = bspline_surfaces(surfaces)
    assert sum(len(members) for _, members in groups.values()) == 60 and len(groups) > 5
    for table, members in groups.values():
        which, uvs = [], []
        for slot, k in enumerate(members):
            s = surfaces[k]
            u0, u1, v0, v1 = s.Bounds()
            # inside, at both ends and on the ends' lines (the last span takes the end of the range)
            inside = np.column_stack([rng.uniform(u0, u1, 30), rng.uniform(v0, v1, 30)])
            inside = np.vstack([inside, [[u0, v0], [u1, v1], [u1, rng.uniform(v0, v1)]]])
            chosen = np.vstack([_away_from_knots(s, inside), inside[-3:]])
            which += [slot] * len(chosen)
            uvs.append(chosen)
        uvs_all = np.vstack(uvs)
        ours = bspline_derivatives(table, np.array(which), uvs_all)
        start = 0
        for slot, k in enumerate(members):
            theirs = _occt(surfaces[k], uvs[slot])
            mine = ours[start : start + len(theirs)]
            start += len(theirs)
            scale = np.abs(theirs).reshape(-1, 6, 3).max(axis=(0, 2)).repeat(3)  # each derivative's own size
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-9 * (scale.max() + 1.0))


def test_a_g2_parts_faces_agree_with_occt_where_they_are():
    """Every B-spline face of a G2 part (located copies of its surfaces: their poles where the faces are)."""
    from spiral_cad.app.gallery import gallery_part

    part = gallery_part("plate_pocket_holes")
    faces, surfaces = [], []
    for face in part.faces():
        surface = BRep_Tool.Surface_s(face.wrapped)
        while isinstance(surface, Geom_RectangularTrimmedSurface):
            surface = surface.BasisSurface()
        if isinstance(surface, Geom_BSplineSurface):
            faces.append(face.wrapped)
            surfaces.append(surface)
    assert len(surfaces) > 300
    rng = np.random.default_rng(3)
    for table, members in bspline_surfaces(surfaces).values():
        for slot, k in enumerate(members):
            u0, u1, v0, v1 = BRepTools.UVBounds_s(faces[k])
            uvs = _away_from_knots(surfaces[k], np.column_stack([rng.uniform(u0, u1, 12), rng.uniform(v0, v1, 12)]))
            theirs = _occt(BRepAdaptor_Surface(faces[k]), uvs)
            mine = bspline_derivatives(table, np.full(len(uvs), slot), uvs)
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-9 * (np.abs(theirs).max() + 1.0))


def test_periodic_surfaces_are_left_to_occt():
    surface = _random_surface(np.random.default_rng(5))
    surface.SetUPeriodic()
    assert surface.IsUPeriodic() and bspline_surfaces([surface]) == {}


def _random_curve(rng: np.random.Generator) -> Geom_BSplineCurve:
    """A random 3-D B-spline curve: degree 1–9, inner knots of any multiplicity up to the degree, weights or none."""
    degree, inner = int(rng.integers(1, 10)), int(rng.integers(0, 5))
    values = np.sort(rng.uniform(-3.0, 7.0, inner + 2))
    multiplicities = [degree + 1] + [int(rng.integers(1, degree + 1)) for _ in range(inner)] + [degree + 1]
    count = sum(multiplicities) - degree - 1
    poles, weights = TColgp_Array1OfPnt(1, count), TColStd_Array1OfReal(1, count)
    for i in range(1, count + 1):
        poles.SetValue(i, gp_Pnt(*rng.uniform(-50.0, 50.0, 3)))
        weights.SetValue(i, float(rng.uniform(0.3, 3.0)))
    knots, mults = TColStd_Array1OfReal(1, len(values)), TColStd_Array1OfInteger(1, len(values))
    for i, (value, m) in enumerate(zip(values, multiplicities), start=1):
        knots.SetValue(i, float(value))
        mults.SetValue(i, m)
    if rng.random() < 0.5:
        return Geom_BSplineCurve(poles, weights, knots, mults, degree)
    return Geom_BSplineCurve(poles, knots, mults, degree)


def test_random_curves_of_every_degree_agree_with_occt():
    """80 random curves (rational or not, degrees 1–9) in one batch per degree, each sample on its own
    curve, the ends included: the same point and first derivative as OCCT's D1, to rounding."""
    rng = np.random.default_rng(17)
    curves = [_random_curve(rng) for _ in range(80)]
    groups = bspline_curves(curves)
    assert sum(len(members) for _, members in groups.values()) == 80 and len(groups) >= 8
    p, d1 = gp_Pnt(), gp_Vec()
    for table, members in groups.values():
        for slot, k in enumerate(members):
            c = curves[k]
            knots = np.array([c.Knot(i) for i in range(1, c.NbKnots() + 1)])
            ts = rng.uniform(c.FirstParameter(), c.LastParameter(), 40)
            ts = np.concatenate([ts[np.abs(ts[:, None] - knots).min(axis=1) > 1e-9], [c.FirstParameter(), c.LastParameter()]])
            theirs = []
            for t in ts.tolist():
                c.D1(t, p, d1)
                theirs.append([*p.Coord(), *d1.Coord()])
            point, derivative = bspline_curve_points(table, np.full(len(ts), slot), ts)
            expected = np.array(theirs)
            np.testing.assert_allclose(np.hstack([point, derivative]), expected, rtol=0, atol=1e-9 * (np.abs(expected).max() + 1.0))


def test_periodic_curves_are_left_to_occt():
    curve = _random_curve(np.random.default_rng(5))
    curve.SetPeriodic()
    assert curve.IsPeriodic() and bspline_curves([curve]) == {}
