"""G-code read as lines and true arcs (spiral_cad.io.gcode_paths), judged against LinuxCNC's rs274."""

import math
import random
from pathlib import Path

import numpy as np
import pytest
from helpers import linuxcnc_rs274

from spiral_cad.core.segments import Arc, Line
from spiral_cad.io import rs274
from spiral_cad.io.gcode_paths import parse_gcode_moves, read_gcode_moves

needs_rs274 = pytest.mark.skipif(
    rs274.rs274_executable() is None,
    reason=f"LinuxCNC's rs274 is not installed (Debian package {rs274.PACKAGE}; `make test` installs it where it can)",
)

PLANES = """G21 G90 F100
G0 X5 Y5 Z0
G0 X10 Y0 Z0
G3 X0 Y10 I-10 J0
G1 X0 Y10 Z3
G18 G3 X-3 Z6 I0 K3
G19 G2 Y4 Z6 J-3 K0
G17 G3 X-3 Y4 I2 J0 P2
G1 X5
M2
"""


def on_circle(arc: Arc, centre, radius: float, count: int = 9) -> float:
    """The largest distance of the arc's points from the circle of ``centre`` and ``radius`` (in its plane)."""
    points = arc.point(np.linspace(0.0, 1.0, count))
    return float(np.abs(np.linalg.norm(points - np.asarray(centre, dtype=float), axis=1) - radius).max())


def canonical_arcs(text: str, folder) -> list[list[float]]:
    """rs274's own ARC_FEED calls of ``text``: (first end, second end, first centre, second centre, rotation, normal end)."""
    program = folder / "p.ngc"
    program.write_text(text)
    linuxcnc_rs274(program, folder / "c.txt", check=True)
    calls = [line for line in (folder / "c.txt").read_text().splitlines() if "ARC_FEED(" in line]
    return [[float(v) for v in line.split("ARC_FEED(")[1].rstrip(")").split(",")[:6]] for line in calls]


@pytest.mark.parametrize("interpreter", ["builtin", pytest.param("rs274", marks=needs_rs274)])
def test_arcs_in_every_plane_are_true_arcs(interpreter):
    moves = parse_gcode_moves(PLANES, "planes.ngc", interpreter=interpreter)
    kinds = [type(s).__name__ for s in moves.segments]
    assert kinds == ["Line", "Arc", "Line", "Arc", "Arc", "Arc", "Arc", "Line"]  # P2: one arc a turn
    # the path starts where the first move ends (G0 X5 Y5: where the tool stood before it is not known)
    assert moves.lines.tolist() == [3, 4, 5, 6, 7, 8, 8, 9] and moves.rapid.tolist() == [True] + [False] * 7
    xy, zx, yz, turn1, turn2 = (moves.segments[i] for i in (1, 3, 4, 5, 6))
    assert on_circle(xy, (0, 0, 0), 10) < 1e-12 and xy.sweep == pytest.approx(math.pi / 2)
    assert on_circle(zx, (0, 10, 6), 3) < 1e-12 and np.allclose(zx.end, (-3, 10, 6))
    assert on_circle(yz, (-3, 7, 6), 3) < 1e-12 and np.allclose(yz.end, (-3, 4, 6))
    for turn in (turn1, turn2):
        assert on_circle(turn, (-1, 4, 6), 2) < 1e-12 and turn.sweep == pytest.approx(2 * math.pi)
    for a, b in zip(moves.segments[:-1], moves.segments[1:]):
        assert np.abs(a.end - b.start).max() < 1e-12
    assert moves.program_feeds == (100.0,) and moves.units == "mm"


@needs_rs274
def test_arc_centres_agree_with_rs274s_own_arcs(tmp_path):
    """rs274's canonical ARC_FEED (its centre, end and turn) against the arcs the built-in reader makes."""
    rng = random.Random(7)
    lines, at = ["G21 G90 G17 F200", "G0 X5 Y5", "G0 X0 Y0"], (0.0, 0.0)
    for _ in range(30):
        i, j = round(rng.uniform(-20, 20), 4), round(rng.uniform(-20, 20), 4)
        radius, turn = math.hypot(i, j), rng.uniform(0.3, 5.5)
        angle = math.atan2(-j, -i) + turn
        end = (round(at[0] + i + radius * math.cos(angle), 4), round(at[1] + j + radius * math.sin(angle), 4))
        lines.append(f"{rng.choice(['G2', 'G3'])} X{end[0]} Y{end[1]} I{i} J{j}")
        at = end
    text = "\n".join([*lines, "M2", ""])
    theirs = canonical_arcs(text, tmp_path)
    ours = [s for s in parse_gcode_moves(text, interpreter="builtin").segments if isinstance(s, Arc)]
    assert len(ours) == len(theirs) == 30
    for arc, (x, y, cx, cy, rotation, _) in zip(ours, theirs):
        assert np.abs(arc.end - (x, y)).max() < 1e-4  # rs274 prints 4 decimals
        assert np.abs(np.asarray(arc.center) - (cx, cy)).max() < 2e-3  # our centre sits on the chord's bisector
        assert math.copysign(1, arc.radius) == math.copysign(1, rotation)


@needs_rs274
def test_the_two_readers_agree_segment_by_segment():
    moves = [parse_gcode_moves(PLANES, interpreter=i) for i in ("builtin", "rs274")]
    assert [type(s) for s in moves[0].segments] == [type(s) for s in moves[1].segments]
    for a, b in zip(moves[0].segments, moves[1].segments):
        assert np.abs(a.point([0, 0.3, 0.7, 1]) - b.point([0, 0.3, 0.7, 1])).max() < 1e-9


