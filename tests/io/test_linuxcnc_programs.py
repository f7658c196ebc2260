"""LinuxCNC's own example programs (tests/data/gcode) built G2 by `build --from-gcode`: arcs kept true arcs, the
program's path within --max-deviation, and every design's program read back by rs274 onto its chain."""

import re
from pathlib import Path

import numpy as np
import pytest
from helpers import distance_to_chain, linuxcnc_rs274

from spiral_cad.app.cli import _parser, gcode_design, main
from spiral_cad.app.designfile import build
from spiral_cad.core.segments import Arc
from spiral_cad.io import rs274
from spiral_cad.io.gcode import read_gcode_chain, reading_options
from spiral_cad.io.gcode_write import TOLERANCE_MM, write_gcode

DATA = Path(__file__).parents[1] / "data" / "gcode"
needs_rs274 = pytest.mark.skipif(rs274.rs274_executable() is None, reason=f"LinuxCNC's rs274 is not installed ({rs274.PACKAGE})")
CANON_PLANES = {"CANON_PLANE_XY": (0, 1, 2), "CANON_PLANE_XZ": (2, 0, 1), "CANON_PLANE_YZ": (1, 2, 0)}


def canonical_ends(program: Path, folder: Path) -> np.ndarray:
    """The end of every feed move and rapid (x, y, z, in the program's unit) as rs274 executes ``program``."""
    done = linuxcnc_rs274(program, folder / "canon.txt", cwd=program.parent)
    assert done.returncode == 0 and "error" not in done.stderr.lower(), done.stderr
    plane, ends = (0, 1, 2), []
    for name, arguments in re.findall(
        r"(STRAIGHT_FEED|STRAIGHT_TRAVERSE|ARC_FEED|SELECT_PLANE)\(([^)]*)\)", (folder / "canon.txt").read_text()
    ):
        if name == "SELECT_PLANE":
            plane = CANON_PLANES[arguments.strip()]
            continue
        values = [float(v) for v in arguments.split(",")]
        if name == "ARC_FEED":
            end = [0.0, 0.0, 0.0]
            end[plane[0]], end[plane[1]], end[plane[2]] = values[0], values[1], values[5]
            ends.append(end)
        else:
            ends.append(values[:3])
    return np.array(ends)


def distance(chain, points: np.ndarray) -> np.ndarray:
    """The distance of points (x, y, z) from a chain; a plane chain lies at z = 0.

    The input's corners lie outside the rounded corners, farther than their spirals' radius of curvature:
    there the projection onto the tangent does not converge, and the measure is the polyline's through
    samples 1/16 of ``spacing`` apart (comp.ngc's corners: 0.0525 at ``spacing``, 0.050002 when dense)."""
    fine = spacing(chain) / 16
    if chain.dim == 3:
        return distance_to_chain(chain, points, fine)
    return np.where(points[:, 2] == 0.0, distance_to_chain(chain, points[:, :2], fine), np.inf)


def spacing(chain) -> float:
    return max(min(chain.length / 2000, float(np.min(chain.lengths)) / 8), chain.length / 1e6)


@needs_rs274
@pytest.mark.parametrize(
    ("name", "interpreter", "deviation"),
    [("hole-circle", "rs274", 0.05), ("3dtest", "builtin", 0.05), ("3dtest", "rs274", 0.05), ("polar", "rs274", 0.05),
     ("comp", "rs274", 0.05)],
)  # fmt: skip
def test_linuxcncs_programs_build_g2_and_read_back(tmp_path, name, interpreter, deviation):
    program = DATA / f"linuxcnc_{name}.ngc"
    args = _parser().parse_args(["build", "--from-gcode", str(program), "--max-deviation", str(deviation), "--interpreter", interpreter])
    with reading_options(interpreter, None, "mm"):  # as `build` reads it (the designs, before their files are written)
        units, built = build(gcode_design(args))
    assert units == "mm" and built
    for b in built:  # LinuxCNC reads the program the build writes for every design; every end it executes lies on the chain
        path = tmp_path / f"{b.name}.ngc"
        write_gcode(b.chain, path, name=b.name, **b.gcode)
        ends = canonical_ends(path, tmp_path)[:, : b.chain.dim]
        # on the chain to rs274's 4 decimals, and spirals off the G17 plane (biarcs, chords) within the writer's 0.001 mm
        assert distance_to_chain(b.chain, ends, spacing(b.chain)).max() < TOLERANCE_MM + 2e-4, b.name
    # every position of the input program, as rs274 executes it (inches), is within the deviation of a G2 path (mm)
    positions = canonical_ends(program, tmp_path) * 25.4
    positions = positions[int(np.argmax(positions.any(axis=1))) :]  # moves to 0 before the first: no path yet
    nearest = np.min([distance(b.chain, positions) for b in built], axis=0)
    assert nearest.max() <= deviation * (1 + 1e-6) + 1e-4 * 25.4  # rs274 prints 4 decimals
    notes = [note for b in built for note in b.notes]
    if name in ("hole-circle", "polar"):
        assert len(built) > 1 and any("split where the path folds straight back" in note for note in notes)
    if name in ("comp", "3dtest"):  # arcs stay arcs
        assert any(isinstance(s, Arc) for b in built for s in b.chain)


def test_a_program_without_a_unit_builds_with_units(tmp_path, capsys):
    program = tmp_path / "bare.ngc"
    program.write_text("G90 F100\nG1 X10 Y0\nG3 X20 Y10 I0 J10\nG1 Y30\nM2\n")
    argv = ["build", "--from-gcode", str(program), "--max-deviation", "0.01", "--no-plots", "--out", str(tmp_path / "out")]
    assert main(argv) == 2
    assert "--units mm or --units in" in capsys.readouterr().err
    assert main([*argv, "--units", "in"]) == 0
    text = capsys.readouterr().out
    assert "read in in as stated" in text
    chain = read_gcode_chain(tmp_path / "out" / "bare.ngc")
    assert chain.units == "in" and chain.end.tolist() == pytest.approx([20, 30])
    arcs = [s for s in chain if isinstance(s, Arc)]
    assert len(arcs) == 1 and abs(arcs[0].radius) < 10  # the arc kept, moved in by the shift its spirals need
    assert np.allclose(arcs[0].center, (10, 10), atol=1e-9)
