"""LandXML 1.2 out (XSD-valid) and in (our files back exactly, real exports read, refusals named)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import xmlschema
from hypothesis import given, settings
from hypothesis import strategies as st

from spiral_cad.design import Alignment, Profile
from spiral_cad.io import read_landxml
from spiral_cad.io.landxml import US_SURVEY_FOOT, AlignmentToWrite, landxml_text, spiral_offsets, write_landxml

DATA = Path(__file__).parent.parent / "data" / "landxml"


@pytest.fixture(scope="module")
def schema() -> xmlschema.XMLSchema:
    return xmlschema.XMLSchema(str(DATA / "LandXML-1.2.xsd"))


def _road(units: str = "m", shape: str = "near-linear") -> tuple[Alignment, Profile]:
    a = Alignment.from_pis([[0, 0], [800, 150], [1500, -100], [2100, 50]], [900, 1200], spiral_lengths=[[90, 90], 110],
                           start_station=25000, units=units, shape=shape)  # fmt: skip
    p = Profile.from_pvis([[25000, 100], [25800, 112], [26400, 104], [a.end_station, 110]], curve_lengths=[200, (150, 250)],
                          units=units, alignment=a)  # fmt: skip
    return a, p


@pytest.mark.parametrize(("units", "survey"), [("m", False), ("ft", False), ("ft", True), ("mm", False)])
def test_written_files_are_valid_landxml_1_2(schema, tmp_path, units, survey):
    a, p = _road(units)
    path = tmp_path / "road.xml"
    write_landxml(a, path, name="rail", profile=p, survey_feet=survey)
    schema.validate(str(path))
    text = path.read_text()
    linear = {"m": "meter", "mm": "millimeter", "ft": "USSurveyFoot" if survey else "foot"}[units]
    assert f'linearUnit="{linear}"' in text and ("<Metric" in text) == (units in ("m", "mm"))
    assert text.count("<Spiral ") == 4 and text.count("<Curve ") == 2 and text.count("<ParaCurve ") == 1
    assert text.count("<UnsymParaCurve ") == 1


def test_points_are_northing_then_easting(tmp_path):
    a, _ = _road()
    text = landxml_text([AlignmentToWrite(a.chain, "rail", a.start_station)], "m")
    end = a.chain.segments[0].end
    assert f"<End>{float(end[1])!r} {float(end[0])!r}</End>" in text


@pytest.mark.parametrize("shape", ["near-linear", "walton-meek"])
def test_spiral_desc_states_the_measured_offset_from_the_clothoid(tmp_path, shape):
    a, _ = _road(shape=shape)
    offsets = spiral_offsets(a.chain)
    spirals = [k for k, s in enumerate(a.chain.segments) if type(s).__name__ == "BezierSpiral"]
    assert (offsets[spirals] > 0).all() and np.count_nonzero(offsets) == len(spirals)
    bound = 0.005 if shape == "near-linear" else 5.0  # near-linear: mm over 90–110 m spirals; walton-meek: metres
    assert offsets.max() < bound
    text = landxml_text([AlignmentToWrite(a.chain, "rail", a.start_station)], "m")
    assert f"within {offsets[spirals[0]]:.3g} m of it" in text and f"(shape {shape})" in text


@pytest.mark.parametrize(("units", "survey"), [("m", False), ("ft", True)])
def test_round_trip_gives_the_same_chain(tmp_path, units, survey):
    a, p = _road(units, "walton-meek")
    path = tmp_path / "road.xml"
    write_landxml(a, path, name="rail", profile=p, survey_feet=survey)
    (r,) = read_landxml(path)
    assert r.name == "rail" and r.units == units and r.start_station == pytest.approx(25000, rel=1e-12)
    s = np.linspace(0, a.chain.length, 2001)
    assert np.abs(r.chain.point_at(s) - a.chain.point_at(s)).max() < 1e-9 * a.chain.length
    assert len(r.chain) == len(a.chain)
    assert r.kinds == ("Line", "Spiral", "Curve", "Spiral", "Line", "Spiral", "Curve", "Spiral", "Line")
    stations = a.chain.stations[:-1] + a.start_station
    assert np.allclose(r.stations, stations, rtol=0, atol=1e-9 * a.chain.length)
    # each spiral's offset from the clothoid the file states: the reader's (nearest points, both ways) is at
    # most the writer's (at equal arc lengths) and of its size
    stated = spiral_offsets(a.chain)
    assert np.all(r.offsets <= stated + 1e-9) and np.all(r.offsets[1::2] > 0.5 * stated[1::2])
    z = np.linspace(p.start, p.end, 500)
    assert np.abs(r.profile.elevation(z) - p.elevation(z)).max() < 1e-9


def test_civil3d_export_in_feet_and_degrees():
    (r,) = read_landxml(DATA / "civil3d_gsg_basic_road.xml")
    assert r.name == "Basic_Road" and r.units == "ft" and r.kinds == ("Line", "Curve", "Line", "Curve", "Line")
    # lines onto arcs without spirals: one G2 run per element, each joint named
    assert len(r.chains) == 5 and "station 460.661" in r.breaks[0]
    with pytest.raises(ValueError, match="Basic_Road.*not G2.*curvature jumps"):
        r.chain  # noqa: B018
    # the file's own End points are where our elements end
    ends = np.array([[1031525.00794186, 77807.290425910003], [1031541.03714373, 77597.314977369999],
                     [1031456.52461059, 77434.284766059995]])  # fmt: skip
    assert np.abs(np.array([c.end[:2] for c in r.chains[:3]]) - ends).max() < 1e-6
    assert r.offset < 1e-6
    assert np.allclose(np.diff(r.stations), [c.length for c in r.chains[:-1]], atol=1e-6)  # stations continue
    assert r.profile is not None and r.profile.pvis.shape == (6, 2)
    assert r.profile.elevation([0.0, 1658.626221424434]) == pytest.approx([77.906, 104.850331642669], abs=1e-9)
    assert r.profile.curves[0].length == pytest.approx(200.0)


def test_carlson_export_in_us_survey_feet_and_radians():
    (r,) = read_landxml(DATA / "carlson_trout_run_road.xml")
    assert r.units == "ft" and r.kinds == ("Curve", "Line", "Line", "Curve", "Curve", "Line")
    scale = US_SURVEY_FOOT / 0.3048
    end = r.chains[-1].end[:2]
    assert end == pytest.approx(np.array([5375829.46100000, 3932103.21900000]) * scale, abs=1e-4)
    assert r.offset < 1e-6
    assert "kink of 0.0337 rad" in r.breaks[0]  # the file turns 2° between its first arc and line
    assert r.profile is None and "not read" in r.notes[0]  # a grade break without a curve


def test_civil3d_spiral_rebuilt_with_the_stated_offset():
    (r,) = read_landxml(DATA / "civil3d_spiral_r63.xml")
    (spiral,) = r.chain.segments
    assert spiral.length == pytest.approx(100.0, rel=1e-12)
    assert spiral.start_curvature == pytest.approx(-1 / 63, rel=1e-9) and abs(spiral.end_curvature) < 1e-12
    gap = math.dist(spiral.end[:2], (7787.491818113435, 3913.351640529602))
    assert gap == pytest.approx(r.offsets[0], rel=1e-3)  # the file's End is the clothoid's end: the offset is the gap
    (w,) = read_landxml(DATA / "civil3d_spiral_r63.xml", shape="walton-meek")
    assert 1.0 < w.offset < r.offset < 2.0  # a 45° spiral: walton-meek (1.39 m) is nearer than near-linear (1.65 m)


def test_spiral_between_two_radii_and_spiral_to_spiral():
    head = ('<LandXML xmlns="http://www.landxml.org/schema/LandXML-1.2"><Units><Metric linearUnit="meter" '
            'angularUnit="grads" directionUnit="grads"/></Units><Alignments><Alignment name="c" staStart="0"><CoordGeom>')  # fmt: skip
    body = (
        '<Spiral length="80" radiusStart="400" radiusEnd="200" rot="ccw" spiType="clothoid" dirStart="50">'
        "<Start>0 0</Start><PI/><End/></Spiral>"
        '<Spiral length="60" radiusStart="200" radiusEnd="INF" rot="ccw" spiType="clothoid"><Start/><PI/><End/></Spiral>'
    )
    (r,) = read_landxml(head + body + "</CoordGeom></Alignment></Alignments></LandXML>", directions="east-ccw")
    first = r.chain.segments[0]
    assert first.start_curvature == pytest.approx(1 / 400, rel=1e-9) and first.end_curvature == pytest.approx(1 / 200, rel=1e-9)
    assert first.length == pytest.approx(80, rel=1e-9)
    assert math.degrees(math.atan2(*first.start_tangent[1::-1])) == pytest.approx(45.0)  # 50 grads
    assert r.offsets[0] < 0.5 and r.offset < 1.0  # measured 0.35 m for the piece, 0.96 m where the exit follows it
    negative = '<Spiral length="80" radiusStart="-300" radiusEnd="150" rot="cw" spiType="clothoid" dirStart="0"><Start>0 0</Start><PI/><End/></Spiral>'
    with pytest.raises(ValueError, match=r"element 0 \(Spiral\) at station 0: radius -300.0 has no finite positive curvature"):
        read_landxml(head + negative + "</CoordGeom></Alignment></Alignments></LandXML>")


@pytest.mark.parametrize(("element", "message"), [
    ('<Spiral length="50" radiusStart="INF" radiusEnd="100" rot="cw" spiType="bloss"><Start>0 0</Start><PI>0 1</PI><End/></Spiral>',
     r"alignment 'x', CoordGeom element 1 \(Spiral\) at station 10: spiral type 'bloss'"),
    ("<IrregularLine><Start>0 0</Start><End>1 1</End></IrregularLine>", r"element 1 \(IrregularLine\) at station 10: IrregularLine cannot"),
    ("<Chain>1 2</Chain>", r"element 1 \(Chain\) at station 10: Chain cannot"),
])  # fmt: skip
def test_refusals_are_named(element, message):
    text = ('<LandXML><Units><Metric linearUnit="meter"/></Units><Alignments><Alignment name="x"><CoordGeom>'
            f'<Line><Start>0 0</Start><End>0 10</End></Line>{element}</CoordGeom></Alignment></Alignments></LandXML>')  # fmt: skip
    with pytest.raises(ValueError, match=message):
        read_landxml(text)


def test_alignpis_only_is_refused_by_name():
    with pytest.raises(ValueError, match="alignment 'MntnRoad': no CoordGeom .*AlignPIs"):
        read_landxml(DATA / "sdms_mntnroad_alignpis.xml")


def test_chord_defined_curve_and_directions_in_degrees_minutes_seconds():
    # a line along 30°15'36" (dir and length only), then a curve of R 100 ft given by its chord only
    text = ('<LandXML><Units><Imperial linearUnit="foot" angularUnit="decimal dd.mm.ss" directionUnit="decimal dd.mm.ss"/></Units>'
            '<Alignments><Alignment name="d" staStart="100"><CoordGeom>'
            '<Line dir="30.1536" length="50"><Start>10 20</Start></Line>'
            '<Curve rot="ccw" radius="100" chord="60"><Start/></Curve>'
            "</CoordGeom></Alignment></Alignments></LandXML>")  # fmt: skip
    (r,) = read_landxml(text, directions="east-ccw")  # placed by dir alone: the file cannot tell its convention
    line, arc = (chain.segments[0] for chain in r.chains)
    heading = math.degrees(math.atan2(line.start_tangent[1], line.start_tangent[0]))
    assert heading == pytest.approx(30 + 15 / 60 + 36 / 3600, abs=1e-12)
    assert tuple(line.start[:2]) == (20.0, 10.0)  # easting 20, northing 10
    assert arc.length == pytest.approx(200 * math.asin(0.3), rel=1e-12)
    assert math.dist(arc.start[:2], arc.end[:2]) == pytest.approx(60.0, rel=1e-12)
    assert r.start_station == 100 and r.stations[1] == pytest.approx(150.0)


def _file_ends(path: Path) -> np.ndarray:
    """Every CoordGeom element's <End> (easting, northing) as the file states it, read without our reader."""
    import xml.etree.ElementTree as ET

    ends = [e for e in ET.parse(path).iter() if e.tag.endswith("}End") or e.tag == "End"]
    return np.array([[float(v) for v in e.text.split()[1::-1]] for e in ends])


