"""OpenDRIVE: exact export checked by the ASAM XSD, the ASAM quality checker and pyxodr; reading and checking."""

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from helpers import independent_check

import spiral_cad as sc
from spiral_cad import Arc, BezierSpiral
from spiral_cad.app.cli import main
from spiral_cad.cad.export import CrossSection, export_opendrive
from spiral_cad.design import Alignment, round_corners
from spiral_cad.io.opendrive import check_opendrive, read_network, read_opendrive

REPO = Path(__file__).resolve().parents[2]
PIS = [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]]


@pytest.fixture(scope="module")
def highway() -> Alignment:
    return Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=80, start_station=10000)


def test_export_passes_the_asam_schema_and_checker_and_pyxodr_reads_the_chain(highway, tmp_path):
    path = tmp_path / "highway.xodr"
    export_opendrive(highway, path)
    result = independent_check(path)
    assert result["schema"] == []
    statuses = result["checker"]
    assert statuses["check_asam_xodr_xml_valid_schema"] == ["completed", 0]
    assert statuses["check_asam_xodr_road_geometry_parampoly3_length_match"] == ["completed", 0]
    assert all(issues == 0 for _, issues in statuses.values()), statuses
    # pyxodr samples every geometry at parameters evenly spaced in [0, 1]: the same u on our segments
    (geometries,) = result["roads"].values()
    assert len(geometries) == len(highway.chain)
    for segment, points in zip(highway.chain, geometries):
        points = np.array(points)
        assert np.abs(segment.point(np.linspace(0.0, 1.0, len(points))) - points).max() <= 1e-9


def test_a_broken_file_fails_the_schema(tmp_path):
    path = tmp_path / "broken.xodr"
    export_opendrive(round_corners([(0, 0), (40, 0), (40, 30)], units="m").chain, path)
    text = path.read_text().replace('pRange="normalized"', 'pRange="sideways"', 1)
    path.write_text(text)
    assert independent_check(path)["schema"]


def test_spirals_are_exact_param_poly3_in_their_local_frame(highway, tmp_path):
    path = tmp_path / "h.xodr"
    export_opendrive(highway, path)
    root = ET.parse(path).getroot()
    assert (root.find("header").get("revMajor"), root.find("header").get("revMinor")) == ("1", "8")
    geometries = root.findall("road/planView/geometry")
    s = 0.0
    for element, segment in zip(geometries, highway.chain):
        assert float(element.get("s")) == pytest.approx(s, abs=1e-9)
        assert float(element.get("length")) == pytest.approx(segment.length, rel=1e-12)
        s += segment.length
        (shape,) = list(element)
        if isinstance(segment, BezierSpiral):
            assert shape.tag == "paramPoly3" and shape.get("pRange") == "normalized"
            assert [float(shape.get(k)) for k in ("aU", "aV", "bV")] == [0.0, 0.0, 0.0] and float(shape.get("bU")) > 0
        elif isinstance(segment, Arc):
            assert shape.tag == "arc" and float(shape.get("curvature")) == pytest.approx(1 / segment.radius, rel=1e-15)
        else:
            assert shape.tag == "line"
    assert float(root.find("road").get("length")) == pytest.approx(highway.chain.length, rel=1e-12)
    assert root.find("road/userData").get("value") == "10000.0"


def test_superelevation_ramps_along_the_spirals_and_falls_to_the_inside(highway, tmp_path):
    path = tmp_path / "h.xodr"
    export_opendrive(highway, path)
    records = [(float(e.get("s")), float(e.get("a")), float(e.get("b"))) for e in ET.parse(path).getroot().iter("superelevation")]
    first = highway.curves[0]  # a right turn: the road falls to the right, positive roll
    e = highway.checks[0].banking
    at_sc = [r for r in records if r[0] == pytest.approx(first.sc - highway.start_station)][0]
    assert first.deflection < 0 and at_sc[1] == pytest.approx(math.atan(e)) and at_sc[2] == 0.0
    second = highway.curves[1]  # a left turn
    assert second.deflection > 0
    assert [r for r in records if r[0] == pytest.approx(second.sc - highway.start_station)][0][1] == pytest.approx(
        -math.atan(highway.checks[1].banking)
    )


