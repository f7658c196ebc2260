"""A LandXML file rewritten G2 in place (spiral_cad.io.landxml_g2): the LandXML 1.2 XSD (xmlschema) judges the
file, our reader reads it back onto the G2 chain, and everything but the rewritten CoordGeom is the input's."""

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import xmlschema

from spiral_cad.design import make_g2
from spiral_cad.io import read_landxml
from spiral_cad.io.landxml_g2 import rewrite_landxml_g2

DATA = Path(__file__).resolve().parents[1] / "data" / "landxml"


@pytest.fixture(scope="module")
def schema():
    return xmlschema.XMLSchema(str(DATA / "LandXML-1.2.xsd"))


def local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def without_coordgeom(path: Path, skip=("CoordGeom",)) -> list[str]:
    """The document as canonical text of every element outside the CoordGeoms (and the alignments' own
    ``length``, which the rewrite updates)."""
    root = ET.parse(path).getroot()
    out = []
    for parent in root.iter():
        for child in list(parent):
            if local(child.tag) in skip:
                parent.remove(child)
    for a in root.iter():
        if local(a.tag) == "Alignment":
            a.attrib.pop("length", None)
    for e in root.iter():
        e.text = (e.text or "").strip()
        e.tail = (e.tail or "").strip()
    out.append(ET.tostring(root, encoding="unicode"))
    return out


def points(chain, count: int = 9) -> np.ndarray:
    u = np.linspace(0.0, 1.0, count)
    return np.vstack([np.atleast_2d(s.point(u)) for s in chain])


@pytest.mark.parametrize("name, valid", [("openroads_indot_twin_branch.xml", True), ("civil3d_gsg_basic_road.xml", False)])
def test_an_alignment_of_lines_and_arcs_comes_back_g2_in_the_same_file(tmp_path, schema, name, valid):
    source, target = DATA / name, tmp_path / name
    report = rewrite_landxml_g2(source, target, 0.01)
    (path,) = report.paths
    assert path.made and 0.0 < path.deviation <= 0.01 * (1 + 1e-9) and path.changed == path.joints > 0
    # the XSD: the output is valid where the input is, and has no error the input has not
    before, after = ({e.reason for e in schema.iter_errors(str(f))} for f in (source, target))
    assert after <= before and (not valid or not after)
    # everything outside the CoordGeom is the input's (the profile, units, application, attributes, names)
    assert without_coordgeom(target) == without_coordgeom(source)
    # our reader reads it back as one G2 chain of lines, arcs and spirals, onto the G2 chain make_g2 makes
    (old,) = read_landxml(source)
    (new,) = read_landxml(target)
    assert new.name == old.name and len(new.chains) == 1 and new.kinds.count("Spiral") == path.joints
    g2 = make_g2([s for c in old.chains for s in c], 0.01, closed=False, units=old.units).chain
    size = float(np.abs(points(g2)).max())
    assert len(new.chain) == len(g2)
    assert float(np.abs(points(new.chain) - points(g2)).max()) <= 1e-9 * max(size, 1.0) * 10
    for a, b in zip(list(new.chain)[:-1], list(new.chain)[1:]):  # every joint G2 as read back
        t0, t1 = a.end_tangent, b.start_tangent
        assert abs(math.atan2(t0[0] * t1[1] - t0[1] * t1[0], float(np.dot(t0, t1)))) <= 1e-6
        k0, k1 = a.end_curvature, b.start_curvature
        scale = max(abs(k) for k in (a.start_curvature, a.end_curvature, b.start_curvature, b.end_curvature))
        assert abs(k0 - k1) <= 1e-5 * scale  # relative to the curvature of the two pieces
    # stations: each element starts where the one before ends, from the alignment's own staStart
    assert new.start_station == old.start_station
    assert np.allclose(new.stations, new.start_station + np.concatenate([[0.0], np.cumsum(new.chain.lengths)[:-1]]), rtol=1e-12)
    assert float(ET.parse(target).getroot().find(".//{*}Alignment").get("length")) == pytest.approx(new.chain.length / _scale(new))


