"""LandXML through the design-file build: the demo writes highway.xml, and ``spiral-cad build FILE.xml``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xmlschema

from spiral_cad.app.cli import DEMO_DESIGN, main
from spiral_cad.app.designfile import build
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
