"""Parts a face checker with fixed samples passed though they are not G2 (issue 29), shared by the
checker's tests and the CLI's."""

from __future__ import annotations

import math

import build123d as bd


def _array(kind, values):
    out = kind(1, len(values))
    for k, value in enumerate(values):
        out.SetValue(k + 1, value)
    return out


def bump_join(lo: float = 0.91, hi: float = 0.96) -> bd.Shell:
    """The plane z = 0 (−1 ≤ x ≤ 0) joined at x = 0 to the face z = x²·b(y) (0 ≤ x ≤ 1), b a cubic B-spline
    bump, nonzero on (lo, hi) only: tangent all along the edge, the curvature across it jumps over 5 % of it."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    inner = [lo + (hi - lo) * i / 4 for i in range(5)]
    flat = [0.0] * 4 + inner + [1.0] * 4
    count = len(flat) - 4
    greville = [sum(flat[j + 1 : j + 4]) / 3 for j in range(count)]  # y of the poles: y itself is linear
    bump = [1.0 if j == 4 else 0.0 for j in range(count)]  # the basis function on the knots lo … hi
    poles = TColgp_Array2OfPnt(1, 3, 1, count)
    for i, (x, a) in enumerate(((0.0, 0.0), (0.5, 0.0), (1.0, 1.0))):  # x² over 0 ≤ x ≤ 1, quadratic
        for j in range(count):
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, greville[j], a * bump[j]))
    surface = Geom_BSplineSurface(poles, _array(TColStd_Array1OfReal, [0.0, 1.0]), _array(TColStd_Array1OfReal, [0.0, *inner, 1.0]),
                                  _array(TColStd_Array1OfInteger, [3, 3]), _array(TColStd_Array1OfInteger, [4, 1, 1, 1, 1, 1, 4]),
                                  2, 3)  # fmt: skip
    sewing = BRepBuilderAPI_Sewing(1e-6)
    sewing.Add(bd.Face.make_rect(1, 1).moved(bd.Location((-0.5, 0.5, 0))).wrapped)
    sewing.Add(BRepBuilderAPI_MakeFace(surface, 1e-7).Face())
    sewing.Perform()
    return bd.Shell(sewing.SewedShape())


def circle_square_circle_loft() -> bd.Part:
    return bd.loft([bd.Sketch() + bd.Circle(10), bd.Pos(0, 0, 10) * bd.Rectangle(12, 8), bd.Pos(0, 0, 20) * bd.Circle(6)])


def quadratic_prism() -> bd.Part:
    """A prism on a quadratic B-spline with simple knots (C1: its curvature jumps at each knot) closed by a line."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    points = [(0, 0), (10, 0), (15, 8), (5, 14), (-4, 9), (-6, 3)]
    poles = TColgp_Array1OfPnt(1, len(points))
    for i, (x, y) in enumerate(points):
        poles.SetValue(i + 1, gp_Pnt(x, y, 0))
    spans = len(points) - 2
    curve = Geom_BSplineCurve(poles, _array(TColStd_Array1OfReal, [i / spans for i in range(spans + 1)]),
                              _array(TColStd_Array1OfInteger, [3] + [1] * (spans - 1) + [3]), 2)  # fmt: skip
    edge = bd.Edge(BRepBuilderAPI_MakeEdge(curve).Edge())
    return bd.extrude(bd.make_face([edge, bd.Line(edge @ 1, edge @ 0)]), 5)


def _cubic_basis(knots: list[float], t: float) -> list[float]:
    """The cubic B-spline basis functions on ``knots`` at ``t`` (Cox–de Boor; t = the last knot counts in the last span)."""
    last = len(knots) - 1
    values = [1.0 if knots[i] <= t < knots[i + 1] or (t == knots[-1] and knots[i] < t == knots[i + 1]) else 0.0 for i in range(last)]
    for degree in range(1, 4):
        values = [((t - knots[i]) / (knots[i + degree] - knots[i]) * values[i] if knots[i + degree] > knots[i] else 0.0)
                  + ((knots[i + degree + 1] - t) / (knots[i + degree + 1] - knots[i + 1]) * values[i + 1]
                     if knots[i + degree + 1] > knots[i + 1] else 0.0) for i in range(last - degree)]  # fmt: skip
    return values


def knot_surface(below: float = 0.25, above: float = 1.0):
    """A cubic B-spline surface z(y) (x = u, y = v, both 0…1) with a double knot at v = 0.5, tangent across
    it, its curvature across the line ``below`` for v < 0.5 and ``above`` for v > 0.5 (OCP)."""
    import numpy as np
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    flat = [0.0] * 4 + [0.5] * 2 + [1.0] * 4
    ys = np.linspace(0.0, 1.0, 41)
    zs = np.where(ys < 0.5, below / 2, above / 2) * (ys - 0.5) ** 2  # z'' = below, above: κ across the line
    heights = np.linalg.lstsq(np.array([_cubic_basis(flat, y) for y in ys]), zs, rcond=None)[0]
    poles = TColgp_Array2OfPnt(1, 2, 1, 6)
    for i, x in enumerate((0.0, 1.0)):
        for j in range(6):
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, sum(flat[j + 1 : j + 4]) / 3, heights[j]))  # y at the Greville points

    return Geom_BSplineSurface(poles, _array(TColStd_Array1OfReal, [0.0, 1.0]), _array(TColStd_Array1OfReal, [0.0, 0.5, 1.0]),
                               _array(TColStd_Array1OfInteger, [2, 2]), _array(TColStd_Array1OfInteger, [4, 2, 4]), 1, 3)  # fmt: skip


