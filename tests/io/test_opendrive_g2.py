"""An OpenDRIVE file made G2 in place (spiral_cad.io.opendrive_g2; ``spiral-cad g2 road.xodr``).

The judge is the OpenDRIVE formulas, written here from the standard (line, arc, paramPoly3 with pRange
normalized), not our reader: every joint of a rewritten road continuous in point, heading and curvature;
the new reference line within D of the old one, measured both ways on dense samples; the road's ends and
headings unchanged; every element outside the planView kept, its ``s`` positions moved onto the new line
within D of where they were; and the rest of the document equal to the input.
"""

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spiral_cad.app.cli import main
from spiral_cad.io.opendrive_g2 import rewrite_opendrive_g2

DATA = Path(__file__).resolve().parents[1] / "data"
ESMINI = DATA / "opendrive" / "esmini_fade_roadmarks.xodr"


def local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


# ------------------------------------------------------------------ the standard's formulas


def geometry_frames(g: ET.Element, t: np.ndarray):
    """Points, headings and curvatures of one <geometry> at t ∈ [0, 1] of its length (paramPoly3: of p)."""
    x0, y0, hdg, length = (float(g.get(k)) for k in ("x", "y", "hdg", "length"))
    (shape,) = [c for c in g if local(c.tag) in ("line", "arc", "paramPoly3")]
    kind = local(shape.tag)
    if kind in ("line", "arc"):
        k = float(shape.get("curvature", 0.0))
        s = t * length
        heading = hdg + k * s
        if k == 0.0:
            x, y = x0 + s * math.cos(hdg), y0 + s * math.sin(hdg)
        else:
            x = x0 + (np.sin(heading) - math.sin(hdg)) / k
            y = y0 - (np.cos(heading) - math.cos(hdg)) / k
        return np.column_stack([x + 0 * s, y + 0 * s]), heading, np.full_like(s, k)
    assert shape.get("pRange") == "normalized"
    a = {name: float(shape.get(name)) for name in ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV")}
    p = t
    u = a["aU"] + a["bU"] * p + a["cU"] * p**2 + a["dU"] * p**3
    v = a["aV"] + a["bV"] * p + a["cV"] * p**2 + a["dV"] * p**3
    du, dv = a["bU"] + 2 * a["cU"] * p + 3 * a["dU"] * p**2, a["bV"] + 2 * a["cV"] * p + 3 * a["dV"] * p**2
    ddu, ddv = 2 * a["cU"] + 6 * a["dU"] * p, 2 * a["cV"] + 6 * a["dV"] * p
    c, s = math.cos(hdg), math.sin(hdg)
    points = np.column_stack([x0 + u * c - v * s, y0 + u * s + v * c])
    return points, hdg + np.arctan2(dv, du), (du * ddv - dv * ddu) / (du * du + dv * dv) ** 1.5


def geometries(road: ET.Element) -> list[ET.Element]:
    (plan,) = [c for c in road if local(c.tag) == "planView"]
    return [g for g in plan if local(g.tag) == "geometry"]


def dense(road: ET.Element, per_metre: float = 50.0) -> tuple[np.ndarray, np.ndarray]:
    """Points along the road's reference line and their s (the file's s of each geometry plus the arc length
    along it, measured on the points for a paramPoly3)."""
    points, stations = [], []
    for g in geometries(road):
        n = max(int(float(g.get("length")) * per_metre), 50)
        t = np.linspace(0.0, 1.0, n)
        p, _, _ = geometry_frames(g, t)
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
        first = 1 if points else 0  # a joint's point once: the polyline's edges on both sides of it
        points.append(p[first:])
        stations.append(float(g.get("s")) + along[first:])
    return np.vstack(points), np.concatenate(stations)


#: What the dense polylines may add to a distance: their chords' sag (2 cm apart on radii ≥ 30 m: ≤ 1.7e-6 m).
SAG = 2e-6


def polyline_distance(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance of each point to the polyline through ``line`` (the nearest vertex, then its two edges)."""
    _, i = cKDTree(line).query(points)
    best = np.full(len(points), np.inf)
    for a, b in ((i - 1, i), (i, i + 1)):
        a, b = np.clip(a, 0, len(line) - 1), np.clip(b, 0, len(line) - 1)
        d = line[b] - line[a]
        length2 = np.maximum((d * d).sum(axis=1), 1e-300)
        h = np.clip(((points - line[a]) * d).sum(axis=1) / length2, 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(points - line[a] - h[:, None] * d).T))
    return best


def outside(road: ET.Element) -> list[ET.Element]:
    """The road's elements outside its planView, in document order."""
    return [e for child in road if local(child.tag) != "planView" for e in child.iter()]


def point_at(road: ET.Element, s: float) -> np.ndarray:
    points, stations = dense(road, 200.0)
    return np.array([np.interp(s, stations, points[:, 0]), np.interp(s, stations, points[:, 1])])


# ------------------------------------------------------------------ a network a designer would bring


def _place(pieces):
    """<geometry> texts of pieces ("line", length) / ("arc", length, curvature) from the origin along +x."""
    x = y = hdg = s = 0.0
    out = []
    for piece in pieces:
        kind, length = piece[0], piece[1]
        k = piece[2] if kind == "arc" else 0.0
        shape = "<line/>" if kind == "line" else f'<arc curvature="{k!r}"/>'
        out.append(f'<geometry s="{s!r}" x="{x!r}" y="{y!r}" hdg="{hdg!r}" length="{length!r}">{shape}</geometry>')
        if k == 0.0:
            x, y = x + length * math.cos(hdg), y + length * math.sin(hdg)
        else:
            end = hdg + k * length
            x, y = x + (math.sin(end) - math.sin(hdg)) / k, y - (math.cos(end) - math.cos(hdg)) / k
            hdg = end
        s += length
    return "\n      ".join(out), s, (x, y, hdg)


MAIN = [("line", 100.0), ("arc", 100.0, 1 / 200), ("line", 80.0), ("arc", 60.0, -1 / 150), ("line", 60.0)]
ENDS_ON_ARC = [("line", 40.0), ("arc", 30.0, 1 / 60)]
LOOP_END = [("line", 20.0), ("arc", 200.0, 1 / 50)]  # a loop ramp: its end arc turns 4 rad
# CARLA Town06's road 77: a compound curve of two nearly equal radii from its start: no tighter start arc nests in the next
COMPOUND_START = [("arc", 8.283, 1 / 50.6), ("arc", 29.686, 1 / 50.94), ("line", 11.52)]


def network() -> str:
    main_plan, main_length, (ex, ey, eh) = _place(MAIN)
    arc_plan, arc_length, _ = _place(ENDS_ON_ARC)
    short_plan, short_length, _ = _place(LOOP_END)
    compound_plan, compound_length, _ = _place(COMPOUND_START)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE>
  <!-- a comment the file keeps -->
  <header revMajor="1" revMinor="6" name="g2 test" vendor="tests" north="300" south="-10" east="500" west="-10">
    <geoReference>+proj=utm +zone=32 +ellps=WGS84</geoReference>
    <offset x="1000.5" y="-20.25" z="0" hdg="0.1"/>
    <userData code="vendor:x" value="keep me"/>
  </header>
  <road name="main" length="{main_length!r}" id="1" junction="-1" rule="RHT" vendor:flag="kept" xmlns:vendor="urn:vendor">
    <link><successor elementType="junction" elementId="100"/></link>
    <type s="0.0" type="rural"><speed max="80" unit="km/h"/></type>
    <type s="180.0" type="town"/>
    <planView>
      {main_plan}
    </planView>
    <elevationProfile>
      <elevation s="0.0" a="10.0" b="0.02" c="0.0" d="0.0"/>
      <elevation s="120.0" a="12.4" b="0.02" c="-0.0001" d="1e-7"/>
      <elevation s="250.0" a="13.4" b="0.0" c="0.0" d="0.0"/>
    </elevationProfile>
    <lateralProfile>
      <superelevation s="0.0" a="0.0" b="0.0" c="0.0" d="0.0"/>
      <superelevation s="110.0" a="0.0" b="0.001" c="0.0" d="0.0"/>
    </lateralProfile>
    <lanes>
      <laneOffset s="0.0" a="0.0" b="0.0" c="0.0" d="0.0"/>
      <laneOffset s="200.0" a="0.0" b="0.01" c="0.0" d="0.0"/>
      <laneSection s="0.0">
        <center><lane id="0" type="none" level="false"><roadMark sOffset="0.0" type="broken"/></lane></center>
        <right><lane id="-1" type="driving" level="false">
          <width sOffset="0.0" a="3.5" b="0.0" c="0.0" d="0.0"/>
          <width sOffset="60.0" a="3.5" b="0.01" c="0.0" d="0.0"/>
          <roadMark sOffset="0.0" type="solid"/>
        </lane></right>
      </laneSection>
      <laneSection s="150.5">
        <right><lane id="-1" type="driving" level="false"><width sOffset="0.0" a="3.5" b="0.0" c="0.0" d="0.0"/>
          <roadMark sOffset="30.0" type="solid"><type name="x" width="0.1"><line length="3" space="9" tOffset="0" sOffset="2"/></type></roadMark>
        </lane></right>
      </laneSection>
      <laneSection s="300.0">
        <right><lane id="-1" type="driving" level="false"><width sOffset="0.0" a="3.5" b="0.0" c="0.0" d="0.0"/></lane></right>
      </laneSection>
    </lanes>
    <objects>
      <object id="o1" s="50.0" t="-5.0" type="pole" zOffset="0"/>
      <object id="o2" s="170.0" t="5.0" type="tree" zOffset="0"><repeat s="170.0" length="50" distance="10" tStart="5" tEnd="5" zOffsetStart="0" zOffsetEnd="0" heightStart="1" heightEnd="1"/></object>
      <object id="o3" s="{main_length - 1.0!r}" t="-6.0" type="pole" zOffset="0"/>
    </objects>
    <signals>
      <signal id="s1" s="200.0" t="-4.0" dynamic="no" orientation="+" zOffset="1.5" type="274" subtype="80" country="DE"/>
    </signals>
    <vendorThing answer="42"/>
  </road>
  <road name="connector" length="20.0" id="2" junction="100">
    <link><predecessor elementType="road" elementId="1" contactPoint="end"/><successor elementType="road" elementId="3" contactPoint="start"/></link>
    <planView><geometry s="0.0" x="{ex!r}" y="{ey!r}" hdg="{eh!r}" length="20.0"><line/></geometry></planView>
  </road>
  <road name="ends on an arc" length="{arc_length!r}" id="3" junction="-1">
    <planView>
      {arc_plan}
    </planView>
  </road>
  <road name="loop ramp" length="{short_length!r}" id="4" junction="-1">
    <planView>
      {short_plan}
    </planView>
  </road>
  <road name="clothoid after a line" length="50.0" id="5" junction="-1">
    <planView>
      <geometry s="0.0" x="0.0" y="-50.0" hdg="0.0" length="30.0"><line/></geometry>
      <geometry s="30.0" x="30.0" y="-50.0" hdg="0.0" length="20.0"><spiral curvStart="0.01" curvEnd="0.02"/></geometry>
    </planView>
  </road>
  <road name="compound start" length="{compound_length!r}" id="6" junction="-1">
    <planView>
      {compound_plan}
    </planView>
  </road>
  <junction id="100" name="j">
    <connection id="0" incomingRoad="1" connectingRoad="2" contactPoint="start"><laneLink from="-1" to="-1"/></connection>
  </junction>
</OpenDRIVE>
"""


@pytest.fixture
def made(tmp_path):
    source, target = tmp_path / "net.xodr", tmp_path / "net_g2.xodr"
    source.write_text(network(), encoding="utf-8")
    report = rewrite_opendrive_g2(source, target, 0.05)
    return source, target, report


def roads(path: Path) -> dict[str, ET.Element]:
    return {r.get("id"): r for r in ET.parse(path).getroot() if local(r.tag) == "road"}


# ------------------------------------------------------------------ the tests


def test_every_joint_of_a_rewritten_road_is_g2_by_the_standards_formulas(made):
    _, target, report = made
    road = roads(target)["1"]
    items = geometries(road)
    assert len(items) > len(MAIN) and any(c.tag == "paramPoly3" for g in items for c in g)
    for a, b in zip(items, items[1:]):
        (pa, ha, ka), (pb, hb, kb) = geometry_frames(a, np.array([1.0])), geometry_frames(b, np.array([0.0]))
        assert np.hypot(*(pa[0] - pb[0])) < 1e-7
        assert abs(math.remainder(ha[0] - hb[0], 2 * math.pi)) < 1e-8
        assert abs(ka[0] - kb[0]) < 1e-7
    # s runs on, each geometry's length is its arc length, the road's length is their sum
    for a, b in zip(items, items[1:]):
        assert float(b.get("s")) == pytest.approx(float(a.get("s")) + float(a.get("length")), abs=1e-9)
    for g in items:
        p, _, _ = geometry_frames(g, np.linspace(0.0, 1.0, 4001))
        assert np.hypot(*np.diff(p, axis=0).T).sum() == pytest.approx(float(g.get("length")), rel=1e-7)
    assert float(road.get("length")) == pytest.approx(float(items[-1].get("s")) + float(items[-1].get("length")), abs=1e-9)
    # the report: the road made G2 with its measured deviation, every joint changed
    (path,) = [p for p in report.paths if p.name.startswith("road 1 ")]
    assert path.made and path.changed == path.joints == len(MAIN) - 1 and 0.0 < path.deviation <= 0.05


def test_the_new_reference_line_lies_within_the_bound_both_ways_and_keeps_its_ends(made):
    source, target, _ = made
    old, new = roads(source)["1"], roads(target)["1"]
    (p_old, _), (p_new, _) = dense(old), dense(new)
    there, back = polyline_distance(p_old, p_new).max(), polyline_distance(p_new, p_old).max()
    assert 0.02 < max(there, back) <= 0.05 + SAG  # the transitions use the bound, and stay within it
    for which in (0, -1):
        g_old, g_new = geometries(old)[which], geometries(new)[which]
        t = np.array([0.0 if which == 0 else 1.0])
        (a, ha, ka), (b, hb, kb) = geometry_frames(g_old, t), geometry_frames(g_new, t)
        assert np.hypot(*(a[0] - b[0])) < 1e-9 and abs(math.remainder(ha[0] - hb[0], 2 * math.pi)) < 1e-12 and ka[0] == kb[0]


def test_s_positions_move_onto_the_new_line_and_none_lies_past_its_end(made):
    source, target, report = made
    old, new = roads(source)["1"], roads(target)["1"]
    new_length = float(new.get("length"))
    assert new_length < float(old.get("length"))  # transitions cut the curves
    pairs = [(a, b) for a, b in zip(outside(old), outside(new)) if "s" in a.attrib]
    assert len(pairs) >= 15
    for a, b in pairs:
        s_old, s_new = float(a.get("s")), float(b.get("s"))
        assert 0.0 <= s_new <= new_length
        # the point at the new s lies within the bound of the old point at the old s (nearest-point mapping)
        assert np.hypot(*(point_at(old, s_old) - point_at(new, s_new))) <= 0.05 + SAG, (a.tag, a.attrib)

    # an sOffset stands for its parent's position plus it (a lane section's s, a road mark's sOffset): that
    # road position moves onto the new line too
    def offsets(road):
        out = []
        for section in road.iter():
            if local(section.tag) == "laneSection":
                for lane in section.iter():
                    for mark in lane:
                        if "sOffset" in mark.attrib:
                            at = float(section.get("s")) + float(mark.get("sOffset"))
                            out.append(at)
                            out += [
                                at + float(inner.get("sOffset")) for inner in mark.iter() if inner is not mark and "sOffset" in inner.attrib
                            ]
        return out

    moved = 0
    for s_old, s_new in zip(offsets(old), offsets(new), strict=True):
        assert 0.0 <= s_new <= new_length and np.hypot(*(point_at(old, s_old) - point_at(new, s_new))) <= 0.05 + SAG
        moved += s_new != s_old
    assert moved >= 3
    # the object 1 m before the old end is 1 m before the new end: the last line is kept up to the end
    (o3,) = [o for o in new.iter() if o.get("id") == "o3"]
    assert float(o3.get("s")) == pytest.approx(new_length - 1.0, abs=1e-9)

    # a cubic past a transition is rescaled to its interval: the same elevation at its interval's ends
    def elevation(road, s):
        rows = sorted((float(e.get("s")), *(float(e.get(k)) for k in "abcd")) for e in road.iter() if local(e.tag) == "elevation")
        s0, a, b, c, d = [r for r in rows if r[0] <= s + 1e-12][-1]
        ds = s - s0
        return a + b * ds + c * ds**2 + d * ds**3

    old_s = [float(e.get("s")) for e in old.iter() if local(e.tag) == "elevation"] + [float(old.get("length"))]
    new_s = [float(e.get("s")) for e in new.iter() if local(e.tag) == "elevation"] + [new_length]
    for k in range(len(old_s) - 1):
        assert elevation(new, new_s[k + 1] - 1e-9) == pytest.approx(elevation(old, old_s[k + 1] - 1e-9), abs=1e-6)
    (note,) = [n for n in report.notes if n.startswith("road 1 ")]
    assert "moved to the nearest point of the new reference line" in note and "rescaled" in note


def without(path: Path) -> str:
    """The document without the rewritten road's planView geometries and the attributes the rewrite moves."""
    root = ET.parse(path).getroot()
    for e in root.iter():
        for child in list(e):
            if local(child.tag) == "geometry":
                e.remove(child)
        if local(e.tag) == "road":
            e.attrib.pop("length", None)
        for name in ("s", "sOffset", "b", "c", "d"):
            e.attrib.pop(name, None)
        e.text, e.tail = (e.text or "").strip(), (e.tail or "").strip()
    return ET.tostring(root, encoding="unicode")


def test_everything_outside_the_planview_is_kept(made):
    source, target, report = made
    assert without(source) == without(target)
    # the roads not made G2 are kept exactly, geometries and all
    for road in ("2", "5", "6"):
        assert ET.tostring(roads(source)[road]) == ET.tostring(roads(target)[road])
    text = target.read_text(encoding="utf-8")
    assert "<!-- a comment the file keeps -->" in text and 'vendor:flag="kept"' in text and "urn:vendor" in text


@pytest.mark.parametrize("road", ["3", "4"])  # an arc of 0.5 rad, a loop of 4 rad
def test_a_road_ending_on_an_arc_keeps_its_end_point_and_heading(made, road):
    source, target, report = made
    (path,) = [p for p in report.paths if p.name.startswith(f"road {road} ")]
    assert path.made and path.changed == 1 and path.deviation <= 0.05
    old, new = roads(source)[road], roads(target)[road]
    items = geometries(new)
    for a, b in zip(items, items[1:]):
        (pa, ha, ka), (pb, hb, kb) = geometry_frames(a, np.array([1.0])), geometry_frames(b, np.array([0.0]))
        assert np.hypot(*(pa[0] - pb[0])) < 1e-7 and abs(math.remainder(ha[0] - hb[0], 2 * math.pi)) < 1e-8 and abs(ka[0] - kb[0]) < 1e-7
    (a, ha, ka), (b, hb, kb) = (geometry_frames(geometries(r)[-1], np.array([1.0])) for r in (old, new))
    assert np.hypot(*(a[0] - b[0])) < 1e-9 and abs(math.remainder(ha[0] - hb[0], 2 * math.pi)) < 1e-9
    assert ka[0] < kb[0] < 1.25 * ka[0]  # the end arc turned about the end point, a little tighter
    (p_old, _), (p_new, _) = dense(old), dense(new)
    assert max(polyline_distance(p_old, p_new).max(), polyline_distance(p_new, p_old).max()) <= 0.05 + SAG
    assert any(n.startswith(f"road {road} ") and "turned about the end point" in n for n in report.notes)


def test_a_road_make_g2_cannot_take_or_whose_start_would_move_is_kept_and_named_with_its_numbers(made):
    _, _, report = made
    (connector,) = [p for p in report.paths if p.name.startswith("road 2 ")]
    (clothoid,) = [p for p in report.paths if p.name.startswith("road 5 ")]
    assert connector.kept and connector.g2  # one geometry
    assert clothoid.kept and not clothoid.g2 and "spiral" in clothoid.kept and "joint 0 (line → spiral)" in clothoid.kept
    assert "curvature jump 0.01 1/m" in clothoid.kept
    (compound,) = [p for p in report.paths if p.name.startswith("road 6 ")]
    assert compound.kept and not compound.g2 and "its start would move" in compound.kept and "geometry 0" in compound.kept
    assert 0.0 < float(compound.kept.split("move ")[1].split(" m")[0]) <= 0.05
    assert report.below_g2 == (clothoid, compound)


def test_a_public_road_esmini_comes_back_g2_with_its_road_marks(tmp_path):
    target = tmp_path / "fade.xodr"
    report = rewrite_opendrive_g2(ESMINI, target, 0.02)
    (path,) = report.paths
    assert path.made and path.changed == 2 and 0.0 < path.deviation <= 0.02
    old, new = roads(ESMINI)["0"], roads(target)["0"]
    (p_old, _), (p_new, _) = dense(old), dense(new)
    assert max(polyline_distance(p_old, p_new).max(), polyline_distance(p_new, p_old).max()) <= 0.02 + SAG
    assert without(ESMINI) == without(target)
    # every road mark's start (lane section s + sOffset) lies within the bound of where it was, and before the end
    for a, b in zip(outside(old), outside(new)):
        if local(a.tag) == "roadMark":
            assert 0.0 <= float(b.get("sOffset")) <= float(new.get("length"))


def test_the_command_rewrites_reports_and_refuses_by_road(tmp_path, capsys):
    source, target = tmp_path / "net.xodr", tmp_path / "out.xodr"
    source.write_text(network(), encoding="utf-8")
    assert main(["g2", str(source), "--max-deviation", "0.05", "-o", str(target)]) == 1  # written; 2 roads told by the exit
    out = capsys.readouterr().out
    assert "road 1 (main): G2 within" in out and "road 5 (clothoid after a line): kept as is" in out and "2 left below G2" in out
    assert main(["g2", str(source), "--max-deviation", "0.05", "-o", str(target), "--allow-splits"]) == 0
    capsys.readouterr()
    assert main(["g2", str(source), "--max-deviation", "0.05", "-o", str(target), "--units", "mm"]) == 2
    assert "units" in capsys.readouterr().err
    broken = tmp_path / "broken.xodr"
    broken.write_text(network().replace('length="20.0"><line/>', 'length="-3.0"><line/>'), encoding="utf-8")
    assert main(["g2", str(broken), "--max-deviation", "0.05", "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert "road 2" in err and "-3.0" in err and "Traceback" not in err


def test_a_file_that_is_g2_already_is_written_back_unchanged_in_its_roads(tmp_path):
    target = tmp_path / "lanes.xodr"
    source = DATA / "esmini_lane_offset_junction.xodr"
    report = rewrite_opendrive_g2(source, target, 0.05)
    assert not any(p.made for p in report.paths)
    for road_id, road in roads(source).items():
        assert ET.tostring(road) == ET.tostring(roads(target)[road_id])


def test_a_file_rewritten_onto_itself_is_whole(tmp_path):
    source, other = tmp_path / "net.xodr", tmp_path / "other.xodr"
    source.write_text(network(), encoding="utf-8")
    rewrite_opendrive_g2(source, other, 0.05)
    report = rewrite_opendrive_g2(source, source, 0.05)
    assert source.read_bytes() == other.read_bytes() and any(p.made for p in report.paths)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net.xodr", "other.xodr"]  # no temporary file left