def test_mdt_export_in_grads_with_sharp_spirals_and_its_profile():
    path = DATA / "mdt_aplitop_alignment1.xml"
    (r,) = read_landxml(path)
    assert r.name == "Horizontal" and r.units == "m" and len(r.kinds) == 15 and r.kinds.count("Spiral") == 7
    # element 0 is a line onto an arc without a spiral: two runs, the second G2 through every spiral
    assert len(r.chains) == 2 and "at station 10 " in r.breaks[0]
    ends = _file_ends(path)
    assert np.abs(r.chains[0].end[:2] - ends[0]).max() < 1e-6
    # the file's lines and arcs are kept, the spirals solved between them: the chain ends on the file's last
    # line (which it reaches a little earlier or later) and every spiral is within centimetres of its clothoid
    last = r.chains[-1].segments[-1]
    direction = (ends[-1] - last.start[:2]) / math.dist(ends[-1], last.start[:2])
    assert abs(direction[0] * last.end_tangent[1] - direction[1] * last.end_tangent[0]) < 1e-9
    assert 0.0 < r.offset < 0.1 and abs(r.station_shift) < 0.01
    assert r.profile.elevation([0.0, 507.067]) == pytest.approx([365.8, 350.7], abs=1e-9)


def test_mdt_compound_spiral_beyond_any_cubic_of_its_length_is_refused_by_name():
    with pytest.raises(ValueError, match=r"alignment 'Alignment2', CoordGeom element 5 \(Spiral\) at station 3945.2: .* turns 63.8°"):
        read_landxml(DATA / "mdt_aplitop_alignment2.xml", placement="length")


