"""OpenDRIVE links judged at the right road ends and lane by lane (lane centres through junctions)."""

import math

import numpy as np
import pytest

from spiral_cad.app.cli import main
from spiral_cad.io.opendrive import check_opendrive
from spiral_cad.io.opendrive_lanes import read_lanes

HEADER = '<?xml version="1.0"?>\n<OpenDRIVE><header revMajor="1" revMinor="6"/>{}</OpenDRIVE>'
R = 100.0


def circle_map() -> str:
    """A circle of radius 100 split into a 300° road 1 and a 60° connecting road 10 in junction 5:
    both ends of road 1 are in the junction; every joint is exactly G2."""
    big, small = R * math.radians(300), R * math.radians(60)
    return HEADER.format(f"""
<road id="1" junction="-1" length="{big!r}">
  <link><predecessor elementType="junction" elementId="5"/><successor elementType="junction" elementId="5"/></link>
  <planView><geometry s="0" x="0" y="{-R!r}" hdg="0" length="{big!r}"><arc curvature="{1 / R!r}"/></geometry></planView>
</road>
<road id="10" junction="5" length="{small!r}">
  <link><predecessor elementType="road" elementId="1" contactPoint="end"/><successor elementType="road" elementId="1" contactPoint="start"/></link>
  <planView><geometry s="0" x="{R * math.cos(math.radians(210))!r}" y="{R * math.sin(math.radians(210))!r}" hdg="{math.radians(300)!r}" length="{small!r}"><arc curvature="{1 / R!r}"/></geometry></planView>
</road>
<junction id="5"><connection id="0" incomingRoad="1" connectingRoad="10" contactPoint="start"/>
  <connection id="1" incomingRoad="1" connectingRoad="10" contactPoint="end"/></junction>
""")


def test_the_incoming_roads_end_is_the_one_in_the_junction(tmp_path):
    path = tmp_path / "circle.xodr"
    path.write_text(circle_map())
    report = check_opendrive(path)
    names = {link.name: link for link in report.links}
    assert set(names) == {"road 1 end → road 10 start", "road 1 start → road 10 end"}
    for link in report.links:
        assert str(link.joint.level) == "G2" and link.joint.gap < 1e-9
    assert main(["check", str(path), "--links", "G2"]) == 0


def lane_junction(width_b: float = 0.0, offset: float = 1.75) -> str:
    """Road 1 (x 0…50) and road 2 (x 70…120), two lanes of 3.5 m each side, their reference lines on
    y = 0, meet in junction 9; connecting road 3 runs straight from x 50 to 70 with its reference
    line on y = −``offset`` and a laneOffset of +``offset``, so its lanes lie exactly over the roads'
    lanes although the reference lines are apart. Road 3's lane −1 may widen (``width_b``)."""
    lanes = """<lanes>{offset}<laneSection s="0">
    <left><lane id="1" type="driving"><link><predecessor id="1"/><successor id="1"/></link><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane></left>
    <center><lane id="0" type="none"/></center>
    <right><lane id="-1" type="driving"><link><predecessor id="-1"/><successor id="-1"/></link><width sOffset="0" a="3.5" b="{b}" c="0" d="0"/></lane></right>
  </laneSection></lanes>"""
    plain = lanes.format(offset="", b="0")
    shifted = lanes.format(offset=f'<laneOffset s="0" a="{offset!r}" b="0" c="0" d="0"/>', b=repr(width_b))
    return HEADER.format(f"""
<road id="1" junction="-1" length="50"><link><successor elementType="junction" elementId="9"/></link>
  <planView><geometry s="0" x="0" y="0" hdg="0" length="50"><line/></geometry></planView>{plain}</road>
<road id="2" junction="-1" length="50"><link><predecessor elementType="junction" elementId="9"/></link>
  <planView><geometry s="0" x="70" y="0" hdg="0" length="50"><line/></geometry></planView>{plain}</road>
<road id="3" junction="9" length="20">
  <link><predecessor elementType="road" elementId="1" contactPoint="end"/><successor elementType="road" elementId="2" contactPoint="start"/></link>
  <planView><geometry s="0" x="50" y="{-offset!r}" hdg="0" length="20"><line/></geometry></planView>{shifted}</road>
<junction id="9"><connection id="0" incomingRoad="1" connectingRoad="3" contactPoint="start">
  <laneLink from="1" to="1"/><laneLink from="-1" to="-1"/></connection></junction>
""")