@pytest.mark.parametrize("interpreter", ["builtin", pytest.param("rs274", marks=needs_rs274)])
def test_a_helix_is_refused_by_name_or_read_as_chords_within_the_tolerance(interpreter):
    text = "G21 G90 F100\nG0 X5 Y5\nG0 X10 Y0 Z0\nG3 X-10 Y0 Z-4 I-10 J0\nM2\n"
    with pytest.raises(ValueError, match=r"line 4: a helical arc .* \(helix_tolerance; build: --arc-tolerance\)"):
        parse_gcode_moves(text, "helix.ngc", interpreter=interpreter)
    moves = parse_gcode_moves(text, "helix.ngc", interpreter=interpreter, helix_tolerance=0.01)
    chords = moves.segments[1:]
    assert all(isinstance(s, Line) for s in chords) and moves.chords.tolist() == [False] + [True] * len(chords)
    # every chord's middle is within the tolerance of the helix (its radius 10 about the z axis, z falling evenly)
    middles = np.array([s.point(0.5) for s in chords])
    assert np.abs(np.hypot(middles[:, 0], middles[:, 1]) - 10).max() <= 0.01
    assert "1 helical arc(s) read as chords within 0.01 mm" in moves.notes


@pytest.mark.parametrize("interpreter", ["builtin", pytest.param("rs274", marks=needs_rs274)])
def test_plunges_and_retracts_split_the_path(interpreter):
    text = "G21 G90 F100\nG0 X0 Y0 Z5\nG1 Z-1\nG0 Z5\nG0 X10\nG1 Z-1\nG2 X20 Y0 I5 J0\nG3 X30 Y0 I5 J0\nG1 Z5\nM2\n"
    moves = parse_gcode_moves(text, interpreter=interpreter)
    # (the rapid up to Z5 is where the path starts) down, up again (a fold); along, down, an S of two tangent arcs,
    # up (corners only)
    assert [int(moves.lines[j + 1]) for j in moves.folds()] == [4]
    assert moves.parts() == [(0, 1), (1, 7)]
    assert moves.straight(0, 1) and not moves.straight(1, 7)


def test_arcs_meeting_in_a_cusp_split_there():
    text = "G21 G90 F100\nG0 X-5\nG1 X10 Y0\nG2 X20 Y0 I5 J0\nG3 X10 Y0 I-5 J0\nM2\n"  # the second arc turns back on the first
    assert parse_gcode_moves(text).folds().tolist() == [1]


def test_an_arc_folding_back_onto_a_line_splits_there():
    text = "G21 G90 F100\nG0 X-5\nG1 X10 Y0\nG3 X10 Y0 I0 J5\nG1 X0 Y0\nM2\n"  # along, a full circle, straight back
    moves = parse_gcode_moves(text)
    assert moves.folds().tolist() == [1]  # the circle ends heading +x, the line runs -x
    assert [type(s).__name__ for s in moves.segments] == ["Line", "Arc", "Line"]


@pytest.mark.parametrize("interpreter", ["builtin", pytest.param("rs274", marks=needs_rs274)])
def test_a_program_without_a_unit_is_refused_unless_the_unit_is_stated(interpreter):
    text = "G90 F10\nG1 X1 Y0\nG2 X2 Y1 I0 J1\nM2\n"
    with pytest.raises(ValueError, match=r"build: --units mm or --units in"):
        parse_gcode_moves(text, "bare.ngc", interpreter=interpreter)
    inches = parse_gcode_moves(text, "bare.ngc", interpreter=interpreter, program_units="in", units="mm")
    assert inches.program_units == "in" and inches.units == "mm"
    assert np.allclose(inches.segments[-1].end, (50.8, 25.4)) and inches.segments[-1].radius == pytest.approx(-25.4)
    with pytest.raises(ValueError, match=r"program_units must be 'mm' or 'in'"):
        parse_gcode_moves(text, program_units="cm")


@needs_rs274
def test_rs274_finds_subroutine_files_in_the_programs_folder(tmp_path):
    (tmp_path / "square.ngc").write_text("o<square> sub\nG1 X#1\nG1 Y#1\no<square> endsub\nM2\n")
    (tmp_path / "main.ngc").write_text("G21 G90 F100\nG0 X-1\no<square> call [5]\nG2 X0 Y5 I-2.5 J0\nM2\n")
    moves = read_gcode_moves(tmp_path / "main.ngc", interpreter="rs274")
    assert [type(s).__name__ for s in moves.segments] == ["Line", "Line", "Arc"]
    assert moves.lines[-1] == 4 and np.allclose(moves.segments[1].end, (5, 5))


@needs_rs274
def test_a_helix_of_radius_zero_is_a_plunge(tmp_path):
    """LinuxCNC's useful-subroutines.ngc mills a hole as wide as the tool under cutter compensation: rs274 runs it as
    arcs whose ends lie at their centre, descending (ARC_FEED(0, 0, 0, 0, 1, z)); read as the straight moves they make."""
    program = Path(__file__).parents[1] / "data" / "gcode" / "linuxcnc_useful-subroutines.ngc"
    theirs = canonical_arcs(program.read_text(), tmp_path)
    zero = [a for a in theirs if a[:4] == [0, 0, 0, 0]]
    assert len(zero) >= 4
    moves = read_gcode_moves(program, interpreter="rs274", helix_tolerance=1e-4)
    plunges = [s for s in moves.segments if isinstance(s, Line) and np.allclose(s.start[:2], 0) and np.allclose(s.end[:2], 0)]
    assert sorted({round(float(s.end[2]), 4) for s in plunges} & {a[5] for a in zero}) == sorted({a[5] for a in zero})
