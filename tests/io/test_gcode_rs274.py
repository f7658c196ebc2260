"""Full NGC through LinuxCNC's own interpreter rs274, cross-checked against the built-in reader."""

import random
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from spiral_cad.io import rs274
from spiral_cad.io.gcode import parse_gcode, read_gcode

needs_rs274 = pytest.mark.skipif(
    rs274.rs274_executable() is None,
    reason=f"LinuxCNC's rs274 is not installed (Debian package {rs274.PACKAGE}; `make test` installs it where it can)",
)


def test_lines_are_numbered_for_rs274_to_print():
    text = "%\nG21\n  n10 G1 X1\n/G0 X2\no100 sub\n\n(comment)\n"
    assert rs274.numbered(text).split("\n") == ["%", "N2 G21", "  N3  G1 X1", "/N4 G0 X2", "o100 sub", "", "N7 (comment)", ""]


def test_a_clear_error_when_rs274_is_absent(monkeypatch):
    monkeypatch.setattr(rs274.shutil, "which", lambda name: None)
    with pytest.raises(ValueError, match=r"interpreter 'rs274' is not installed: .* linuxcnc-uspace"):
        parse_gcode("G21 G1 X1 F1\nG1 X2\nM2\n", interpreter="rs274")
    with pytest.raises(ValueError, match=r"interpreter must be 'builtin' or 'rs274'; got 'emc'"):
        parse_gcode("G21\n", interpreter="emc")


@needs_rs274
def test_parameters_expressions_loops_and_subroutines():
    text = """G21 G90 F100
#100 = 5
o100 sub
  G1 X[#1] Y[#1 * 2]
o100 endsub
#101 = 0
o200 while [#101 LT 3]
  o100 call [#100 + #101]
  #101 = [#101 + 1]
o200 endwhile
G0 Z[#100]
M2
"""
    path = parse_gcode(text, "full.ngc", interpreter="rs274")
    assert path.units == "mm"
    assert path.points.tolist() == [[5, 10, 0], [6, 12, 0], [7, 14, 0], [7, 14, 5]]
    assert path.lines.tolist() == [4, 4, 4, 11]  # the line of the move, inside the subroutine
    assert path.rapid.tolist() == [False, False, False, True]


@needs_rs274
def test_rs274_refusals_name_the_line():
    with pytest.raises(ValueError, match=r"bad.ngc line 3: rs274 refused the program: Two g codes used from same modal group"):
        parse_gcode("G21 F100\nG1 X1\nG90 G91 X2\nM2\n", "bad.ngc", interpreter="rs274")
    with pytest.raises(ValueError, match=r"line 3: an arc \(ARC_FEED\) is refused"):
        parse_gcode("G21 F100\nG1 X1\nG2 X2 Y1 I0 J1\nM2\n", interpreter="rs274")


@needs_rs274
def test_canned_cycles_expand_into_moves():
    path = parse_gcode("G21 G90 F100\nG0 X0 Y0 Z5\nG81 X1 Y1 Z-1 R2\nG80\nM2\n", interpreter="rs274")
    assert path.points.tolist()[-3:] == [[1, 1, 2], [1, 1, -1], [1, 1, 2]] and set(path.lines[-3:]) == {3}