def knot_line_join(tilt: float = 1e-13, below: float = 0.25, above: float = 1.0, shift: float = 0.0, apart: float = 0.0):
    """Two faces of one cubic B-spline surface z(y) (x = u, y = v) with a double knot at v = 0.5, meeting on
    that knot line, tangent there, the curvature across it ``below`` on one side and ``above`` on the other
    (a G1 join); one face's pcurve of the shared edge tilted by ``tilt`` out of the face's bounds, as a file
    from another CAD system may have it, or its parameter shifted by ``shift`` along the edge (the same
    points, at other parameters); ``apart`` lifts the upper face by that much before the two are sewn (a
    real gap, within the sewn edge's tolerance). Returns the sewn shell (OCP)."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.BRepTools import BRepTools
    from OCP.Geom2d import Geom2d_Line
    from OCP.gp import gp_Dir2d, gp_Pnt2d, gp_Vec
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

    def surface():  # one copy per face: each face gets its own pcurve of the shared edge
        return knot_surface(below, above)

    sewing = BRepBuilderAPI_Sewing(max(1e-6, 10 * apart))
    upper = surface()
    upper.Translate(gp_Vec(0.0, 0.0, apart))
    sewing.Add(BRepBuilderAPI_MakeFace(surface(), 0.0, 1.0, 0.0, 0.5, 1e-7).Face())
    sewing.Add(BRepBuilderAPI_MakeFace(upper, 0.0, 1.0, 0.5, 1.0, 1e-7).Face())
    sewing.Perform()
    shell = sewing.SewedShape()
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shell, TopAbs_EDGE, TopAbs_FACE, ancestors)
    shared = next(i for i in range(1, ancestors.Extent() + 1) if ancestors.FindFromIndex(i).Extent() == 2)
    edge, face = TopoDS.Edge_s(ancestors.FindKey(shared)), TopoDS.Face_s(ancestors.FindFromIndex(shared).First())
    if tilt:
        line = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0).Lin2d()
        outwards = 1.0 if BRepTools.UVBounds_s(face)[3] < 0.75 else -1.0  # the face below the line: tilt above it
        d = line.Direction()
        BRep_Builder().UpdateEdge(edge, Geom2d_Line(line.Location(), gp_Dir2d(d.X(), d.Y() + outwards * tilt * abs(d.X()))), face, 1e-7)
    if shift:
        line = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0).Lin2d()
        d, at = line.Direction(), line.Location()
        BRep_Builder().UpdateEdge(edge, Geom2d_Line(gp_Pnt2d(at.X() + shift * d.X(), at.Y() + shift * d.Y()), d), face, 1e-7)
    return shell


def periodic_bspline_cylinder(start: float = 1.0, turn: float = 2 * math.pi, radius: float = 10.0, height: float = 10.0):
    """A cylinder stored as a periodic rational B-spline (knots 0, 2π/3, 4π/3, 2π, each double: C0 in its
    parameter, a circle in space) and one face of it over u in [start, start + turn]: past one period of
    its knots when the face does not start at 0. Returns the face (OCP)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_CylindricalSurface, Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert
    from OCP.gp import gp_Ax3

    surface = GeomConvert.SurfaceToBSplineSurface_s(
        Geom_RectangularTrimmedSurface(Geom_CylindricalSurface(gp_Ax3(), radius), 0.0, 2 * math.pi, 0.0, height)
    )
    surface.SetUPeriodic()
    return BRepBuilderAPI_MakeFace(surface, start, start + turn, 0.0, height, 1e-7).Face()


