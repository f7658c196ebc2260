"""Roads in 3-D through design files and ``spiral-cad build``: the profile table, the 3-D STEP and the .xodr."""

import csv
import xml.etree.ElementTree as ET

import pytest

from spiral_cad.app.cli import DEMO_DESIGN, main
from spiral_cad.app.designfile import DesignError, build

ROAD = {
    "name": "road", "type": "alignment", "pis": [[0, 0], [220, 10], [430, 120]], "radii": 200, "design_speed": 60,
    "profile": {"pvis": [[0, 10], [150, 14], [320, 8], [600, 10]]},
}  # fmt: skip


def design(**profile) -> dict:
    road = dict(ROAD, profile={**ROAD["profile"], **profile})
    return {"units": "m", "designs": [road]}


def test_build_writes_the_profile_table_the_3d_step_and_the_xodr(tmp_path, capsys):
    import json

    path = tmp_path / "road.json"
    path.write_text(json.dumps({"units": "m", "designs": [ROAD]}))
    assert main(["build", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "road profile: ProfileCriteria, design speed 60 km/h" in printed and "every PVI meets the profile criteria" in printed
    assert "road: 3-D centre line:" in printed and "corridor: 1 solid" in printed
    out = tmp_path / "out"
    rows = list(csv.DictReader((out / "road_profile.csv").open()))
    assert [r["kind"] for r in rows] == ["crest", "sag"] and "K [m/%]" in rows[0]
    assert rows[0]["verdict"] == "ok"
    elevations = ET.parse(out / "road.xodr").getroot().findall("road/elevationProfile/elevation")
    assert len(elevations) == 5 and float(elevations[0].get("a")) == 10.0
    step = (out / "road_3d.step").read_text()
    assert "road in 3-D: corridor solid and centre line (plan exact; z within" in step
    # one product (FreeCAD 0.20's Import.insert crashed on the assembly OCCT made of solid + curves), the centre
    # line one wire, and the description names the joints that are only G1 and why
    assert step.count("PRODUCT(") == 1 and "NEXT_ASSEMBLY_USAGE_OCCURRENCE" not in step
    assert step.count("CONNECTED_EDGE_SET(") == 1 and "GEOMETRIC_CURVE_SET" not in step
    header = " ".join(step.split("FILE_NAME")[0].split())
    assert "centre line one wire, G2 at every joint but G1 at stations" in header
    assert "(vertical curve ends BVC and EVC, where the second derivative of the profile jumps)" in header
    from build123d import Shape

    from spiral_cad.cad.readers import read_shape

    shape = Shape.cast(read_shape(out / "road_3d.step", units="m"))
    (solid,) = shape.solids()
    assert solid.is_valid and len(shape.edges()) > len(solid.edges())  # the centre line's edges beside the solid's


def test_the_demo_highway_has_a_profile_inside_its_alignment():
    units, (highway, *_) = build(DEMO_DESIGN)
    profile = highway.profile
    assert profile.start <= highway.source.start_station and profile.end >= highway.source.end_station
    assert [c.kind for c in profile.curves] == ["crest", "sag"] and all(row.ok for row in profile.checks)


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(pvis=[[0, 10]]), r"\.pvis: must be a list of at least 2 points"),
        (dict(curve_lengths=[100, 100], k_values=[30, 30]), ": give at most one of curve_lengths and k_values"),
        (dict(curve_lengths=[100]), r"\.curve_lengths: needs one entry per interior PI \(2\)"),
        (dict(k_values=[30, -1]), r"\.k_values\[1\]: must be positive"),
        (dict(terrain="hilly"), r"\.terrain: must be one of level, rolling, mountainous"),
        (dict(max_grade=0.02), r": profile criteria violated: PVI 0: grade 2\.667 % > 2 %"),
        (dict(pvis=[[10, 10], [600, 12]]), ": the profile runs from station 10 .* must cover the alignment"),
        (dict(curve_lengths=[400, [100, 60]]), ": PVI 1: the curve \\(400 m\\) starts at -50"),
        (dict(speed=1), ": unknown field"),
    ],
)
def test_bad_profiles_are_named(change, message):
    data = design(**change)
    if "max_grade" in change:
        data["designs"][0]["strict"] = True
    with pytest.raises(DesignError, match=r"^designs\[0\] \(road\)\.profile" + message):
        build(data)


def test_a_profile_without_road_criteria_needs_its_curves():
    data = design()
    del data["designs"][0]["design_speed"]
    data["designs"][0]["spiral_angles_deg"] = 8
    with pytest.raises(DesignError, match="give curve_lengths or k_values"):
        build(data)
    data["designs"][0]["profile"]["k_values"] = 20
    (built,) = build(data)[1]
    assert [c.k for c in built.profile.curves] == pytest.approx([20, 20])


def test_curve_lengths_in_a_design_file_are_whole_lengths_or_halves():
    (built,) = build(design(curve_lengths=[120, [50, 70]]))[1]
    first, second = built.profile.curves
    assert (first.length_in, first.length_out, second.length_in, second.length_out) == (60, 60, 50, 70)
