"""LandXML through the design-file build: the demo writes highway.xml, and ``spiral-cad build FILE.xml``."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xmlschema

from spiral_cad.app.cli import DEMO_DESIGN, main
from spiral_cad.app.designfile import build, build_landxml
from spiral_cad.io import read_landxml

DATA = Path(__file__).parent.parent / "data" / "landxml"


def test_demo_writes_a_valid_highway_xml_that_reads_back(tmp_path):
    assert main(["demo", "--out", str(tmp_path), "--no-plots"]) == 0
    path = tmp_path / "highway.xml"
    xmlschema.XMLSchema(str(DATA / "LandXML-1.2.xsd")).validate(str(path))
    (highway, *_) = build(DEMO_DESIGN)[1]
    (read,) = read_landxml(path)
    s = np.linspace(0.0, highway.chain.length, 3001)
    assert np.abs(read.chain.point_at(s) - highway.chain.point_at(s)).max() < 1e-9 * highway.chain.length
    assert read.start_station == highway.source.start_station
    stations = np.linspace(highway.profile.start, highway.profile.end, 700)
    assert np.abs(read.profile.elevation(stations) - highway.profile.elevation(stations)).max() < 1e-9


def test_build_of_a_landxml_file_writes_every_output(tmp_path, capsys):
    assert main(["build", str(DATA / "civil3d_spiral_r63.xml"), "--out", str(tmp_path), "--no-plots"]) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert {"spiral_R63.step", "spiral_R63.svg", "spiral_R63.xodr", "spiral_R63_landxml.txt"} <= names
    report = (tmp_path / "spiral_R63_landxml.txt").read_text()
    assert "largest offset from the file 1.65 m" in report and "Spiral" in report
    assert "station shift at the end" in report and "length change  rebuilt by" in report and report.rstrip().endswith("length")
    assert "LandXML alignment" in capsys.readouterr().out


def test_build_of_a_landxml_file_it_cannot_represent_names_the_element(tmp_path, capsys):
    assert main(["build", str(DATA / "sdms_mntnroad_alignpis.xml"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "alignment 'MntnRoad': no CoordGeom" in err and "Traceback" not in err


def _alignments(*pairs: tuple[str, float]) -> str:
    """A LandXML document of one line per alignment: (name, length)."""
    body = "".join(f'<Alignment name="{name}"><CoordGeom><Line><Start>0 0</Start><End>0 {length!r}</End></Line></CoordGeom></Alignment>'
                   for name, length in pairs)  # fmt: skip
    return ('<?xml version="1.0" encoding="UTF-8"?><LandXML xmlns="http://www.landxml.org/schema/LandXML-1.2" version="1.2">'
            f'<Units><Metric linearUnit="meter"/></Units><Alignments>{body}</Alignments></LandXML>')  # fmt: skip


def test_alignments_of_one_name_are_built_under_unique_names_and_told(tmp_path, capsys):
    # the tester's dup_same.xml: two alignments named "D" (100 m and 50 m); D.xodr held only the second
    path = tmp_path / "dup_same.xml"
    path.write_text(_alignments(("D", 100.0), ("D", 50.0)), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["build", str(path), "--out", str(out), "--no-plots"]) == 0
    lengths = {name: float(re.search(r'<road [^>]*length="([^"]+)"', (out / f"{name}.xodr").read_text()).group(1)) for name in ("D", "D_2")}
    assert lengths == pytest.approx({"D": 100.0, "D_2": 50.0})
    told = "alignment 'D' (number 2) written as 'D_2': 'D' names the outputs of alignment 'D'"
    assert told in capsys.readouterr().out and told in (out / "D_2_landxml.txt").read_text()


@pytest.mark.parametrize(("names", "expected", "renamed"), [
    (["X Y", "X_Y", "x_y"], ["X_Y", "X_Y_2", "x_y_3"], [False, True, True]),  # equal once sanitised, or but for case
    (["a" * 60 + "1", "a" * 60 + "2"], ["a" * 56, "a" * 56 + "_2"], [False, True]),  # equal in their first 56 characters
    (["R", "R_2", "R"], ["R", "R_2", "R_3"], [False, False, True]),  # a suffix never takes another alignment's name
])  # fmt: skip
def test_output_names_never_collide(tmp_path, names, expected, renamed):
    path = tmp_path / "names.xml"
    path.write_text(_alignments(*((name, 10.0 + k) for k, name in enumerate(names))), encoding="utf-8")
    built = build_landxml(path)[1]
    assert [b.name for b in built] == expected and [bool(b.renamed) for b in built] == renamed
    assert [b.chain.length for b in built] == pytest.approx([10.0 + k for k in range(len(names))])


def test_build_refuses_a_file_whose_direction_convention_cannot_be_told(tmp_path, capsys):
    path = tmp_path / "dir_only.xml"
    path.write_text(_alignments(("L", 10.0)).replace("<Line><Start>0 0</Start><End>0 10.0</End></Line>",
                                                     '<Line dir="30" length="10"><Start>0 0</Start></Line>'), encoding="utf-8")  # fmt: skip
    assert main(["build", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "CoordGeom element 0 (Line) at station 0: the element is placed only by its dir" in err
    assert "Traceback" not in err
    assert main(["build", str(path), "--out", str(tmp_path / "out"), "--no-plots", "--directions", "north-cw"]) == 0
    assert "north-cw" not in capsys.readouterr().err


def test_the_build_states_each_alignments_largest_offset_and_refuses_beyond_max_offset(tmp_path, capsys):
    source = str(DATA / "civil3d_spiral_r63.xml")  # one clothoid R 63 m → straight over 100 m, 1.65 m from any cubic
    assert main(["build", source, "--out", str(tmp_path / "a"), "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "spiral_R63: warning: largest offset from the file's alignment 'spiral R63': element 0 (Spiral) at station 0: 1.65 m (1.65% of its length)" in out  # fmt: skip
    assert main(["build", source, "--out", str(tmp_path / "b"), "--max-offset", "0.5"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "element 0 (Spiral) at station 0: ours lies 1.65 m from the file's element, more than max_offset 0.5" in err and "--max-offset inf" in err  # fmt: skip
    assert not (tmp_path / "b").exists()
    assert main(["build", str(DATA / "sdms_mntnroad_alignpis.xml").replace(".xml", ".json"), "--max-offset", "1"]) == 2
    assert "--max-offset: only with a LandXML file" in capsys.readouterr().err
    assert main(["build", str(DATA / "x.json"), "--directions", "north-cw"]) == 2
    assert "--directions: only with a LandXML file" in capsys.readouterr().err


def test_the_build_of_public_exports_keeps_every_element(tmp_path, capsys):
    """Civil 3D 2023 (lines and arcs, two arcs of one centre) once lost a 391 ft arc and a 72 ft line with
    --max-offset inf; Civil 3D 2020's asymmetric S was cut into three designs by 3e-4 rad kinks."""
    source = DATA / "civil3d2023_main_road_lines_arcs.xml"
    assert main(["build", str(source), "--out", str(tmp_path / "c3d"), "--no-plots", "--max-offset", "inf"]) == 0
    reports = sorted((tmp_path / "c3d").glob("*_landxml.txt"))
    rows = {int(m.group(1)) for r in reports for m in re.finditer(r"^\s+(\d+)  (?:Line|Curve)", r.read_text(), re.M)}
    assert rows == set(range(8))  # every element of the file in the report
    assert all("Curve" in r.read_text() or "Line" in r.read_text() for r in reports)
    assert main(["build", str(DATA / "civil3d2020_a_kolu_asymmetric_s.xml"), "--out", str(tmp_path / "kolu"), "--no-plots"]) == 0
    (report,) = (tmp_path / "kolu").glob("*_landxml.txt")  # one design
    text = report.read_text()
    assert text.count("note: joint at station") == 3 and "break:" not in text
    capsys.readouterr()
