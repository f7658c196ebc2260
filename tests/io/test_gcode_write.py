"""G-code out: exact G5 spirals, arcs in their planes, chords in space, biarcs for the generic dialect;
checked by LinuxCNC's rs274 and its interpreter library, and read back by our own reader."""

import re
from pathlib import Path

import numpy as np
import pytest
from helpers import distance_to_chain, helix_chain, linuxcnc_preview, linuxcnc_rs274

import spiral_cad as sc
from spiral_cad import Arc, BezierSpiral, Chain
from spiral_cad.core.space import PlaneFrame
from spiral_cad.design import round_corners
from spiral_cad.io import rs274
from spiral_cad.io.gcode import parse_gcode, parse_gcode_chain, read_gcode_chain
from spiral_cad.io.gcode_write import gcode_program, spiral_biarcs, write_gcode

needs_rs274 = pytest.mark.skipif(
    rs274.rs274_executable() is None,
    reason=f"LinuxCNC's rs274 is not installed (Debian package {rs274.PACKAGE}; `make test` installs it where it can)",
)

#: A word of a program we write: a letter and a plain decimal (no exponent, at most 15 decimals).
WORD = re.compile(r"[A-Z]-?\d+(\.\d{1,15})?")


def robot(scale=20.0, units="mm") -> Chain:
    """The demo's robot path, scaled (lines and spiral pairs in the plane)."""
    points = np.array([[0, 0], [1.0, 0.1], [1.4, 0.9], [2.4, 1.0], [2.6, 0.2], [3.6, 0.4]]) * scale
    return round_corners(points, max_curvature=6.0 / scale, units=units).chain


def placed_road(frame: PlaneFrame) -> Chain:
    """Line → spiral → arc → spiral → line (the README's first curve), placed in ``frame``."""
    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = sc.line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    return Chain.join([enter, leave], start=(-20, 0), end=(400, 250), units="mm").placed(frame)


def body(text: str) -> list[str]:
    return [line for line in text.splitlines() if line and not line.startswith("(")]


def assert_plain_numbers(text: str) -> None:
    for line in body(text):
        for word in line.split():
            assert WORD.fullmatch(word), f"{word!r} in {line!r}"


def test_a_plane_path_is_lines_and_exact_g5_cubics():
    chain = robot()
    program = gcode_program(chain, name="robot", feed=1200)
    lines = body(program.text)
    spirals = [s for s in chain if isinstance(s, BezierSpiral)]
    assert lines[:4] == ["G21 G90 G91.1 G94 G17 G40 G49", "G64 P0.001", "F1200", "G0 X0 Y0"]
    assert lines[-1] == "M2"
    assert sum(line.startswith("G5 ") for line in lines) == len(spirals) == program.counts["G5"] == 8
    assert sum(line.startswith("G1 ") for line in lines) == len(chain) - len(spirals)
    assert_plain_numbers(program.text)
    assert "(unit: mm, G21;" in program.text and "8 G5 exact cubic" in program.text
    # G5's words are the spiral's control points: I J from the start, P Q from the end
    first = next(line for line in lines if line.startswith("G5 "))
    words = dict((w[0], float(w[1:])) for w in first.split()[1:])
    cp = spirals[0].control_points
    assert words["X"] == pytest.approx(cp[3][0], abs=1e-12) and words["Y"] == pytest.approx(cp[3][1], abs=1e-12)
    assert (words["I"], words["J"]) == pytest.approx(tuple(cp[1] - cp[0]), abs=1e-12)
    assert (words["P"], words["Q"]) == pytest.approx(tuple(cp[2] - cp[3]), abs=1e-12)


def test_our_reader_reads_the_program_back_as_the_same_chain(tmp_path):
    points = np.array([[0, 0], [1.0, 0.1], [1.4, 0.9], [2.4, 1.0], [2.6, 0.2], [3.6, 0.4]]) * 20.0
    rounded = round_corners(points, max_curvature=0.3, units="mm")
    chain = rounded.chain
    path = write_gcode(rounded, tmp_path / "robot.ngc")  # a rounded path writes its chain
    again = read_gcode_chain(path)
    assert again.units == "mm" and again.dim == 2 and len(again) == len(chain)
    assert np.asarray(again.rows.kind).tolist() == np.asarray(chain.rows.kind).tolist()
    # control points equal to the printed decimals (13 here: 15 digits for coordinates below 100)
    assert np.abs(again.rows.geometry - chain.rows.geometry).max() < 1e-12
    assert again.length == pytest.approx(chain.length, abs=1e-11)
    # and written again, the same program
    assert write_gcode(again) == write_gcode(chain)