def surface_only_step(surfaces) -> str:
    """The text of a surface-only STEP file (AP214, millimetres): each surface a ``B_SPLINE_SURFACE_WITH_KNOTS``
    of one ``GEOMETRIC_SET``, no face, shell or solid. ``surfaces``: (poles as rows of (x, y, z) along u,
    (u degree, v degree), (u knots, v knots), (u multiplicities, v multiplicities)) each."""
    lines, n = [], [0]

    def add(text):
        n[0] += 1
        lines.append(f"#{n[0]} = {text};")
        return f"#{n[0]}"

    ctx_len = add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
    ctx_ang = add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
    ctx_sol = add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
    unc = add(f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),{ctx_len},'distance_accuracy_value','confusion accuracy')")
    ctx = add(
        f"( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT(({unc})) GLOBAL_UNIT_ASSIGNED_CONTEXT(({ctx_len},{ctx_ang},{ctx_sol})) REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY') )"
    )

    def reals(values) -> str:
        return "(" + ",".join(repr(float(a)) for a in values) + ")"

    def ints(values) -> str:
        return "(" + ",".join(str(int(a)) for a in values) + ")"

    items = []
    for poles, (du, dv), (ku, kv), (mu, mv) in surfaces:
        rows = []
        for row in poles:
            rows.append("(" + ",".join(add(f"CARTESIAN_POINT('',({x!r},{y!r},{z!r}))") for x, y, z in row) + ")")
        items.append(
            add(
                f"B_SPLINE_SURFACE_WITH_KNOTS('',{du},{dv},({','.join(rows)}),.UNSPECIFIED.,.F.,.F.,.F.,{ints(mu)},{ints(mv)},{reals(ku)},{reals(kv)},.UNSPECIFIED.)"
            )
        )
    gset = add(f"GEOMETRIC_SET('',({','.join(items)}))")
    app = add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
    add(f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,{app})")
    pc = add(f"PRODUCT_CONTEXT('',{app},'mechanical')")
    prod = add(f"PRODUCT('surfaces','surfaces','',({pc}))")
    pdf = add(f"PRODUCT_DEFINITION_FORMATION('','',{prod})")
    pdc = add(f"PRODUCT_DEFINITION_CONTEXT('part definition',{app},'design')")
    pd = add(f"PRODUCT_DEFINITION('design','',{pdf},{pdc})")
    pds = add(f"PRODUCT_DEFINITION_SHAPE('','',{pd})")
    rep = add(f"GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION('',({gset}),{ctx})")
    add(f"SHAPE_DEFINITION_REPRESENTATION({pds},{rep})")
    head = (
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('surfaces only'),'2;1');\nFILE_NAME('s','2026-01-01T00:00:00',(''),(''),'','','');\n"
        "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
    )
    return head + "\n".join(lines) + "\nENDSEC;\nEND-ISO-10303-21;\n"


def tangent_patches_step() -> str:
    """A surface-only STEP of two B-spline patches: the plane z = 0 (0 ≤ x ≤ 1) and z = (x − 1)² (1 ≤ x ≤ 2),
    tangent along x = 1, the curvature across it 0 against 2 (a G1 join)."""
    flat = [[(0.0, 0.0, 0.0), (0.0, 1.0, 0.0)], [(1.0, 0.0, 0.0), (1.0, 1.0, 0.0)]]
    bent = [[(1.0, 0.0, 0.0), (1.0, 1.0, 0.0)], [(1.5, 0.0, 0.0), (1.5, 1.0, 0.0)], [(2.0, 0.0, 1.0), (2.0, 1.0, 1.0)]]
    return surface_only_step([(flat, (1, 1), ((0, 1), (0, 1)), ((2, 2), (2, 2))),
                              (bent, (2, 1), ((0, 1), (0, 1)), ((3, 3), (2, 2)))])  # fmt: skip


def seam_torus(degree: int = 12, start: float = 1.0, major: float = 20.0, minor: float = 5.0):
    """A torus-like periodic B-spline surface of ``degree`` in u and v, one span a period (knots 0 and 2π, each
    of multiplicity ``degree``: C0 where the period closes, a kink of 2π/``degree`` through the pole there),
    and one face of it over [start, start + 2π]² — across the surface's seam. Returns the face (OCP)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    poles = TColgp_Array2OfPnt(1, degree, 1, degree)
    for i in range(degree):
        a = 2 * math.pi * i / degree
        for j in range(degree):
            b = 2 * math.pi * j / degree
            ring = major + minor * math.cos(b)
            poles.SetValue(i + 1, j + 1, gp_Pnt(ring * math.cos(a), ring * math.sin(a), minor * math.sin(b)))
    knots, multiplicities = _array(TColStd_Array1OfReal, [0.0, 2 * math.pi]), _array(TColStd_Array1OfInteger, [degree, degree])
    surface = Geom_BSplineSurface(poles, knots, knots, multiplicities, multiplicities, degree, degree, True, True)
    return BRepBuilderAPI_MakeFace(surface, start, start + 2 * math.pi, start, start + 2 * math.pi, 1e-7).Face()


def plug_on_knot_line(below: float = 0.25, above: float = 1.0):
    """One face of ``knot_surface`` over the whole square with a rectangular hole [0.25, 0.75] × [0.5, 0.8] in
    (u, v), and the plug filling the hole, on the same surface: the hole's lower edge lies on the knot line
    v = 0.5, inside the bounds of the face with the hole (whose side there is below the line: curvature
    ``below``) and on the border of the plug (above: ``above``). Returns the shell of the two (OCP)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS, TopoDS_Shell

    surface = knot_surface(below, above)
    plug = BRepBuilderAPI_MakeFace(surface, 0.25, 0.75, 0.5, 0.8, 1e-7).Face()
    outer = BRepBuilderAPI_MakeFace(surface, 0.0, 1.0, 0.0, 1.0, 1e-7)
    outer.Add(TopoDS.Wire_s(BRepTools.OuterWire_s(plug).Reversed()))  # the same edges: shared, on the same surface
    shell, builder = TopoDS_Shell(), BRep_Builder()
    builder.MakeShell(shell)
    builder.Add(shell, outer.Face())
    builder.Add(shell, plug)
    return shell
