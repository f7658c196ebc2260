"""LandXML out: names XML cannot hold refused by name; a file is replaced only by a complete one."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from spiral_cad.design import Alignment
from spiral_cad.io import read_landxml
from spiral_cad.io.landxml import write_landxml


@pytest.fixture(scope="module")
def road() -> Alignment:
    return Alignment.from_pis([[0, 0], [800, 150], [1500, -100]], [900], spiral_lengths=[90], units="m")


@pytest.mark.parametrize(("name", "code", "position"), [("\ud800", "D800", 0), ("a\x01b", "0001", 1), ("ok\ufffe", "FFFE", 2)])
def test_a_name_xml_cannot_hold_is_refused_and_the_old_file_kept(tmp_path, road, name, code, position):
    # the tester's r10_name.py: a lone surrogate left victim.xml at 0 bytes; "\x01" gave a file no XML parser reads
    victim = tmp_path / "victim.xml"
    write_landxml(road, victim, name="good")
    before = victim.read_bytes()
    with pytest.raises(
        ValueError, match=rf"the collection name .*: the character U\+{code} at position {position} cannot be written in XML"
    ):
        write_landxml(road, victim, name=name)
    assert victim.read_bytes() == before and sorted(os.listdir(tmp_path)) == ["victim.xml"]


def test_a_written_file_replaces_the_old_one_whole_and_reads_back(tmp_path, road):
    path = tmp_path / "road.xml"
    path.write_text("old", encoding="utf-8")
    write_landxml(road, path, name="tab\there & <there> é")
    ET.parse(path)  # well-formed
    (back,) = read_landxml(path)
    assert back.name == "tab\there & <there> é" and sorted(os.listdir(tmp_path)) == ["road.xml"]
    plain = tmp_path / "plain"
    plain.write_text("", encoding="utf-8")  # the mode an ordinary new file gets here, not mkstemp's private 0600
    assert path.stat().st_mode & 0o777 == plain.stat().st_mode & 0o777


def test_a_cubic_with_an_inflection_is_refused_not_written_as_a_spiral(tmp_path):
    # the tester's scurve.ngc: G5 I3 J3 P-3 Q-3 X10 Y0, curvature −0.26 → +0.26, was written as one "Spiral"
    from spiral_cad.core.chain import Chain
    from spiral_cad.core.spiral import BezierSpiral

    s_curve = BezierSpiral.from_control_points(np.array([[0.0, 0.0], [3.0, 3.0], [7.0, -3.0], [10.0, 0.0]]))
    path = tmp_path / "s.xml"
    with pytest.raises(ValueError, match=r"segment 0 \(a cubic\) is not a spiral: its curvature changes sign \(-0.388485 to 0.388485 1/mm: an inflection"):
        write_landxml(Chain([s_curve], units="mm"), path, name="s")
    assert not path.exists()