def test_inches_g20_and_a_chain_in_metres_converted_to_mm():
    inch = robot(scale=1.0, units="in")
    program = gcode_program(inch)
    assert "G20 G90" in program.text and program.units == "in"
    back = parse_gcode_chain(program.text)
    assert back.units == "in" and np.abs(back.rows.geometry - inch.rows.geometry).max() < 1e-13
    metres = robot(scale=0.02, units="m")
    program = gcode_program(metres, arc_tolerance=1e-6)
    assert "G21 G90" in program.text and "converted from the chain's m, times 1000" in program.text
    back = parse_gcode_chain(program.text, units="m")
    assert np.abs(back.rows.geometry - metres.rows.geometry).max() < 1e-15
    # tolerances are in the chain's unit: 1e-6 m is 0.001 mm in the header
    assert "arc tolerance 0.001 mm" in program.text
    assert "G20" in gcode_program(robot(units="ft")).text  # feet are written in inches


def test_arcs_in_xz_and_yz_are_g18_and_g19_and_spirals_there_biarcs(tmp_path):
    for plane, frame in (("G18", PlaneFrame(normal=(0, -1, 0))), ("G19", PlaneFrame(x_dir=(0, 1, 0), normal=(1, 0, 0)))):
        chain = placed_road(frame)
        program = gcode_program(chain, arc_tolerance=0.005)
        lines = body(program.text)
        assert plane in lines and not any(line.startswith("G5") for line in lines)
        arcs = [line for line in lines if line.startswith(("G2 ", "G3 "))]
        assert program.counts["arc"] == 1 and program.counts["biarcs"] == 2
        offsets = "IK" if plane == "G18" else "JK"
        assert all({w[0] for w in line.split()[1:] if w[0] in "IJK"} == set(offsets) for line in arcs)
        assert 0.0 < program.arc_error <= 0.005


def test_pieces_in_tilted_planes_become_chords_within_the_tolerance():
    chain, _, _ = helix_chain()
    program = gcode_program(chain, chord_tolerance=0.002)
    assert program.counts["chords"] == 14 and program.counts["G5"] == 0 and program.counts["arc"] == 0
    assert "within chord tolerance 0.002 mm" in program.text
    assert 0.0 < program.chord_error <= 0.002
    assert not any(line.split()[0] in ("G2", "G3", "G5") for line in body(program.text))


def test_generic_dialect_has_no_g5_and_its_arcs_stay_within_the_tolerance():
    chain = robot()
    program = gcode_program(chain, dialect="generic", arc_tolerance=0.002)
    lines = body(program.text)
    assert not any(line.startswith("G5") or "G64" in line or "G91.1" in line for line in lines)
    assert program.counts["biarcs"] == 8 and 0.0 < program.arc_error <= 0.002
    # every arc, read with our reader as chords 1e-5 from it, stays within the tolerance of the chain
    path = parse_gcode(program.text, arc_tolerance=1e-5)
    assert distance_to_chain(chain, path.points, 0.01).max() <= 0.002 + 1e-5


def test_biarcs_of_one_spiral_are_tangent_and_within_the_tolerance():
    spiral = robot()[1]
    pieces, error = spiral_biarcs(spiral.control_points, 1e-4)
    assert error <= 1e-4 and len(pieces) >= 2
    assert np.allclose(pieces[-1][0], spiral.end, atol=1e-12)


@needs_rs274
@pytest.mark.parametrize("dialect", ["linuxcnc", "generic"])
def test_rs274_reads_our_programs(tmp_path, dialect):
    chain = robot()
    program = gcode_program(chain, dialect=dialect, arc_tolerance=0.005)
    path = tmp_path / "robot.ngc"
    path.write_text(program.text)
    done = linuxcnc_rs274(path, tmp_path / "canon.txt")
    assert done.returncode == 0 and "error" not in done.stderr.lower(), done.stderr
    canon = (tmp_path / "canon.txt").read_text()
    assert canon.count("NURBS_FEED(4, ...)") == program.counts["G5"]  # rs274 prints each G5 as a 4-point spline
    assert "USE_LENGTH_UNITS(CANON_UNITS_MM)" in canon and "SET_FEED_RATE(1000.0000)" in canon
    # every end rs274 prints (4 decimals) lies on the chain
    ends = np.array([[float(v) for v in m.split(",")[:2]] for m in re.findall(r"(?:STRAIGHT_FEED|ARC_FEED)\(([^)]*)\)", canon)])
    assert distance_to_chain(chain, ends, 0.01).max() < (1e-4 if dialect == "linuxcnc" else 0.005 + 1e-4)  # biarc joints
    if dialect == "generic":  # rs274's own arcs, as chords 1e-4 from them, within the arc tolerance
        moves = rs274.run_rs274(program.text, arc_tolerance=1e-4)
        assert distance_to_chain(chain, moves.points, 0.01).max() <= 0.005 + 2e-4


