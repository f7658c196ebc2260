"""The face-to-face checker on solids that build123d and OCCT made (not spiral_cad's solids), also
through STEP and IGES files."""

from __future__ import annotations

import json
import math
import re
import subprocess
import textwrap

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
from face_reproducers import bump_join, circle_square_circle_loft, quadratic_prism  # noqa: E402
from helpers import freecad_lib  # noqa: E402
from OCP.IGESControl import IGESControl_Writer  # noqa: E402
from OCP.Interface import Interface_Static  # noqa: E402

from spiral_cad.build123d import ContinuousRectangle  # noqa: E402
from spiral_cad.cad.faces import FEATURE_ANGLE, check_faces, holds_faces  # noqa: E402
from spiral_cad.cad.mesh import face_mesh  # noqa: E402


def filleted_box(radius: float = 2.0, length: float = 40.0, width: float = 20.0, height: float = 8.0) -> bd.Part:
    return bd.fillet(bd.Box(length, width, height).edges().filter_by(bd.Axis.Z), radius)


def continuous_slab() -> bd.Part:
    return bd.extrude(ContinuousRectangle(40, 20, 5), 8)


def write_iges(shape, path) -> None:
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)  # faces and solids (5.3), not trimmed surfaces only
    writer = IGESControl_Writer("MM", 1)
    writer.AddShape(shape.wrapped)
    writer.ComputeModel()
    assert writer.Write(str(path))


def found(report) -> dict[str, int]:
    """The classes found, with their counts."""
    return {level: count for level, count in report.counts.items() if count}


def assert_box_calibration(report, radius: float = 2.0) -> None:
    assert found(report) == {"G1": 8, "sharp": 16}
    for edge in report.tangent_edges:
        assert sorted(edge.surfaces) == ["cylinder", "plane"]
        assert edge.angle <= 1e-7
        assert edge.jump == pytest.approx(1.0, abs=1e-9)  # κn 0 against 1/r, relative to 1/r
        assert sorted(abs(k) for k in edge.curvatures) == pytest.approx([0.0, 1.0 / radius], abs=1e-9)
    for edge in report.sharp_edges:
        assert edge.angle == pytest.approx(math.pi / 2, abs=1e-9)
    assert report.worst == "G1" and report.passes("G1") and not report.passes("G2")


def test_box_with_circular_fillets_is_g1_with_a_jump_of_one_and_sixteen_sharp_edges():
    report = check_faces(filleted_box())
    assert report.faces == 10 and report.free_edges == 0
    assert_box_calibration(report)
    assert report.units == "mm" and report.size == pytest.approx(math.sqrt(40**2 + 20**2 + 8**2), rel=1e-3)


def test_extruded_continuous_rectangle_is_g2_with_sharp_top_and_bottom():
    report = check_faces(continuous_slab())
    assert found(report) == {"G2": 16, "sharp": 32}
    assert max(e.jump for e in report.tangent_edges) < 1e-10
    assert report.worst == "G2" and report.passes("G2")
    # the spiral faces are B-spline/extrusion surfaces, not only planes and cylinders
    assert any("extrusion" in e.surfaces or "bspline" in e.surfaces for e in report.tangent_edges)


def test_filleted_cylinder_is_g1():
    report = check_faces(bd.fillet(bd.Cylinder(10, 20).edges(), 2))
    joins = [e for e in report.edges if not e.seam]
    assert len(joins) == 4 and all(e.level == "G1" for e in joins)
    assert all(e.jump == pytest.approx(1.0, abs=1e-6) for e in joins)
    assert all(e.level == "G2" for e in report.edges if e.seam)  # a closed face meets itself smoothly
    assert report.worst == "G1"


def test_sphere_seam_is_g2_and_its_poles_are_skipped():
    report = check_faces(bd.Sphere(5))
    assert report.faces == 1 and len(report.edges) == 1
    (seam,) = report.edges
    assert seam.seam and seam.faces == (0, 0) and seam.surfaces == ("sphere", "sphere")
    assert seam.level == "G2" and seam.curvatures == pytest.approx((-0.2, -0.2))


def test_box_is_all_sharp_and_passes():
    report = check_faces(bd.Box(10, 10, 10))
    assert report.counts["sharp"] == 12 and not report.tangent_edges
    assert report.worst == "G2" and report.passes("G2")


def test_near_tangent_kink_is_a_crease_and_fails_g1():
    kink = math.radians(1.0)
    outline = bd.Polyline((0, 0), (10, 0), (20, 10 * math.tan(kink)), (20, 10), (0, 10), close=True)
    report = check_faces(bd.extrude(bd.make_face(outline), 5))
    creases = [e for e in report.edges if e.level == "crease"]
    assert len(creases) == 1 and creases[0].angle == pytest.approx(kink, rel=1e-9)
    assert report.worst == "crease" and not report.passes("G1")
    # the same kink is a feature when the feature threshold is below it
    assert check_faces(bd.extrude(bd.make_face(outline), 5), feature_angle=kink / 2).passes("G2")


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_files_written_by_build123d_and_occt_give_the_same_verdicts(tmp_path, suffix):
    for name, part, expected in (("box", filleted_box(), {"G1": 8, "sharp": 16}),
                                 ("slab", continuous_slab(), {"G2": 16, "sharp": 32})):  # fmt: skip
        path = tmp_path / f"{name}{suffix}"
        if suffix == ".step":
            assert bd.export_step(part, str(path))
        else:
            write_iges(part, path)
        report = check_faces(path)
        assert found(report) == expected, report.table()
        assert report.source == path.name and report.units == "mm"
    assert_box_calibration(check_faces(tmp_path / f"box{suffix}"))


