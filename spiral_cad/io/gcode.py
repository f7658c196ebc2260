"""G-code in: the straight moves of a CNC program as a polyline, in a small, documented subset.

What is read (anything else is refused with its line number and the word):

* words are a letter and a decimal number of ASCII digits (``X-1.5``,
  ``x .5``, ``G01``; no exponents), upper or lower case, spaces allowed
  between words, after the letter and after a sign;
* ``G0``/``G00`` (rapid) and ``G1``/``G01`` (feed) straight moves with
  ``X``, ``Y``, ``Z``; the motion mode is modal (a line of coordinates alone
  moves as the last G0/G1 did); an axis a move does not name keeps its value,
  and every axis starts at 0;
* ``G90`` absolute and ``G91`` incremental coordinates (absolute at the start);
* ``G20`` inch and ``G21`` mm: one of them must come before the first move
  (a CNC path in the wrong unit is worse than none), and the unit may not
  change after it;
* states that do not change the path are accepted and ignored: ``G17``
  (XY plane), ``G40`` (no cutter compensation), ``G49`` (no tool length
  offset), ``G54`` (the first work offset: coordinates are read as written),
  ``G80`` (no canned cycle), ``G94`` (feed per minute), ``F``, ``S``, ``T``,
  ``N`` (line numbers), ``M3``–``M9`` (spindle, tool change, coolant); ``M2``
  and ``M30`` end the program (nothing after them is read);
* comments ``( … )`` and ``; …`` to the end of the line, blank lines and
  ``%`` lines.

Refused by name, with the line: arcs ``G2``/``G3`` (have the CAM output
straight moves, or linearise the arcs first), every other G and M code
(``G28`` homing, ``G81`` drilling cycles, ``G55``–``G59`` work offsets, …),
other words (``A``, ``B``, ``C``, ``I``, ``J``, ``K``, ``R``, ``P``, …), two
motion codes on one line, coordinates with no motion mode in effect, numbers
that are not finite, text that is not a word (``X1e3``, ``X--1``), an
unclosed comment, control characters (line breaks are ``\n``, ``\r\n`` or
``\r``; a vertical tab, form feed or Unicode line separator is refused, not
read as a line break), lines longer than 65 536 characters, and bytes that
are not UTF-8.

A move that ends where it started is not a point of the path (it would be a
corner of no length); the path's first point is where the first move ends.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..core.units import MM_PER_UNIT, length_unit

if TYPE_CHECKING:
    from ..design.rounding import RoundedPath

#: Files larger than this are refused before reading (a full disk or a wrong file, not a program).
MAX_BYTES = 1 << 30
#: What a G-code program's file name ends in (a design file cannot make the build read, and
#: quote in its error, any other file).
SUFFIXES = (".nc", ".ngc", ".gcode", ".gc", ".g", ".tap", ".cnc", ".mpt", ".mpf")
#: Codes that keep a state the path does not depend on.
NEUTRAL_G = {17: "XY plane", 40: "no cutter compensation", 49: "no tool length offset", 54: "work offset 1",
             80: "no canned cycle", 94: "feed per minute"}  # fmt: skip
NEUTRAL_M = {3, 4, 5, 6, 7, 8, 9}
END_M = {2, 30}
ARCS = {2: "G2 (a clockwise arc)", 3: "G3 (a counterclockwise arc)"}
IGNORED_WORDS = set("FSTN")

#: Lines longer than this are refused before their words are read (memory grows with a line's words).
MAX_LINE = 1 << 16

_WORD = re.compile(r"\s*([A-Za-z])\s*([+-]?\s*(?:\d+\.?\d*|\.\d+))", re.ASCII)
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029]")
#: A G or M code as written: an integer, perhaps with a point and zeros (G01, G1.0).
_INTEGER = re.compile(r"[+-]?[0-9]+(?:\.0*)?")
#: A whole comment, or a parenthesis or semicolon that starts or ends none.
_COMMENT = re.compile(r"\([^()]*\)|[;()]")


@dataclass(frozen=True)
class GcodePath:
    """The straight moves of a G-code program.

    Attributes:
        points: (n, 3) where each move ends, in the program's unit.
        lines: (n,) the line (1-based) of each move.
        rapid: (n,) True where the move was a rapid (G0).
        units: ``"mm"`` (G21) or ``"in"`` (G20).
        source: the file's name, for messages.
    """

    points: NDArray
    lines: NDArray
    rapid: NDArray
    units: str
    source: str = "G-code"

    def __len__(self) -> int:
        return len(self.points)

    def in_units(self, units: str) -> GcodePath:
        """The same moves in ``units`` (mm, cm, m, km, in, ft): converted from the program's G20/G21."""
        factor = MM_PER_UNIT[self.units] / MM_PER_UNIT[length_unit(units)]
        return GcodePath(self.points * factor if factor != 1.0 else self.points, self.lines, self.rapid, units, self.source)

    def at_lines(self, message: str) -> str:
        """``message`` with every ``point i``/``corner i`` followed by the G-code line of that move."""

        def line(match: re.Match) -> str:
            i = int(match.group(2))
            return f"{match.group(0)} (line {int(self.lines[i])})" if 0 <= i < len(self.lines) else match.group(0)

        return re.sub(r"\b(points?|corner) (\d+)\b", line, message)