@pytest.mark.parametrize("units", ["mm", "in"])
def test_linuxcncs_interpreter_evaluates_our_g5_on_the_spirals(tmp_path, units):
    """LinuxCNC's interpreter library evaluates G5 as a cubic B-spline (its AXIS preview: 60 points each,
    in double precision): every point lies on our chain, so LinuxCNC reads the control points we meant."""
    chain = robot(scale=20.0 if units == "mm" else 1.0, units=units)
    path = write_gcode(chain, tmp_path / "robot.ngc")
    moves = linuxcnc_preview(path, units)
    on_splines = np.array([p for kind, _, p in moves if kind == "feed"])
    assert len(on_splines) >= 8 * 60
    assert distance_to_chain(chain, on_splines, 0.05 if units == "mm" else 0.002).max() < (1e-9 if units == "mm" else 1e-11)


def test_linuxcncs_interpreter_reads_our_arcs_in_their_planes(tmp_path):
    chain = placed_road(PlaneFrame(normal=(0, -1, 0)))  # the XZ plane: G18 arcs
    program = gcode_program(chain, arc_tolerance=0.01)
    path = tmp_path / "road.ngc"
    path.write_text(program.text)
    points = np.array([p for kind, _, p in linuxcnc_preview(path, "mm") if kind == "arc"])
    assert len(points) > 50
    assert distance_to_chain(chain, points, 0.05).max() <= 0.01 + 1e-6


def test_g5_is_read_as_linuxcnc_reads_it():
    """LinuxCNC's own example (g-code.adoc, G5): a curvy N, and a second one without I J."""
    text = "G21 G90 G17\nG1 X0 Y0 F100\nG5 I0 J3 P0 Q-3 X1 Y1\nG5 P0 Q-3 X2 Y2\nM2\n"
    path = parse_gcode(text, arc_tolerance=1e-4)
    assert path.points[-1].tolist() == [2, 2, 0] and len(path) > 20
    # I J continue the previous P Q: the second cubic's control points are (1, 1), (1, 4), (2, -1), (2, 2);
    # the chord ends of each cubic are its points at even parameters
    for line, cp in ((3, [[0, 0], [0, 3], [1, -2], [1, 1]]), (4, [[1, 1], [1, 4], [2, -1], [2, 2]])):
        points = path.points[path.lines == line][:, :2]
        u = (np.arange(len(points)) + 1.0)[:, None] / len(points)
        c = np.array(cp, dtype=float)
        expected = (1 - u) ** 3 * c[0] + 3 * (1 - u) ** 2 * u * c[1] + 3 * (1 - u) * u**2 * c[2] + u**3 * c[3]
        assert np.abs(points - expected).max() < 1e-12


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G21 G1 X0 F1\nG5 P0 Q-3 X1 Y1\n", r"line 2: the first G5 of a series needs I and J"),
        ("G21 G1 X0 F1\nG5 I1 P0 Q-3 X1 Y1\n", r"line 2: G5 needs both I and J, or neither"),
        ("G21 G1 X0 F1\nG5 I1 J0 P0 X1 Y1\n", r"line 2: G5 needs both P and Q"),
        ("G21 G1 X0 F1\nG18 G5 I1 J0 P0 Q1 X1 Y1\n", r"line 2: G5 .* needs the XY plane \(G17\)"),
        ("G21 G1 X0 F1\nG5 I1 J0 P0 Q1 X1 Y1 Z1\n", r"line 2: G5 .* moves X and Y only"),
        ("G21 G1 X0 F1\nG1 X1\nG5 P0 Q-3 X2 Y1\n", r"line 3: the first G5 of a series needs I and J"),
        (
            f"G21\nG1 X{'9' * 308} F1\nG5 I{'9' * 308} J0 P0 Q0 X1 Y1\n",
            r"line 3: the G5 spline's control points are beyond the float range",
        ),
        ("G21\nG1 X1 F1\nG5 I0 J0 P0 Q0 X2 Y0\n", r"line 3: control_points make a degenerate spiral"),  # not a chain's segment
    ],
)
def test_g5_refusals_follow_linuxcnc(text, message):
    with pytest.raises(ValueError, match=message):
        parse_gcode_chain(text)