def test_a_junction_offset_by_lane_offset_is_judged_lane_by_lane(tmp_path):
    path = tmp_path / "offset.xodr"
    path.write_text(lane_junction())
    report = check_opendrive(path)
    names = {link.name: link for link in report.links}
    assert set(names) == {"road 1 end lane 1 → road 3 start lane 1", "road 1 end lane -1 → road 3 start lane -1",
                          "road 3 end lane -1 → road 2 start lane -1", "road 3 end lane 1 → road 2 start lane 1"}  # fmt: skip
    for link in report.links:
        assert str(link.joint.level) == "G2" and link.joint.gap < 1e-12, link.name
    assert names["road 1 end lane -1 → road 3 start lane -1"].lanes == (-1, -1)
    assert main(["check", str(path), "--links", "G2"]) == 0


def test_a_lane_that_does_not_line_up_is_a_gap_of_the_right_size(tmp_path):
    path = tmp_path / "off.xodr"
    # road 3's reference line 1.75 below, its laneOffset only 1.5: its lanes lie 0.25 low
    path.write_text(lane_junction(offset=1.75).replace('a="1.75" b="0"', 'a="1.5" b="0"'))
    links = {link.name: link.joint for link in check_opendrive(path).links}
    assert links["road 1 end lane 1 → road 3 start lane 1"].gap == pytest.approx(0.25)
    assert str(links["road 1 end lane 1 → road 3 start lane 1"].level) == "none"
    assert main(["check", str(path), "--links", "G0"]) == 1


def test_a_widening_lane_turns_its_centre_and_the_angle_is_half_the_width_rate(tmp_path):
    # lane −1 of road 3 widens by 0.02 per metre: its centre heads away at atan(0.01) from road 1's lane
    path = tmp_path / "widen.xodr"
    path.write_text(lane_junction(width_b=0.02))
    links = {link.name: link.joint for link in check_opendrive(path).links}
    joint = links["road 1 end lane -1 → road 3 start lane -1"]
    assert joint.gap < 1e-12 and joint.angle == pytest.approx(math.atan(0.01), rel=1e-12)
    assert str(links["road 1 end lane 1 → road 3 start lane 1"].level) == "G2"


def test_lane_centre_curvature_on_an_arc_is_the_offset_circles(tmp_path):
    # a road on a circle of radius 100 with 3.5 m lanes: lane 1's centre is the circle of radius 98.25
    from spiral_cad.io.opendrive import read_network
    from spiral_cad.io.opendrive_lanes import lane_frame

    path = tmp_path / "arc.xodr"
    path.write_text(
        lane_junction().replace(
            "<line/></geometry></planView><lanes><laneOffset", '<arc curvature="0.01"/></geometry></planView><lanes><laneOffset'
        )
    )
    network = read_network(path)
    road = next(r for r in network.roads if r.id == "3")
    frame = lane_frame(road, read_lanes(path).roads["3"], 1, "end", "test")
    t = 1.75 + 1.75  # laneOffset + half the lane
    assert math.hypot(frame[6], frame[7]) == pytest.approx(0.01 / (1 - 0.01 * t), rel=1e-12)


def test_a_lane_link_to_a_missing_lane_is_named(tmp_path):
    path = tmp_path / "bad.xodr"
    path.write_text(lane_junction().replace('<laneLink from="-1" to="-1"/>', '<laneLink from="-1" to="-3"/>'))
    with pytest.raises(ValueError, match=r"junction 9, connection 0: road 3 has no lane -3 at its start \(lanes \[-1, 1\]\)"):
        check_opendrive(path)
    assert main(["check", str(path), "--links", "G0"]) == 2


