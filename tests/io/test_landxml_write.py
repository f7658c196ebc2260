"""LandXML out: names XML cannot hold and cubics no Spiral describes refused by name; a file is replaced only by a
complete one; our spirals read back as the very cubics (their Feature)."""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from helpers import around

from spiral_cad import circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from spiral_cad.core.chain import Chain
from spiral_cad.core.spiral import BezierSpiral
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
    s_curve = BezierSpiral.from_control_points(np.array([[0.0, 0.0], [3.0, 3.0], [7.0, -3.0], [10.0, 0.0]]))
    path = tmp_path / "s.xml"
    with pytest.raises(
        ValueError, match=r"segment 0 \(a cubic\) is not a spiral: its curvature changes sign \(-0.388485 to 0.388485 1/mm: an inflection"
    ):
        write_landxml(Chain([s_curve], units="mm"), path, name="s")
    assert not path.exists()


def _transitions(shape: str) -> dict:
    return {
        "line-circle": line_to_circle((0, 0), (1, 0), (60, 26.5), 25.0, shape=shape),
        "C": circle_to_circle((0, 0), 20.0, (28, 0), 15.0, shape=shape),
        "S": circle_to_circle((0, 0), 20.0, (40, 0), -15.0, shape=shape),
        "line-line": line_to_line((-100, 0), (0, 0), (60, 80), shape=shape),
        "nested": circle_in_circle((0, 0), 100.0, (39.8, 0.0), 60.0, shape=shape),  # the tester's r03 (R 100 → 60)
    }


@pytest.mark.parametrize("shape", ["near-linear", "walton-meek"])
@pytest.mark.parametrize("kind", ["line-circle", "C", "S", "line-line", "nested"])
@pytest.mark.parametrize("alone", [True, False])
def test_our_spirals_read_back_as_the_very_cubics(tmp_path, shape, kind, alone):
    # r03: a lone Walton–Meek spiral R 100 → 60 came back as a near-linear one 10.6 mm away (control points 0.14 m)
    t = _transitions(shape)[kind]
    chain = Chain(list(t.spirals), units="m") if alone else around(t, sweep=0.3)
    path = tmp_path / "t.xml"
    write_landxml(chain, path, name=kind)
    (back,) = read_landxml(path)
    ours = [seg for seg in chain if hasattr(seg, "control_points")]
    theirs = [seg for c in back.chains for seg in c if hasattr(seg, "control_points")]
    assert len(theirs) == len(ours) and {m for m, k in zip(back.methods, back.kinds) if k == "Spiral"} == {"spiral_cad cubic"}
    for a, b in zip(ours, theirs):
        assert np.abs(a.control_points - b.control_points).max() <= 1e-12 * chain.length and b.shape == shape


def test_a_spirals_control_points_that_no_longer_fit_it_are_not_used(tmp_path):
    chain = Chain(list(_transitions("near-linear")["line-circle"].spirals), units="m")
    path = tmp_path / "t.xml"
    write_landxml(chain, path, name="n")
    text = path.read_text(encoding="utf-8")
    # the element edited since we wrote it: 1% longer
    edited = re.sub(r'(<Spiral [^>]*?length=")([^"]+)"', lambda m: f'{m.group(1)}{float(m.group(2)) * 1.01!r}"', text)
    (back,) = read_landxml(edited, max_offset=float("inf"))
    assert back.methods != ("spiral_cad cubic",) and any("do not fit the element" in note for note in back.notes)


def test_the_batch_spiral_check_never_passes_what_monotone_pieces_would_cut():
    """The writer certifies most cubics at once (bezier.plain_spirals) and sends only the rest through
    bezier.monotone_pieces: every cubic it certifies must be one piece there too, and real spirals pass."""
    from spiral_cad.core.bezier import monotone_pieces, plain_spirals

    rng = np.random.default_rng(29)
    spirals = np.array([BezierSpiral((0.0, 0.0), (1.0, 0.0), theta, 0.01, shape).control_points[:, :2]
                        for theta in np.linspace(0.05, 0.8, 16) for shape in ("near-linear", "walton-meek")])  # fmt: skip
    # spirals disturbed by up to a tenth of their size: some stay spirals, others gain an inflection or a peak
    size = np.ptp(spirals, axis=1).max(axis=1)[:, None, None]
    cubics = np.concatenate([spirals + rng.normal(size=spirals.shape) * size * scale for scale in (1e-3, 1e-2, 0.1)])
    plain = plain_spirals(cubics)
    for cp, certified in zip(cubics, plain):
        try:
            pieces = len(monotone_pieces(cp))
        except ValueError:  # a cusp: monotone_pieces refuses it, the batch must not certify it
            pieces = 0
        assert not certified or pieces == 1
    assert 0 < plain.sum() < len(plain)
    assert plain_spirals(spirals).all()