def test_openroads_export_in_us_survey_feet_with_three_coordinates():
    path = DATA / "openroads_indot_twin_branch.xml"
    (r,) = read_landxml(path)
    assert (
        r.units == "ft" and r.kinds == ("Line", "Curve", "Line") and r.start_station == pytest.approx(2103.72056 * US_SURVEY_FOOT / 0.3048)
    )
    ends = _file_ends(path) * (US_SURVEY_FOOT / 0.3048)
    assert np.abs(np.array([c.end[:2] for c in r.chains]) - ends).max() < 1e-6
    assert r.chains[1].segments[0].length == pytest.approx(1705.3152959346885 * US_SURVEY_FOOT / 0.3048, rel=1e-9)
    assert r.profile is not None and len(r.profile.curves) == 4


def test_novapoint_inframodel_profile_with_a_circular_vertical_curve():
    (r,) = read_landxml(DATA / "novapoint_toi_y3.xml")
    assert r.name == "Tie2 oikea" and r.kinds == ("Line",) and r.chain.length == pytest.approx(37.043112, abs=1e-6)
    assert "CircCurve" in r.notes[0] and r.profile.curves[0].length == pytest.approx(9.901082)


def test_zero_length_elements_are_skipped_and_noted_negative_ones_refused():
    head = '<LandXML><Units><Metric linearUnit="meter"/></Units><Alignments><Alignment name="z"><CoordGeom>'
    line = "<Line><Start>0 0</Start><End>0 10</End></Line>"
    curve = '<Curve rot="cw" radius="50" length="{}"><Start>0 10</Start><Center>-50 10</Center></Curve>'
    (r,) = read_landxml(head + line + curve.format(0) + "</CoordGeom></Alignment></Alignments></LandXML>")
    assert r.kinds == ("Line",) and "element 1 (Curve) at station 10: zero length, skipped" in r.notes[0]
    with pytest.raises(ValueError, match=r"element 1 \(Curve\) at station 10: length -5.0 is not positive"):
        read_landxml(head + line + curve.format(-5) + "</CoordGeom></Alignment></Alignments></LandXML>")