def program(seed: int) -> str:
    """A random program the built-in reader accepts: 4 decimals, G90/G91 moves, XY arcs (I, J)."""
    rng = random.Random(seed)
    units = rng.choice(["G20", "G21"])
    out = [f"%\n({seed})\n{units} G90 G17 F100", "G0 X0 Y0 Z0"]
    at = [0.0, 0.0]
    for _ in range(rng.randint(5, 40)):
        kind = rng.random()
        if kind < 0.1:
            out.append(rng.choice(["G61", "G64 P0.01", "S1000 M3", "M9", "G4 P0.1", "T2 M6"]))
            continue
        x, y, z = (round(rng.uniform(-50, 50), 4) for _ in range(3))
        if kind < 0.6:
            out.append(f"{rng.choice(['G0', 'G1'])} X{x} Y{y}" + (f" Z{z}" if rng.random() < 0.3 else ""))
            at = [x, y]
        elif kind < 0.8:
            dx, dy = round(x / 10, 4), round(y / 10, 4)
            out.append(f"G91 G1 X{dx} Y{dy}\nG90")
            at = [round(at[0] + dx, 4), round(at[1] + dy, 4)]
        else:  # an arc about a centre at (i, j) from here, ending on the same circle (to 4 decimals)
            i, j = round(x / 5, 4), round(y / 5, 4)
            radius, turn = np.hypot(i, j), rng.uniform(0.2, 6.0)
            angle = np.arctan2(-j, -i) + turn
            end = [round(at[0] + i + radius * np.cos(angle), 4), round(at[1] + j + radius * np.sin(angle), 4)]
            out.append(f"{rng.choice(['G2', 'G3'])} X{end[0]} Y{end[1]} I{i} J{j}")
            at = end
    out.append("M30\n%\n")
    return "\n".join(out)


@needs_rs274
@pytest.mark.parametrize("seed", range(12))
def test_rs274_agrees_with_the_built_in_reader(seed):
    text = program(seed)
    ours = parse_gcode(text, arc_tolerance=0.001)
    theirs = parse_gcode(text, interpreter="rs274", arc_tolerance=0.001)
    assert ours.units == theirs.units and ours.lines.tolist() == theirs.lines.tolist()
    assert ours.rapid.tolist() == theirs.rapid.tolist()
    scale = np.abs(ours.points).max()
    assert np.abs(ours.points - theirs.points).max() <= 1e-9 * scale


@needs_rs274
def test_rs274_agrees_on_arcs_in_every_plane():
    text = """G21 G90 F100
G0 X10 Y0 Z0
G3 X0 Y10 I-10 J0
G2 X10 Y0 Z-2 I0 J-10
G18 G3 X0 Z8 I-10 K0
G19 G2 Y10 Z8 J5 K0
G17 G91.1 G3 X5 Y5 I5 J0 P2
G90.1 G2 X0 Y5 I2.5 J5
M2
"""
    ours = parse_gcode(text, arc_tolerance=0.0005)
    theirs = parse_gcode(text, interpreter="rs274", arc_tolerance=0.0005)
    assert ours.lines.tolist() == theirs.lines.tolist()
    assert np.abs(ours.points - theirs.points).max() <= 1e-9 * np.abs(ours.points).max()


@needs_rs274
def test_read_gcode_takes_the_interpreter(tmp_path):
    file = tmp_path / "p.ngc"
    file.write_text("G20 F1\n#100=0.5\nG1 X#100\nG1 Y[#100*3]\nM2\n", encoding="utf-8")
    path = read_gcode(file, interpreter="rs274")
    assert path.units == "in" and path.points.tolist() == [[0.5, 0, 0], [0.5, 1.5, 0]] and path.source == "p.ngc"


@needs_rs274
def test_build_from_gcode_with_the_rs274_interpreter(tmp_path, capsys):
    from spiral_cad.app.cli import main

    program = tmp_path / "loop.ngc"
    program.write_text("G21 G90 F100\n#100=0\no1 while [#100 LT 4]\nG1 X[#100*10] Y[#100 MOD 2 * 10]\n#100=[#100+1]\no1 endwhile\nG2 X30 Y0 I0 J-5\nM2\n",
                       encoding="utf-8")  # fmt: skip
    out = tmp_path / "out"
    argv = ["build", "--from-gcode", str(program), "--max-deviation", "0.05", "--no-plots", "--out", str(out)]
    assert main([*argv, "--interpreter", "rs274", "--arc-tolerance", "0.01"]) == 0
    assert list(out.glob("loop*_samples.csv"))  # one design per G2 path (a corner next to the arc may split it)
    assert main([*argv, "--interpreter", "builtin"]) == 2
    assert "parameters, expressions and O-words are not read by the built-in reader" in capsys.readouterr().err