def test_lanes_follow_the_cross_section(tmp_path):
    path = tmp_path / "lanes.xodr"
    chain = round_corners([(0, 0), (40, 0), (40, 30)], units="m").chain
    export_opendrive(chain, path, cross_section=CrossSection(driving_lanes=2, lane_width=3.25, shoulder_width=0.0))
    lanes = ET.parse(path).getroot().findall("road/lanes/laneSection/right/lane")
    assert [(lane.get("id"), lane.get("type"), lane.find("width").get("a")) for lane in lanes] == [
        ("-1", "driving", "3.25"),
        ("-2", "driving", "3.25"),
    ]


def test_a_design_in_feet_is_written_in_metres(tmp_path):
    chain = round_corners([(0, 0), (400, 0), (400, 300)], units="ft").chain
    path = tmp_path / "ft.xodr"
    export_opendrive(chain, path)
    root = ET.parse(path).getroot()
    assert float(root.find("road").get("length")) == pytest.approx(chain.length * 0.3048, rel=1e-12)
    assert "design units: ft" in root.find("header/userData").get("value")
    (road,) = read_opendrive(path)
    back = road.chain()
    assert back.units == "m" and back.length == pytest.approx(chain.length * 0.3048, rel=1e-12)


def test_read_back_gives_the_same_chain(highway, tmp_path):
    path = tmp_path / "h.xodr"
    export_opendrive([highway, highway.chain.reversed()], path)
    roads = read_opendrive(path)
    assert [r.id for r in roads] == ["1", "2"] and roads[0].exact
    for road, chain in zip(roads, (highway.chain, highway.chain.reversed())):
        back = road.chain()
        assert [type(s) for s in back] == [type(s) for s in chain]
        for a, b in zip(back, chain):
            assert np.abs(a.point(np.linspace(0, 1, 9)) - b.point(np.linspace(0, 1, 9))).max() <= 1e-9
    report = check_opendrive(path)
    assert report.pieces == 2 and report.passes("G2", pieces=2)


HEADER = '<?xml version="1.0"?>\n<OpenDRIVE><header revMajor="1" revMinor="8"/>{}</OpenDRIVE>'


def road(geometries: str, rid: str = "7") -> str:
    return f'<road id="{rid}" junction="-1" length="1"><planView>{geometries}</planView></road>'


def write(tmp_path, body: str) -> Path:
    path = tmp_path / "hand.xodr"
    path.write_text(HEADER.format(body))
    return path


def test_a_line_into_an_arc_is_only_g1(tmp_path):
    path = write(
        tmp_path,
        road(
            '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
            '<geometry s="10" x="10" y="0" hdg="0" length="5"><arc curvature="0.02"/></geometry>'
        ),
    )
    report = check_opendrive(path)
    (joint,) = report.joints
    assert str(joint.level) == "G1" and joint.curvature_after == pytest.approx(0.02)
    with pytest.raises(ValueError, match="road 7: Chain is not G2 at joint 0"):
        read_opendrive(path)[0].chain()