def test_written_geometry_is_consistent_as_a_plain_xml_reader_sees_it(tmp_path):
    import xml.etree.ElementTree as ET

    a, _ = _road("ft")
    path = tmp_path / "road.xml"
    write_landxml(a, path, name="rail")
    ns = {"l": "http://www.landxml.org/schema/LandXML-1.2"}
    elements = list(ET.parse(path).getroot().find("l:Alignments/l:Alignment/l:CoordGeom", ns))

    def ne(e, tag):  # (easting, northing) of a point written northing first
        north, east = map(float, e.find(f"l:{tag}", ns).text.split())
        return np.array([east, north])

    for before, after in zip(elements, elements[1:]):
        assert np.abs(ne(before, "End") - ne(after, "Start")).max() < 1e-9  # continuous
        assert float(before.get("staStart")) + float(before.get("length")) == pytest.approx(float(after.get("staStart")), abs=1e-9)
        assert float(before.get("dirEnd", before.get("dir"))) == pytest.approx(float(after.get("dirStart", after.get("dir"))), abs=1e-9)
    for curve in (e for e in elements if e.tag.endswith("Curve")):
        radius = float(curve.get("radius"))
        for tag in ("Start", "End"):
            assert math.dist(ne(curve, tag), ne(curve, "Center")) == pytest.approx(radius, rel=1e-12)
        sweep = math.radians((float(curve.get("dirEnd")) - float(curve.get("dirStart")) + 180) % 360 - 180)
        assert abs(sweep) * radius == pytest.approx(float(curve.get("length")), rel=1e-12)
        assert (sweep > 0) == (curve.get("rot") == "ccw")
    spirals = [e for e in elements if e.tag.endswith("Spiral")]
    assert [(s.get("radiusStart") == "INF", s.get("radiusEnd") == "INF") for s in spirals] == [(True, False), (False, True)] * 2


