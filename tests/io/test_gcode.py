"""G-code in: the documented subset read, everything else refused by name and line; toolpaths rounded G2."""

import math
import random
import re
from pathlib import Path

import numpy as np
import pytest

from spiral_cad.io.gcode import parse_gcode, read_gcode
from spiral_cad.io.toolpath_rounding import round_toolpath

HERE = Path(__file__).resolve().parents[1] / "gcode"


def test_a_pocket_program_with_the_usual_preamble():
    path = read_gcode(HERE / "pocket.nc")
    assert path.units == "mm" and path.source == "pocket.nc"
    assert path.points[0].tolist() == [5, 5, 10] and path.points[-1].tolist() == [5, 10, 10]
    assert path.lines[0] == 7 and path.lines[-1] == 19  # the G-code lines of the moves (1-based)
    assert path.rapid[:2].tolist() == [True, True] and not path.rapid[2]
    assert len(path) == 13


def test_incremental_inch_moves_accumulate():
    path = read_gcode(HERE / "helix_incremental.nc")
    assert path.units == "in"
    assert np.allclose(path.points[-1], [1.0, 0.0, -0.3])  # a full hexagon down 6 steps, after X1 first
    assert np.allclose(path.points[1], [1.5, 0.866, -0.05])


def test_arcs_are_refused_by_name_with_their_line():
    with pytest.raises(ValueError, match=r"with_arcs.nc line 5: G2 \(a clockwise arc\) is refused: only straight moves"):
        read_gcode(HERE / "with_arcs.nc")
    with pytest.raises(ValueError, match=r"line 2: G3 \(a counterclockwise arc\)"):
        parse_gcode("G21 G90\nG03 X1 Y1 R1\n")


@pytest.mark.parametrize(
    "text, match",
    [
        ("G21\nG28 X0\n", r"line 2: G28 is refused: a move to the machine's home position"),
        ("G21\nG81 X1 Z-1 R1\n", r"line 2: G81 is refused: a canned cycle"),
        ("G21\nG10 L2 P2 X5\n", r"line 2: G10 is refused: setting work offsets"),
        ("G21\nG1 X1 A90\n", r"line 2: the word A90 is not in the supported subset"),
        ("G21\nM98 P100\n", r"line 2: M98 is not in the supported subset"),
        ("G1 X1\n", r"line 1: the program sets no unit before its first move"),
        ("G21\nX1\n", r"line 2: coordinates with no motion mode"),
        ("G21 G1 X1\nG20\nX2\n", r"line 2: G20 changes the unit after the first move"),
        ("G21\nG0 G1 X1\n", r"line 2: G0 and G1 are both in modal group 1 \(motion\)"),
        ("G21\nG1 X1 X2\n", r"line 2: X is given twice"),
        ("G21\nG1 X1e3\n", r"line 2: X1e3 is a number with an exponent"),
        ("G21\nG1 X--1\n", r"line 2: 'X--1' is not a G-code word"),
        ("G21\nG1 X" + "9" * 400 + "\n", r"line 2: X9+… is not a finite number"),
        ("G21\nG1 X1 (open comment\n", r"line 2: a comment is not closed"),
        ("G21\nG1 X1\x07\n", r"line 2: control character"),
        ("G21\nG1 Xnan\n", r"line 2: 'Xnan' is not a G-code word"),
        ("G21\nG1 X1\n", r"has 1 move\(s\)"),
        ("", r"has 0 move\(s\)"),
        ("G21 G90\nG1 X1\x0bY1\nG1 X2 Y2\n", r"line 2: control character '\\x0b'"),  # not a line break
        ("G21 G90\nG1 X1\u2028Y1\nG1 X2 Y2\n", r"line 2: control character"),
        ("G21\nG1 X1 Y1\nG1 X\u0663 Y5\n", r"line 3: 'X\u0663 Y5' is not a G-code word"),  # an Arabic-Indic 3
        ("G21\nG1 X\uff11\uff12\n", r"line 2: .* is not a G-code word"),  # full-width digits
        ("G21\nG1 X1 (a(b)c)\n", r"line 2: a comment is not closed \(or is nested\)"),
        ("G21\nG0.00000000000000000000005 X1\n", r"line 2: G0.000000000000000000… is not a LinuxCNC G code"),
        ("G21\nG" + "9" * 300 + "\n", r"line 2: G99999999999999999999… is not a LinuxCNC G code"),
        ("G21\nG1 X1 )\n", r"line 2: a comment is not closed"),
        ("G21\nG1 X1" + " F1" * 30_000 + "\n", r"line 2: the line has 90,005 characters; at most 65,536"),
    ],
)
def test_everything_outside_the_subset_is_refused_by_name(text, match):
    with pytest.raises(ValueError, match=match):
        parse_gcode(text)