class _Reader:
    """The interpreter's state while lines are read."""

    def __init__(self, source: str):
        self.source = source
        self.position = [0.0, 0.0, 0.0]
        self.absolute = True
        self.motion: int | None = None
        self.units: str | None = None
        self.points: list[tuple[float, float, float]] = []
        self.lines: list[int] = []
        self.rapid: list[bool] = []
        self.ended = False

    def error(self, number: int, text: str) -> ValueError:
        return ValueError(f"{self.source} line {number}: {text}")

    def words(self, number: int, text: str) -> list[tuple[str, float, str]]:
        """(letter, value, as written) of every word of one line, comments removed."""
        if len(text) > MAX_LINE:
            raise self.error(number, f"the line has {len(text):,} characters; at most {MAX_LINE:,} are read")
        control = _CONTROL.search(text)
        if control:
            raise self.error(number, f"control character {control.group(0)!r} in the line")
        kept, at = [], 0
        for comment in _COMMENT.finditer(text):  # left to right, in one pass: ( … ) or ; to the end of the line
            kept.append(text[at : comment.start()])
            at = comment.end()
            if comment.group(0) == ";":
                at = len(text)
                break
            if len(comment.group(0)) == 1:  # "(" with no ")" before the next "(", or a ")" with no "("
                raise self.error(number, "a comment is not closed (or is nested): comments are ( … ) on one line")
            kept.append(" ")
        kept.append(text[at:])
        text = "".join(kept)
        found, at = [], 0
        stripped = text.rstrip()
        while at < len(stripped):
            match = _WORD.match(stripped, at)
            if match is None:
                bad = stripped[at:].strip()[:20]
                raise self.error(number, f"{bad!r} is not a G-code word (a letter and a decimal number, no exponents)")
            letter, written = match.group(1).upper(), match.group(2).replace(" ", "")
            value = float(written)
            if not math.isfinite(value):
                raise self.error(number, f"{letter}{written[:20]}… is not a finite number")
            shown = f"{letter}{written}" if len(written) <= 20 else f"{letter}{written[:20]}…"  # for messages
            found.append((letter, value, shown))
            at = match.end()
        return found

    def read_line(self, number: int, text: str) -> None:
        stripped = text.strip()
        if not stripped or stripped == "%" or self.ended:
            return
        words = self.words(number, text)
        motion: list[int] = []
        target: dict[int, float] = {}
        for letter, value, written in words:
            code = int(value) if _INTEGER.fullmatch(written[1:]) else None  # G0.0…05 is no G0
            if letter == "G":
                if code in (0, 1):
                    motion.append(code)
                elif code in ARCS:
                    raise self.error(number, f"{ARCS[code]} is refused: only straight moves (G0, G1) are read; have the CAM write straight moves, or linearise the arcs first")
                elif code in (90, 91):
                    self.absolute = code == 90
                elif code in (20, 21):
                    units = "in" if code == 20 else "mm"
                    if self.points and units != self.units:
                        raise self.error(number, f"{written} changes the unit after the first move; one unit per program")
                    self.units = units
                elif code not in NEUTRAL_G:
                    raise self.error(number, f"{written} is not in the supported subset (G0, G1, G17, G20, G21, G40, G49, G54, G80, G90, G91, G94)")
            elif letter == "M":
                if code in END_M:
                    self.ended = True
                elif code not in NEUTRAL_M:
                    raise self.error(number, f"{written} is not in the supported subset (M2, M30 end the program; M3–M9 are ignored)")
            elif letter in "XYZ":
                axis = "XYZ".index(letter)
                if axis in target:
                    raise self.error(number, f"{letter} is given twice")
                target[axis] = value
            elif letter not in IGNORED_WORDS:
                raise self.error(number, f"the word {written} is not in the supported subset (X, Y, Z, F, S, T, N besides G and M codes)")
        if len(motion) > 1:
            raise self.error(number, "two motion codes (G0/G1) on one line")
        if motion:
            self.motion = motion[0]
        if not target:
            return
        if self.motion is None:
            raise self.error(number, "coordinates with no motion mode in effect (G0 or G1)")
        if self.units is None:
            raise self.error(number, "the program sets no unit before its first move: add G21 (mm) or G20 (inch)")
        moved = list(self.position)
        for axis, value in target.items():
            moved[axis] = value if self.absolute else moved[axis] + value
        if not all(math.isfinite(v) for v in moved):
            raise self.error(number, "the move's position is beyond the float range")
        if moved != self.position or not self.points:
            self.points.append((moved[0], moved[1], moved[2]))
            self.lines.append(number)
            self.rapid.append(self.motion == 0)
        self.position = moved