def test_a_clothoid_into_an_arc_is_g2(tmp_path):
    # clothoid from κ = 0 to 1/50 over 40 m: heading 0.4 rad at its end; the arc continues from there
    k, length = 1 / 50, 40.0
    (road_,) = read_opendrive(
        write(tmp_path, road(f'<geometry s="0" x="0" y="0" hdg="0" length="{length}"><spiral curvStart="0" curvEnd="{k}"/></geometry>'))
    )
    (end,), (tangent,), _ = road_.geometries[0].evaluate([1.0])
    heading = math.atan2(tangent[1], tangent[0])
    assert heading == pytest.approx(k * length / 2, abs=1e-14)
    # the clothoid's end by an independent quadrature of its heading
    from scipy.integrate import quad

    x = quad(lambda s: math.cos(k * s * s / (2 * length)), 0, length, epsabs=0, epsrel=1e-13, limit=200)[0]
    y = quad(lambda s: math.sin(k * s * s / (2 * length)), 0, length, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert end == pytest.approx([x, y], abs=1e-12)
    path = write(
        tmp_path,
        road(
            f'<geometry s="0" x="0" y="0" hdg="0" length="{length}"><spiral curvStart="0" curvEnd="{k}"/></geometry>'
            f'<geometry s="{length}" x="{x!r}" y="{y!r}" hdg="{heading!r}" length="30"><arc curvature="{k}"/></geometry>'
        ),
    )
    report = check_opendrive(path)
    assert [str(j.level) for j in report.joints] == ["G2"]
    assert not read_opendrive(path)[0].exact
    with pytest.raises(ValueError, match="road 7: spiral geometries have no exact Chain form"):
        read_opendrive(path)[0].chain()


def test_param_poly3_in_both_ranges_and_the_deprecated_poly3_are_evaluated(tmp_path):
    spiral = sc.BezierSpiral((0, 0), (1, 0), 0.4, 0.05)
    b = spiral.control_points
    du, cu, ddu = (c.tolist() for c in (3 * (b[1] - b[0]), 3 * (b[2] - 2 * b[1] + b[0]), b[3] - 3 * b[2] + 3 * b[1] - b[0]))
    length = spiral.length
    normalized = (f'aU="0" bU="{du[0]!r}" cU="{cu[0]!r}" dU="{ddu[0]!r}" aV="0" bV="{du[1]!r}" cV="{cu[1]!r}" '
                  f'dV="{ddu[1]!r}" pRange="normalized"')  # fmt: skip
    arc_length = (f'aU="0" bU="{du[0] / length!r}" cU="{cu[0] / length**2!r}" dU="{ddu[0] / length**3!r}" aV="0" '
                  f'bV="{du[1] / length!r}" cV="{cu[1] / length**2!r}" dV="{ddu[1] / length**3!r}" pRange="arcLength"')  # fmt: skip
    body = "".join(road(f'<geometry s="0" x="0" y="0" hdg="0" length="{length!r}"><paramPoly3 {p}/></geometry>', rid)
                   for rid, p in (("1", normalized), ("2", arc_length)))  # fmt: skip
    body += road('<geometry s="0" x="0" y="0" hdg="0" length="2"><poly3 a="0" b="0" c="0.1" d="0"/></geometry>', "3")
    roads = read_opendrive(write(tmp_path, body))
    for r in roads[:2]:
        back = r.chain()[0]
        assert np.abs(back.control_points - spiral.control_points).max() <= 1e-12
    (p,), (t,), (k,) = roads[2].geometries[0].evaluate([1.0])
    # v = 0.1 u²: arc length 2 reached at u ≈ 1.8, curvature 0.2/(1 + (0.2u)²)^1.5
    u = p[0]
    assert p[1] == pytest.approx(0.1 * u * u, rel=1e-12) and k == pytest.approx(0.2 / (1 + (0.2 * u) ** 2) ** 1.5, rel=1e-12)
    assert math.asinh(0.2 * u) / 0.4 + 0.2 * u * math.sqrt(1 + (0.2 * u) ** 2) / 0.4 == pytest.approx(2.0, rel=1e-12)


@pytest.mark.parametrize(
    "body, message",
    [
        ("<OpenDRIVE><road", "not well-formed XML"),
        ('<road id="3" junction="-1" length="1"></road>', "road 3 has no planView"),
        (
            road('<geometry s="0" x="0" y="0" hdg="0" length="1"><clothoid/></geometry>', "4"),
            "road 4, planView geometry 0: needs exactly one of line, arc, spiral, paramPoly3, poly3; found clothoid",
        ),
        (
            road('<geometry s="0" x="0" y="0" hdg="0" length="nan"><line/></geometry>', "5"),
            "road 5, planView geometry 0: length must be finite",
        ),
        (
            road('<geometry s="0" x="0" y="0" hdg="0" length="-2"><line/></geometry>', "6"),
            "road 6, planView geometry 0: length must be positive",
        ),
        (
            road(
                '<geometry s="5" x="0" y="0" hdg="0" length="1"><line/></geometry>'
                '<geometry s="2" x="1" y="0" hdg="0" length="1"><line/></geometry>',
                "8",
            ),
            "road 8, planView geometry 1: s = 2.0 is not after",
        ),
        (
            road('<geometry s="0" x="0" y="0" hdg="0" length="1"><arc/></geometry>', "9"),
            "road 9, planView geometry 0 <arc>: missing attribute curvature",
        ),
    ],
)
def test_bad_opendrive_is_refused_by_road_and_element(tmp_path, capsys, body, message):
    path = tmp_path / "bad.xodr"
    path.write_text(body if body.startswith("<OpenDRIVE><road") else HEADER.format(body))
    with pytest.raises(ValueError, match=message):
        read_opendrive(path)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "Traceback" not in err


def test_cli_checks_opendrive(highway, tmp_path, capsys):
    path = tmp_path / "h.xodr"
    export_opendrive(highway, path)
    assert main(["check", str(path), "--require", "G2"]) == 0
    assert "OK: 1 road of 13 geometries" in capsys.readouterr().out
    g1 = write(
        tmp_path,
        road(
            '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
            '<geometry s="10" x="10" y="0" hdg="0" length="5"><arc curvature="0.02"/></geometry>'
        ),
    )
    assert main(["check", str(g1), "--require", "G2"]) == 1
    assert "below the required G2" in capsys.readouterr().out


def test_demo_writes_a_valid_highway_xodr(tmp_path):
    assert main(["demo", "--out", str(tmp_path), "--no-plots"]) == 0
    result = independent_check(tmp_path / "highway.xodr")
    assert result["schema"] == [] and all(issues == 0 for _, issues in result["checker"].values())
    assert "verdict" in (tmp_path / "highway_criteria.csv").read_text()
    # the highway in 3-D: pyxodr's elevation is the designed profile (s along its 0.5 m polyline)
    from spiral_cad.app.cli import DEMO_DESIGN
    from spiral_cad.app.designfile import build

    (highway, *_) = build(DEMO_DESIGN)[1]
    ((distance, z),) = [np.array(v).T for v in result["elevation"].values()]
    assert np.abs(z - highway.profile.elevation(highway.source.start_station + distance)).max() <= 1e-5
    assert len(ET.parse(tmp_path / "highway.xodr").getroot().findall("road/lateralProfile/superelevation")) > 4


# ------------------------------------------------------ hostile numbers


def line_at(s: str, x: str, length: str) -> str:
    return f'<geometry s="{s}" x="{x}" y="0" hdg="0" length="{length}"><line/></geometry>'


@pytest.mark.parametrize(
    "body, message",
    [
        (
            road(line_at("0", "0", "1e308") + line_at("1e308", "1e308", "1e308")),
            r"road 7, planView geometry 1 <line>: its end point is not a finite number \(x=1e\+308",
        ),
        (
            road('<geometry s="0" x="0" y="0" hdg="0" length="10"><spiral curvStart="-1e300" curvEnd="0"/></geometry>'),
            r"road 7, planView geometry 0 <spiral>: cannot be evaluated \(.*curvStart=-1e\+300",
        ),
        (
            road(line_at("0", "0", "10") + '<geometry s="10" x="10" y="0" hdg="0" length="10"><arc curvature="1e308"/></geometry>'),
            r"road 7, planView geometry 1 <arc>: its end point is not a finite number .*curvature=1e\+308",
        ),
        (road(line_at("0", "0", "10")).replace('length="1"', 'length="abc"'), r"road 7: length must be a number; got 'abc'"),
        (road(line_at("0", "0", "10")).replace('length="1"', 'length="nan"'), r"road 7: length must be finite; got 'nan'"),
        (road(line_at("0", "0", "10")).replace('length="1"', 'length="-5"'), r"road 7: length must be positive"),
        (
            road(line_at("0", "0", "10"), "&#10;" + "r" * 100).replace('length="1"', 'length="abc"'),
            r"road '\\nr{39}'…: length must be a number",
        ),  # a newline and 100 letters: quoted and cut
    ],
)
def test_hostile_numbers_are_refused_by_road_and_element(tmp_path, capsys, body, message):
    path = write(tmp_path, body)
    with pytest.raises(ValueError, match=message):
        check_opendrive(path)
    assert main(["check", str(path), "--require", "G2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "Traceback" not in err


def test_a_model_wider_than_the_float_range_names_its_coordinates(tmp_path):
    path = write(tmp_path, road(line_at("0", "-1.7e308", "1e300") + line_at("1e300", "1.7e308", "1e300")))
    with pytest.raises(ValueError, match=r"hand.xodr: the model spans x = -1.7e\+308 to 1.70*1e\+308, wider than a float"):
        check_opendrive(path)


def test_a_zero_speed_param_poly3_after_a_line_is_unmeasurable_never_g2(tmp_path, capsys):
    # bU = bV = 0: no tangent at its start (0/0), where a 90° kink hides; NaN used to pass every comparison
    kink = road(
        line_at("0", "0", "10") + '<geometry s="10" x="10" y="0" hdg="0" length="10">'
        '<paramPoly3 aU="0" bU="0" cU="0" dU="1" aV="0" bV="0" cV="1" dV="0" pRange="normalized"/></geometry>'
    )
    path = write(tmp_path, kink)
    (joint,) = check_opendrive(path).joints
    assert str(joint.level) == "unmeasurable" and math.isnan(joint.angle)
    for level in ("G0", "G1", "G2"):
        assert main(["check", str(path), "--require", level]) == 1
        assert "FAIL: worst joint is unmeasurable" in capsys.readouterr().out
    with pytest.raises(ValueError, match="road 7"):
        read_opendrive(path)[0].chain()


def test_not_a_file_is_refused_without_reading(tmp_path):
    (tmp_path / "dir.xodr").mkdir()
    os.mkfifo(tmp_path / "fifo.xodr")  # would block a reader for ever
    for name in ("dir.xodr", "fifo.xodr"):
        with pytest.raises(ValueError, match="not a regular file"):
            read_opendrive(tmp_path / name)
    with pytest.raises(ValueError, match="no such file"):
        read_opendrive(tmp_path / "none.xodr")


# ---------------------------------------------------- property: any file

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-1e3, 1e3).map(repr),
    st.integers(-10, 10).map(str),
    st.sampled_from(["0", "-0", "1e308", "-1e308", "1e-320", "5e-324", "1e300", "nan", "inf", "1e400", "abc", "", " 1 ", "0x10", "1_0"]),
)
KINDS = {"line": [], "arc": ["curvature"], "spiral": ["curvStart", "curvEnd"], "poly3": list("abcd"),
         "paramPoly3": [f"{c}{a}" for a in "UV" for c in "abcd"]}  # fmt: skip


@st.composite
def geometry_elements(draw) -> str:
    kind = draw(st.sampled_from(sorted(KINDS) + ["clothoid"]))
    attributes = {name: draw(NUMBERS) for name in KINDS.get(kind, []) if draw(st.booleans()) or draw(st.booleans())}
    if kind == "paramPoly3" and draw(st.booleans()):
        attributes["pRange"] = draw(st.sampled_from(["normalized", "arcLength", "both"]))
    head = {name: draw(NUMBERS) for name in ("s", "x", "y", "hdg", "length") if draw(st.integers(0, 9))}
    text = " ".join(f'{k}="{v}"' for k, v in head.items())
    inner = " ".join(f'{k}="{v}"' for k, v in attributes.items())
    return f"<geometry {text}><{kind} {inner}/></geometry>"


@st.composite
def documents(draw) -> str:
    roads = []
    for rid in range(draw(st.integers(1, 2))):
        length = draw(st.one_of(st.none(), NUMBERS))
        geometries = "".join(draw(st.lists(geometry_elements(), min_size=0, max_size=4)))
        roads.append(
            f'<road id="{rid}"' + (f' length="{length}"' if length is not None else "") + f"><planView>{geometries}</planView></road>"
        )
    return HEADER.format("".join(roads))


@st.composite
def mutated_exports(draw) -> str:
    """A valid export with one number replaced."""
    text = MUTABLE_EXPORT
    spots = [m for m in __import__("re").finditer(r'="(-?[0-9][^"]*)"', text)]
    spot = draw(st.sampled_from(spots))
    return text[: spot.start(1)] + draw(NUMBERS) + text[spot.end(1) :]


def _small_export() -> str:
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "small.xodr"
        export_opendrive(round_corners([(0, 0), (40, 0), (40, 30), (80, 30)], units="m").chain, path)
        return path.read_text()


MUTABLE_EXPORT = _small_export()


@settings(max_examples=150, deadline=None)
@given(text=st.one_of(documents(), mutated_exports()))
def test_any_file_reads_as_verified_chains_or_a_value_error(text):
    import tempfile
    import warnings

    from spiral_cad import Chain
    from spiral_cad.continuity.joints import Continuity

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "any.xodr"
        path.write_text(text)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the reader and checker warn about nothing: they grade it
            try:
                roads = read_opendrive(path)
            except ValueError:
                return
            report = None
            try:
                report = check_opendrive(path)
            except ValueError as error:
                assert "model spans" in str(error)  # the only refusal left once every element read
        if report is not None:
            assert all(isinstance(j.level, Continuity) for j in report.joints)
            assert len(report.wires) == len(roads)
        for road_ in roads:
            try:
                chain = road_.chain()
            except ValueError as error:
                assert str(error).startswith(f"road {road_.id}")
            else:
                assert isinstance(chain, Chain) and math.isfinite(chain.length)


def test_two_roads_of_one_id_are_refused_by_name(tmp_path):
    line = '<geometry s="0" x="{x}" y="0" hdg="0" length="10"><line/></geometry>'
    body = "".join(
        f'<road id="{rid}" length="10" junction="-1"><planView>{line.format(x=x)}</planView></road>'
        for rid, x in (("1", 0), ("2", 10), ("1", 500))
    )
    with pytest.raises(ValueError, match=r"roads 0 and 2 \(in file order\) both have id '1'; ids must be unique"):
        read_network(write(tmp_path, body))