def test_comments_blank_lines_and_program_end():
    path = parse_gcode("%\n(a) G21 ; mm\n\nG1 X1 (b) Y0\nG1 X1 Y0 (no move: not a point)\nY1\nM30\nG28\n%\n")
    assert path.points.tolist() == [[1, 0, 0], [1, 1, 0]] and path.lines.tolist() == [4, 6]


def test_many_comments_on_one_line_are_read_in_one_pass():
    # One pass over the line: 20 000 comments take milliseconds (each once cost a copy of the rest).
    path = parse_gcode("G21 G90\nG1 X1 " + "(a)" * 20_000 + "\nG1 X2 Y1 ; done (\r\nG1 X3 Y1\rG1 X3 Y2\n")
    assert path.points.tolist() == [[1, 0, 0], [2, 1, 0], [3, 1, 0], [3, 2, 0]] and path.lines.tolist() == [2, 3, 4, 5]


def test_a_file_name_with_control_characters_is_shown_quoted(tmp_path):
    odd = tmp_path / "evil\x1b[31mRED\nline.nc"
    odd.write_text("G1 X1\n", encoding="utf-8")
    with pytest.raises(ValueError) as error:
        read_gcode(odd)
    assert "\x1b" not in str(error.value) and "\n" not in str(error.value) and "\\x1b[31mRED\\nline.nc" in str(error.value)


def test_files_that_are_not_programs(tmp_path):
    secret = tmp_path / "passwd"
    secret.write_text("root:x:0:0:root:/root:/bin/sh\n", encoding="utf-8")
    with pytest.raises(ValueError, match="passwd: not a G-code file name") as error:
        read_gcode(secret)  # a design file naming any file: neither read nor quoted
    assert "root" not in str(error.value)
    with pytest.raises(ValueError, match="is a folder"):
        read_gcode(tmp_path)
    with pytest.raises(ValueError, match="is missing"):
        read_gcode(tmp_path / "none.nc")
    bad = tmp_path / "latin1.nc"
    bad.write_bytes(b"G21\nG1 X1 (caf\xe9)\n")
    with pytest.raises(ValueError, match=r"latin1.nc line 2: byte 0xe9 is not UTF-8 text"):
        read_gcode(bad)


def test_a_toolpath_rounds_g2_within_the_tolerance_and_errors_name_the_line():
    path = read_gcode(HERE / "pocket.nc")
    rounded = round_toolpath(path, max_deviation=0.05)
    chain = rounded.chain
    assert chain.dim == 3 and chain.units == "mm"
    assert np.array_equal(chain.start, path.points[0]) and np.array_equal(chain.end, path.points[-1])
    u = np.linspace(0, 1, 2001)[:, None]
    for corner in rounded.corners:
        pts = [(1 - u) ** 3 * c[0] + 3 * u * (1 - u) ** 2 * c[1] + 3 * u**2 * (1 - u) * c[2] + u**3 * c[3]
               for c in (s.control_points for s in corner.spirals)]  # fmt: skip
        nearest = min(np.linalg.norm(p - path.points[corner.index], axis=1).min() for p in pts)
        assert 0.99 * 0.05 <= nearest <= 0.05
    drill = parse_gcode("G21 G90\nG0 X0 Y0 Z5\nG1 Z-3\nG0 Z5\nG0 X10\n", "drill.nc")
    with pytest.raises(ValueError, match=r"drill.nc: .*folds straight back at point 1 \(line 3\)"):
        round_toolpath(drill, max_deviation=0.05)