@needs_rs274
def test_a_program_that_never_ends_is_stopped():
    endless = "G21 F100\n#100=0\no1 while [1]\nG1 X[#100 MOD 2]\n#100=[#100+1]\no1 endwhile\nM2\n"
    with pytest.raises(ValueError, match=r"endless.ngc: rs274 was still running after 2 s \(a loop that never ends\?\); stopped"):
        rs274.run_rs274(endless, "endless.ngc", timeout=2)


@needs_rs274
def test_a_program_that_prints_without_end_is_stopped_by_size(monkeypatch):
    monkeypatch.setattr(rs274, "MAX_OUTPUT", 1 << 20)
    endless = "G21 F100\n#100=0\no1 while [1]\nG1 X[#100 MOD 2]\n#100=[#100+1]\no1 endwhile\nM2\n"
    with pytest.raises(ValueError, match=r"rs274 printed more than 1 MB of moves"):
        rs274.run_rs274(endless, "endless.ngc", timeout=60)


@needs_rs274
def test_a_program_that_never_names_its_unit_is_refused_as_by_the_built_in_reader():
    text = "G90 F10 (G21 only in a comment)\nG1 X1 Y0\nX2 Y1\nM30\n"
    with pytest.raises(ValueError, match=r"never says G20 \(inches\) or G21 \(mm\)"):
        parse_gcode(text, interpreter="rs274")
    assert parse_gcode("G 2 1 G90 F10\nG1 X1 Y0\nX2 Y1\nM30\n", interpreter="rs274").units == "mm"


@needs_rs274
def test_rs274_runs_in_its_own_home_so_runs_side_by_side_and_a_running_linuxcnc_keep_their_tool_tables(tmp_path, monkeypatch):
    """rs274 opens ``$HOME/.tool.mmap`` and empties it: in the user's home a run would empty the tool table of a
    LinuxCNC running there, and two runs at once break each other (SIGBUS, "Requested tool 1 not found")."""
    home = tmp_path / "home"
    home.mkdir()
    table = home / ".tool.mmap"
    table.write_bytes(b"a running LinuxCNC's tool table")
    monkeypatch.setenv("HOME", str(home))
    program = "G21 G90 G17\nT1 M6\nG0 X0 Y0\nG1 X10 Y0 F100\nG1 X10 Y5\nM2\n"
    with ThreadPoolExecutor(8) as pool:
        paths = list(pool.map(lambda _: rs274.run_rs274(program), range(24)))
    assert all(np.allclose(path.points[-1][:2], (10, 5)) for path in paths)
    assert table.read_bytes() == b"a running LinuxCNC's tool table"


@pytest.mark.parametrize("deaths", [1, 2, 3])
def test_rs274_dying_by_a_signal_is_run_again_and_named_when_it_keeps_dying(tmp_path, monkeypatch, deaths):
    """LinuxCNC's rs274 sometimes dies by SIGBUS on a program it reads on the next run: run again (3 runs at most), and
    when it keeps dying say so by the signal's name, not as the program refused."""
    real = rs274.rs274_executable()
    if real is None:
        pytest.skip(f"LinuxCNC's rs274 is not installed ({rs274.PACKAGE})")
    count = tmp_path / "runs"
    fake = tmp_path / "rs274"
    fake.write_text(f'#!/bin/sh\necho x >> {count}\n[ "$(wc -l < {count})" -le {deaths} ] && kill -BUS $$\nexec {real} "$@"\n')
    fake.chmod(0o755)
    monkeypatch.setattr(rs274, "rs274_executable", lambda: str(fake))
    program = "G21 G90 G17\nG0 X0 Y0\nG1 X10 Y0 F100\nG1 X10 Y5\nM2\n"
    if deaths < rs274.SIGNAL_RUNS:
        path = rs274.run_rs274(program)
        assert np.allclose(path.points[-1][:2], (10, 5)) and count.read_text().count("x") == deaths + 1
    else:
        with pytest.raises(ValueError, match=r"rs274 died by SIGBUS 3 times, saying nothing"):
            rs274.run_rs274(program)
        assert count.read_text().count("x") == rs274.SIGNAL_RUNS
