"""How many public G-code programs the reader accepts, and why it refuses the rest.

Usage::

    python tools/gcode_acceptance.py FOLDER [--glob 'nc_files/**/*.ngc'] [--top 10] [--interpreter rs274]

FOLDER holds the programs (for example the ``.ngc`` files of a LinuxCNC checkout:
``git clone https://github.com/LinuxCNC/linuxcnc`` and point at it; the programs are
not part of this repository). Refusals are grouped by their message with the line
numbers, numbers and file names taken out, so "G28 is refused" counts once per file.
"""

from __future__ import annotations

import argparse
import collections
import re
import sys
from pathlib import Path

from spiral_cad.formats.gcode import read_gcode


def reason(message: str) -> str:
    """A refusal's message without what differs between files (the file, the line, the numbers)."""
    message = re.sub(r"^.*? line \d+: ", "", message)
    message = re.sub(r"^[^:]*\.ngc: ", "", message)
    message = re.sub(r"(?<![A-Za-z])([A-Z])[-+]?[0-9.]+", lambda m: m.group(0) if m.group(1) in "GM" else m.group(1) + "…", message)
    return re.sub(r"\b\d+(\.\d+)?\b(?![.)])", "#", message)[:120]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--glob", default="nc_files/**/*.ngc")
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--interpreter", choices=["builtin", "rs274"], default="builtin")
    args = parser.parse_args(argv)
    files = sorted(Path(args.folder).glob(args.glob))
    reasons: collections.Counter[str] = collections.Counter()
    accepted = 0
    for file in files:
        try:
            if args.interpreter == "builtin":
                read_gcode(file)
            else:
                read_gcode(file, interpreter=args.interpreter)
            accepted += 1
        except (ValueError, OSError) as error:
            reasons[reason(str(error))] += 1
    print(f"{accepted} of {len(files)} programs accepted ({args.glob} under {args.folder})")
    for text, count in reasons.most_common(args.top):
        print(f"{count:5d}  {text}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