def test_mutated_programs_are_read_or_refused_never_crash():
    original = (HERE / "pocket.nc").read_bytes()
    rng = random.Random(16)
    outcomes = {"read": 0, "refused": 0}
    for _ in range(300):
        data = bytearray(original)
        for _ in range(rng.randint(1, 4)):
            data[rng.randrange(len(data))] = rng.randrange(256)
        try:
            text = bytes(data).decode("utf-8")
        except UnicodeDecodeError:
            continue
        try:
            path = parse_gcode(text, "mutated.nc")
            round_toolpath(path, max_deviation=0.05)
            outcomes["read"] += 1
        except ValueError as error:
            assert "line" in str(error) or "move" in str(error) or "corner" in str(error) or "point" in str(error), str(error)
            outcomes["refused"] += 1
    assert outcomes["read"] > 0 and outcomes["refused"] > 0


def test_huge_and_tiny_coordinates():
    big = parse_gcode("G21\nG1 X1e0\n".replace("X1e0", "X" + "1" + "0" * 300) + "G1 Y" + "1" + "0" * 300 + "\n")
    assert math.isclose(big.points[-1][1], 1e300)
    tiny = parse_gcode("G21\nG1 X0.000001\nG1 Y0.000001\nG1 Z0.000001\n")
    assert round_toolpath(tiny, max_deviation=1e-8, for_occt=False).chain.dim == 3
    with pytest.raises(
        ValueError, match=r"line 3: the rounded path's segment 1 \(BezierSpiral, length .* mm\) is shorter than OCCT's 1e-07"
    ):
        round_toolpath(tiny, max_deviation=1e-8)  # legs of 1e-6 mm: no STEP edge can be that short


# ------------------------------------------------------------ the command line and design files


def csv_table(path):
    lines = path.read_text().splitlines()
    return lines[0], np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


def test_build_from_gcode_writes_step_and_samples_of_a_g2_path(tmp_path, capsys):
    from spiral_cad.app.cli import main
    from spiral_cad.cad.continuity import check_continuity

    out = tmp_path / "out"
    assert main(["build", "--from-gcode", str(HERE / "pocket.nc"), "--max-deviation", "0.05", "--out", str(out)]) == 0
    assert "pocket: rounded_polyline" in capsys.readouterr().out
    assert {p.name for p in out.iterdir()} >= {"pocket.step", "pocket_samples.csv", "pocket.igs", "pocket.dxf"}
    report = check_continuity(out / "pocket.step")
    assert report.passes("G2") and report.pieces == 1 and report.units == "mm"
    head, table = csv_table(out / "pocket_samples.csv")
    assert head == "s [mm],x [mm],y [mm],z [mm],tx [1],ty [1],tz [1],curvature [1/mm]"
    assert table[0, 1:4].tolist() == [5, 5, 10] and table[-1, 1:4].tolist() == [5, 10, 10]
    assert table[:, 7].max() == pytest.approx(1 / 0.09, rel=1e-9)  # radius 0.09 mm at a 0.05 mm tolerance
    # the same design as a design file, next to its program: the same samples
    design = tmp_path / "design.json"
    (tmp_path / "pocket.nc").write_bytes((HERE / "pocket.nc").read_bytes())
    design.write_text('{"units": "mm", "designs": [{"name": "pocket", "type": "rounded_polyline", "gcode": "pocket.nc",'
                      ' "max_deviation": 0.05, "samples": {"chord_tolerance": 0.005}}]}')  # fmt: skip
    assert main(["build", str(design), "--out", str(tmp_path / "file")]) == 0
    assert (tmp_path / "file" / "pocket_samples.csv").read_bytes() == (out / "pocket_samples.csv").read_bytes()


def test_an_inch_program_is_converted_to_the_outputs_unit(tmp_path):
    from spiral_cad.app.cli import main

    assert main(["build", "--from-gcode", str(HERE / "helix_incremental.nc"), "--max-deviation", "1", "--sample-step", "5",
                 "--out", str(tmp_path)]) == 0  # fmt: skip
    _, table = csv_table(tmp_path / "helix_incremental_samples.csv")
    assert table[0, 1:4].tolist() == [25.4, 0, 0]  # X1 inch, in mm
    assert np.diff(table[:, 0]).max() <= 5.0