def test_file_read_in_another_unit_scales_curvature_and_size(tmp_path):
    path = tmp_path / "box.step"
    bd.export_step(filleted_box(), str(path))
    report = check_faces(path, units="cm")
    assert report.units == "cm" and report.size == pytest.approx(check_faces(path).size / 10, rel=1e-6)  # the box grows by the tolerance
    assert sorted(abs(k) for k in report.tangent_edges[0].curvatures) == pytest.approx([0.0, 5.0], abs=1e-9)


def test_table_lists_every_edge_with_its_class():
    text = check_faces(filleted_box()).table()
    assert "10 faces, 24 shared edges (8 G1, 16 sharp); worst tangent edge G1" in text
    assert text.count("  G1 ") == 8 and text.count("  sharp ") == 16
    assert "model size 45.4" in text and "mm" in text


@pytest.mark.parametrize(
    "options",
    [dict(gap_tol=-1.0), dict(angle_tol=math.nan), dict(curvature_tol=math.inf), dict(samples=0), dict(samples=2.5),
     dict(feature_angle=0.0), dict(feature_angle=4.0)],
)  # fmt: skip
def test_bad_options_raise_value_error_naming_them(options):
    with pytest.raises(ValueError, match=next(iter(options))):
        check_faces(bd.Box(1, 1, 1), **options)


def test_unreadable_file_and_bad_require_raise_value_error(tmp_path):
    bad = tmp_path / "bad.step"
    bad.write_text("not a step file\n")
    with pytest.raises(ValueError, match="bad.step"):
        check_faces(bad)
    with pytest.raises(ValueError, match="require"):
        check_faces(bd.Box(1, 1, 1)).passes("G3")


def test_default_feature_angle_is_documented_five_degrees():
    assert FEATURE_ANGLE == pytest.approx(math.radians(5.0))


@settings(max_examples=6, deadline=None)
@given(radius=st.floats(0.2, 3.9), length=st.floats(20.0, 60.0), width=st.floats(8.0, 30.0))
def test_any_circular_fillet_of_a_box_is_g1_with_relative_jump_one_never_g2(radius, length, width):
    report = check_faces(filleted_box(radius, length, width))
    assert report.counts["G1"] == 8 and report.counts["G2"] == 0
    assert all(e.jump == pytest.approx(1.0, abs=1e-9) for e in report.tangent_edges)
    assert not report.passes("G2")


# ------------------------------------------------------------ FreeCAD's own evaluation of the same file


FREECAD = freecad_lib()
#: In FreeCAD (system Python): for each point, the faces through it, each with its oriented normal
#: (``Face.normalAt``) and its normal curvature across the edge through it, by Euler's formula from
#: FreeCAD's principal curvatures and directions (``Surface.curvature``, ``Surface.curvatureDirections``).
FREECAD_SCRIPT = textwrap.dedent(
    """
    import json, math, sys
    sys.path.append(sys.argv[1])
    import FreeCAD, Part
    shape = Part.read(sys.argv[2])
    out = []
    for x, y, z in json.loads(sys.argv[3]):
        p = FreeCAD.Vector(x, y, z)
        vertex = Part.Vertex(p)
        edge = min(shape.Edges, key=lambda e: e.distToShape(vertex)[0])
        t = edge.tangentAt(edge.Curve.parameter(p))
        found = []
        for face in shape.Faces:
            if face.distToShape(vertex)[0] > 1e-6:
                continue
            u, v = face.Surface.parameter(p)
            n = face.normalAt(u, v)
            k1, k2 = face.Surface.curvature(u, v, "Max"), face.Surface.curvature(u, v, "Min")
            d1, d2 = face.Surface.curvatureDirections(u, v)
            d = n.cross(t)
            c = d.normalize().dot(d1.normalize())
            found.append([n.x, n.y, n.z, abs(k1 * c * c + k2 * (1 - c * c))])
        out.append(found)
    print(json.dumps(out))
    """
)


