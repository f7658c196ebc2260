"""G2 paths in space in CAD: G2Polyline, g2_fillet of 3-D wires, CadQuery g2Polyline, sweeps and 3-D files."""

import math

import numpy as np
import pytest

pytest.importorskip("build123d")

from build123d import BuildLine, BuildPart, BuildSketch, Circle, GeomType, Plane, Polyline, Vector, Wire, sweep

from spiral_cad import NoSolutionError
from spiral_cad.build123d import G2Polyline, g2_fillet
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.export import export_dxf, export_iges, export_samples, export_step, export_svg
from spiral_cad.design import fillet_polyline, round_corners

RUN = [(0, 0, 0), (100, 0, 0), (100, 80, 30), (0, 80, 60), (0, 0, 90)]


def edge_types(wire):
    return [e.geom_type for e in wire.edges()]


def test_g2polyline_is_a_g2_wire_of_lines_and_bezier_pairs_on_the_builders_plane():
    with BuildLine(Plane.XZ) as line:
        made = G2Polyline(*RUN, radius=15)
    placed = line.line  # on Plane.XZ: local (x, y, z) at world x·X + y·Y + z·Z of the plane, as Polyline's
    assert sorted(t.name for t in edge_types(placed)) == sorted(["LINE"] * 4 + ["BEZIER"] * 6)
    report = check_continuity(placed)
    assert report.passes("G2") and report.pieces == 1
    ends = [Vector(v) for v in placed.vertices()]
    for point in (RUN[0], RUN[-1]):
        assert min((v - Plane.XZ.from_local_coords(Vector(point))).length for v in ends) <= 1e-9
    assert made.rounded.max_curvature == pytest.approx(1 / 15, rel=1e-12)
    within = G2Polyline(RUN, max_deviation=2.0)  # a list of points works as for Polyline
    assert within.rounded.max_deviation <= 2.0 and within.rounded.max_deviation == pytest.approx(2.0, rel=1e-9)


def test_g2polyline_refuses_bad_input_by_name():
    with pytest.raises(ValueError, match="radius must be positive"):
        G2Polyline(*RUN, radius=-1)
    with pytest.raises(NoSolutionError, match="corner 1"):
        G2Polyline(*RUN, radius=0.001, max_deviation=1e-6)
    with pytest.raises(ValueError, match=r"\(n ≥ 3"):
        G2Polyline((0, 0, 0), (1, 1, 1))


def test_a_handrail_swept_with_a_circle_is_a_valid_solid():
    with BuildPart() as rail:
        with BuildLine() as path:
            G2Polyline(*RUN, radius=15)
        with BuildSketch(Plane(origin=path.wire() @ 0, z_dir=path.wire() % 0)):
            Circle(4)
        sweep(path=path.wire())
    assert rail.part.is_valid
    expected = math.pi * 16 * round_corners(RUN, max_curvature=1 / 15).chain.length  # Pappus: area × path length
    assert rail.part.volume == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("closed", [False, True])
def test_g2_fillet_of_a_3d_wire_of_lines_rounds_each_corner_in_its_plane(closed):
    wire = Polyline(*RUN, close=closed)
    rounded = g2_fillet(wire, 10)
    assert isinstance(rounded, Wire) and rounded.is_closed == closed
    report = check_continuity(rounded)
    assert report.passes("G2") and report.pieces == 1
    corners = 5 if closed else 3
    assert edge_types(rounded).count(GeomType.CIRCLE) == corners and edge_types(rounded).count(GeomType.BEZIER) == 2 * corners
    # each corner's fillet is the plane fillet of that corner: same radius, in the plane of its edges
    path = fillet_polyline(RUN, 10, closed=closed)
    for corner in path.corners:
        assert corner.fillet.radius == pytest.approx(math.copysign(10, corner.fillet.turn))
        n = np.asarray(corner.frame.normal)
        for segment, owner in zip(path.segments, path.owners):
            if owner == corner.vertex:
                pts = segment.point(np.linspace(0, 1, 9))
                assert np.abs((pts - np.asarray(RUN[corner.vertex], dtype=float)) @ n).max() <= 1e-12 * 200
    chosen = g2_fillet(wire, 10, vertices=[v for v in wire.vertices() if Vector(v) == Vector(RUN[2])])
    assert edge_types(chosen).count(GeomType.CIRCLE) == 1


def test_g2_fillet_in_space_names_the_corner_that_does_not_fit():
    with pytest.raises(NoSolutionError, match=r"corner 1 at \(100, 0, 0\): .*edge 0"):
        g2_fillet(Polyline(*RUN), 80)


def test_cadquery_g2polyline_sweeps_into_a_valid_tube():
    cq = pytest.importorskip("cadquery")
    import spiral_cad.cadquery  # noqa: F401

    path = cq.Workplane("XY", origin=(0, 0, 5)).g2Polyline(RUN, max_deviation=3.0, shape="near-linear")
    wire = path.val()
    assert check_continuity(wire).passes("G2")
    start = wire.startPoint()
    tube = cq.Workplane(cq.Plane(origin=start, xDir=(0, 0, 1), normal=wire.tangentAt(0))).circle(3).sweep(path)
    assert tube.val().isValid()
    assert (wire.endPoint() - cq.Vector(0, 0, 95)).Length <= 1e-9