DATA = __import__("pathlib").Path(__file__).resolve().parents[1] / "data"


def test_a_real_lane_offset_junction_lines_up_lane_by_lane_but_not_by_reference_lines(capsys):
    # esmini's lane_offset_intersection (trimmed): road 7 opens a turn lane (laneOffset and lane −1's width
    # grow as the same cubic), so at its end the reference line lies 3.5 m beside connecting road 13's
    from spiral_cad.io.opendrive import read_network

    path = DATA / "esmini_lane_offset_junction.xodr"
    roads = {r.id: r for r in read_network(path).roads}
    reference_gap = math.dist(roads["7"].plan.frames[-1, 1, :2], roads["13"].plan.frames[0, 0, :2])
    assert reference_gap == pytest.approx(3.5, abs=1e-5)
    links = {link.name: link.joint for link in check_opendrive(path).links}
    assert set(links) == {"road 1 end lane -2 → road 9 start lane -1", "road 7 end lane -1 → road 13 start lane -1",
                          "road 9 end lane -1 → road 7 end lane 1", "road 13 end lane -1 → road 1 end lane 1"}  # fmt: skip
    assert max(joint.gap for joint in links.values()) < 1e-5  # the file's own rounding: micrometres
    assert max(joint.angle for joint in links.values()) < 1e-7
    assert main(["check", str(path), "--links", "G1", "--gap-tol", "1e-5"]) == 0
    assert "road 1 end lane -2 → road 9 start lane -1" in capsys.readouterr().out


def test_a_lane_centre_on_a_straight_road_follows_its_offset_polynomial():
    # road 1 is a straight line; lane −1's centre lies at t(s) = laneOffset(s) − width(s)/2, a graph over the
    # line: heading atan(t'), curvature t''/(1 + t'²)^1.5 — both from the file's numbers, written out here
    from spiral_cad.io.opendrive import read_network
    from spiral_cad.io.opendrive_lanes import lane_frame

    path = DATA / "esmini_lane_offset_junction.xodr"
    road = next(r for r in read_network(path).roads if r.id == "1")
    offset = np.polynomial.Polynomial([0.0, 0.0, 0.01311473410248621, -0.0003089963334634307])
    width = np.polynomial.Polynomial([0.0, 0.0, 0.01311473410248621, -0.00030899633346343077])
    t = offset - width / 2
    s, hdg = 28.295339204595706, 2.603087685674666
    frame = lane_frame(road, read_lanes(path).roads["1"], -1, "end", "test")
    slope, bend = t.deriv()(s), t.deriv(2)(s)
    heading = hdg + math.atan(slope)
    assert frame[3:5] == pytest.approx((math.cos(heading), math.sin(heading)), abs=1e-14)
    assert math.hypot(*frame[6:8]) == pytest.approx(abs(bend) / (1 + slope**2) ** 1.5, rel=1e-12)
    start = (5.696453094482422, -5.444994926452637)
    normal = (-math.sin(hdg), math.cos(hdg))
    expected = (start[0] + s * math.cos(hdg) + t(s) * normal[0], start[1] + s * math.sin(hdg) + t(s) * normal[1])
    assert frame[:2] == pytest.approx(expected, abs=1e-12)


def with_profiles(text: str, road: str, profiles: str) -> str:
    """``text`` with ``profiles`` (elevationProfile/lateralProfile elements) after road ``road``'s planView."""
    head, tail = text.split(f'<road id="{road}"', 1)
    before, after = tail.split("</planView>", 1)
    return f'{head}<road id="{road}"{before}</planView>{profiles}{after}'


