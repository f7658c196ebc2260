"""OpenDRIVE maps judged road by road and link by link: a hand-written map of 5 roads, 4 links and a junction."""

import math

import numpy as np
import pytest

from spiral_cad.app.cli import main
from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment, Profile
from spiral_cad.io.opendrive import check_opendrive, read_network, read_opendrive

HEADER = '<?xml version="1.0"?>\n<OpenDRIVE><header revMajor="1" revMinor="8"/>{}</OpenDRIVE>'
Q = math.pi / 4
# Road 2 turns left on the circle of radius 100 about (100, 100) from (100, 0) through 45°; road 3 is
# the next 45° of that circle drawn the other way (its end meets road 2's end: an end-to-end link);
# road 3's start at (200, 100) leads into a junction whose connecting roads 4 (the circle goes on: G2)
# and 5 (a straight line: G1) start there.
END2 = (100 + 100 * math.sin(Q), 100 - 100 * math.cos(Q))
MAP = HEADER.format(f"""
<road id="1" junction="-1" length="100"><link><successor elementType="road" elementId="2" contactPoint="start"/></link>
  <planView><geometry s="0" x="0" y="0" hdg="0" length="100"><line/></geometry></planView>
  <elevationProfile><elevation s="0" a="10" b="0.01" c="0" d="0"/><elevation s="60" a="10.6" b="-0.02" c="0" d="0"/></elevationProfile>
</road>
<road id="2" junction="-1" length="{100 * Q!r}">
  <link><predecessor elementType="road" elementId="1" contactPoint="end"/><successor elementType="road" elementId="3" contactPoint="end"/></link>
  <planView><geometry s="0" x="100" y="0" hdg="0" length="{100 * Q!r}"><arc curvature="0.01"/></geometry></planView>
  <lateralProfile><superelevation s="0" a="0" b="0" c="{3 * 0.05 / (100 * Q) ** 2!r}" d="{-2 * 0.05 / (100 * Q) ** 3!r}"/>
    <superelevation s="{100 * Q!r}" a="0.05" b="0" c="0" d="0"/></lateralProfile>
</road>
<road id="3" junction="-1" length="{100 * Q!r}">
  <link><predecessor elementType="junction" elementId="100"/><successor elementType="road" elementId="2" contactPoint="end"/></link>
  <planView><geometry s="0" x="200" y="100" hdg="{-math.pi / 2!r}" length="{100 * Q!r}"><arc curvature="-0.01"/></geometry></planView>
</road>
<road id="4" junction="100" length="20"><link><predecessor elementType="road" elementId="3" contactPoint="start"/></link>
  <planView><geometry s="0" x="200" y="100" hdg="{math.pi / 2!r}" length="20"><arc curvature="0.01"/></geometry></planView>
</road>
<road id="5" junction="100" length="30"><link><predecessor elementType="road" elementId="3" contactPoint="start"/></link>
  <planView><geometry s="0" x="200" y="100" hdg="{math.pi / 2!r}" length="30"><line/></geometry></planView>
</road>
<junction id="100" name="fork">
  <connection id="0" incomingRoad="3" connectingRoad="4" contactPoint="start"/>
  <connection id="1" incomingRoad="3" connectingRoad="5" contactPoint="start"/>
</junction>
""")


@pytest.fixture
def network_map(tmp_path):
    path = tmp_path / "five.xodr"
    path.write_text(MAP)
    return path


def test_the_map_reads_roads_links_junctions_and_profiles(network_map):
    network = read_network(network_map)
    assert [r.id for r in network.roads] == ["1", "2", "3", "4", "5"]
    road1, road2, road3, *_ = network.roads
    assert road1.successor.element_id == "2" and road1.successor.contact_point == "start"
    assert road3.predecessor.element_type == "junction" and road3.junction == "-1" and network.roads[3].junction == "100"
    (junction,) = network.junctions
    assert [(c.incoming, c.connecting, c.contact_point) for c in junction.connections] == [("3", "4", "start"), ("3", "5", "start")]
    # elevation and superelevation are evaluated from their records
    assert road1.elevation_at([0, 50, 60, 100]) == pytest.approx([10, 10.5, 10.6, 9.8])
    assert road1.elevation_at(80, derivative=1) == pytest.approx(-0.02)
    assert road2.superelevation_at([0, 100 * Q / 2, 100 * Q]) == pytest.approx([0, 0.025, 0.05])
    assert road3.superelevation_at([0, 5]).tolist() == [0, 0]  # no records: level
    assert read_opendrive(network_map)[4].length == 30


def test_five_roads_four_links_one_junction_each_link_measured(network_map):
    report = check_opendrive(network_map)
    assert report.describe() == "5 roads (1, 1, 1, 1, 1 geometries), 4 links, 1 junction"
    links = {link.name: link for link in report.links}
    assert set(links) == {"road 1 end → road 2 start", "road 2 end → road 3 end", "road 3 start → road 4 start",
                          "road 3 start → road 5 start"}  # fmt: skip
    # end-to-start: a line into an arc, G1 with the curvature jump 0.01
    joint = links["road 1 end → road 2 start"].joint
    assert str(joint.level) == "G1" and joint.gap <= 1e-12 and joint.curvature_jump == pytest.approx(0.01)
    # end-to-end: road 3 travelled backwards continues road 2's circle, G2
    joint = links["road 2 end → road 3 end"].joint
    assert str(joint.level) == "G2" and joint.gap <= 1e-12 and joint.angle <= 1e-12
    # through the junction: out of road 3's start into the connecting roads
    assert str(links["road 3 start → road 4 start"].joint.level) == "G2"
    assert links["road 3 start → road 4 start"].via == "junction 100"
    assert str(links["road 3 start → road 5 start"].joint.level) == "G1"
    # per road: the kinked elevation of road 1 is C0; road 2's cubic ease of the roll is C1
    profiles = {(p.road, p.kind): p for p in report.profiles}
    assert profiles[("1", "elevation")].level == "C0"
    assert profiles[("1", "elevation")].worst[0] == 60.0 and profiles[("1", "elevation")].worst[2] == pytest.approx(0.03)
    assert profiles[("2", "superelevation")].level == "C1"


