"""``spiral-cad check`` on files that hold faces: verdicts on solids build123d and OCCT wrote,
sharp features listed and not failed, and the zebra and curvature pictures."""

from __future__ import annotations

import pytest

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.image import imread  # noqa: E402
from OCP.IGESControl import IGESControl_Writer  # noqa: E402
from OCP.Interface import Interface_Static  # noqa: E402

from spiral_cad.app.cli import main  # noqa: E402
from spiral_cad.build123d import ContinuousRectangle  # noqa: E402
from spiral_cad.cad.faces import holds_faces  # noqa: E402


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A box with circular vertical fillets (G1), an extruded continuous rectangle (G2), as STEP and IGES."""
    folder = tmp_path_factory.mktemp("faces")
    parts = {"box": bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 5),
             "slab": bd.extrude(ContinuousRectangle(40, 20, 5), 8)}  # fmt: skip
    out = {}
    for name, part in parts.items():
        out[name] = folder / f"{name}.step"
        bd.export_step(part, str(out[name]))
        Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
        writer = IGESControl_Writer("MM", 1)
        writer.AddShape(part.wrapped)
        writer.ComputeModel()
        out[f"{name}_iges"] = folder / f"{name}.igs"
        assert writer.Write(str(out[f"{name}_iges"]))
    return out


@pytest.mark.parametrize("suffix", ["", "_iges"])
def test_check_judges_faces_g1_box_fails_g2_and_passes_g1(files, capsys, suffix):
    assert main(["check", str(files["box" + suffix]), "--require", "G2"]) == 1
    text = capsys.readouterr().out
    assert "10 faces, 24 shared edges (8 G1, 16 sharp); worst tangent edge G1" in text
    assert "FAIL: worst tangent edge is G1, below the required G2" in text
    assert main(["check", str(files["box" + suffix]), "--require", "G1", "--timing"]) == 0
    text = capsys.readouterr().out
    assert "OK: 10 faces" in text and "for 10 faces and 24 edges, reading included" in text


@pytest.mark.parametrize("suffix", ["", "_iges"])
def test_check_passes_the_continuous_slab_g2_with_its_sharp_edges_listed(files, capsys, suffix):
    assert main(["check", str(files["slab" + suffix]), "--require", "G2"]) == 0
    text = capsys.readouterr().out
    assert "(16 G2, 32 sharp)" in text and "OK: 18 faces" in text
    assert "separate pieces" not in text  # the face boundary wires are no longer judged as paths


def test_tolerances_and_feature_angle_reach_the_face_check(files, capsys):
    # a jump of 1 within a curvature tolerance of 2 is G2
    assert main(["check", str(files["box"]), "--require", "G2", "--curvature-tol", "2"]) == 0
    assert "curvature jump 2 relative" in capsys.readouterr().out
    # with the feature angle above a right angle, the box's right-angled edges are creases: defects
    assert main(["check", str(files["box"]), "--require", "G1", "--feature-angle", "2"]) == 1
    assert "(16 crease, 8 G1)" in capsys.readouterr().out
    assert main(["check", str(files["box"]), "--feature-angle", "4"]) == 2
    assert "error: feature_angle must be" in capsys.readouterr().err


def test_wire_files_are_still_judged_joint_by_joint(tmp_path, capsys):
    path = tmp_path / "wire.step"
    bd.export_step(bd.Polyline((0, 0), (10, 0), (10, 10)), str(path))
    assert main(["check", str(path)]) == 0
    assert "worst joint G0" in capsys.readouterr().out
    assert main(["check", str(path), "--zebra", str(tmp_path / "z.png")]) == 2
    assert "holds none" in capsys.readouterr().err


def _picture(path):
    return imread(str(path))[..., :3]


def test_zebra_and_curvature_pictures_are_written_and_tell_g1_from_g2(files, tmp_path, capsys):
    pictures = {}
    for name in ("box", "slab"):
        zebra, curvature = tmp_path / f"{name}_zebra.png", tmp_path / f"{name}_curvature.png"
        assert main(["check", str(files[name]), "--zebra", str(zebra), "--curvature-map", str(curvature)]) == 0
        pictures[name] = _picture(zebra)
        assert _picture(curvature).std() > 0.05  # not blank
    assert f"zebra stripes written to {tmp_path / 'slab_zebra.png'}" in capsys.readouterr().out
    box, slab = pictures["box"], pictures["slab"]
    dark = [(p < 0.2).all(axis=2).mean() for p in (box, slab)]
    assert min(dark) > 0.02 and box.std() > 0.1  # stripes drawn, not a blank page
    rows, columns = min(box.shape[0], slab.shape[0]), min(box.shape[1], slab.shape[1])  # each picture sized by its part
    assert np.abs(box[:rows, :columns] - slab[:rows, :columns]).mean() > 0.01  # G1 and G2 stripes differ


def test_picture_options_size_and_aim_the_pictures_and_are_refused_by_name(files, tmp_path, capsys):
    zebra = tmp_path / "z.png"
    argv = ["check", str(files["box"]), "--zebra", str(zebra)]
    assert main([*argv, "--pixels", "300", "--stripes", "40", "--view", "0,-1,0.3"]) == 0
    assert 280 <= max(_picture(zebra).shape[:2]) <= 320  # the picture pixel for pixel
    capsys.readouterr()
    for extra, named in ((["--stripes", "0"], "stripes must be an integer from 1 to 200; got 0"),
                         (["--pixels", "9"], "pixels must be an integer from 16 to 8000; got 9"),
                         (["--view", "1,2"], "--view must be three numbers"), (["--view", "0,0,0"], "--view must be three numbers")):  # fmt: skip
        assert main([*argv, *extra]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: ") and named in err, err
    assert main(["check", str(files["box"]), "--stripes", "30"]) == 2
    assert "--stripes: only with --zebra or --curvature-map" in capsys.readouterr().err


def test_bad_picture_paths_are_errors_not_tracebacks(files, tmp_path, capsys):
    assert main(["check", str(files["box"]), "--zebra", str(tmp_path / "z.jpg")]) == 2
    assert "give a .png file" in capsys.readouterr().err
    assert main(["check", str(files["box"]), "--curvature-map", str(tmp_path / "no" / "c.png")]) == 2
    assert "error: --curvature-map" in capsys.readouterr().err


def test_comb_of_a_face_file_is_written_beside_the_face_verdict(files, tmp_path, capsys):
    comb = tmp_path / "comb.step"
    assert main(["check", str(files["box"]), "--require", "G1", "--comb", str(comb)]) == 0
    assert "OK: 10 faces" in capsys.readouterr().out
    assert comb.stat().st_size > 1000 and not holds_faces(comb)  # the comb is lines only


def test_faces_that_meet_nowhere_fail_a_requirement_with_nothing_judged(tmp_path, capsys):
    path = tmp_path / "apart.step"
    bd.export_step(bd.Compound([bd.Face.make_rect(10, 10), bd.Face.make_rect(10, 10).moved(bd.Location((50, 0, 0)))]), str(path))
    assert main(["check", str(path), "--require", "G1"]) == 1
    out = capsys.readouterr().out
    assert "FAIL: no shared edges were judged" in out and "free edges that no other face could be sewn to (8)" in out


def test_loose_faces_in_a_file_are_sewn_and_judged(tmp_path, capsys):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy

    box = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 5)
    path = tmp_path / "loose.step"
    bd.export_step(bd.Compound([bd.Face(BRepBuilderAPI_Copy(f.wrapped).Shape()) for f in box.faces()]), str(path))
    assert main(["check", str(path), "--require", "G2"]) == 1
    out = capsys.readouterr().out
    assert "24 stitched" in out and "8 G1" in out and "FAIL: worst tangent edge is G1" in out


def test_a_picture_that_cannot_be_written_is_named(files, tmp_path, capsys, monkeypatch):
    from matplotlib.figure import Figure

    def full(self, *args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    assert main(["check", str(files["box"]), "--zebra", str(tmp_path / "z.png")]) == 2
    err = capsys.readouterr().err
    assert "cannot write the zebra stripes to" in err and "z.png" in err and "No space left on device" in err


def test_a_failure_while_meshing_is_named_meshing_not_reading(files, monkeypatch):
    from spiral_cad.cad import mesh

    def timed_out(*args, **kwargs):
        raise ValueError("the STEP reader failed on 'box.step': it timed out after 120 s")

    monkeypatch.setattr(mesh, "read_file", timed_out)
    with pytest.raises(ValueError, match=r"^meshing for the picture: reading and meshing failed on 'box.step': it timed out"):
        mesh.face_mesh(files["box"])


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_check_fails_g2_on_a_curvature_jump_over_five_percent_of_an_edge(tmp_path, capsys, suffix):
    from face_reproducers import bump_join

    path = tmp_path / f"bump{suffix}"
    if suffix == ".step":
        bd.export_step(bump_join(), str(path))
    else:
        Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
        writer = IGESControl_Writer("MM", 1)
        writer.AddShape(bump_join().wrapped)
        writer.ComputeModel()
        assert writer.Write(str(path))
    assert main(["check", str(path), "--require", "G2"]) == 1
    assert "FAIL: worst tangent edge is G1, below the required G2" in capsys.readouterr().out
    assert main(["check", str(path), "--require", "G1"]) == 0


def test_a_step_file_whose_length_unit_is_a_second_is_refused_by_name(files, tmp_path, capsys):
    # issue 39: read as metres, exit 0
    text = files["box"].read_text()
    length = "( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )"
    assert text.count(length) == 1
    path = tmp_path / "second.step"
    path.write_text(text.replace(length, "( NAMED_UNIT(*) SI_UNIT($,.SECOND.) TIME_UNIT() )"))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "second (time unit)" in err and "no length" in err and "Traceback" not in err
    assert main(["check", str(files["box"])]) == 0  # the same file with its length unit is read


def test_the_table_says_where_the_gap_limit_came_from(files, capsys):
    assert main(["check", str(files["box"])]) == 0
    out = capsys.readouterr().out
    assert "gap from the file: stated uncertainty" in out
    assert main(["check", str(files["box"]), "--gap-tol", "1e-6"]) == 0
    assert "gap 1e-06 × size (given)" in capsys.readouterr().out


def test_a_lone_face_is_judged_by_its_boundary_as_a_curve_chain(tmp_path, capsys):
    # issue 39: one face shares no edge, so "nothing shows G2"; its boundary is the curve chain to judge
    smooth, square = tmp_path / "smooth.step", tmp_path / "square.step"
    bd.export_step(bd.Face(ContinuousRectangle(40, 20, 5).wire()), str(smooth))
    bd.export_step(bd.Face.make_rect(10, 10), str(square))
    assert main(["check", str(smooth), "--require", "G2"]) == 0
    out = capsys.readouterr().out
    assert "its boundary is judged as the curve chain it is" in out and "1 wire of 16 edges" in out
    assert out.rstrip().endswith("every joint at least G2")
    assert main(["check", str(square), "--require", "G1"]) == 1  # a square's corners are G0
    assert "1 wire of 4 edges" in capsys.readouterr().out


def test_a_surface_only_step_file_is_judged_face_to_face(tmp_path, capsys):
    # issue 39: B-spline surfaces in a geometric set, no face entity: judged as wires, worst joint G0
    from face_reproducers import tangent_patches_step

    path = tmp_path / "surfaces.step"
    path.write_text(tangent_patches_step())
    assert holds_faces(path)
    assert main(["check", str(path), "--require", "G2"]) == 1
    out = capsys.readouterr().out
    assert "2 faces, 1 shared edges (1 G1)" in out and "wire" not in out
    assert main(["check", str(path), "--require", "G1"]) == 0