def test_lane_links_are_judged_with_elevation(tmp_path):
    # road 1 climbs at 2 % to z = 1 at its end; road 3 goes on from z = 1 at 2 % (G2) or at 5 % (a kink)
    base = with_profiles(
        lane_junction(offset=0.0), "1", '<elevationProfile><elevation s="0" a="0" b="0.02" c="0" d="0"/></elevationProfile>'
    )
    path = tmp_path / "climb.xodr"
    for grade, level, angle in ((0.02, "G2", 0.0), (0.05, "G0", math.atan(0.05) - math.atan(0.02))):
        path.write_text(with_profiles(base, "3", f'<elevationProfile><elevation s="0" a="1" b="{grade}" c="0" d="0"/></elevationProfile>'))
        joint = {link.name: link.joint for link in check_opendrive(path).links}["road 1 end lane 1 → road 3 start lane 1"]
        assert str(joint.level) == level and joint.gap < 1e-12 and joint.angle == pytest.approx(angle, abs=1e-12)


def test_lane_links_are_judged_with_superelevation(tmp_path):
    # both roads rolled by 0.05 rad about one reference line: lane 1's centre meets; road 3 rolled 0.08: it
    # sits t·(sin 0.08 − sin 0.05) higher and t·(cos 0.05 − cos 0.08) nearer the reference line
    roll = '<lateralProfile><superelevation s="0" a="{}" b="0" c="0" d="0"/></lateralProfile>'
    path = tmp_path / "roll.xodr"
    for other, gap in ((0.05, 0.0), (0.08, 1.75 * math.hypot(math.sin(0.08) - math.sin(0.05), math.cos(0.08) - math.cos(0.05)))):
        path.write_text(with_profiles(with_profiles(lane_junction(offset=0.0), "1", roll.format(0.05)), "3", roll.format(other)))
        joint = {link.name: link.joint for link in check_opendrive(path).links}["road 1 end lane 1 → road 3 start lane 1"]
        assert joint.gap == pytest.approx(gap, abs=1e-12)
        assert str(joint.level) == ("G2" if gap == 0.0 else "none")


def test_lane_centre_curvature_on_a_spiral_with_a_growing_lane_matches_a_sampled_curve(tmp_path):
    # the closed form (κ, κ', t, t', t'') against the lane centre sampled at 9 stations before the road's end and
    # differentiated by a polynomial fit: a clothoid reference line and a lane whose width is a cubic
    from spiral_cad.io.opendrive import read_network
    from spiral_cad.io.opendrive_lanes import lane_frame

    length, k0, k1 = 40.0, 0.002, 0.03
    width = np.polynomial.Polynomial([3.0, 0.02, 4e-4, -5e-6])
    offset = np.polynomial.Polynomial([0.3, -0.01, 2e-4, 0.0])
    path = tmp_path / "spiral.xodr"
    path.write_text(
        HEADER.format(f"""
<road id="1" junction="-1" length="{length!r}">
  <planView><geometry s="0" x="3" y="-2" hdg="0.4" length="{length!r}"><spiral curvStart="{k0!r}" curvEnd="{k1!r}"/></geometry></planView>
  <lanes><laneOffset s="0" a="{float(offset.coef[0])!r}" b="{float(offset.coef[1])!r}" c="{float(offset.coef[2])!r}" d="{float(offset.coef[3])!r}"/>
    <laneSection s="0"><center><lane id="0"/></center><right><lane id="-1" type="driving">
      <width sOffset="0" a="{float(width.coef[0])!r}" b="{float(width.coef[1])!r}" c="{float(width.coef[2])!r}" d="{float(width.coef[3])!r}"/></lane></right></laneSection></lanes>
</road>""")
    )
    (road,) = read_network(path).roads
    (geometry,) = road.geometries
    frame = lane_frame(road, read_lanes(path).roads["1"], -1, "end", "test")
    s = length - np.linspace(0.0, 4.0, 9)
    points, tangents, _ = geometry.evaluate(s / length)
    t = offset(s) - width(s) / 2
    centre = points + t[:, None] * np.column_stack([-tangents[:, 1], tangents[:, 0]])
    fit = [np.polynomial.Polynomial.fit(s - length, centre[:, k], 8).convert() for k in range(2)]
    d1 = np.array([f.deriv()(0.0) for f in fit])
    d2 = np.array([f.deriv(2)(0.0) for f in fit])
    curvature = (d1[0] * d2[1] - d1[1] * d2[0]) / np.linalg.norm(d1) ** 3
    assert frame[:2] == pytest.approx(centre[0], abs=1e-12)
    assert frame[3:5] == pytest.approx(d1 / np.linalg.norm(d1), abs=1e-9)
    normal = (-frame[4], frame[3])
    assert frame[6] * normal[0] + frame[7] * normal[1] == pytest.approx(curvature, rel=1e-6)


