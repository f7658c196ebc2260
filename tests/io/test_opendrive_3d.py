"""OpenDRIVE in 3-D: elevation as exact cubics, superelevation as exact C1 cubics, read from the file itself."""

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from helpers import independent_check

from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment, Profile, Superelevation

PIS = [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]]


@pytest.fixture(scope="module")
def highway() -> Alignment:
    return Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=80, start_station=10000)


@pytest.fixture(scope="module")
def profile(highway) -> Profile:
    # the profile starts before the alignment and ends after it: the file holds the alignment's part
    return Profile.from_pvis([(9900, 118.5), (10700, 132), (11500, 116), (12500, 121)], units="m", design_speed=80,
                             alignment=highway)  # fmt: skip


def records(root, tag: str) -> np.ndarray:
    return np.array([[float(e.get(k)) for k in "sabcd"] for e in root.iter(tag)])


def polynomial_at(rows: np.ndarray, s: float, side: str = "right") -> tuple[float, float, float]:
    """Value, slope and second derivative of piecewise cubic records at s (the piece before s with side='left')."""
    k = int(np.searchsorted(rows[:, 0], s, side=side)) - 1
    s0, a, b, c, d = rows[k]
    x = s - s0
    return a + x * (b + x * (c + x * d)), b + x * (2 * c + 3 * x * d), 2 * c + 6 * x * d


def test_elevation_is_the_parabolas_and_grades_read_from_the_file(highway, profile, tmp_path):
    path = tmp_path / "highway.xodr"
    export_opendrive(highway, path, profile=profile)
    rows = records(ET.parse(path).getroot(), "elevation")
    start = highway.start_station
    assert rows[0, 0] == 0.0 and (rows[:, 4] == 0.0).all()  # parabolas: no cubic term
    # the grades between PVIs, read as the slopes of the linear records
    grades = [row[2] for row in rows if row[3] == 0.0]
    assert grades == pytest.approx([13.5 / 800, -16 / 800, 5 / 1000], rel=1e-12)
    # the vertical curves: K = 1/(100·|2c|), the design's K; they start at BVC and end where the next grade begins
    curves = [row for row in rows if row[3] != 0.0]
    for row, curve in zip(curves, profile.curves):
        assert 1 / (100 * abs(2 * row[3])) == pytest.approx(curve.k, rel=1e-12)
        assert row[0] == pytest.approx(curve.bvc - start, abs=1e-9)
        assert polynomial_at(rows, curve.evc - start)[1] == pytest.approx(curve.grade_out, rel=1e-12)
    # continuous in value and slope at every record boundary (C1), and the elevations of the PVIs on the grade lines
    for s in rows[1:, 0]:
        before, after = polynomial_at(rows, s, "left"), polynomial_at(rows, s)
        assert before[0] == pytest.approx(after[0], abs=1e-9) and before[1] == pytest.approx(after[1], abs=1e-12)
    assert polynomial_at(rows, 0.0)[0] == pytest.approx(118.5 + 13.5 / 800 * 100, abs=1e-12)


def test_superelevation_is_exact_c1_cubics_in_the_file(highway, tmp_path):
    path = tmp_path / "highway.xodr"
    export_opendrive(highway, path)
    root = ET.parse(path).getroot()
    rows = records(root, "superelevation")
    plan = sorted(float(g.get("s")) for g in root.iter("geometry"))
    # every ramp starts and ends on a planView geometry boundary (TS, SC, CS, ST)
    for s in rows[1:, 0]:
        assert min(abs(p - s) for p in plan) == 0.0
    # the maliput-style C1 check: the slope jump at every ramp end
    for s in rows[1:, 0]:
        before, after = polynomial_at(rows, s, "left"), polynomial_at(rows, s)
        assert abs(before[0] - after[0]) <= 1e-12
        assert abs(before[1] - after[1]) <= 1e-9
    # on each circle the roll is atan(e), towards the centre
    for curve, check in zip(highway.curves, highway.checks):
        middle = 0.5 * (curve.sc + curve.cs) - highway.start_station
        roll = polynomial_at(rows, middle)[0]
        assert roll == pytest.approx(-math.copysign(math.atan(check.cross_slope), curve.deflection), rel=1e-14)