@pytest.mark.skipif(FREECAD is None, reason="FreeCAD is not installed (Debian/Ubuntu: apt-get install freecad-python3)")
@pytest.mark.parametrize("name", ["box", "slab"])
def test_freecad_evaluates_the_same_normals_and_normal_curvatures(tmp_path, name):
    part = filleted_box() if name == "box" else continuous_slab()
    path = tmp_path / f"{name}.step"
    bd.export_step(part, str(path))
    report = check_faces(path)
    edges = report.tangent_edges
    points = [list(e.jump_at) for e in edges]
    run = subprocess.run(["/usr/bin/python3", "-c", FREECAD_SCRIPT, FREECAD, str(path), json.dumps(points)],
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    for edge, faces in zip(edges, json.loads(run.stdout.splitlines()[-1])):
        assert len(faces) == 2, f"edge {edge.index}: FreeCAD finds {len(faces)} faces through {edge.jump_at}"
        na, nb = np.array(faces[0][:3]), np.array(faces[1][:3])
        ka, kb = faces[0][3], faces[1][3]
        assert math.acos(min(1.0, float(na @ nb))) <= 1e-7  # FreeCAD's oriented normals agree: tangent
        assert sorted([ka, kb]) == pytest.approx(sorted(abs(k) for k in edge.curvatures), abs=1e-9)
        freecad_jump = abs(ka - kb) / max(ka, kb, 1.0 / report.size)
        assert freecad_jump == pytest.approx(edge.jump, abs=1e-6)
        assert (freecad_jump > report.curvature_tol) == (edge.level == "G1")


# ------------------------------------------------------------ what the CLI and the pictures rest on


def test_holds_faces_tells_solid_files_from_wire_files(tmp_path):
    solid, iges, wire = tmp_path / "solid.step", tmp_path / "solid.igs", tmp_path / "wire.step"
    bd.export_step(bd.Box(1, 2, 3), str(solid))
    write_iges(bd.Box(1, 2, 3), iges)
    bd.export_step(bd.Polyline((0, 0), (1, 0), (1, 1)), str(wire))
    assert holds_faces(solid) and holds_faces(iges)
    assert not holds_faces(wire) and not holds_faces(tmp_path / "missing.step") and not holds_faces(tmp_path)


def test_mesh_normals_and_curvatures_are_the_surfaces(tmp_path):
    mesh = face_mesh(bd.Sphere(5), angle=0.2)
    radial = mesh.points / np.linalg.norm(mesh.points, axis=1)[:, None]
    assert np.abs(np.einsum("ij,ij->i", mesh.normals, radial) - 1.0).max() < 1e-12  # outward, exact
    assert mesh.mean_curvature == pytest.approx(0.2, abs=1e-9) and mesh.gaussian_curvature == pytest.approx(0.04, abs=1e-9)
    # triangles wind counter-clockwise seen from outside, on a reversed face too
    box = face_mesh(filleted_box(), angle=0.2)
    a, b, c = (box.points[box.triangles[:, i]] for i in range(3))
    assert (np.einsum("ij,ij->i", np.cross(b - a, c - a), box.normals[box.triangles].mean(axis=1)) > 0).all()
    assert sorted(set(np.round(box.mean_curvature, 9))) == pytest.approx([0.0, 0.25])  # planes, r = 2 fillets (1/2r)
    path = tmp_path / "box.step"
    bd.export_step(filleted_box(), str(path))
    assert face_mesh(path, units="cm", angle=0.2).size == pytest.approx(box.size / 10, rel=1e-9)
    with pytest.raises(ValueError, match="no faces"):
        face_mesh(bd.Polyline((0, 0, 0), (1, 0, 0)))


def test_edges_without_pcurves_are_measured_by_projection(monkeypatch):
    # a file may leave out an edge's curve on a face: the edge's points are then projected on the surface
    from OCP.BRep import BRep_Builder
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    import spiral_cad.cad.face_sampling as sampling

    shape = filleted_box().wrapped
    builder, faces_found = BRep_Builder(), TopExp_Explorer(shape, TopAbs_FACE)
    while faces_found.More():
        face = TopoDS.Face_s(faces_found.Current())
        edges = TopExp_Explorer(face, TopAbs_EDGE)
        while edges.More():
            builder.UpdateEdge(TopoDS.Edge_s(edges.Current()), None, face, 1e-7)  # drop the pcurve
            edges.Next()
        faces_found.Next()
    projected = []
    original = sampling.projected
    monkeypatch.setattr(sampling, "projected", lambda *args: projected.append(args) or original(*args))
    assert_box_calibration(check_faces(shape))
    # the fillets' edges, once each: nothing turns or changes along them, so no second round (a plane's
    # pcurves OCCT computes itself)
    assert len(projected) == 16


def test_box_with_every_edge_filleted_is_g1_at_its_sphere_corners_too():
    report = check_faces(bd.fillet(bd.Box(40, 20, 16).edges(), 6))
    assert found(report) == {"G1": 48}
    corners = [e for e in report.edges if "sphere" in e.surfaces]
    assert len(corners) == 24 and all(e.jump == pytest.approx(1.0, abs=1e-6) for e in corners)  # 0 against 1/r


def test_failing_names_the_edges_below_the_requirement_worst_first():
    report = check_faces(filleted_box())
    assert report.failing("G1") == [] and len(report.failing("G2")) == 8
    assert all(e.level == "G1" and e.tangent for e in report.failing())
    kink = bd.Polyline((0, 0), (10, 0), (20, 10 * math.tan(math.radians(1.0))), (20, 10), (0, 10), close=True)
    creased = check_faces(bd.extrude(bd.make_face(kink), 5))
    assert [e.level for e in creased.failing("G1")] == ["crease"]
    with pytest.raises(ValueError, match="require"):
        report.failing("G0")


def loose_faces(part) -> bd.Compound:
    """The part's faces each copied on its own: nothing shared, as a surface export writes them."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy

    return bd.Compound([bd.Face(BRepBuilderAPI_Copy(f.wrapped).Shape()) for f in part.faces()])


def test_loose_faces_are_sewn_before_judging_and_the_stitches_counted():
    report = check_faces(loose_faces(filleted_box()))
    assert_box_calibration(report)
    assert report.stitched == 24 and report.free_edges == 0
    assert "24 stitched" in report.describe()


def test_surface_only_iges_export_is_sewn_and_judged(tmp_path):
    Interface_Static.SetIVal_s("write.iges.brep.mode", 0)  # trimmed surfaces, one by one: no shared edges
    writer = IGESControl_Writer("MM", 0)
    writer.AddShape(filleted_box().wrapped)
    writer.ComputeModel()
    assert writer.Write(str(tmp_path / "faces.igs"))
    report = check_faces(tmp_path / "faces.igs")
    assert found(report) == {"G1": 8, "sharp": 16}  # the fillets come back as surfaces of revolution
    assert report.worst == "G1" and report.passes("G1") and not report.passes("G2")
    assert report.stitched == 24


def test_faces_that_meet_nowhere_never_pass_and_their_free_edges_are_listed():
    apart = bd.Compound([bd.Face.make_rect(10, 10), bd.Face.make_rect(10, 10).moved(bd.Location((50, 0, 0)))])
    report = check_faces(apart)
    assert report.edges == () and report.stitched == 0 and report.free_edges == 8
    assert not report.passes("G1") and not report.passes("G2")
    assert {round(at[0]) for _, at in report.free_at} == {-5, 0, 5, 45, 50, 55}
    assert "free edges that no other face could be sewn to (8)" in report.table()


def shell_of(faces) -> bd.Shell:
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Shell

    builder, shell = BRep_Builder(), TopoDS_Shell()
    builder.MakeShell(shell)
    for face in faces:
        builder.Add(shell, face)
    return bd.Shell(shell)


@pytest.mark.parametrize("reversed_fillets", [1, 4])
def test_a_face_reversed_in_its_shell_is_an_orientation_note_never_a_sharp_edge(reversed_fillets):
    box = filleted_box()
    cylinders = [f for f in box.faces() if f.geom_type == bd.GeomType.CYLINDER][:reversed_fillets]
    shell = shell_of([f.wrapped.Reversed() if f in cylinders else f.wrapped for f in box.faces()])
    report = check_faces(shell)
    assert_box_calibration(report)
    flagged = [e for e in report.edges if "orientation" in e.note]
    assert len(flagged) == 4 * reversed_fillets  # each reversed fillet: two tangent edges and its top and bottom
    assert sorted(e.level for e in flagged) == ["G1"] * 2 * reversed_fillets + ["sharp"] * 2 * reversed_fillets
    assert "inconsistent shell" in report.table()


def test_every_pair_of_faces_at_a_non_manifold_edge_is_judged():
    from OCP.BOPAlgo import BOPAlgo_Builder

    plane = bd.Face.make_rect(10, 10).moved(bd.Location((-5, 0, 0)))  # z = 0, x ≤ 0
    cylinder = next(f for f in bd.Cylinder(5, 10, rotation=(90, 0, 0)).moved(bd.Location((0, 0, 5))).faces()
                    if f.geom_type == bd.GeomType.CYLINDER)  # fmt: skip
    quarter = (cylinder & bd.Box(5, 10, 5, align=(bd.Align.MIN, bd.Align.CENTER, bd.Align.MIN))).faces()[0]
    fin = bd.Face.make_rect(10, 10, plane=bd.Plane.YZ).moved(bd.Location((0, 0, -5)))  # x = 0, going down
    for order in ([plane, fin, quarter], [fin, plane, quarter], [plane, quarter, fin]):
        builder = BOPAlgo_Builder()
        for face in order:
            builder.AddArgument(face.wrapped)
        builder.Perform()
        report = check_faces(builder.Shape())
        shared = [e for e in report.edges if e.note.startswith("non-manifold: 3 faces")]
        assert len(shared) == 3 and len({e.index for e in shared}) == 1
        assert sorted(e.level for e in shared) == ["G1", "sharp", "sharp"]  # the plane meets the fillet G1, the fin at 90°
        assert not report.passes("G2")


def test_an_edge_tangent_over_part_of_its_length_is_a_crease_not_a_feature():
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    flat = bd.Face.make_bezier_surface([[bd.Vector(i, j, 0) for j in range(4)] for i in range(4)])
    # the second face leaves the first tangent at y = 0 and at 0.2 rad (11°) at y = 3
    fading = bd.Face.make_bezier_surface([[bd.Vector(3 + i, j, i * 0.2 * j / 3) for j in range(4)] for i in range(4)])
    sewing = BRepBuilderAPI_Sewing(1e-6)
    for face in (flat, fading):
        sewing.Add(face.wrapped)
    sewing.Perform()
    report = check_faces(sewing.SewedShape())
    (edge,) = report.edges
    assert edge.angle > FEATURE_ANGLE and edge.level == "crease" and "partly tangent" in edge.note
    assert not report.passes("G1")


def bspline_face(heights: list[float]) -> bd.Face:
    """A cubic B-spline face over 0 ≤ x ≤ 6, 0 ≤ y ≤ 3 whose u knot at x = 3 has multiplicity 3
    (a Bézier join: C0 there): ``heights`` are the z of its seven rows of poles."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    poles = TColgp_Array2OfPnt(1, len(heights), 1, 4)
    for i, z in enumerate(heights):
        for j in range(4):
            poles.SetValue(i + 1, j + 1, bd.Vector(i, j, z).to_pnt())

    def array(kind, values):
        out = kind(1, len(values))
        for k, value in enumerate(values):
            out.SetValue(k + 1, value)
        return out

    surface = Geom_BSplineSurface(poles, array(TColStd_Array1OfReal, [0.0, 1.0, 2.0]), array(TColStd_Array1OfReal, [0.0, 1.0]),
                                  array(TColStd_Array1OfInteger, [4, 3, 4]), array(TColStd_Array1OfInteger, [4, 4]), 3, 3)  # fmt: skip
    return bd.Face(BRepBuilderAPI_MakeFace(surface, 1e-7).Face())


@pytest.mark.parametrize(
    ("heights", "level"),
    [([0, 0, 0, 0, 0, 0.5, 1.0], "G1"),  # flat, then bending away: tangent, curvature jumps from 0
     ([0, 0, 0, 0, 0.02, 0.04, 0.06], "crease"),  # a kink of 0.02 rad inside the face
     ([0, 0, 0, 0, 0.2, 0.4, 0.6], "sharp")],  # 0.2 rad: a feature, listed
)  # fmt: skip
def test_a_knot_line_inside_a_bspline_face_is_judged_as_a_pseudo_edge(heights, level):
    face = bspline_face(heights)
    for part, lines in ((face, 1), (bd.extrude(face, 1, dir=(0, 0, -1)), 2)):  # the slab: its top and bottom
        inside = [e for e in check_faces(part).edges if e.index == -1 and "bspline" in e.surfaces]
        assert len(inside) == lines and {e.level for e in inside} == {level}
        assert all(e.note.startswith("inside face") and "u = 1 (knot of multiplicity 3)" in e.note for e in inside)
        assert all(e.jump_at[0] == pytest.approx(3.0) for e in inside)
    # the slab's sides are extrusions of its edges, B-splines that bend at x = 3 within the planes y = 0 and
    # y = 3: their knot lines are judged too, and a plane is G2 however its curve bends
    slab = check_faces(bd.extrude(face, 1, dir=(0, 0, -1)))
    sides = [e for e in slab.edges if e.index == -1 and e.surfaces == ("extrusion", "extrusion")]
    assert len(sides) == 2 and all(e.level == "G2" and "extrusion surface's B-spline" in e.note for e in sides)


def test_a_smooth_knot_line_stays_g2():
    # poles collinear across the join and equally spaced: the two spans are one cubic, C2 at x = 3
    report = check_faces(bspline_face([0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    (inside,) = [e for e in report.edges if e.index == -1]
    assert inside.level == "G2"


def test_table_columns_stay_in_line_with_long_surface_names():
    from spiral_cad.build123d import G2Polyline

    with bd.BuildPart() as vase:
        with bd.BuildSketch(bd.Plane.XZ):
            with bd.BuildLine():
                G2Polyline((0, 0), (10, 0), (10, 10), (4, 20), (0, 20), radius=2)
                bd.Line((0, 20), (0, 0))
            bd.make_face()
        bd.revolve(axis=bd.Axis.Z)
    lines = check_faces(vase.part).table().splitlines()
    rows = lines[3:]
    assert any(len(f"{e.surfaces[0]}/{e.surfaces[1]} seam") > 22 for e in check_faces(vase.part).edges if e.seam)
    start = lines[2].index("gap") + 3  # the gap column ends here in the header and in every row
    assert all(row[start - 1] != " " and row[start] == " " for row in rows)


# ------------------------------------------------------------ defects a fixed set of samples missed


def reproducer_file(tmp_path, part, suffix: str):
    path = tmp_path / f"part{suffix}"
    if suffix == ".step":
        assert bd.export_step(part, str(path))
    else:
        write_iges(part, path)
    return path


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_a_curvature_jump_over_five_percent_of_an_edge_is_g1(tmp_path, suffix):
    # 16 equally spaced samples fall at y = 0.906 and 0.969, either side of the bump
    report = check_faces(reproducer_file(tmp_path, bump_join(), suffix))
    (edge,) = report.edges
    assert edge.level == "G1" and not report.passes("G2") and report.passes("G1")
    assert 0.91 < edge.jump_at[1] < 0.96 and edge.jump == pytest.approx(1.0)  # 0 on the plane against 2·b(y)
    assert edge.angle < 1e-9


@pytest.mark.parametrize("where", [(0.01, 0.03), (0.5, 0.52), (0.97, 0.99)])
def test_a_bump_over_two_percent_of_an_edge_is_found_wherever_it_is(where):
    (edge,) = check_faces(bump_join(*where)).edges
    assert edge.level == "G1" and where[0] < edge.jump_at[1] < where[1]


def test_a_loft_whose_edges_turn_tangent_at_the_circles_has_creases_not_sharp_features():
    report = check_faces(circle_square_circle_loft())
    creases = [e for e in report.edges if e.level == "crease"]
    assert len(creases) == 4 and all("partly tangent" in e.note for e in creases)
    assert report.worst == "crease" and not report.passes("G1")


def test_a_prism_on_a_c1_quadratic_bspline_has_g1_knot_lines_in_its_side():
    report = check_faces(quadratic_prism())
    inside = [e for e in report.edges if e.index == -1]
    assert len(inside) == 3 and all(e.level == "G1" and e.surfaces == ("extrusion", "extrusion") for e in inside)
    assert all("extrusion surface's B-spline" in e.note for e in inside)
    assert len({(round(e.jump_at[0], 6), round(e.jump_at[1], 6)) for e in inside}) == 3  # three knots, three lines
    assert not report.passes("G2")


def test_extra_samples_go_where_the_geometry_is_not_where_it_is_plain():
    plain = check_faces(bd.Box(10, 10, 10))
    assert {e.samples for e in plain.edges} == {18}  # the floor of 16 and the two ends
    (bump,) = check_faces(bump_join()).edges
    assert bump.samples >= 18 + 2 * 6  # two in each of the six spans the bump's knots cut the edge into


#: In FreeCAD: for each point, the edge through it sampled at 400 points (and 1e-6 from its ends), and at
#: each the angle between the two faces' normals (``Face.normalAt``): the least and the largest.
FREECAD_ALONG = textwrap.dedent(
    """
    import json, math, sys
    sys.path.append(sys.argv[1])
    import FreeCAD, Part
    shape = Part.read(sys.argv[2])
    out = []
    for x, y, z in json.loads(sys.argv[3]):
        vertex = Part.Vertex(FreeCAD.Vector(x, y, z))
        edge = min(shape.Edges, key=lambda e: e.distToShape(vertex)[0])
        faces = [f for f in shape.Faces if any(e.isSame(edge) for e in f.Edges)]
        a, b = edge.FirstParameter, edge.LastParameter
        ts = [a + 1e-6 * (b - a), b - 1e-6 * (b - a)] + [a + (b - a) * (k + 0.5) / 400 for k in range(400)]
        angles = []
        for t in ts:
            p = edge.valueAt(t)
            n = [f.normalAt(*f.Surface.parameter(p)) for f in faces]
            angles.append(math.acos(max(-1.0, min(1.0, n[0].dot(n[1])))))
        out.append([min(angles), max(angles)])
    print(json.dumps(out))
    """
)


def freecad(script: str, path, points) -> list:
    run = subprocess.run(["/usr/bin/python3", "-c", script, FREECAD, str(path), json.dumps(points)],
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    return json.loads(run.stdout.splitlines()[-1])


@pytest.mark.skipif(FREECAD is None, reason="FreeCAD is not installed (Debian/Ubuntu: apt-get install freecad-python3)")
def test_freecad_agrees_on_the_reproducers(tmp_path):
    # the bump: at the worst point FreeCAD's faces are tangent and their normal curvatures jump
    bump = reproducer_file(tmp_path, bump_join(), ".step")
    (edge,) = check_faces(bump).edges
    ((a, b),) = freecad(FREECAD_SCRIPT, bump, [list(edge.jump_at)])
    assert math.acos(min(1.0, float(np.dot(a[:3], b[:3])))) <= 1e-7
    assert abs(a[3] - b[3]) / max(a[3], b[3]) > check_faces(bump).curvature_tol
    assert sorted([a[3], b[3]]) == pytest.approx(sorted(abs(k) for k in edge.curvatures), abs=1e-9)
    # the loft: FreeCAD finds the same edges tangent over part of their length (least angle below the
    # feature angle, largest above), and the others sharp all along
    path = tmp_path / "loft.step"
    bd.export_step(circle_square_circle_loft(), str(path))
    report = check_faces(path)
    judged = [e for e in report.edges if e.level in ("crease", "sharp")]
    for e, (least, most) in zip(judged, freecad(FREECAD_ALONG, path, [list(e.angle_at) for e in judged])):
        assert (least < FEATURE_ANGLE < most) == (e.level == "crease"), (e.index, e.level, least, most)
        assert least > FEATURE_ANGLE or e.level == "crease"
    # the prism: FreeCAD's curvature either side of each knot line of the extruded B-spline differs
    prism = tmp_path / "prism.step"
    bd.export_step(quadratic_prism(), str(prism))
    inside = [e for e in check_faces(prism).edges if e.index == -1]
    assert len(inside) == 3
    for ka, kb in freecad(FREECAD_KNOT, prism, [list(e.jump_at) for e in inside]):
        assert abs(ka - kb) / max(abs(ka), abs(kb)) > 1e-2


#: In FreeCAD: for each point on a knot line u = k of an extruded B-spline, the curvature of the face just
#: before and just after the knot (``Surface.curvature``, the larger principal one, at u = k ∓ 1e-6).
FREECAD_KNOT = textwrap.dedent(
    """
    import json, sys
    sys.path.append(sys.argv[1])
    import FreeCAD, Part
    shape = Part.read(sys.argv[2])
    out = []
    for x, y, z in json.loads(sys.argv[3]):
        p = FreeCAD.Vector(x, y, z)
        vertex = Part.Vertex(p)
        face = min((f for f in shape.Faces if f.Surface.TypeId != "Part::GeomPlane"), key=lambda f: f.distToShape(vertex)[0])
        u, v = face.Surface.parameter(p)
        out.append([face.Surface.curvature(u + h, v, "Max") + face.Surface.curvature(u + h, v, "Min") for h in (-1e-6, 1e-6)])
    print(json.dumps(out))
    """
)


@pytest.mark.parametrize("tilt", [0.0, 1e-13, -1e-13, 1e-9])
def test_faces_meeting_on_a_knot_line_are_read_each_from_its_own_side(tilt):
    # issue 39: a pcurve 1e-13 outside its face's bound, on the knot line where the face ends, read the
    # neighbouring patch (a G1 join reported G2); each face is now evaluated from its own side of the line
    from face_reproducers import knot_line_join
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    shell = knot_line_join(tilt)
    explorer, bounds = TopExp_Explorer(shell, TopAbs_FACE), []
    while explorer.More():
        bounds.append(BRepTools.UVBounds_s(TopoDS.Face_s(explorer.Current())))
        explorer.Next()
    if tilt > 0.0:  # the reproducer is what the issue describes: a face's bounds reach past the knot line
        assert any(0.5 < v1 < 0.5 + 2 * tilt or 0.5 - 2 * tilt < v0 < 0.5 for _, _, v0, v1 in bounds)
    report = check_faces(shell)
    (edge,) = report.edges
    assert edge.level == "G1" and not report.passes("G2")
    assert sorted(abs(k) for k in edge.curvatures) == pytest.approx([0.25, 1.0], rel=1e-6)
    assert edge.gap < 1e-12 and edge.angle < 1e-9


def test_a_pcurve_with_a_shifted_parameter_is_not_a_gap():
    # issue 39: the gap was measured between the two faces' pcurve points, so a pcurve whose parameter is
    # shifted along the edge read as a gap where both surfaces contain the edge; now each face is read at
    # the projection of the edge's 3-D point
    from face_reproducers import knot_line_join

    report = check_faces(knot_line_join(0.0, shift=0.02))
    (edge,) = report.edges
    assert edge.level == "G1" and edge.gap < 1e-12
    assert sorted(abs(k) for k in edge.curvatures) == pytest.approx([0.25, 1.0], rel=1e-6)


def test_the_gap_limit_comes_from_the_edges_tolerances_and_the_file_and_the_table_says_so(tmp_path):
    # the faces are sewn 2e-5 apart: within the tolerance sewing gave their edge, beyond 1e-7 × size
    from face_reproducers import knot_line_join
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    shell = knot_line_join(0.0, apart=2e-5)
    explorer, tolerance = TopExp_Explorer(shell, TopAbs_EDGE), 0.0
    while explorer.More():
        tolerance = max(tolerance, BRep_Tool.Tolerance_s(TopoDS.Edge_s(explorer.Current())))
        explorer.Next()
    (edge,) = check_faces(shell).edges
    assert 1e-5 < edge.gap <= tolerance and edge.level == "G1"
    assert check_faces(shell, gap_tol=1e-7).edges[0].level == "gap"
    report = check_faces(shell)
    assert report.gap_from.startswith("file: no stated uncertainty, twice the edge tolerances") and "(given)" not in report.table()
    # a STEP file states its precision: a coarser one is used, and named
    path = tmp_path / "join.step"
    bd.export_step(bd.Shell(shell), str(path))
    text, count = re.subn(r"UNCERTAINTY_MEASURE_WITH_UNIT\(LENGTH_MEASURE\([^)]*\)", "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.01)",
                          path.read_text())  # fmt: skip
    assert count == 1
    path.write_text(text)
    report = check_faces(path)
    assert "stated uncertainty 0.01" in report.gap_from and "stated uncertainty 0.01" in report.table()
    assert report.gap_tol * report.size == pytest.approx(0.01)
    given = check_faces(path, gap_tol=1e-7)
    assert given.gap_from == "given" and "1e-07 × size (given)" in given.table() and given.edges[0].level == "gap"


def _without_pcurves(shape):
    """``shape`` with every edge's pcurves dropped (a file may leave them out; a plane's OCCT computes itself)."""
    from OCP.BRep import BRep_Builder
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    builder, faces_found = BRep_Builder(), TopExp_Explorer(shape, TopAbs_FACE)
    while faces_found.More():
        face = TopoDS.Face_s(faces_found.Current())
        edges = TopExp_Explorer(face, TopAbs_EDGE)
        while edges.More():
            builder.UpdateEdge(TopoDS.Edge_s(edges.Current()), None, face, 1e-7)
            edges.Next()
        faces_found.Next()
    return shape


@pytest.mark.parametrize("lo", [0.11, 0.47, 0.91])
def test_an_edge_without_pcurves_is_still_sampled_at_the_knots_of_its_faces(lo):
    # issue 39: without pcurves the knot lines crossing the edge were not found (16 floor samples left):
    # a curvature bump between two knots over 2 % of the edge was missed between them
    shell = bump_join(lo, lo + 0.02).wrapped
    with_pcurves = check_faces(shell)
    report = check_faces(_without_pcurves(shell))
    tangent = [e for e in report.edges if e.index >= 0 and e.tangent]
    assert [e.level for e in tangent] == ["G1"] and lo < tangent[0].jump_at[1] < lo + 0.02
    assert report.counts == with_pcurves.counts


@pytest.mark.parametrize(("start", "turn"), [(1.0, 2 * math.pi), (5.0, 4.0), (-7.0, 5.0)])
def test_knot_lines_of_a_periodic_bspline_cylinder_past_one_period_are_g2_never_gaps(start, turn):
    # issue 39: a knot line of the face one period on was evaluated from the spans of another knot:
    # a cylinder read as a 10 mm gap at 60°
    from face_reproducers import periodic_bspline_cylinder

    report = check_faces(periodic_bspline_cylinder(start, turn))
    inside = [e for e in report.edges if e.index == -1]
    # every knot line the face crosses is judged (2π/3 apart), each a circle's curvature on both sides
    assert len(inside) == sum(1 for k in range(-6, 9) if start < k * 2 * math.pi / 3 < start + turn)
    assert inside and all(e.level == "G2" and e.gap < 1e-12 and e.angle < 1e-12 for e in inside)
    assert all(k == pytest.approx(-0.1, rel=1e-9) for e in report.edges for k in e.curvatures)
    assert report.worst == "G2"


def test_a_solid_exported_with_a_loose_wire_beside_it_is_judged(tmp_path):
    # issue 39: the demo's highway_3d.step (the corridor with its centre line) failed with
    # "Standard_NoSuchObject: NCollection_List::First": an edge in no face
    box = filleted_box()
    line = bd.Wire([bd.Edge.make_line((50, 0, 0), (60, 0, 0)), bd.Edge.make_line((60, 0, 0), (60, 10, 5))])
    shape = bd.Compound([box, line])
    path = tmp_path / "with_wire.step"
    bd.export_step(shape, str(path))
    for report in (check_faces(shape), check_faces(path)):
        assert_box_calibration(report)
        assert report.free_edges == 0


@pytest.mark.parametrize("degree", [3, 12])
def test_a_high_degree_periodic_surface_whose_face_crosses_the_seam_is_judged(tmp_path, degree):
    # issue 39: an IGES torus of degree 12 crossing the seam gave "min() arg is an empty sequence"; its
    # seam knot lines (C0 there: the surface turns by 2π/degree through the pole) are now judged
    from face_reproducers import seam_torus

    path = tmp_path / "torus.igs"
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
    writer = IGESControl_Writer("MM", 1)
    writer.AddShape(seam_torus(degree))
    writer.ComputeModel()
    assert writer.Write(str(path))
    # OCCT's IGES round trip may trim the face onto one knot line: the other stays inside it
    for report, knot_lines in ((check_faces(seam_torus(degree)), {2}), (check_faces(path), {1, 2})):
        seams = [e for e in report.edges if e.seam]
        inside = [e for e in report.edges if e.index == -1]
        assert seams and all(e.level == "G2" for e in seams)  # two seams, sewn into one from the IGES file
        assert len(inside) in knot_lines and all(e.level != "gap" and e.gap < 1e-6 for e in report.edges)
        # the kink through the pole: at most 2π/degree between the normals, reached somewhere along the line
        assert all(0.5 * 2 * math.pi / degree < e.angle <= 2 * math.pi / degree + 1e-9 for e in inside)


def test_an_edge_on_a_knot_line_inside_its_faces_bounds_is_read_from_the_faces_side():
    # the hole's lower edge lies on the knot line v = 0.5 inside the bounds of the face with the hole: its
    # side there (below the line) is found by OCCT's classifier, not by its bounds; read from above, the
    # join was G2 (κ 1 against 1)
    from face_reproducers import plug_on_knot_line

    report = check_faces(plug_on_knot_line())
    shared = sorted((e for e in report.edges if e.index >= 0), key=lambda e: e.jump)
    assert [e.level for e in shared] == ["G2", "G2", "G2", "G1"]
    assert shared[-1].curvatures == pytest.approx((0.25, 1.0), rel=1e-6)  # the holed face's, then the plug's
    assert shared[-1].jump_at[1] == pytest.approx(0.5)