def test_files_in_space_read_back_as_g2_paths(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    chain = fillet_polyline(RUN, 10).chain  # lines, arcs in space and spirals
    for name, write in (("run.step", export_step), ("run.igs", export_iges)):
        write(chain, tmp_path / name)
        report = check_continuity(tmp_path / name, units="mm")
        assert report.passes("G2") and report.pieces == 1, report.describe()
    export_dxf(chain, tmp_path / "run.dxf")
    doc = ezdxf.readfile(tmp_path / "run.dxf")
    entities = list(doc.modelspace())
    assert [e.dxftype() for e in entities] == [type(s).__name__.replace("BezierSpiral", "SPLINE").upper() for s in chain]
    for segment, entity in zip(chain, entities):  # every entity where the segment is, read by ezdxf
        if entity.dxftype() == "ARC":
            ends = [entity.start_point, entity.end_point]
            want = [segment.point(0.0), segment.point(1.0)]
            assert all(np.allclose(tuple(a), b, atol=1e-9) for a, b in zip(ends, want))
        elif entity.dxftype() == "SPLINE":
            assert np.array_equal(np.array(entity.control_points), segment.control_points)
    low, high = doc.header["$EXTMIN"], doc.header["$EXTMAX"]
    assert low[2] == 0.0 and high[2] == pytest.approx(90.0)
    with pytest.raises(ValueError, match="SVG is a plane format"):
        export_svg(chain, tmp_path / "run.svg")


def test_samples_for_machines(tmp_path):
    chain = round_corners(RUN, max_deviation=2.0).chain
    count = export_samples(chain, tmp_path / "run.csv", chord_tolerance=0.01)
    lines = (tmp_path / "run.csv").read_text().splitlines()
    assert lines[0] == "s [mm],x [mm],y [mm],z [mm],tx [1],ty [1],tz [1],curvature [1/mm]"
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    assert len(table) == count and table[0, 0] == 0.0 and table[-1, 0] == pytest.approx(chain.length)
    assert np.all(np.diff(table[:, 0]) > 0)
    assert np.allclose(table[:, 1:4], chain.point_at(table[:, 0]), atol=1e-12 * chain.size)
    assert np.allclose(np.linalg.norm(table[:, 4:7], axis=1), 1.0)
    # the path between neighbours strays at most 0.01 from their chord (measured densely here)
    for s0, s1, *_ in zip(table[:-1, 0], table[1:, 0]):
        s = np.linspace(s0, s1, 33)
        p, a, b = chain.point_at(s), chain.point_at(s0), chain.point_at(s1)
        t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
        assert np.linalg.norm(p - a - t[:, None] * (b - a), axis=1).max() <= 0.01
    assert export_samples(chain, tmp_path / "step.csv", step=5.0) >= chain.length / 5.0
    for bad, match in (({"step": -1}, "step must be a positive"), ({}, "give step or chord_tolerance"),
                       ({"step": 1e-9}, "samples"), ({"step": 1.0, "chord_tolerance": 1.0}, "one of them")):  # fmt: skip
        with pytest.raises(ValueError, match=match):
            export_samples(chain, tmp_path / "bad.csv", **bad)


def test_samples_of_a_plane_chain_with_arcs_carry_signed_curvature(tmp_path):
    from spiral_cad.design import Alignment
    from spiral_cad.io.samples import sample_path

    chain = Alignment.from_pis([(0, 0), (300, 60), (560, -40), (820, 90)], radii=[220, 260], spiral_angles=0.12, units="m").chain
    for options in ({"step": 2.0}, {"chord_tolerance": 0.001}):
        table = sample_path(chain, **options)
        assert np.all(table[:, 3] == 0.0) and np.all(table[:, 6] == 0.0)
        assert np.allclose(table[:, 1:3], chain.point_at(table[:, 0]), atol=1e-9)
        assert np.allclose(table[:, 7], chain.curvature_at(table[:, 0]), atol=1e-12)
        assert table[:, 7].min() < 0 < table[:, 7].max()  # turns both ways
        if "step" in options:
            assert np.diff(table[:, 0]).max() <= 2.0
    assert export_samples(chain, tmp_path / "a.csv", step=2.0) == len(sample_path(chain, step=2.0))
    assert (tmp_path / "a.csv").read_text().splitlines()[0].startswith("s [m],x [m]")


def test_the_checker_reports_where_a_path_in_space_changes_plane(tmp_path):
    path = round_corners(RUN, max_deviation=2.0)
    export_step(path.chain, tmp_path / "run.step")
    report = check_continuity(tmp_path / "run.step")
    assert report.passes("G2")
    joints = report.wires[0].joints
    # independently: the corners' planes, and the angle between consecutive ones
    pts = np.array(RUN, dtype=float)
    normals = [np.cross(b - a, c - b) / np.linalg.norm(np.cross(b - a, c - b)) for a, b, c in zip(pts, pts[1:], pts[2:])]
    expected = [math.acos(min(1.0, abs(m @ n))) for m, n in zip(normals, normals[1:])]
    # segments: line, pair, line, pair, line, pair, line: the twists show where each next pair begins (joints 3 and 6)
    assert math.isnan(joints[0].plane_change)  # the path starts straight: no plane before it
    assert [j.index for j in joints if j.plane_change > 1e-9] == [3, 6]
    assert [joints[3].plane_change, joints[6].plane_change] == pytest.approx(expected, abs=1e-12)
    assert all(j.plane_change <= 1e-12 for j in joints[1:] if j.index not in (3, 6))
    text = report.format_table()
    assert f"largest plane change {math.degrees(max(expected)):.4g}° at joint" in text and "plane°" in text
    flat = round_corners([p[:2] for p in RUN], max_deviation=2.0).chain  # in the plane: no plane change anywhere
    assert all(j.plane_change <= 1e-12 for j in check_continuity(flat).wires[0].joints[1:])
