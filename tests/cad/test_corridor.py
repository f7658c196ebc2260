"""The corridor solid and the 3-D centre line wire through OCCT (a short road with a crest and a sag)."""

import numpy as np
import pytest

pytest.importorskip("OCP")

from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402

from spiral_cad.build123d import centerline_wire, corridor  # noqa: E402
from spiral_cad.cad.export import CrossSection, export_step  # noqa: E402
from spiral_cad.cad.readers import read_shape  # noqa: E402
from spiral_cad.design import Profile, centerline_3d  # noqa: E402


@pytest.fixture(scope="module")
def road(short_road):
    return short_road


def test_the_corridor_is_a_valid_solid_with_the_volume_of_its_section(road, tmp_path):
    alignment, profile = road
    section = CrossSection(driving_lanes=2, lane_width=3.5, shoulder_width=2.0, depth=0.3)
    built = corridor(alignment, profile, section, tolerance=1e-6)
    solid = built.solid
    assert solid.is_valid and BRepCheck_Analyzer(solid.wrapped).IsValid()
    # independent: the pavement is the top moved down by its depth, so every plan point carries 0.3 m,
    # and a section symmetric about the centre line sweeps width × depth × plan length exactly
    expected = (2 * (2 * 3.5 + 2.0)) * 0.3 * alignment.chain.length
    assert solid.volume == pytest.approx(expected, rel=1e-7)
    assert built.deviation <= 1e-6
    roles = {role: len(faces) for role, faces in built.faces.items()}
    segments = len(alignment.chain)
    assert roles == {"lane 3": segments, "lane 2": segments, "lane 1": segments, "lane -1": segments, "lane -2": segments,
                     "lane -3": segments, "bottom": 2 * segments, "side": 2 * segments, "end": 2}  # fmt: skip
    assert len(solid.faces()) == sum(roles.values())
    # through STEP and back: still one valid solid of the same volume
    path = tmp_path / "road.step"
    export_step(solid, path, units="m")
    shape = read_shape(path, units="m")
    from build123d import Shape

    again = Shape.cast(shape)
    assert BRepCheck_Analyzer(shape).IsValid() and len(again.solids()) == 1
    assert again.solids()[0].volume == pytest.approx(solid.volume, rel=1e-9)


def test_the_top_follows_profile_crossfall_and_banking(road):
    alignment, profile = road
    built = corridor(alignment, profile, CrossSection(driving_lanes=1, lane_width=3.5, shoulder_width=0.0, crossfall=0.02, depth=0.25))
    start = alignment.start_station
    # at the start (a tangent): centre on the profile, both edges 2 % below it, the pavement 0.25 m under the top
    section = built.roadway.section(0)
    assert section[1, 2] == pytest.approx(profile.elevation(start))
    assert section[0, 2] == pytest.approx(profile.elevation(start) - 0.07) and section[2, 2] == pytest.approx(section[0, 2])
    assert section[3:, 2] == pytest.approx(section[[2, 1, 0], 2] - 0.25)
    assert len(built.solid.faces()) == 6 * len(alignment.chain) + 2
    # on the circle: one plane at the curve's cross slope, falling to the inside (a left turn: the left edge lower)
    (curve,) = alignment.curves
    rows = np.flatnonzero((built.roadway.stations[:-1] >= curve.sc) & (built.roadway.stations[1:] <= curve.cs))
    left, centre, right = built.roadway.edges[:, rows[0], 0]
    e = alignment.checks[0].cross_slope
    assert (centre[2] - left[2]) / 3.5 == pytest.approx(e, rel=1e-9) and (right[2] - centre[2]) / 3.5 == pytest.approx(e, rel=1e-9)


def test_the_centre_line_wire_is_the_plan_lifted(road):
    alignment, profile = road
    line = centerline_3d(alignment, profile, tolerance=1e-8)
    wire = centerline_wire(line)
    edges = wire.edges()
    assert len(edges) == len(alignment.chain)
    for edge, segment, station in zip(edges, alignment.chain, alignment.chain.stations):
        start = edge.position_at(0)
        assert (start.X, start.Y) == pytest.approx(tuple(segment.start), abs=1e-9)
        assert start.Z == pytest.approx(profile.elevation(alignment.start_station + station), abs=1e-9)
    # the 3-D length: ∫ √(1 + z'²) ds along the plan
    s = np.linspace(alignment.start_station, alignment.end_station, 200_001)
    slope = profile.grade(s)
    expected = np.trapezoid(np.sqrt(1 + slope**2), s)
    assert wire.length == pytest.approx(expected, rel=1e-8)


def test_corridor_errors(road):
    alignment, profile = road
    with pytest.raises(ValueError, match="depth must be a finite number ≥ 0"):
        corridor(alignment, profile, CrossSection(depth=-1))
    with pytest.raises(ValueError, match="cross_section must be a CrossSection"):
        corridor(alignment, profile, {"depth": 1})
    with pytest.raises(ValueError, match="the profile is in ft but the alignment in m"):
        corridor(alignment, Profile.from_pvis([(0, 0), (2000, 0)], units="ft"))