HOSTILE = ["nan", "inf", "-inf", "0", "-1", "1e308", "1e-308", "", "abc", "5e-324", "1 2 3", "-0"]


@pytest.mark.filterwarnings("error")  # no silent overflow either
@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_any_mutated_export_reads_or_is_refused_with_a_value_error(data):
    """Every number of real exports replaced by hostile text: a result or a ValueError, nothing else."""
    name = data.draw(st.sampled_from(["mdt_aplitop_alignment1.xml", "civil3d_gsg_basic_road.xml", "openroads_indot_twin_branch.xml"]))
    text = (DATA / name).read_text(encoding="utf-8-sig")
    numbers = list(re.finditer(r"-?\d+\.?\d*(?:e-?\d+)?", text))
    for match in sorted(data.draw(st.lists(st.sampled_from(numbers), min_size=1, max_size=4, unique_by=lambda m: m.start())),
                        key=lambda m: -m.start()):  # fmt: skip
        text = text[: match.start()] + data.draw(st.sampled_from(HOSTILE)) + text[match.end() :]
    try:
        for r in read_landxml(text):
            assert all(np.isfinite(c.length) for c in r.chains) and np.isfinite(r.offsets).all()
    except ValueError:
        pass


@pytest.mark.filterwarnings("error")
def test_lengths_near_the_largest_float_do_not_overflow_the_offset_limits():
    """Found by the test above: two Line starts at 1e308 made the alignment's length overflow (a RuntimeWarning)."""
    text = (DATA / "openroads_indot_twin_branch.xml").read_text(encoding="utf-8-sig")
    for start in (1540, 879):  # the x of two Line starts (the test's own numbering of the file's numbers)
        number = re.compile(r"-?\d+\.?\d*(?:e-?\d+)?").match(text, start)
        assert number is not None and number.group(0).startswith("6"), text[start : start + 20]
        text = text[:start] + "1e308" + text[number.end() :]
    try:
        for r in read_landxml(text):
            assert all(np.isfinite(c.length) for c in r.chains) and np.isfinite(r.offsets).all()
    except ValueError:
        pass