def test_g5_without_an_arc_tolerance_is_refused_by_the_polyline_reader():
    with pytest.raises(ValueError, match=r"line 2: G5 .* read_gcode_chain .* or give arc_tolerance"):
        parse_gcode("G21 G1 X0 F1\nG5 I1 J0 P0 Q1 X1 Y1\n")


def test_a_program_that_is_not_g2_is_refused_naming_its_lines():
    with pytest.raises(ValueError, match=r"lines 2 and 3: Chain is not G2 .* do not join G2"):
        parse_gcode_chain("G21 G90\nG1 X1 F100\nG1 Y1\nM2\n")
    with pytest.raises(ValueError, match=r"line 3: a rapid move \(G0\) between feed moves"):
        parse_gcode_chain("G21 G90\nG1 X1 F100\nG0 X2\nG1 X3\nM2\n")


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"dialect": "grbl"}, r"dialect must be one of linuxcnc, generic; got 'grbl'"),
        ({"units": "m"}, r"units must be 'mm' \(G21\) or 'in' \(G20\)"),
        ({"feed": 0}, r"feed must be a positive finite number; got 0"),
        ({"feed": float("nan")}, r"feed must be a positive finite number; got nan"),
        ({"chord_tolerance": -1.0}, r"chord_tolerance must be a positive finite number"),
        ({"arc_tolerance": float("inf")}, r"arc_tolerance must be a positive finite number"),
        ({"plane_tolerance": 0.0}, r"plane_tolerance must be a positive finite number"),
        ({"decimals": 40}, r"decimals must be a whole number from 1 to 15; got 40"),
        ({"name": "a (b)"}, r"cannot stand in a G-code comment"),
    ],
)
def test_refusals(options, message):
    with pytest.raises(ValueError, match=message):
        gcode_program(robot(), **options)
    with pytest.raises(ValueError, match=r"chain must be a Chain \(or hold one as .chain\); got list"):
        gcode_program([])  # type: ignore[arg-type]


def test_far_coordinates_are_refused_rather_than_printed_long():
    far = Chain([sc.Line((0, 0), (1e10, 0)), sc.Line((1e10, 0), (2e10, 0))])
    with pytest.raises(ValueError, match=r"beyond 1e\+09 program units"):
        gcode_program(far)


def test_an_arc_chain_in_the_plane_is_exact_g2_g3(tmp_path):
    arcs = [Arc((0, 0), -5.0, np.pi / 2, 3.0), Arc((0, 0), -5.0, np.pi / 2 - 3.0, 2 * np.pi)]  # clockwise, then a full turn
    chain = Chain(arcs, units="mm")
    program = gcode_program(chain)
    assert [line.split()[0] for line in body(program.text)][-3:] == ["G2", "G2", "M2"]
    back = parse_gcode_chain(program.text)
    assert [a.radius for a in back] == pytest.approx([-5.0, -5.0], abs=1e-12)
    assert [a.sweep for a in back] == pytest.approx([3.0, 2 * np.pi], abs=1e-12)


@needs_rs274
def test_rs274_reads_paths_in_space_within_the_stated_tolerances():
    """Chords in tilted planes (the helix) and G18/G19 arcs and biarcs: rs274's moves (4 decimals) stay within
    the chord or arc tolerance of the chain, at every end and at the middle of every chord."""
    helix, _, _ = helix_chain()
    cases = [(helix, {"chord_tolerance": 0.01}, 0.01)]
    for frame in (PlaneFrame(normal=(0, -1, 0)), PlaneFrame(x_dir=(0, 1, 0), normal=(1, 0, 0))):
        cases.append((placed_road(frame), {"arc_tolerance": 0.01}, 0.01))
    for chain, options, tolerance in cases:
        program = gcode_program(chain, **options)
        moves = rs274.run_rs274(program.text, arc_tolerance=1e-4)
        points = moves.points[~moves.rapid]
        middles = (points[1:] + points[:-1]) / 2.0
        spacing = chain.length / 2000  # the nearest polyline point, then refined on the chain
        assert distance_to_chain(chain, points, spacing).max() <= tolerance + 2e-4
        if "chord_tolerance" in options:  # every move is a line or a chord: its middle too
            assert distance_to_chain(chain, middles, spacing).max() <= tolerance + 2e-4


