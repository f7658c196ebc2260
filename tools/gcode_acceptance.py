"""How many public G-code programs the reader accepts, and why it refuses the rest.

Usage::

    python tools/gcode_acceptance.py FOLDER [--glob 'nc_files/**/*.ngc'] [--top 10] [--interpreter rs274]
        [--arc-tolerance 0.001] [--cross-check]

FOLDER holds the programs (for example the ``.ngc`` files of a LinuxCNC checkout:
``git clone https://github.com/LinuxCNC/linuxcnc`` and point at it; the programs are
not part of this repository). Refusals are grouped by their message with the line
numbers, numbers and file names taken out, so "G28 is refused" counts once per file. With
``--cross-check``, every program the built-in reader accepts is also run through LinuxCNC's
rs274 and the two toolpaths compared (largest difference relative to the path's size).

Measured on LinuxCNC's repository (github.com/LinuxCNC/linuxcnc, commit 5c41560e, 2026-08-22;
795 ``.ngc`` files, 247 of them under ``nc_files/``), built-in reader:

* before the LinuxCNC rules (the G0/G1 subset): 6 of 795 accepted, 0 of 247 in nc_files;
* now, arcs refused: 48 of 795; with ``--arc-tolerance 0.001``: 118 of 795, 4 of 247
  (nc_files are mostly demonstrations of parameters, subroutines and NURBS: 183 of the 243
  refusals there are parameters, expressions or O-words, which ``--interpreter rs274`` reads;
  it accepts 18 of 247, most of the rest being files of subroutines with no program);
* ``--cross-check``: on 117 of the 118, rs274's moves are the built-in reader's (same lines,
  same points) to within rs274's printed precision (4 decimals: at most 5e-05 of the unit on
  straight moves, at most 5e-05 of the path's size with arcs), and exactly where the program
  has at most 4 decimals (tests/test_gcode_rs274.py). The one other, plasmatest.ngc: after
  its ``M06``, a ``G00`` line with no axis word makes rs274 issue a traverse to where the
  tool is (the origin), which the built-in reader, seeing no axis word, does not count as a
  point: one more point from rs274, the others equal.
"""

from __future__ import annotations

import argparse
import collections
import re
import sys
from pathlib import Path

import numpy as np

from spiral_cad.io.gcode import read_gcode


def reason(message: str) -> str:
    """A refusal's message without what differs between files (the file, the line, the numbers)."""
    message = re.sub(r"^.*? line \d+: ", "", message)
    message = re.sub(r"^[^:]*\.ngc: ", "", message)
    message = re.sub(r"^'.*?': (parameters, expressions and O-words)", r"\1", message)  # which parameter: one reason
    message = re.sub(r"rs274 refused the program: (.*)", lambda m: "rs274 refused: " + re.sub(r"[-0-9.]+", "#", m.group(1)), message)
    message = re.sub(r"(?<![A-Za-z])([A-Z])[-+]?[0-9.]+", lambda m: m.group(0) if m.group(1) in "GM" else m.group(1) + "…", message)
    return re.sub(r"\b\d+(\.\d+)?\b(?![.)])", "#", message)[:120]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--glob", default="nc_files/**/*.ngc")
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--interpreter", choices=["builtin", "rs274"], default="builtin")
    parser.add_argument("--arc-tolerance", type=float, help="read arcs as chords within this (in the program's unit)")
    parser.add_argument("--cross-check", action="store_true", help="compare rs274's moves with the accepted programs'")
    args = parser.parse_args(argv)
    worst, compared, differ = 0.0, 0, []
    files = sorted(Path(args.folder).glob(args.glob))
    reasons: collections.Counter[str] = collections.Counter()
    accepted = 0
    for file in files:
        try:
            path = read_gcode(file, interpreter=args.interpreter, arc_tolerance=args.arc_tolerance)
            accepted += 1
            if args.cross_check:
                try:
                    theirs = read_gcode(file, interpreter="rs274", arc_tolerance=args.arc_tolerance)
                except ValueError as error:
                    differ.append(f"{file.name}: rs274 refused: {error}")
                    continue
                compared += 1
                if theirs.points.shape != path.points.shape or theirs.lines.tolist() != path.lines.tolist():
                    differ.append(f"{file.name}: {len(path)} moves here, {len(theirs)} from rs274")
                    continue
                gap = float(np.abs(theirs.points - path.points).max() / max(np.abs(path.points).max(), 1.0))
                worst = max(worst, gap)
                if gap > 1e-9:
                    differ.append(f"{file.name}: differs by {gap:.3g} of its size")
        except (ValueError, OSError) as error:
            reasons[reason(str(error))] += 1
    print(f"{accepted} of {len(files)} programs accepted ({args.glob} under {args.folder})")
    for text, count in reasons.most_common(args.top):
        print(f"{count:5d}  {text}")
    if args.cross_check:
        print(f"cross-check with rs274: {compared} compared, largest relative difference {worst:.3g}; {len(differ)} differ:")
        for line in differ:
            print("   ", line[:200])
    return 0


if __name__ == "__main__":
    sys.exit(main())