def test_the_cli_judges_roads_profiles_and_links(network_map, capsys):
    assert main(["check", str(network_map), "--require", "G2"]) == 0  # every planView (one geometry each) is fine
    out = capsys.readouterr().out
    assert "OK: 5 roads (1, 1, 1, 1, 1 geometries), 4 links, 1 junction" in out and "road 2 end → road 3 end" in out
    assert main(["check", str(network_map), "--links", "G1"]) == 0
    assert main(["check", str(network_map), "--links", "G2"]) == 1
    assert "FAIL: worst link is G1, below the required G2" in capsys.readouterr().out
    assert main(["check", str(network_map), "--profiles", "C0"]) == 0
    assert main(["check", str(network_map), "--profiles", "C1"]) == 1
    assert "worst elevation/superelevation is C0, below the required C1" in capsys.readouterr().out
    assert main(["check", str(network_map), "--pieces", "4"]) == 1
    assert main(["check", str(network_map), "--pieces", "5", "--require", "G1"]) == 0


def test_a_direct_junction_offset_by_a_lane_is_reported_not_a_gap(tmp_path):
    path = tmp_path / "direct.xodr"
    path.write_text(
        HEADER.format("""
<road id="1" junction="-1" length="50"><link><successor elementType="junction" elementId="7"/></link>
  <planView><geometry s="0" x="0" y="0" hdg="0" length="50"><line/></geometry></planView></road>
<road id="2" junction="-1" length="40">
  <planView><geometry s="0" x="50" y="-3.5" hdg="0" length="40"><line/></geometry></planView></road>
<junction id="7" type="direct"><connection id="0" incomingRoad="1" linkedRoad="2" contactPoint="start"/></junction>
""")
    )
    (link,) = check_opendrive(path).links
    assert link.via == "direct junction 7" and link.offset == pytest.approx(-3.5) and str(link.joint.level) == "G2"
    assert main(["check", str(path), "--links", "G2"]) == 0


@pytest.mark.parametrize(
    "change, message",
    [
        (
            ('elementId="2" contactPoint="start"', 'elementId="9" contactPoint="start"'),
            "road 1 <successor> links to road 9, which is not in the file",
        ),
        (
            ('elementId="2" contactPoint="start"', 'elementId="2" contactPoint="middle"'),
            "road 1 <successor>: a road link needs contactPoint start or end",
        ),
        (
            ('<predecessor elementType="junction" elementId="100"/>', '<predecessor elementType="junction" elementId="101"/>'),
            "road 3 links to junction 101, which is not in the file",
        ),
        (
            ('<predecessor elementType="junction" elementId="100"/>', ""),
            "junction 100, connection 0: its incoming road 3 names the junction as neither predecessor nor successor",
        ),
        (
            ('connectingRoad="5" contactPoint="start"', 'connectingRoad="5"'),
            "junction 100, connection 1: contactPoint must be start or end",
        ),
        (('<elevation s="60"', '<elevation s="-60"'), "road 1, elevation 1: s = -60.0 is before s = 0.0 of elevation 0"),
        (('a="10.6"', 'a="nan"'), "road 1, elevation 1: a must be finite"),
    ],
)
def test_bad_links_and_records_are_named(tmp_path, change, message):
    path = tmp_path / "bad.xodr"
    path.write_text(MAP.replace(*change, 1))
    with pytest.raises(ValueError, match=message):
        check_opendrive(path)


def test_a_designed_road_is_c1_in_elevation_and_superelevation_through_the_cli(tmp_path, capsys):
    road = Alignment.from_pis([[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]], [450, 400, 600], units="m",
                              design_speed=80)  # fmt: skip
    profile = Profile.from_pvis([(0, 120), (700, 132), (1500, 116), (road.end_station, 121)], units="m", design_speed=80)
    path = tmp_path / "highway.xodr"
    export_opendrive(road, path, profile=profile)
    assert main(["check", str(path), "--require", "G2", "--profiles", "C1"]) == 0
    report = check_opendrive(path)
    assert {p.kind: p.level for p in report.profiles} == {"elevation": "C1", "superelevation": "C1"}
    # what read back evaluates is the design: z and the roll at the stations of the curves
    (back,) = read_opendrive(path)
    s = np.linspace(0, road.chain.length, 101)
    assert np.abs(back.elevation_at(s) - profile.elevation(s)).max() <= 1e-9
    curve = road.curves[1]
    roll = -math.copysign(math.atan(road.checks[1].cross_slope), curve.deflection)  # a left turn falls to the left
    assert curve.deflection > 0 and back.superelevation_at(0.5 * (curve.sc + curve.cs)) == pytest.approx(roll, rel=1e-14)