def test_the_example_pocket_rounded_in_space_as_linuxcnc_reads_it(tmp_path):
    """examples/pocket.nc rounded G2: G5 at the corners in XY, G18/G19 biarcs where the tool plunges; LinuxCNC's
    interpreter library puts every point of it within the arc tolerance of the chain."""
    from spiral_cad.io.gcode import read_gcode
    from spiral_cad.io.toolpath_rounding import round_toolpath

    chain = round_toolpath(read_gcode(Path(__file__).parents[2] / "examples" / "pocket.nc"), max_deviation=0.05).chain
    program = gcode_program(chain, arc_tolerance=0.002)
    assert program.counts["G5"] > 0 and program.counts["biarcs"] > 0 and program.counts["chords"] == 0
    path = tmp_path / "pocket.ngc"
    path.write_text(program.text)
    points = np.array([p for kind, _, p in linuxcnc_preview(path, "mm") if kind != "rapid"])
    assert distance_to_chain(chain, points, chain.length / 2000).max() <= 0.002 + 1e-9


def test_a_mm_chain_as_an_inch_program_and_without_the_rapid():
    chain = robot()
    program = gcode_program(chain, units="in", rapid_to_start=False, feed=30)
    lines = body(program.text)
    assert lines[0].startswith("G20 ") and "F30" in lines and not any(line.startswith("G0") for line in lines)
    assert "converted from the chain's mm, times 0.0393701" in program.text
    back = parse_gcode_chain(program.text.replace("F30\n", "F30\nG0 X0 Y0\n"), units="mm")  # the machine starts at the start
    assert np.abs(back.rows.geometry - chain.rows.geometry).max() < 1e-11


def _arc_radii(text: str) -> list[float]:
    """The radius of every G2/G3 of a program we write: the length of its centre words (G91.1: from its start)."""
    radii = []
    for line in body(text):
        if line.startswith(("G2 ", "G3 ")):
            radii.append(float(np.hypot(*[float(w[1:]) for w in line.split()[1:] if w[0] in "IJK"])))
    return radii


@needs_rs274
def test_no_arc_below_linuxcncs_least_radius_is_written_and_rs274_reads_the_program(tmp_path):
    """A corner rounded within 0.0003 mm in the XZ plane (G18: biarcs) and a true arc of radius 0.001 mm in XY:
    their biarcs and the arc would be G2/G3 of radius below 0.00005 in (0.00127 mm), which rs274 refuses as
    zero-radius arcs (comp.ngc, lathe_g7x_quadrants.ngc); they are straight moves within the tolerances."""
    least = 0.00005 * 25.4
    corner = round_corners(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1.0], [2, 0, 1]]), max_deviation=0.0003).chain
    spiral = np.asarray(corner[1].control_points)[:, [2, 0]]  # in G18's (Z, X) coordinates
    unrestricted, _ = spiral_biarcs(spiral, 0.001)
    assert any(about is not None and abs(radius) < least for _, about, radius in unrestricted)  # the case arises
    pieces, error = spiral_biarcs(spiral, 0.001, least)
    assert error <= 0.001 and not any(about is not None and abs(radius) < least for _, about, radius in pieces)
    tiny_arc = Chain([Arc((0.0, 0.0), 0.001, 0.0, 2.0)], units="mm")
    for chain in (corner, tiny_arc):
        program = gcode_program(chain)
        assert all(radius >= least for radius in _arc_radii(program.text))
        assert "(arcs below LinuxCNC's least radius 0.00127 mm: straight moves within the tolerances above)" in program.text
        assert program.arc_error <= 0.001 and program.chord_error <= 0.001
        path = tmp_path / "tiny.ngc"
        path.write_text(program.text)
        done = linuxcnc_rs274(path, tmp_path / "canon.txt")
        assert done.returncode == 0 and "error" not in done.stderr.lower() and "radius" not in done.stderr.lower(), done.stderr
        moves = rs274.run_rs274(program.text, arc_tolerance=1e-4)
        points = moves.points[~moves.rapid][:, : chain.dim]
        assert distance_to_chain(chain, points, chain.length / 2000).max() <= 0.001 + 2e-4
    assert gcode_program(tiny_arc).counts["chords"] == 1