@pytest.mark.parametrize(
    "argv, message",
    [
        (
            ["--from-gcode", "with_arcs.nc", "--max-deviation", "0.05", "--max-curvature", "100"],
            r"max_curvature: corner options of straight moves; with_arcs.nc line 5 starts a path with arcs",
        ),
        (["--from-gcode", "pocket.nc"], r"--from-gcode needs --max-deviation"),
        (["--from-gcode", "../data/landxml", "--max-deviation", "1"], r"the G-code file is a folder"),  # holds no program (else: all built)
        (["--from-gcode", "pocket.nc", "--max-deviation", "nan"], r"--max-deviation must be a positive finite number; got nan"),
        (["--from-gcode", "pocket.nc", "--max-deviation=-1"], r"--max-deviation must be a positive finite number; got -1.0"),
        (["--from-gcode", "pocket.nc", "--max-deviation", "5e-324"], r"max_deviation 4.94066e-324 is below what float64 resolves"),
        (["--from-gcode", "pocket.nc", "--max-deviation", "1", "--sample-step", "0"], r"--sample-step must be a positive"),
        (["--from-gcode", "pocket.nc", "--max-deviation", "1", "--sample-step", "1", "--chord-tolerance", "1"], r"not both"),
        (
            ["--from-gcode", "pocket.nc", "--max-deviation", "0.001", "--max-curvature", "1"],
            r"corner 2 \(line 9\) at \(5, 5, -1\): .*above max_curvature 1",
        ),
        (["design.json", "--max-deviation", "1"], r"--max-deviation: only with --from-gcode"),
        (["design.json", "--interpreter", "rs274"], r"--interpreter: only with --from-gcode"),
        (
            ["--from-gcode", "with_arcs.nc", "--max-deviation", "0.05", "--arc-tolerance", "0"],
            r"arc_tolerance must be a positive finite length; got 0.0",
        ),
        ([], r"give a design file, or --from-gcode"),
    ],
)
def test_build_from_gcode_refuses_by_name_and_writes_nothing(tmp_path, capsys, monkeypatch, argv, message):
    from spiral_cad.app.cli import main

    monkeypatch.chdir(HERE)
    out = tmp_path / "out"
    assert main(["build", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err) and "Traceback" not in err, err
    assert not out.exists() or not any(out.iterdir())


def test_design_files_take_3d_points_and_every_rounding_option(tmp_path):
    from spiral_cad.app.designfile import DesignError, build

    helix = [[40 * math.cos(0.9 * k), 40 * math.sin(0.9 * k), 9 * 0.9 * k] for k in range(8)]
    for option in ({"max_deviation": 0.4}, {"max_curvature": 0.3}, {"spiral_lengths": [2.5] * 6}, {"curvature": 0.25},
                   {"max_deviation": 0.4, "max_curvature": 2.0}):  # fmt: skip
        _, (built,) = build({"units": "mm", "designs": [{"name": "h", "type": "rounded_polyline", "points": helix, **option}]})
        assert built.chain.dim == 3
    bad = [
        ({"points": helix, "gcode": "x.nc"}, "give points or gcode"),
        ({"points": [[0, 0], [1, 0, 0], [1, 1]]}, r"points\[1\]: must be a point like the first"),
        ({"points": helix, "max_deviation": -1}, r"max_deviation: must be positive"),
        ({"points": helix, "spiral_lengths": [1, 2]}, r"spiral_lengths needs one value or one per interior point"),
        ({"points": helix, "samples": {"step": 1, "chord_tolerance": 1}}, r"samples: must be"),
        ({"gcode": 12}, r"gcode: must be the path of a G-code file"),
        ({"points": helix, "curvature": 1, "max_deviation": 1}, r"not both"),
    ]
    for fields, message in bad:
        with pytest.raises(DesignError, match=message):
            build({"units": "mm", "designs": [{"name": "h", "type": "rounded_polyline", **fields}]})


def test_bytes_and_a_second_unit_are_value_errors():
    with pytest.raises(ValueError, match="text must be the program as str; got bytes"):
        parse_gcode(b"G21\nG1 X1\n")
    path = parse_gcode("G21\nG1 X1\nG1 X1 Y1\nG1 X2 Y1\n")
    with pytest.raises(ValueError, match="units: the program's own"):
        round_toolpath(path, units="m", max_deviation=0.1)
