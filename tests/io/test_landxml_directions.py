"""LandXML in: the file's direction convention (counter-clockwise from east, or clockwise from north) inferred
from its own elements, refused by name when inconsistent or untellable where it matters."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from spiral_cad.design import Alignment
from spiral_cad.io import read_landxml
from spiral_cad.io.landxml import landxml_text

DATA = Path(__file__).parent.parent / "data" / "landxml"
NS = "{http://www.landxml.org/schema/LandXML-1.2}"


def _points(chain, n: int = 401) -> np.ndarray:
    return chain.point_at(np.linspace(0.0, chain.length, n))


@pytest.mark.parametrize(("name", "expected"), [
    ("civil3d_gsg_basic_road.xml", "east-ccw"),
    ("carlson_trout_run_road.xml", "east-ccw"),
    ("novapoint_toi_y3.xml", "north-cw"),
    ("mdt_aplitop_alignment1.xml", "north-cw"),
    ("civil3d_spiral_r63.xml", "unknown"),  # no direction at all: placed by its points
])  # fmt: skip
def test_the_convention_of_real_exports_is_told_from_their_own_points(name, expected):
    assert {a.directions for a in read_landxml(DATA / name)} == {expected}


def _strip(text: str, *tags: str) -> str:
    """The document without any child element named in ``tags`` (e.g. every Center and PI)."""
    root = ET.fromstring(text)
    for parent in root.iter():
        for child in list(parent):
            if isinstance(child.tag, str) and child.tag.rsplit("}", 1)[-1] in tags:
                parent.remove(child)
    return ET.tostring(root, encoding="unicode")


def test_mdt_curves_placed_by_their_azimuth_land_where_their_points_put_them():
    # MDT writes grads clockwise from north; without Center and PI the curves are placed by dirStart alone
    # (the tester's mdt1_nocenter.xml: 6 G2 runs and 138 m off when read counter-clockwise from east)
    text = (DATA / "mdt_aplitop_alignment1.xml").read_text(encoding="utf-8")
    (full,) = read_landxml(text)
    (bare,) = read_landxml(_strip(text, "Center", "PI"))
    assert bare.directions == "north-cw" and len(bare.chains) == len(full.chains)
    for ours, theirs in zip(bare.chains, full.chains):
        assert np.abs(_points(ours) - _points(theirs)).max() < 1e-3  # the file's dirStart rounds to 1e-8 grads
    assert bare.offset < 0.05
    assert any("clockwise from north" in note for note in bare.notes)


def _azimuths(text: str, drop: tuple[str, ...]) -> str:
    """Our file with every direction rewritten as radians clockwise from north and the children ``drop`` removed."""
    text = text.replace('directionUnit="decimal degrees"', 'directionUnit="radians"')

    def azimuth(m: re.Match) -> str:
        return f'{m.group(1)}="{math.remainder(math.radians(90.0 - float(m.group(2))), 2 * math.pi) % (2 * math.pi)!r}"'

    return _strip(re.sub(r'\b(dir|dirStart|dirEnd)="([^"]+)"', azimuth, text), *drop)


def test_spirals_placed_by_an_azimuth_dirStart_land_on_the_road():
    # like the Dubai Metro TN07 export: radians clockwise from north, spirals with dirStart and no PI
    road = Alignment.from_pis([[0, 0], [800, 150], [1500, -100]], [600], spiral_lengths=[90], units="m", shape="near-linear")
    ours = landxml_text([_to_write(road)], "m")
    (direct,) = read_landxml(ours)
    assert direct.directions == "east-ccw"  # what we write, as Civil 3D and Carlson do: every dir agrees with its points
    (turned,) = read_landxml(_azimuths(ours, ("PI",)))
    assert turned.directions == "north-cw" and len(turned.chains) == 1
    assert np.abs(_points(turned.chain) - _points(direct.chain)).max() < 1e-6 * road.chain.length
    assert turned.offset == pytest.approx(direct.offset, rel=1e-6)  # our cubic against the file's clothoid, as before


def _to_write(road):
    from spiral_cad.io.landxml import AlignmentToWrite

    return AlignmentToWrite(road.chain, "road", road.start_station)


def _file(*elements: str, unit: str = "decimal degrees") -> str:
    return ('<LandXML><Units><Metric linearUnit="meter" angularUnit="decimal degrees" '
            f'directionUnit="{unit}"/></Units><Alignments><Alignment name="d"><CoordGeom>'
            + "".join(elements) + "</CoordGeom></Alignment></Alignments></LandXML>")  # fmt: skip


# a line due north-east-ish: 30° counter-clockwise from east is 60° clockwise from north
EAST_LINE = '<Line dir="30" length="10"><Start>0 0</Start><End>5 8.660254037844386</End></Line>'
NORTH_LINE = '<Line dir="60" length="10"><Start>5 8.660254037844386</Start><End>10 17.32050807568877</End></Line>'


def test_directions_that_disagree_between_elements_are_refused_by_name():
    with pytest.raises(ValueError, match=r"inconsistent: alignment 'd', CoordGeom element 0 \(Line\) dir agrees .* from east "
                                         r"\(1 such\), alignment 'd', CoordGeom element 1 \(Line\) dir only counted clockwise from north"):  # fmt: skip
        read_landxml(_file(EAST_LINE, NORTH_LINE))


def test_a_direction_with_nothing_to_tell_its_convention_is_refused_where_it_places_an_element():
    lone = '<Line dir="30" length="10"><Start>0 0</Start></Line>'
    with pytest.raises(ValueError, match=r"element 0 \(Line\) at station 0: the element is placed only by its dir.*cannot be told"):
        read_landxml(_file(lone))
    (east,) = read_landxml(_file(lone), directions="east-ccw")
    (north,) = read_landxml(_file(lone), directions="north-cw")
    assert np.allclose(east.chain.end[:2], [10 * math.cos(math.radians(30)), 10 * math.sin(math.radians(30))])
    assert np.allclose(north.chain.end[:2], [10 * math.sin(math.radians(30)), 10 * math.cos(math.radians(30))])
    assert east.directions == "east-ccw" and any("as chosen" in note for note in east.notes)


@pytest.mark.parametrize(("first", "heading"), [(EAST_LINE, 120.0), (NORTH_LINE, 90.0 - 120.0)])
def test_evidence_from_one_element_places_another_placed_only_by_its_direction(first, heading):
    (r,) = read_landxml(_file(first, '<Line dir="120" length="10"/>'))  # the second line: its dir alone
    line = r.chains[-1].segments[0]
    assert math.degrees(math.atan2(line.start_tangent[1], line.start_tangent[0])) == pytest.approx(heading, abs=1e-9)
    assert r.directions == ("east-ccw" if first == EAST_LINE else "north-cw")


def test_the_directions_argument_is_checked():
    with pytest.raises(ValueError, match="directions must be 'auto'"):
        read_landxml(_file(EAST_LINE), directions="clockwise")


def test_a_clothoid_no_cubic_follows_is_refused_beyond_max_offset():
    # a clothoid straight → R 40 m over 80 m (57° of turn) after a line: ours strays 4.5 m (5.6% of its length)
    text = _file('<Line><Start>0 0</Start><End>0 100</End></Line>',
                 '<Spiral length="80" radiusStart="INF" radiusEnd="40" rot="ccw" spiType="clothoid"><Start>0 100</Start><PI/><End/></Spiral>')  # fmt: skip
    (a,) = read_landxml(text, max_offset=math.inf)
    assert a.worst.startswith("element 1 (Spiral) at station 100: ") and a.offset > 0.5
    with pytest.raises(
        ValueError, match=r"element 1 \(Spiral\) at station 100: ours lies .* m from the file's element, more than max_offset 0.1"
    ):
        read_landxml(text, max_offset=0.1)
    with pytest.raises(ValueError, match=r"element 1 \(Spiral\) at station 100: .* more than 0.05 of its length 80 "):
        read_landxml(text)  # the default: 5% of the element's length
    huge = text.replace('length="80"', 'length="1000"').replace('radiusEnd="40"', 'radiusEnd="10"')  # the tester's 972 m
    with pytest.raises(ValueError, match=r"more than 0.05 of its length 1000 .*max_offset=math.inf, or build --max-offset inf, accepts"):
        read_landxml(huge)
    with pytest.raises(ValueError, match="max_offset must be a length"):
        read_landxml(text, max_offset=-1.0)


def test_points_given_by_pntref_are_read_from_the_files_cgpoints():
    # the tester's pntref.xml: the XSD's PointType may name a CgPoint instead of holding coordinates
    points = '<CgPoints><CgPoint name="P1">0 0</CgPoint><CgPoint name="P2">0 100</CgPoint></CgPoints>'
    text = _file('<Line length="100"><Start pntRef="P1"/><End pntRef="P2"/></Line>').replace("<Alignments>", points + "<Alignments>")
    (a,) = read_landxml(text)
    assert np.allclose(a.chain.start[:2], [0, 0]) and np.allclose(a.chain.end[:2], [100, 0])  # northing 0, easting 100
    with pytest.raises(ValueError, match=r"element 0 \(Line\) at station 0: <End pntRef='P3'> names no CgPoint"):
        read_landxml(text.replace('pntRef="P2"', 'pntRef="P3"'))


@pytest.mark.parametrize(("element", "message"), [
    ('<Spiral rot="ccw" radiusStart="100" length="20" spiType="clothoid"/>', "a Spiral needs radiusEnd"),  # spiral_missing_re.xml
    ('<Spiral rot="ccw" radiusEnd="100" length="20" spiType="clothoid"/>', "a Spiral needs radiusStart"),
    ('<Spiral rot="ccw" radiusStart="INF" radiusEnd="100" length="20"/>', "a Spiral needs spiType"),
    ('<Curve rot="ccw" radius="50" chord="200"/>', r"chord 200 is not in \(0, 2 × radius 50\]"),  # curve_chord_too_long.xml
    ('<Curve rot="ccw" radius="INF" length="20"/>', "a Curve's radius 'INF' is not finite"),
])  # fmt: skip
def test_missing_or_impossible_values_are_refused_by_name(element, message):
    text = _file('<Line length="100"><Start>0 0</Start><End>0 100</End></Line>', element).replace('name="d"', 'name="A"')
    with pytest.raises(ValueError, match=rf"alignment 'A', CoordGeom element 1 \(\w+\) at station 100: {message}"):
        read_landxml(text)
