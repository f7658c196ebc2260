"""OpenDRIVE: exact export checked by the ASAM XSD, the ASAM quality checker and pyxodr; reading and checking."""

import json
import math
import os
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import spiral_cad as sc
from spiral_cad import Arc, BezierSpiral
from spiral_cad.cli import main
from spiral_cad.design import Alignment, round_corners
from spiral_cad.export import CrossSection, export_opendrive
from spiral_cad.formats.opendrive import check_opendrive, read_opendrive

REPO = Path(__file__).resolve().parent.parent
PIS = [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]]


def tools_python() -> str:
    """The python of the OpenDRIVE tools environment that `make test` builds (numpy < 2: not ours)."""
    path = os.environ.get("SPIRAL_CAD_XODR_TOOLS") or str(REPO / ".venv-tools" / "bin" / "python")
    if not Path(path).exists():
        pytest.skip("the OpenDRIVE tools environment is missing: run `make test`")
    return path


def independent_check(path: Path) -> dict:
    done = subprocess.run([tools_python(), str(REPO / "tests" / "tools" / "xodr_check.py"), str(path)],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout)


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
    assert [r for r in records if r[0] == pytest.approx(second.sc - highway.start_station)][0][1] == pytest.approx(-math.atan(highway.checks[1].banking))


def test_lanes_follow_the_cross_section(tmp_path):
    path = tmp_path / "lanes.xodr"
    chain = round_corners([(0, 0), (40, 0), (40, 30)], units="m").chain
    export_opendrive(chain, path, cross_section=CrossSection(driving_lanes=2, lane_width=3.25, shoulder_width=0.0))
    lanes = ET.parse(path).getroot().findall("road/lanes/laneSection/right/lane")
    assert [(lane.get("id"), lane.get("type"), lane.find("width").get("a")) for lane in lanes] == [("-1", "driving", "3.25"), ("-2", "driving", "3.25")]


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
    path = write(tmp_path, road('<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
                                '<geometry s="10" x="10" y="0" hdg="0" length="5"><arc curvature="0.02"/></geometry>'))
    report = check_opendrive(path)
    (joint,) = report.joints
    assert str(joint.level) == "G1" and joint.curvature_after == pytest.approx(0.02)
    with pytest.raises(ValueError, match="road 7: Chain is not G2 at joint 0"):
        read_opendrive(path)[0].chain()


def test_a_clothoid_into_an_arc_is_g2(tmp_path):
    # clothoid from κ = 0 to 1/50 over 40 m: heading 0.4 rad at its end; the arc continues from there
    k, length = 1 / 50, 40.0
    (road_,) = read_opendrive(write(tmp_path, road(
        f'<geometry s="0" x="0" y="0" hdg="0" length="{length}"><spiral curvStart="0" curvEnd="{k}"/></geometry>')))
    (end,), (tangent,), _ = road_.geometries[0].evaluate([1.0])
    heading = math.atan2(tangent[1], tangent[0])
    assert heading == pytest.approx(k * length / 2, abs=1e-14)
    # the clothoid's end by an independent quadrature of its heading
    from scipy.integrate import quad

    x = quad(lambda s: math.cos(k * s * s / (2 * length)), 0, length, epsabs=0, epsrel=1e-13, limit=200)[0]
    y = quad(lambda s: math.sin(k * s * s / (2 * length)), 0, length, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert end == pytest.approx([x, y], abs=1e-12)
    path = write(tmp_path, road(
        f'<geometry s="0" x="0" y="0" hdg="0" length="{length}"><spiral curvStart="0" curvEnd="{k}"/></geometry>'
        f'<geometry s="{length}" x="{x!r}" y="{y!r}" hdg="{heading!r}" length="30"><arc curvature="{k}"/></geometry>'))
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
        (road('<geometry s="0" x="0" y="0" hdg="0" length="1"><clothoid/></geometry>', "4"),
         "road 4, planView geometry 0: needs exactly one of line, arc, spiral, paramPoly3, poly3; found clothoid"),
        (road('<geometry s="0" x="0" y="0" hdg="0" length="nan"><line/></geometry>', "5"), "road 5, planView geometry 0: length must be finite"),
        (road('<geometry s="0" x="0" y="0" hdg="0" length="-2"><line/></geometry>', "6"), "road 6, planView geometry 0: length must be positive"),
        (road('<geometry s="5" x="0" y="0" hdg="0" length="1"><line/></geometry>'
              '<geometry s="2" x="1" y="0" hdg="0" length="1"><line/></geometry>', "8"), "road 8, planView geometry 1: s = 2.0 is not after"),
        (road('<geometry s="0" x="0" y="0" hdg="0" length="1"><arc/></geometry>', "9"), "road 9, planView geometry 0 <arc>: missing attribute curvature"),
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
    g1 = write(tmp_path, road('<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
                              '<geometry s="10" x="10" y="0" hdg="0" length="5"><arc curvature="0.02"/></geometry>'))
    assert main(["check", str(g1), "--require", "G2"]) == 1
    assert "below the required G2" in capsys.readouterr().out


def test_demo_writes_a_valid_highway_xodr(tmp_path):
    assert main(["demo", "--out", str(tmp_path), "--no-plots"]) == 0
    result = independent_check(tmp_path / "highway.xodr")
    assert result["schema"] == [] and all(issues == 0 for _, issues in result["checker"].values())
    assert "verdict" in (tmp_path / "highway_criteria.csv").read_text()