def _scale(alignment) -> float:
    return 1.0 if alignment.name != "PR_Twin_Branch_section" else (1200 / 3937) / 0.3048


@pytest.mark.parametrize("name", ["mdt_aplitop_alignment2.xml", "civil3d2020_a_kolu_asymmetric_s.xml", "novapoint_toi_y3.xml"])
def test_an_alignment_that_is_g2_already_is_kept_as_it_was(tmp_path, name):
    report = rewrite_landxml_g2(DATA / name, tmp_path / name, 0.01)
    assert all(p.kept.startswith("G2 already") for p in report.paths) and not report.below_g2
    assert without_coordgeom(tmp_path / name, ()) == without_coordgeom(DATA / name, ())
    assert report.lines()[-1].startswith(f"0 of {len(report.paths)} path(s) made G2")


def test_an_alignment_make_g2_refuses_is_kept_and_the_reason_given(tmp_path):
    report = rewrite_landxml_g2(DATA / "freecad_sugar_grove_pi_curves.xml", tmp_path / "out.xml", 0.01)
    sugar = next(p for p in report.paths if p.name == "Sugar Grove Road")
    assert "do not meet" in sugar.kept and "848 apart" in sugar.kept
    assert report.below_g2 == (sugar,)
    assert without_coordgeom(tmp_path / "out.xml", ()) == without_coordgeom(DATA / "freecad_sugar_grove_pi_curves.xml", ())


def test_directions_are_written_as_the_file_counts_them(tmp_path):
    """A north-clockwise file in grads: the rewritten Lines' directions read back onto their own points."""
    text = (DATA / "civil3d_gsg_basic_road.xml").read_text()
    root = ET.fromstring(text)
    imperial = root.find(".//{*}Imperial")
    imperial.set("directionUnit", "grads")
    for e in root.iter():
        for key in ("dir", "dirStart", "dirEnd"):
            if key in e.attrib:  # decimal degrees counter-clockwise from east → grads clockwise from north
                e.set(key, repr(((90.0 - float(e.get(key))) % 360.0) * 400.0 / 360.0))
    source = tmp_path / "grads.xml"
    ET.ElementTree(root).write(source, encoding="utf-8", xml_declaration=True)
    (before,) = read_landxml(source)
    assert before.directions == "north-cw"
    rewrite_landxml_g2(source, tmp_path / "out.xml", 0.01)
    out = ET.parse(tmp_path / "out.xml").getroot()
    for line in out.iter("{http://www.landxml.org/schema/LandXML-1.2}Line"):
        (n0, e0), (n1, e1) = ([float(v) for v in line.find(f"{{*}}{k}").text.split()[:2]] for k in ("Start", "End"))
        azimuth = math.degrees(math.atan2(e1 - e0, n1 - n0)) % 360.0 * 400.0 / 360.0
        assert float(line.get("dir")) == pytest.approx(azimuth, abs=1e-7)
    (after,) = read_landxml(tmp_path / "out.xml")
    assert after.directions == "north-cw" and len(after.chains) == 1


def test_not_landxml_is_refused(tmp_path):
    (tmp_path / "x.xml").write_text("<a/>")
    with pytest.raises(ValueError, match="x.xml: not a LandXML document"):
        rewrite_landxml_g2(tmp_path / "x.xml", tmp_path / "y.xml", 0.01)
    with pytest.raises(ValueError, match="max_deviation"):
        rewrite_landxml_g2(DATA / "novapoint_toi_y3.xml", tmp_path / "y.xml", 0.0)


def test_a_file_rewritten_onto_itself_is_whole(tmp_path):
    target = tmp_path / "road.xml"
    target.write_bytes((DATA / "openroads_indot_twin_branch.xml").read_bytes())
    report = rewrite_landxml_g2(target, target, 0.01)
    assert report.paths[0].made and read_landxml(target)[0].kinds.count("Spiral") == 2
    assert [p.name for p in tmp_path.iterdir()] == ["road.xml"]  # no temporary left behind
