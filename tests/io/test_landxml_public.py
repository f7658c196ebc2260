"""LandXML exports nobody here wrote that the reader once dropped elements of, cut apart or refused
(tests/data/landxml/README.md names their sources): every element kept, each file's worst offset bounded."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

from spiral_cad.io import read_landxml

DATA = Path(__file__).resolve().parents[1] / "data" / "landxml"


def _elements(path: Path) -> list[str]:
    """The tags of the file's CoordGeom elements, in order, read as text (independently of the reader)."""
    text = path.read_text(encoding="utf-8", errors="replace")
    return re.findall(r"<(Line|Curve|Spiral)[\s>]", text.split("<CoordGeom", 1)[1].split("</CoordGeom>", 1)[0])


def _kept(a) -> None:
    """Every element owns segments of our chains, and our lengths per element sum to the chains' length."""
    held = np.concatenate(a.owners)
    assert sorted(set(held.tolist())) == list(range(len(a.kinds)))
    assert sum(c.length for c in a.chains) == pytest.approx(a.file_lengths.sum() + a.length_changes.sum(), rel=1e-12)


def test_civil3d_2023_lines_and_arcs_keep_every_element_exactly():
    path = DATA / "civil3d2023_main_road_lines_arcs.xml"
    for max_offset in (None, math.inf):
        (a,) = read_landxml(path, max_offset=max_offset)
        assert list(a.kinds) == _elements(path)
        _kept(a)
        # the two arcs of one centre and the two collinear lines: each on the file's carrier, whole
        assert np.abs(a.length_changes).max() < 1e-9
        # the only offset is the 2.4e-3 rad kink between the last two lines, absorbed: 281 ft × 2.4e-3
        assert a.offsets[:7].max() < 1e-9 and a.offsets[7] == pytest.approx(
            281.106801716452 * math.radians(340.93973334851 - 340.803550687298), rel=1e-3
        )
        assert any("kink of 0.00238 rad" in note for note in a.notes)
    # the real joints (a 6.4° kink, lines onto arcs without spirals) part the G2 runs, and are named
    assert len(a.chains) == 5 and "kink of 0.111 rad" in a.breaks[0]


def test_civil3d_2020_asymmetric_s_is_one_design_within_a_decimetre():
    path = DATA / "civil3d2020_a_kolu_asymmetric_s.xml"
    (a,) = read_landxml(path)
    assert list(a.kinds) == _elements(path)
    _kept(a)
    # the 3e-4 rad kinks and the 0.15 mm line after the last arc do not cut it: one chain, the joints told
    assert len(a.chains) == 1 and a.breaks == ()
    assert sum("joint at station" in note for note in a.notes) == 3
    # before: 2.19 m (circle_to_circle's symmetric S); on the file's inflection tangent 0.032 m
    assert a.offset < 0.05 and a.offsets[3:5].max() == a.offset
    assert all("inflection tangent" in m for m in a.methods[3:5])


def test_an_offset_beyond_max_offset_refuses_by_name_and_never_removes():
    path = DATA / "civil3d2020_a_kolu_asymmetric_s.xml"
    (a,) = read_landxml(path)
    tight = 0.5 * a.offset
    with pytest.raises(
        ValueError, match=r"element 3 \(Spiral\) at station 223.236: ours lies [\d.]+ m from the file's element, more than max_offset"
    ):
        read_landxml(path, max_offset=tight)


def test_curves_given_by_pi_and_radius_are_placed_on_their_tangents():
    path = DATA / "freecad_sugar_grove_pi_curves.xml"
    alignments = read_landxml(path)
    assert [a.name for a in alignments] == ["Sugar Grove Road", "Penrose Road West", "Penrose Road East"]
    assert alignments[0].directions == "north-cw"  # told by each curve's sense against its directions
    road = alignments[0]
    _kept(road)
    # each arc's start lies one tangent length R·tan(Δ/2) before its PI along dirStart, its end as far after it along dirEnd
    text = path.read_text(encoding="iso-8859-1")
    curves = re.findall(
        r"<Curve rot='(\w+)' length='([\d.]+)' dirStart='([\d.]+)' dirEnd='([\d.]+)'.*?radius='([\d.]+)'>\s*<PI>\s*([-\d.]+) ([-\d.]+)",
        text,
    )
    for chain, (_, length, _, dir_end, radius, north, east) in zip(road.chains, curves[:3]):
        tangent = float(radius) * math.tan(float(length) / float(radius) / 2.0)
        azimuth = math.radians(float(dir_end))
        end = np.array([float(east), float(north)]) + tangent * np.array([math.sin(azimuth), math.cos(azimuth)])
        assert np.hypot(*(np.array(chain.point_at(chain.length)[:2]) - end)) < 1e-6 * float(radius)
    # the curves meet their neighbours across the implied tangents: a gap along the line between PIs, no kink
    assert len(road.breaks) == 2 and all(re.search(r"gap of [\d.]+ ft and a kink of [\d.]+e-08 rad", b) for b in road.breaks)


@pytest.mark.parametrize("unit", ["decimal  dd.mm.ss", "Decimal DD.MM.SS", " decimal\tdd.mm.ss "])
def test_unit_strings_are_read_tolerantly(unit):
    """J-LandXML 1.7 writes directionUnit="decimal  dd.mm.ss" (two spaces)."""
    north, east = 100.0 * math.cos(math.radians(30.5)), 100.0 * math.sin(math.radians(30.5))
    text = f"""<LandXML xmlns="http://www.landxml.org/schema/LandXML-1.2"><Units><Metric linearUnit="Meter"
        angularUnit="{unit}" directionUnit="{unit}"/></Units><Alignments><Alignment name="a"><CoordGeom>
        <Line dir="30.3000"><Start>0 0</Start><End>{north!r} {east!r}</End></Line><Line dir="30.3000" length="50"/>
        </CoordGeom></Alignment></Alignments></LandXML>"""
    (a,) = read_landxml(text)
    # 30°30' (dd.mm.ss, not 30.3°), counted from north as the first line's points tell: the second line straight on
    assert a.units == "m" and a.directions == "north-cw" and len(a.kinds) == 2
    assert a.offset < 1e-9 and len(a.chains) == 1 and not any("kink" in note for note in a.notes)


def test_a_rebuild_that_loses_an_element_is_refused_by_name(monkeypatch):
    """The guard behind "never dropped": a placement that left an element out (as one once did with two
    arcs of one centre) is refused, naming the element, rather than built without it."""
    import spiral_cad.io.landxml_read as reader

    placed = reader._run

    def losing(items, mine, *rest):
        segments, owner, methods = placed(items, mine, *rest)
        kept = [k for k, o in enumerate(owner) if o != 3]
        return [segments[k] for k in kept], [owner[k] for k in kept], methods

    monkeypatch.setattr(reader, "_run", losing)
    with pytest.raises(
        ValueError, match=r"CoordGeom element 3 \(Curve\) at station [\d.]+: the rebuilt chain holds nothing of this element"
    ):
        read_landxml(DATA / "civil3d2023_main_road_lines_arcs.xml", max_offset=math.inf)