@pytest.mark.parametrize("kind", ["paramPoly3", "poly3", "spiral"])
def test_the_curvature_rate_at_a_road_end_matches_a_difference_of_curvatures(kind):
    # dκ/ds at the end of each planView kind whose curvature varies, against (κ(1) − κ(1 − h)) / chord
    from spiral_cad.io.opendrive_lanes import _curvature_rate
    from spiral_cad.io.opendrive_read import Geometry

    params = {"paramPoly3": {"aU": 0.0, "bU": 30.0, "cU": -2.0, "dU": 0.5, "aV": 0.0, "bV": 0.0, "cV": 3.0, "dV": -0.8,
                             "pRange": "normalized"},
              "poly3": {"a": 0.0, "b": 0.1, "c": 0.004, "d": -0.0002},
              "spiral": {"curvStart": 0.001, "curvEnd": 0.02}}[kind]  # fmt: skip
    geometry = Geometry("1", 0, 0.0, 1.0, 2.0, 0.3, 30.0, kind, params)
    h = 1e-6
    points, _, curvature = geometry.evaluate([1.0 - h, 1.0])
    rate = (curvature[1] - curvature[0]) / math.dist(points[0], points[1])
    assert _curvature_rate(geometry, 1.0) == pytest.approx(rate, rel=1e-4)


@pytest.mark.parametrize(
    "change, message",
    [
        (
            ('<width sOffset="0" a="3.5" b="0"', '<width sOffset="0" a="wide" b="0"'),
            r"road 1, lane 1 <width>: a must be a finite number; got 'wide'",
        ),
        (
            ('<lane id="-1" type="driving">', '<lane id="minus one" type="driving">'),
            r"road 1, laneSection 0 <lane>: id must be an integer lane id",
        ),
        (
            ('<laneLink from="1" to="1"/>', '<laneLink from="1"/>'),
            r"junction 9, connection 0 <laneLink>: to must be an integer lane id; got None",
        ),
        (('<laneOffset s="0" a="1.75"', '<laneOffset s="inf" a="1.75"'), r"road 3, laneOffset 0: s must be a finite number; got 'inf'"),
        (
            (
                '<width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane></left>',
                '<border sOffset="0" a="3.5" b="0" c="0" d="0"/></lane></left>',
            ),
            r"road 1, lane 1 is given by <border>, which is not supported; give <width>",
        ),
    ],
)
def test_bad_lanes_are_named(tmp_path, change, message):
    path = tmp_path / "bad.xodr"
    path.write_text(lane_junction().replace(*change, 1))
    with pytest.raises(ValueError, match=message):
        check_opendrive(path)


def test_lane_elements_out_of_place_are_ignored(tmp_path):
    # a width outside a lane section and a laneLink outside a connection are not lanes: the links are as before
    text = lane_junction().replace("<lanes>", '<lanes><userData><x><lane id="5"><width sOffset="0" a="x"/></lane></x></userData>', 1)
    text = text.replace('<junction id="9">', '<junction id="9"><userData><laneLink from="a" to="b"/></userData>')
    path = tmp_path / "odd.xodr"
    path.write_text(text)
    assert all(str(link.joint.level) == "G2" for link in check_opendrive(path).links)