def test_the_3d_road_passes_the_schema_the_asam_checker_and_pyxodr_reads_its_elevation(highway, profile, tmp_path):
    path = tmp_path / "highway.xodr"
    export_opendrive(highway, path, profile=profile)
    result = independent_check(path)
    assert result["schema"] == []
    assert all(issues == 0 for _, issues in result["checker"].values()), result["checker"]
    ((distance, z),) = [np.array(v).T for v in result["elevation"].values()]
    # pyxodr measures s along its 0.5 m polyline (chords: ~1e-7 relative short on the arcs)
    assert np.abs(z - profile.elevation(highway.start_station + distance)).max() <= 1e-5


def test_profiles_and_superelevation_per_item_and_errors(highway, profile, tmp_path):
    other = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m")
    level = Profile.from_pvis([(0, 5), (other.end_station, 5)], units="m")
    path = tmp_path / "two.xodr"
    export_opendrive([highway, other], path, profile=[profile, level],
                     superelevation=[None, Superelevation.from_alignment(other, cross_slopes=0.04)])  # fmt: skip
    roads = ET.parse(path).getroot().findall("road")
    assert len(roads) == 2 and len(roads[1].findall("elevationProfile/elevation")) == 1
    assert max(abs(float(e.get("a"))) for e in roads[1].iter("superelevation")) == pytest.approx(math.atan(0.04))
    with pytest.raises(ValueError, match="profile needs one entry per item"):
        export_opendrive([highway, other], path, profile=[profile])
    with pytest.raises(ValueError, match="must cover the alignment"):
        export_opendrive(other, path, profile=Profile.from_pvis([(10, 5), (other.end_station, 5)], units="m"))
    with pytest.raises(ValueError, match="needs an Alignment"):
        export_opendrive(highway.chain, path, profile=profile)


def test_feet_are_converted_in_elevation_and_superelevation(tmp_path):
    feet = Alignment.from_pis([[0, 0], [2000, 400], [4000, -200]], 1500, units="ft", design_speed=50)
    profile = Profile.from_pvis([(0, 300), (2100, 330), (feet.end_station, 310)], units="ft", design_speed=50, alignment=feet)
    path = tmp_path / "ft.xodr"
    export_opendrive(feet, path, profile=profile)
    root = ET.parse(path).getroot()
    rows = records(root, "elevation")
    assert polynomial_at(rows, 0.0)[0] == pytest.approx(300 * 0.3048, rel=1e-14)
    (curve,) = profile.curves
    parabola = [row for row in rows if row[3] != 0.0][0]
    assert parabola[0] == pytest.approx(curve.bvc * 0.3048, rel=1e-12)
    assert 2 * parabola[3] == pytest.approx(curve.rates[0] / 0.3048, rel=1e-12)  # grade change per metre
    bank = records(root, "superelevation")
    ramp = [row for row in bank if row[4] != 0.0][0]
    length = feet.curves[0].sc - feet.curves[0].ts
    assert ramp[3] == pytest.approx(3 * abs(polynomial_at(bank, ramp[0] + length * 0.3048)[0]) / (length * 0.3048) ** 2
                                    * np.sign(ramp[3]), rel=1e-9)  # fmt: skip


def test_a_chain_in_space_is_refused_by_name(highway, tmp_path):
    from spiral_cad.core.space import PlaneFrame

    tilted = highway.chain.placed(PlaneFrame(normal=(0, 1, 1)))
    assert tilted.dim == 3
    with pytest.raises(ValueError, match="planView holds plane chains; this chain lies in space"):
        export_opendrive(tilted, tmp_path / "space.xodr")
    assert not (tmp_path / "space.xodr").exists()