def parse_gcode(text: str, source: str = "G-code") -> GcodePath:
    """The straight moves of G-code ``text`` (see the module docstring).

    Raises:
        ValueError: anything outside the subset, naming ``source``, the line and the word;
            a program with fewer than two moves.
    """
    if not isinstance(text, str):
        raise ValueError(f"text must be the program as str; got {type(text).__name__} (decode bytes first, or use read_gcode)")
    reader = _Reader(source)
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # not splitlines: it breaks at \v, \f, …
    for number, line in enumerate(lines, 1):
        reader.read_line(number, line)
    if len(reader.points) < 2:
        raise ValueError(f"{source}: the program has {len(reader.points)} move(s) to a new position; a path needs at least two")
    return GcodePath(np.array(reader.points), np.array(reader.lines), np.array(reader.rapid), reader.units, source)


def read_gcode(path: str | os.PathLike) -> GcodePath:
    """Read the straight moves of a G-code file (named ``*.nc``, ``.ngc``, ``.gcode``, ``.gc``, ``.g``,
    ``.tap``, ``.cnc``, ``.mpt`` or ``.mpf``).

    Raises:
        ValueError: another file name, not a regular file (a folder, a device),
            larger than 1 GiB, not UTF-8 text, or outside the subset (named with the line).
        OSError: the file could not be read.
    """
    name = os.fspath(path)
    label = os.path.basename(name) or name
    if not label.isprintable():  # a file name is shown in messages: never raw control characters
        label = repr(label)
    if not os.path.isfile(name):
        what = "a folder" if os.path.isdir(name) else "not a regular file" if os.path.exists(name) else "missing"
        raise ValueError(f"{label}: the G-code file is {what}")
    if not name.lower().endswith(SUFFIXES):
        raise ValueError(f"{label}: not a G-code file name (expected one ending in {', '.join(SUFFIXES)})")
    if os.path.getsize(name) > MAX_BYTES:
        raise ValueError(f"{label}: larger than {MAX_BYTES >> 30} GiB; not read")
    data = open(name, "rb").read()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise ValueError(f"{label} line {line}: byte {data[error.start]:#04x} is not UTF-8 text") from None
    return parse_gcode(text, label)


def round_toolpath(path: GcodePath, **options) -> RoundedPath:
    """The G2 rounding of a toolpath's polyline (``spiral_cad.design.round_corners`` with ``options``:
    ``max_deviation``, ``max_curvature``, ``shape``, …) in the program's unit; an error names the
    G-code line of the corner or point it is about.

    Raises:
        ValueError, NoSolutionError: as ``round_corners``, with the line.
    """
    from ..design.rounding import round_corners

    if "units" in options:
        raise ValueError("units: the program's own (G20/G21); convert the path with GcodePath.in_units first")
    try:
        return round_corners(path.points, units=path.units, **options)
    except ValueError as error:
        raise type(error)(f"{path.source}: {path.at_lines(str(error))}") from None
