"""G-code out and G5 in under hostile input: the input program is never replaced and keeps its feed, unattainable
tolerances and coarse decimals are refused by name, a G5 cubic's curvature is its own, a trailing retract is read
as with G1, and every line of a program fits LinuxCNC's 255 characters."""

import re

import numpy as np
import pytest
from helpers import distance_to_chain, linuxcnc_rs274

from spiral_cad.app.cli import main
from spiral_cad.app.designfile import build, write
from spiral_cad.core import bezier
from spiral_cad.design import round_corners
from spiral_cad.io import gcode_write, rs274
from spiral_cad.io.gcode import parse_gcode, parse_gcode_chain, program_feeds, read_gcode_chain
from spiral_cad.io.gcode_write import gcode_program, spiral_biarcs

#: The tester's program (three G1 moves at F100).
PART = "G21 G90\nG0 X0 Y0\nG1 X10 Y0 F100\nG1 X10 Y10\nG1 X20 Y10\nM2\n"


def zigzag():
    return round_corners([[0, 0], [20, 2], [28, 18], [48, 20], [52, 4], [72, 8]], max_curvature=0.3, units="mm").chain


def feed_word(text: str) -> float:
    return float(re.search(r"^F([0-9.]+)$", text, re.MULTILINE).group(1))


def test_build_from_gcode_refuses_to_replace_its_input_and_writes_nothing(tmp_path, capsys):
    folder = tmp_path / "d"
    folder.mkdir()
    (folder / "part.ngc").write_text(PART)
    argv = ["build", "--from-gcode", str(folder / "part.ngc"), "--max-deviation", "0.5", "--out", str(folder), "--no-plots"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "error: part: the output" in err and "would replace the input" in err and "Traceback" not in err
    assert [p.name for p in folder.iterdir()] == ["part.ngc"] and (folder / "part.ngc").read_text() == PART
    # another name in the same folder is fine, and the rounded program runs at the program's own feed
    assert main([*argv, "--name", "part_g2"]) == 0
    assert (folder / "part.ngc").read_text() == PART
    assert feed_word((folder / "part_g2.ngc").read_text()) == 100.0


def test_the_rounded_program_keeps_the_programs_feed_converted_and_a_stated_feed_wins(tmp_path):
    program = tmp_path / "part.ngc"
    program.write_text(PART.replace("G1 X10 Y10", "G1 X10 Y10 F300"))  # two feeds: the lowest is kept
    design = {"name": "p", "type": "rounded_polyline", "gcode": str(program), "max_deviation": 0.5}
    units, built = build({"units": "in", "designs": [design]})
    write(built, tmp_path / "in", units, progress=lambda line: None, plots=False)
    assert feed_word((tmp_path / "in" / "p.ngc").read_text()) == pytest.approx(100 / 25.4, rel=1e-12)  # G20: in/min
    units, built = build({"units": "mm", "designs": [{**design, "gcode_out": {"feed": 250}}]})
    write(built, tmp_path / "mm", units, progress=lambda line: None, plots=False)
    assert feed_word((tmp_path / "mm" / "p.ngc").read_text()) == 250.0


def test_program_feeds_are_the_f_in_force_on_feed_moves(tmp_path):
    path = tmp_path / "f.ngc"
    path.write_text("G21 G90\nF50\nG0 X1 F9000\nG1 X2\nG5 I1 J0 P-1 Q0 X3 Y0 F75\nG1 X4\nG93 G1 X5 F2\nM2\n")
    # the F9000 on the rapid is modal: in force on the G1 after it; G93's inverse-time F is not a feed rate
    assert program_feeds(path) == ((9000.0, 75.0), "mm")
    assert parse_gcode(PART).feeds == (100.0,)


def test_biarcs_refuse_a_tolerance_float64_cannot_resolve_and_bound_the_pieces(monkeypatch):
    chain = round_corners([[0, 0], [20, 2], [28, 18]], max_curvature=0.3, units="mm").chain
    spiral = next(s for s in chain if type(s).__name__ == "BezierSpiral").control_points[:, :2]
    with pytest.raises(ValueError, match=r"arc_tolerance 1e-14 is below what float64 resolves .* the smallest usable is 2e-12"):
        spiral_biarcs(spiral, 1e-14)
    with pytest.raises(ValueError, match=r"arc_tolerance 1e-15 mm is below .* smallest usable is 7.2e-12 mm"):
        gcode_program(zigzag(), dialect="generic", arc_tolerance=1e-15)
    monkeypatch.setattr(gcode_write, "MAX_BIARCS", 16)
    with pytest.raises(ValueError, match=r"spiral 0 would need more than 16 biarcs"):
        spiral_biarcs(spiral, 1e-9)
    pieces, error = spiral_biarcs(spiral, 1e-3)
    assert len(pieces) <= 32 and error <= 1e-3


def test_decimals_too_coarse_for_the_tolerance_are_refused_naming_the_fewest():
    with pytest.raises(ValueError, match=r"decimals 3 round .* more than half of arc_tolerance 1e-05 mm; give decimals of at least 6"):
        gcode_program(zigzag(), arc_tolerance=1e-5, decimals=3)
    with pytest.raises(ValueError, match=r"decimals 3 .* chord_tolerance 0.001 mm; give decimals of at least 4"):
        gcode_program(zigzag(), decimals=3, arc_tolerance=1.0)
    assert "G64 P0.001\n" in gcode_program(zigzag(), decimals=4).text


@pytest.mark.parametrize("decimals", [6, 8])
def test_the_printed_program_is_within_the_stated_tolerance(decimals):
    """Measured on the printed numbers: the program's arcs read back as fine chords lie within arc_tolerance."""
    chain = zigzag()
    program = gcode_program(chain, dialect="generic", arc_tolerance=1e-5, decimals=decimals)
    printed = parse_gcode(program.text, arc_tolerance=1e-8).points[:, :2]
    assert distance_to_chain(chain, printed, 0.05).max() <= 1e-5 + 1e-8
    blend = [line for line in gcode_program(chain, arc_tolerance=1e-5, decimals=decimals).text.splitlines() if line.startswith("G64")]
    assert blend and float(blend[0][5:]) > 0.0  # never P0: LinuxCNC blends without a limit there


def test_header_lines_fit_linuxcnc_and_feeds_print_as_written():
    text = gcode_program(zigzag(), name="x" * 400).text
    assert max(len(line) for line in text.splitlines()) <= 255 and "xxx..." in text
    for feed in (1e200, 1e-20):
        with pytest.raises(ValueError, match=re.escape(f"feed {feed:g} mm/min cannot be printed with 13 decimals")):
            gcode_program(zigzag(), feed=feed)


def true_peak_curvature(cp, samples=200_001):
    """|Q' × Q''| / |Q'|³ of a cubic on a dense grid, from the Bernstein derivatives written out here."""
    u = np.linspace(0.0, 1.0, samples)[:, None]
    d1 = 3 * ((1 - u) ** 2 * (cp[1] - cp[0]) + 2 * u * (1 - u) * (cp[2] - cp[1]) + u**2 * (cp[3] - cp[2]))
    d2 = 6 * ((1 - u) * (cp[2] - 2 * cp[1] + cp[0]) + u * (cp[3] - 2 * cp[2] + cp[1]))
    kappa = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
    return float(kappa.max()), float(u[np.argmax(kappa), 0])


def test_a_g5_loop_is_read_with_its_true_curvature():
    chain = parse_gcode_chain("G21 G90 G17\nG0 X0 Y0\nG5 I10 J10 P10 Q-10 X1 Y0 F100\nM2\n")
    peak, at = true_peak_curvature(np.array([[0, 0], [10, 10], [11, -10], [1, 0.0]]))
    assert peak == pytest.approx(0.5431518, abs=1e-6) and at == pytest.approx(0.712, abs=1e-3)
    # what the build summary reports: the largest end curvature of the pieces (monotone within each)
    ends = max(max(abs(s.start_curvature), abs(s.end_curvature)) for s in chain)
    assert ends == pytest.approx(peak, rel=1e-9)
    assert len(chain) == 4 and chain.length == pytest.approx(bezier.arc_length(np.array([[0, 0], [10, 10], [11, -10], [1, 0.0]])))


def test_an_s_shaped_g5_is_split_into_one_signed_monotone_pieces_and_a_cusp_is_refused_by_line():
    chain = parse_gcode_chain("G21\nG0 X0 Y0\nG5 I5 J5 P-5 Q-5 X10 Y0\nM2\n")
    u = np.linspace(0.0, 1.0, 201)
    signs = []
    for piece in chain:
        kappa = piece.curvature(u)
        steps = np.diff(kappa)
        assert (steps >= -1e-12).all() or (steps <= 1e-12).all()  # monotone
        assert (kappa >= -1e-12).all() or (kappa <= 1e-12).all()  # one-signed
        signs.append(np.sign(kappa[100]))
    assert len(chain) == 4 and signs == [-1, -1, 1, 1]  # left lobe's peak, the inflection, right lobe's peak
    with pytest.raises(ValueError, match=r"line 3: the cubic .* has a cusp"):
        parse_gcode_chain("G21\nG0 X0 Y0\nG5 I1 J1 P-1 Q1 X1 Y0\nM2\n")


def test_our_spirals_read_back_unsplit(tmp_path):
    path = tmp_path / "z.ngc"
    path.write_text(gcode_program(zigzag()).text)
    assert len(read_gcode_chain(path)) == len(zigzag())


def test_a_g5_program_ending_with_a_retract_is_read_as_with_g1():
    chain = parse_gcode_chain("G21 G90 G17\nG0 X0 Y0\nG5 I0 J3 P0 Q-3 X1 Y1 F100\nG0 Z5\nG0 X0 Y0\nM2\n")
    assert len(chain) >= 1 and np.allclose(chain.end, [1, 1])
    with pytest.raises(ValueError, match=r"line 4: a rapid move \(G0\) between feed moves"):
        parse_gcode_chain("G21 G90 G17\nG0 X0 Y0\nG5 I0 J3 P0 Q-3 X1 Y1 F100\nG0 Z5\nG1 X2\nM2\n")


def test_each_move_keeps_its_own_feed_and_a_corner_takes_the_feed_of_the_move_into_it(tmp_path):
    program = tmp_path / "f3.ngc"
    program.write_text("G21 G90\nG0 X0 Y0\nG1 X10 Y0 F100\nG1 X10 Y10 F300\nG1 X20 Y10\nG1 X20 Y20 F100\nM2\n")
    units, built = build(
        {"units": "mm", "designs": [{"name": "f3", "type": "rounded_polyline", "gcode": str(program), "max_deviation": 0.5}]}
    )
    write(built, tmp_path / "out", units, progress=lambda line: None, plots=False)
    lines = (tmp_path / "out" / "f3.ngc").read_text().splitlines()
    words = [(i, float(line[1:])) for i, line in enumerate(lines) if re.fullmatch(r"F[0-9.]+", line)]
    assert [f for _, f in words] == [100.0, 300.0, 100.0]
    # F300 from the straight piece of the move to (10, 10) on; back to F100 for the last move, to (20, 20)
    assert lines[words[1][0] + 1].startswith("G1 X10 Y8.11") and lines[words[2][0] + 1] == "G1 X20 Y20"
    # as LinuxCNC's interpreter reads it: the feed of every move
    feeds = parse_gcode("\n".join(lines), arc_tolerance=0.01).point_feeds
    assert feeds[-1] == 100.0 and set(feeds[1:].tolist()) == {100.0, 300.0}


def test_feeds_per_segment_are_validated_and_nan_takes_the_feed():
    chain = zigzag()
    with pytest.raises(ValueError, match=r"feeds must hold one feed per segment \(13\); got 2"):
        gcode_program(chain, feeds=[1.0, 2.0])
    with pytest.raises(ValueError, match=re.escape("feed 1e+300 mm/min cannot be printed")):
        gcode_program(chain, feeds=[1e300] * 13)
    text = gcode_program(chain, feed=700, feeds=[np.nan] * 12 + [50.0]).text
    assert re.findall(r"^F([0-9.]+)$", text, re.MULTILINE) == ["700", "50"]


def test_a_path_in_other_units_converts_its_feeds():
    path = parse_gcode("G20 G90\nG0 X0\nG1 X1 F10\nM2\n").in_units("mm")
    assert path.feeds == (254.0,) and path.point_feeds[-1] == 254.0 and np.isnan(path.point_feeds[0])


@pytest.mark.skipif(rs274.rs274_executable() is None, reason=f"LinuxCNC's rs274 is not installed ({rs274.PACKAGE})")
def test_linuxcnc_reads_the_feeds_and_a_long_named_program(tmp_path):
    """rs274 runs the program (no "Command too long" for the header of a 400-character name) at our feeds."""
    chain = zigzag()
    program = tmp_path / "p.ngc"
    program.write_text(gcode_program(chain, name="x" * 400, feed=700, feeds=[np.nan] * 6 + [250.0] * 7).text)
    canon = tmp_path / "canon.txt"
    done = linuxcnc_rs274(program, canon)
    assert done.returncode == 0 and "too long" not in done.stdout + done.stderr
    feeds = [float(f) for f in re.findall(r"SET_FEED_RATE\(([0-9.]+)\)", canon.read_text())]
    assert [f for f in feeds if f] == [700.0, 250.0]


def test_a_design_files_unattainable_arc_tolerance_is_refused_naming_the_design(tmp_path, capsys):
    design = tmp_path / "d.json"
    design.write_text('{"units": "mm", "designs": [{"name": "robot", "type": "rounded_polyline", "max_curvature": 0.3, '
                      '"points": [[0, 0], [20, 2], [28, 18], [48, 20]], "gcode_out": {"dialect": "generic", "arc_tolerance": 1e-15}}]}')  # fmt: skip
    assert main(["build", str(design), "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    assert "error: robot.ngc: arc_tolerance 1e-15 mm is below what float64 resolves" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
