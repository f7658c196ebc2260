"""G-code in: the moves of a CNC program as a polyline, read as LinuxCNC reads RS274/NGC.

Two readers (``interpreter=``): the built-in one below, and ``"rs274"``, LinuxCNC's own
interpreter run as a program (full NGC: parameters, expressions, O-word subroutines and
loops, canned cycles; see ``spiral_cad.io.rs274``).

What the built-in reader reads (anything else is refused with its line number and the word):

* words are a letter and a decimal number of ASCII digits (``X-1.5``, ``x .5``, ``G01``;
  no exponents), upper or lower case, spaces allowed between words, after the letter and
  after a sign; ``N`` line numbers; a leading ``/`` (block delete; LinuxCNC's switch is off,
  so the line runs);
* ``G0`` (rapid) and ``G1`` (feed) straight moves with ``X``, ``Y``, ``Z``, modal as in
  LinuxCNC (a line of coordinates alone moves as the last motion code did); an axis a move
  does not name keeps its value, and every axis starts at 0;
* arcs ``G2``/``G3`` (``I``, ``J``, ``K`` offsets or centre under ``G90.1``, or ``R``; ``P``
  full turns; helical with the plane's normal axis) in the ``G17``/``G18``/``G19`` plane, as
  chords within ``arc_tolerance`` when it is given (refused by name otherwise), with
  LinuxCNC's tolerance on radii that differ;
* cubic splines ``G5`` (``I J``: start to first control point, ``P Q``: end to second control
  point) in the ``G17`` plane, with LinuxCNC's rules (P and Q always; I and J both or neither,
  neither only after another G5, which continues its direction; no Z), as chords within
  ``arc_tolerance`` (refused by name otherwise);
* ``G90``/``G91`` absolute/incremental coordinates, ``G90.1``/``G91.1`` arc centres;
* ``G20`` inch and ``G21`` mm: one of them must come before the first move (a CNC path in
  the wrong unit is worse than none), and the unit may not change after it;
* states that do not change the path: ``G40``, ``G49``, ``G54``–``G59.3`` (work offsets: a
  program that does not set them with G10, which is refused, is read in their common frame),
  ``G61``, ``G61.1``, ``G64`` (``P``, ``Q``), ``G80`` (motion cancelled: coordinates after it
  are refused, as LinuxCNC does), ``G93``–``G95``, ``G96``/``G97`` (``D``), ``G98``/``G99``,
  ``G8``, ``G4`` dwell (``P``); ``F``, ``S``, ``T``; ``M0``, ``M1``, ``M60`` (pauses),
  ``M3``–``M5``, ``M7``–``M9``, ``M6`` (tool change: kept as a note, no move), ``M48``–``M53``;
  ``M2`` and ``M30`` end the program;
* ``%``: a first line ``%`` opens the program and the next ``%`` ends it (nothing after it is
  read, as LinuxCNC); a program opened with ``%`` must close it or end with M2/M30;
* comments ``( … )`` and ``; …`` to the end of the line, blank lines.

LinuxCNC's modal rules: two codes of one modal group on a line (``G90 G91``, ``G20 G21``,
``G0 G1``, ``M3 M5``) are refused, naming the line, both words and the group.

Refused by name, with the line: canned cycles ``G73``–``G89`` (use ``interpreter="rs274"``,
which expands them), ``G28``/``G30`` (moves to a home position the program does not state),
``G10``, ``G52``, ``G53``, ``G92`` (offsets), cutter compensation ``G41``/``G42``, tool length
offsets ``G43``, ``G33``, probing ``G38``, splines and NURBS ``G5.1``–``G6.2``, ``G7``,
parameters (``#``), expressions (``[``) and O-words (use ``interpreter="rs274"``), other words
(``A``, ``B``, ``C``, ``U``, ``V``, ``W``, ``L``, ``H``, ``E``, …), numbers that are not finite,
text that is not a word (``X1e3``, ``X--1``), an unclosed comment, control characters (line
breaks are ``\n``, ``\r\n`` or ``\r``; a vertical tab, form feed or Unicode line separator is
refused, not read as a line break), lines longer than 65 536 characters, and bytes that are
not UTF-8. LinuxCNC also refuses a program with neither M2/M30 nor ``%``; this reader takes the
end of the file as its end.

``read_gcode_chain`` reads a program as its exact path instead: lines, arcs and G5 cubics as the
chain's segments (what ``spiral_cad.io.gcode_write`` writes reads back as the same chain; a cubic
that is not a spiral is cut where its curvature changes sign or turns, so its curvature stays its
own). The built-in reader keeps the feed rates (``F`` under ``G94``) of the feed moves (``GcodePath.feeds``,
``program_feeds``).

A move that ends where it started is not a point of the path (it would be a corner of no
length); the path's first point is where the first move ends. Long reads and roundings say
on stderr that they are still running.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TYPE_CHECKING, Any

import numpy as np

from .gcode_pieces import piece_segments, plain_cubics
from .progress import Progress
from .toolpath import PLANES, GcodePath, arc_points, in_program_unit, spline_points

if TYPE_CHECKING:
    from ..core.chain import Chain

#: Files larger than this are refused before reading (a full disk or a wrong file, not a program).
MAX_BYTES = 1 << 30
#: What a G-code program's file name ends in (a design file cannot make the build read, and
#: quote in its error, any other file).
SUFFIXES = (".nc", ".ngc", ".gcode", ".gc", ".g", ".tap", ".cnc", ".mpt", ".mpf")
#: LinuxCNC's modal groups of G codes (the code times ten: G90.1 is 901); two codes of one group on
#: one line are an error, as in LinuxCNC ("Two g codes used from same modal group").
G_GROUPS: dict[int, tuple[int, str]] = {
    **{c: (1, "motion") for c in (0, 10, 20, 30, 330, 331, 382, 383, 384, 385, 50, 51, 52, 53, 62, 730, 760, 800,
                                  810, 820, 830, 840, 850, 860, 870, 880, 890)},
    **{c: (2, "plane") for c in (170, 171, 180, 181, 190, 191)},
    **{c: (3, "distance mode") for c in (900, 910)},
    **{c: (4, "arc centre mode") for c in (901, 911)},
    **{c: (5, "feed rate mode") for c in (930, 940, 950)},
    **{c: (6, "units") for c in (200, 210)},
    **{c: (7, "cutter compensation") for c in (400, 410, 411, 420, 421)},
    **{c: (8, "tool length offset") for c in (430, 431, 432, 490)},
    **{c: (10, "canned cycle return") for c in (980, 990)},
    **{c: (12, "work offset") for c in (540, 550, 560, 570, 580, 590, 591, 592, 593)},
    **{c: (13, "path control") for c in (610, 611, 640)},
    **{c: (14, "spindle speed mode") for c in (960, 970)},
    **{c: (15, "lathe diameter mode") for c in (70, 80)},
    **{c: (0, "non-modal") for c in (40, 100, 280, 281, 300, 301, 520, 530, 920, 921, 922, 923)},
}  # fmt: skip
#: Codes that keep a state the straight path does not depend on (feeds, stops, exact-stop modes, …).
NEUTRAL_G = {40, 170, 400, 490, 540, 550, 560, 570, 580, 590, 591, 592, 593, 610, 611, 640, 80, 930, 940, 950,
             960, 970, 980, 990}  # fmt: skip
#: Codes refused by name, with why (each would move the tool somewhere the program's words do not say).
REFUSED_G = {
    **{c: "a canned cycle (have the CAM expand cycles into G0/G1 moves, or use interpreter='rs274')"
       for c in (730, 760, 810, 820, 830, 840, 850, 860, 870, 880, 890)},
    280: "a move to the machine's home position (G28), which the program does not state",
    300: "a move to the machine's second home position (G30), which the program does not state",
    281: "setting the home position (G28.1)", 301: "setting the second home position (G30.1)",
    100: "setting work offsets or tool data (G10): the offsets would change the path",
    520: "a local coordinate offset (G52)", 530: "a move in machine coordinates (G53)",
    920: "a coordinate offset (G92)", 921: "a coordinate offset reset (G92.1)", 922: "a coordinate offset reset (G92.2)",
    923: "a coordinate offset restore (G92.3)",
    410: "cutter radius compensation (G41): the tool centre's path is not the programmed one",
    411: "cutter radius compensation (G41.1)", 420: "cutter radius compensation (G42): the tool centre's path is not the programmed one",
    421: "cutter radius compensation (G42.1)",
    430: "a tool length offset (G43) from a tool table", 431: "a dynamic tool length offset (G43.1)",
    432: "an added tool length offset (G43.2)",
    330: "spindle-synchronised motion (G33)", 331: "rigid tapping (G33.1)",
    382: "probing (G38.2)", 383: "probing (G38.3)", 384: "probing (G38.4)", 385: "probing (G38.5)",
    62: "a NURBS curve (G6.2)", 51: "a quadratic spline (G5.1)", 52: "a NURBS block (G5.2)", 53: "a NURBS block end (G5.3)",
    171: "the UV plane (G17.1)", 181: "the WU plane (G18.1)", 191: "the VW plane (G19.1)",
    70: "lathe diameter mode (G7): X would be a diameter",
}  # fmt: skip
#: LinuxCNC's modal groups of M codes that matter for a line's words (M7 and M8 may share a line).
M_GROUPS = {0: 4, 1: 4, 2: 4, 30: 4, 60: 4, 3: 7, 4: 7, 5: 7, 6: 6, 7: 8, 8: 8, 9: 8, 48: 9, 49: 9, 50: 9, 51: 9,
            52: 9, 53: 9}  # fmt: skip
END_M = {2, 30}
#: Words that do not move the tool: feed, spindle speed, tool, line number, dwell/G64 P and Q, G96 D.
IGNORED_WORDS = set("FSTNPQD")

#: Lines longer than this are refused before their words are read (memory grows with a line's words).
MAX_LINE = 1 << 16

_WORD = re.compile(r"\s*([A-Za-z])\s*([+-]?\s*(?:\d+\.?\d*|\.\d+))", re.ASCII)
#: Where a line goes beyond plain words: a parameter, an expression, a named parameter (``#<x>``).
_FULL_NGC = re.compile(r"\s*(?:[A-Za-z]\s*)?[#\[<]")
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029]")
#: A G or M code as written: an integer, perhaps with one decimal and zeros (G01, G1.0, G90.1).
_CODE = re.compile(r"[0-9]{1,4}(?:\.[0-9]?0*)?")
#: A whole comment, or a parenthesis or semicolon that starts or ends none.
_COMMENT = re.compile(r"\([^()]*\)|[;()]")
#: A number written with an exponent (``X1e3``, ``Y.5E-2``): G-code numbers have none.
_EXPONENT = re.compile(r"([A-Za-z])\s*([+-]?\s*(?:\d+\.?\d*|\.\d+))([eE]\s*[+-]?\s*\d+)", re.ASCII)


def exponent_word(text: str) -> str | None:
    """Why a line of G-code is refused for a number written with an exponent (comments aside); None when it has none.

    LinuxCNC reads ``X1e3`` as ``X1`` and a word ``E3`` (and refuses the E word), a printer as ``X1`` and an
    extrusion ``E3``: read as 1000 it would be a path neither machine cuts, read as 1 a silent misreading.

    Args:
        text: one line of a program.
    """
    if "e" not in text and "E" not in text:
        return None
    match = _EXPONENT.search(_COMMENTS.sub(" ", text))
    if match is None:
        return None
    letter, number, exponent = match.group(1), match.group(2).replace(" ", ""), match.group(3).replace(" ", "")
    value = float(number + exponent)
    shown = f"{value:.10f}".rstrip("0").rstrip(".") if math.isfinite(value) and abs(value) < 1e15 else None
    return (f"{letter}{number}{exponent} is a number with an exponent, which G-code numbers do not have "
            f"(LinuxCNC reads it as {letter.upper()}{number} and a word {exponent.upper()}, a printer as an extrusion)"
            + (f"; write {letter.upper()}{shown}" if shown else ""))  # fmt: skip


class _Reader:
    """The interpreter's state while lines are read."""

    def __init__(self, source: str, arc_tolerance: float | None = None, progress: Callable[[int], None] | None = None,
                 arc_units: str | None = None):  # fmt: skip
        self.source = source
        self.arc_tolerance = arc_tolerance
        self.arc_units = arc_units  # the unit of arc_tolerance (None: the program's)
        self.progress = progress
        self.position = [0.0, 0.0, 0.0]
        self.absolute = True
        self.absolute_centre = False  # G91.1, LinuxCNC's default: I, J, K are offsets from the start
        self.plane = 170
        self.motion: int | None = None
        self.cancelled = False
        self.units: str | None = None
        self.points: list[tuple[float, float, float]] = []
        self.lines: list[int] = []
        self.rapid: list[bool] = []
        self.notes: list[str] = []
        self.opened: int | None = None  # the line of an opening %
        self.any_line = False  # a line that is not blank was read (an opening % must be the first)
        self.end_at: int | None = None
        self.ended = False
        self.exact = False  # arcs and G5 splines kept as pieces (``pieces``), no chords needed
        self.assumed_units: str | None = None  # the unit of a program that states none (None: refused)
        self.piece_feeds: list[float] = []  # the F in force on each piece (NaN: a rapid, none, not G94)
        self.pieces: list[tuple[Any, ...]] = []  # (kind, line, rapid, start, data…) of every move (with ``exact``)
        self.spline_end: tuple[float, float] | None = None  # the last G5's (P, Q), while G5 moves follow each other
        self.feed: float | None = None  # the modal F (program unit per minute under G94)
        self.feed_mode = 940  # G93 inverse time, G94 units per minute, G95 per revolution
        self.feeds: dict[float, None] = {}  # the distinct F values in force on feed moves under G94, in order
        self.point_feeds: list[float] = []  # the F in force on the move to each point (NaN: none)

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
        exponent = exponent_word(text)
        if exponent is not None:
            raise self.error(number, exponent)
        found: list[tuple[str, float, str]] = []
        at = 0
        stripped = text.rstrip()
        while at < len(stripped):
            match = _WORD.match(stripped, at)
            if match is None:
                bad = stripped[at:].strip()[:20]
                if _FULL_NGC.match(stripped, at) or found and found[-1][0] == "O":
                    raise self.error(
                        number,
                        f"{bad!r}: parameters, expressions and O-words are not read by the built-in reader; use interpreter='rs274' (--interpreter rs274), LinuxCNC's own",
                    )
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
        if self.ended or not stripped:
            return
        first = not self.any_line
        self.any_line = True
        if stripped == "%":  # LinuxCNC: a % as the first line that is not blank opens the program, the next ends it
            if first:
                self.opened = number
            elif self.opened is not None:
                self.ended = True
            else:
                raise self.error(
                    number,
                    "a % ends only a program that opened with % on its first line; LinuxCNC refuses it here (bad character '%' used)",
                )
            return
        if stripped[0] == "/":  # block delete: LinuxCNC's switch is off by default, so the line runs
            text = text.replace("/", " ", 1)
        words = self.words(number, text)
        groups: dict[tuple[str, int], str] = {}
        motion: int | None = None
        target: dict[int, float] = {}
        centre: dict[str, float] = {}
        turn_count: float | None = None  # P with G2/G3: the number of turns
        spline_pq: dict[str, float] = {}  # P and Q with G5: the end's offset to the second control point
        for letter, value, written in words:
            if letter == "F":  # F applies to the move on its own line too
                self.feed = value
            if letter in "GM":
                code = round(value * 10) if _CODE.fullmatch(written[1:]) else None
                if letter == "M":
                    code = code // 10 if code is not None and code % 10 == 0 else None
            if letter == "G":
                if code not in G_GROUPS:
                    raise self.error(number, f"{written} is not a LinuxCNC G code this reader knows")
                group, name = G_GROUPS[code]
                if group and ("G", group) in groups:
                    if group == 1 and 800 in (code, motion):  # LinuxCNC drops a G80 beside another motion
                        code = motion if code == 800 else code
                    else:
                        raise self.error(
                            number,
                            f"{groups['G', group]} and {written} are both in modal group {group} ({name}); LinuxCNC allows one per line",
                        )
                groups["G", group] = written
                if code in REFUSED_G:
                    raise self.error(number, f"{written} is refused: {REFUSED_G[code]}")
                if group == 1:
                    motion = code
                elif code in (900, 910):
                    self.absolute = code == 900
                elif code in (901, 911):
                    self.absolute_centre = code == 901
                elif code in (200, 210):
                    units = "in" if code == 200 else "mm"
                    if self.points and units != self.units:
                        raise self.error(number, f"{written} changes the unit after the first move; one unit per program")
                    self.units = units
                elif code in PLANES:
                    self.plane = code
                elif code in (930, 940, 950):
                    self.feed_mode = code
                elif code == 40 or code in NEUTRAL_G:
                    pass
            elif letter == "M":
                if code not in M_GROUPS:
                    raise self.error(
                        number,
                        f"{written} is not in the supported subset (M0, M1, M2, M30, M60 stops and ends; M3–M9 spindle, tool change, coolant; M48–M53 overrides)",
                    )
                group = M_GROUPS[code]
                if ("M", group) in groups and not {groups["M", group].upper(), written.upper()} <= {"M7", "M8", "M07", "M08"}:
                    raise self.error(
                        number, f"{groups['M', group]} and {written} are both in M modal group {group}; LinuxCNC allows one per line"
                    )
                groups["M", group] = written
                if code in END_M:
                    self.end_at = number
                elif code == 6:
                    self.notes.append(f"line {number}: {written} tool change (no move)")
            elif letter in "XYZ":
                axis = "XYZ".index(letter)
                if axis in target:
                    raise self.error(number, f"{letter} is given twice")
                target[axis] = value
            elif letter in "IJKR":
                if letter in centre:
                    raise self.error(number, f"{letter} is given twice")
                centre[letter] = value
            elif letter == "P":
                turn_count = value
                spline_pq["P"] = value
            elif letter == "Q":
                spline_pq["Q"] = value
            elif letter == "O":
                raise self.error(
                    number,
                    f"{written}: O-words (subroutines, loops, conditions) are not read by the built-in reader; use interpreter='rs274' (--interpreter rs274), LinuxCNC's own",
                )
            elif letter not in IGNORED_WORDS:
                raise self.error(
                    number,
                    f"the word {written} is not in the supported subset (X, Y, Z, I, J, K, R, F, S, T, N, P, Q, D besides G and M codes)",
                )
        if motion is not None:
            self.motion = None if motion == 800 else motion
        if target or centre and self.motion in (20, 30):  # an arc with no axis word: a full circle back to its start
            if self.motion is None:
                reason = (
                    "after G80 (motion cancelled)" if motion == 800 or self.cancelled else "with no motion mode in effect (G0, G1, G2, G3)"
                )
                raise self.error(number, f"coordinates {reason}; LinuxCNC: cannot use axis values without a G code that uses them")
            if self.units is None:
                if self.assumed_units is None:
                    raise self.error(number, "the program sets no unit before its first move: add G21 (mm) or G20 (inch), "
                                             "or state it (units='mm' or 'in'; build: --units mm or --units in)")  # fmt: skip
                self.units = self.assumed_units
                self.notes.append(f"line {number}: the program states no unit (G20/G21); read in {self.units} as stated")
            moved = list(self.position)
            for axis, value in target.items():
                moved[axis] = value if self.absolute else moved[axis] + value
            if not all(math.isfinite(v) for v in moved):
                raise self.error(number, "the move's position is beyond the float range")
            if self.motion in (20, 30):
                self.arc(number, moved, centre, turn_count)
            elif self.motion == 50:
                self.spline(number, moved, target, centre, spline_pq)
            else:
                if centre:
                    raise self.error(number, f"{', '.join(centre)} with a straight move: only arcs (G2, G3) take I, J, K, R")
                if self.exact:
                    self.pieces.append(("line", number, self.motion == 0, list(self.position), moved))
                self.add(number, moved)
            if self.motion != 50:
                self.spline_end = None
            self.position = moved
        elif centre:
            raise self.error(number, f"{', '.join(centre)} with no axis word: LinuxCNC needs an end point for an arc")
        if motion == 800:
            self.cancelled = True
        if self.end_at is not None:
            self.ended = True

    def add(self, number: int, moved: list[float]) -> None:
        feed = math.nan
        if self.motion != 0 and self.feed_mode == 940 and self.feed is not None and self.feed > 0.0:
            self.feeds[self.feed] = None
            feed = self.feed
        if moved != self.position or not self.points:
            self.points.append((moved[0], moved[1], moved[2]))
            self.point_feeds.append(feed)
            self.lines.append(number)
            self.rapid.append(self.motion == 0)
        if self.exact:  # every piece is followed by one add
            self.piece_feeds.append(feed)
        if self.progress is not None:
            self.progress(len(self.points))

    def arc(self, number: int, end: list[float], centre: dict[str, float], turn_count: float | None) -> None:
        """An arc (G2 clockwise, G3 counterclockwise) in the plane, as chords within ``arc_tolerance``."""
        name = "G2 (a clockwise arc)" if self.motion == 20 else "G3 (a counterclockwise arc)"
        if self.arc_tolerance is None and not self.exact:
            raise self.error(
                number,
                f"{name} is refused: only straight moves (G0, G1) are read unless arc_tolerance is given (arcs become chords within it); or read the program with read_gcode_chain (arcs as true arcs, G5 splines exact)",
            )
        first, second, _ = PLANES[self.plane]
        offsets = {170: "IJ", 180: "KI", 190: "JK"}[self.plane]
        start = self.position
        a0, b0, a1, b1 = start[first], start[second], end[first], end[second]
        if "R" in centre:
            if set(centre) - {"R"}:
                raise self.error(number, f"{name}: R with {', '.join(set(centre) - {'R'})}; give R or the centre offsets, not both")
            radius = centre["R"]
            chord = math.hypot(a1 - a0, b1 - b0)
            if chord == 0.0 or abs(radius) < chord / 2 * (1 - 1e-12):
                raise self.error(number, f"{name}: R{radius:g} cannot join points {chord:g} apart")
            half = math.sqrt(max(radius * radius - chord * chord / 4, 0.0))
            # LinuxCNC: R > 0 takes the shorter arc, R < 0 the longer; the centre is left of the chord for the shorter G3 arc
            side = (1 if self.motion == 30 else -1) * (1 if radius > 0 else -1)
            ca = (a0 + a1) / 2 - side * half * (b1 - b0) / chord
            cb = (b0 + b1) / 2 + side * half * (a1 - a0) / chord
        else:
            if set(centre) - set(offsets) or not centre:
                raise self.error(
                    number,
                    f"{name} in the {'XY' if self.plane == 170 else 'XZ' if self.plane == 180 else 'YZ'} plane takes {offsets[0]} and {offsets[1]}; got {', '.join(centre) or 'none'}",
                )
            i, j = centre.get(offsets[0], 0.0), centre.get(offsets[1], 0.0)
            ca, cb = (i, j) if self.absolute_centre else (a0 + i, b0 + j)
        r0, r1 = math.hypot(a0 - ca, b0 - cb), math.hypot(a1 - ca, b1 - cb)
        # LinuxCNC's tolerances (interp_internal.hh): a zero radius, and radii that differ by more than
        # 100 × CENTER_ARC_RADIUS_TOLERANCE, or by 0.1 % and more than that tolerance
        inch = 1.0 if self.units == "in" else 25.4
        error = abs(r0 - r1)
        if min(r0, r1) < 0.00005 * inch:
            raise self.error(number, f"{name}: a zero-radius arc (the start is {r0:g} from the centre, the end {r1:g})")
        if error > 100 * 0.002 * math.sqrt(2) * inch or error > 0.001 * max(r0, r1) and error > 0.002 * math.sqrt(2) * inch:
            raise self.error(
                number, f"{name}: the start is {r0:g} from the centre and the end {r1:g}; LinuxCNC refuses radii that differ this much"
            )
        turns = 1
        if turn_count is not None:
            if turn_count != int(turn_count) or turn_count < 1:
                raise self.error(number, f"{name}: P{turn_count:g} must be a whole number of turns, at least 1")
            turns = int(turn_count)
        rotation = turns if self.motion == 30 else -turns
        if self.exact:
            self.pieces.append(("arc", number, False, list(start), end, self.plane, ca, cb, rotation))
            self.add(number, end)
            return
        assert self.arc_tolerance is not None  # refused above unless exact
        tolerance = in_program_unit(self.arc_tolerance, self.arc_units, self.units or "mm")
        for point in arc_points(start, end, self.plane, ca, cb, rotation, tolerance):
            self.add(number, point)
            self.position = point

    def spline(self, number: int, end: list[float], target: dict[int, float], centre: dict[str, float],
               pq: dict[str, float]) -> None:  # fmt: skip
        """A cubic spline (G5) in the XY plane, with LinuxCNC's rules; as chords within ``arc_tolerance``
        (or kept exact as a piece, in ``exact`` mode)."""
        if self.plane != 170:
            raise self.error(number, "G5 (a cubic spline) needs the XY plane (G17); LinuxCNC refuses it in G18/G19")
        if 2 in target:
            raise self.error(number, "G5 (a cubic spline) moves X and Y only; LinuxCNC refuses a Z word with it")
        if set(centre) - {"I", "J"}:
            raise self.error(number, f"G5 takes I, J, P and Q; got {', '.join(sorted(set(centre) - {'I', 'J'}))}")
        if set(pq) != {"P", "Q"}:
            raise self.error(number, "G5 needs both P and Q (the end's offset to the second control point)")
        if len(centre) == 1:
            raise self.error(number, "G5 needs both I and J, or neither (to continue the previous G5's direction)")
        start = self.position
        if centre:
            i, j = centre["I"], centre["J"]
        elif self.spline_end is not None:  # LinuxCNC: I, J are the negation of the previous G5's P, Q
            i, j = -self.spline_end[0], -self.spline_end[1]
        else:
            raise self.error(number, "the first G5 of a series needs I and J (the start's offset to the first control point)")
        self.spline_end = (pq["P"], pq["Q"])
        z = start[2]
        cp = np.array([[start[0], start[1], z], [start[0] + i, start[1] + j, z],
                       [end[0] + pq["P"], end[1] + pq["Q"], z], [end[0], end[1], z]])  # fmt: skip
        if not np.isfinite(cp).all() or not np.isfinite(np.diff(cp, axis=0)).all():
            raise self.error(number, "the G5 spline's control points are beyond the float range")
        if self.exact:
            self.pieces.append(("cubic", number, False, list(start), cp))
            self.add(number, list(end))
            return
        if self.arc_tolerance is None:
            raise self.error(
                number,
                "G5 (a cubic spline) is refused here: read the program with read_gcode_chain (the exact cubic), or give "
                "arc_tolerance (splines become chords within it)",
            )
        tolerance = in_program_unit(self.arc_tolerance, self.arc_units, self.units or "mm")
        try:
            chords = spline_points(cp, tolerance)
        except ValueError as error:
            raise self.error(number, str(error)) from None
        for point in chords:
            self.add(number, point)
            self.position = point


#: How ``read_gcode`` reads when its caller does not say (set by ``reading_options``).
_DEFAULTS: ContextVar[tuple[str, float | None, str | None, str | None]] = ContextVar("gcode_reading", default=("builtin", None, None, None))


@contextmanager
def reading_options(
    interpreter: str = "builtin", arc_tolerance: float | None = None, arc_tolerance_units: str | None = None,
    program_units: str | None = None,
) -> Iterator[None]:  # fmt: skip
    """Within the block, ``read_gcode`` and ``read_gcode_moves`` calls that do not name them use this
    interpreter, arc tolerance and unit of a program that states none (``"mm"``, ``"in"``; None refuses
    it): how ``build --from-gcode --interpreter rs274 --units in`` reaches the design file's reader."""
    token = _DEFAULTS.set((interpreter, arc_tolerance, arc_tolerance_units, program_units))
    try:
        yield
    finally:
        _DEFAULTS.reset(token)


def reading_defaults() -> tuple[str, float | None, str | None, str | None]:
    """What ``reading_options`` set: (interpreter, arc tolerance, its unit, the unit of a program that states none)."""
    return _DEFAULTS.get()


def parse_gcode(
    text: str, source: str = "G-code", *, arc_tolerance: float | None = None, interpreter: str = "builtin",
    arc_tolerance_units: str | None = None,
) -> GcodePath:  # fmt: skip
    """The moves of G-code ``text`` (see the module docstring).

    Args:
        text: the program.
        source: its name, for messages.
        arc_tolerance: when given, arcs G2/G3 are read as chords at most this far from the arc;
            when None, arcs are refused by name.
        interpreter: ``"builtin"`` (this module's reader) or ``"rs274"`` (LinuxCNC's own interpreter,
            for parameters, expressions and O-word subroutines; see ``spiral_cad.io.rs274``).
        arc_tolerance_units: the unit of ``arc_tolerance`` (None: the program's, G20/G21).

    Raises:
        ValueError: anything outside the subset, naming ``source``, the line and the word;
            a program with fewer than two moves; rs274 asked for but not installed.
    """
    if not isinstance(text, str):
        raise ValueError(f"text must be the program as str; got {type(text).__name__} (decode bytes first, or use read_gcode)")
    if arc_tolerance is not None and not 0.0 < arc_tolerance < math.inf:
        raise ValueError(f"arc_tolerance must be a positive finite length; got {arc_tolerance}")
    if interpreter == "rs274":
        from .rs274 import run_rs274

        return run_rs274(text, source, arc_tolerance=arc_tolerance, arc_tolerance_units=arc_tolerance_units)
    if interpreter != "builtin":
        raise ValueError(f"interpreter must be 'builtin' or 'rs274'; got {interpreter!r}")
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # not splitlines: it breaks at \v, \f, …
    progress = Progress(f"reading {source}", len(lines))
    reader = _Reader(source, arc_tolerance, arc_units=arc_tolerance_units)
    for number, line in enumerate(lines, 1):
        reader.read_line(number, line)
        if not number & 0x3FFF:
            progress(number)
    progress.done(len(lines))
    if reader.opened is not None and not reader.ended:
        raise ValueError(
            f"{source}: the program opens with % (line {reader.opened}) but has no closing % or M2/M30; LinuxCNC refuses it (file ended with no percent sign)"
        )
    if len(reader.points) < 2:
        raise ValueError(f"{source}: the program has {len(reader.points)} move(s) to a new position; a path needs at least two")
    assert reader.units is not None  # the reader refuses a move before G20/G21
    return GcodePath(np.array(reader.points), np.array(reader.lines), np.array(reader.rapid), reader.units, source, tuple(reader.notes),
                     tuple(reader.feeds), np.array(reader.point_feeds))  # fmt: skip


def _program_text(path: str | os.PathLike) -> tuple[str, str]:
    """(text, name for messages) of a G-code file, with ``read_gcode``'s checks."""
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
    return text, label


def read_gcode(
    path: str | os.PathLike, *, arc_tolerance: float | None = None, interpreter: str | None = None,
    arc_tolerance_units: str | None = None,
) -> GcodePath:  # fmt: skip
    """Read the straight moves of a G-code file (named ``*.nc``, ``.ngc``, ``.gcode``, ``.gc``, ``.g``,
    ``.tap``, ``.cnc``, ``.mpt`` or ``.mpf``).

    Raises:
        ValueError: another file name, not a regular file (a folder, a device),
            larger than 1 GiB, not UTF-8 text, or outside the subset (named with the line).
        OSError: the file could not be read.
    """
    text, label = _program_text(path)
    if interpreter is None:  # neither given: what reading_options set (the built-in reader, arcs refused)
        interpreter, default_tolerance, default_units, _ = _DEFAULTS.get()
        if arc_tolerance is None:
            arc_tolerance, arc_tolerance_units = default_tolerance, default_units
    return parse_gcode(text, label, arc_tolerance=arc_tolerance, interpreter=interpreter, arc_tolerance_units=arc_tolerance_units)


#: A G5 word outside comments (spaces may stand inside words in RS274).
_G5_WORD = re.compile(r"[Gg]\s*0*5(?![\d.])")
_COMMENTS = re.compile(r"\([^()]*\)|;[^\n]*")


def holds_splines(path: str | os.PathLike) -> bool:
    """Whether the G-code file has a cubic spline (G5): its path is then the exact curve it states
    (``read_gcode_chain``), not a polyline to round."""
    text, _ = _program_text(path)
    return _G5_WORD.search(_COMMENTS.sub(" ", text)) is not None


def parse_gcode_chain(text: str, source: str = "G-code", *, units: str | None = None, tolerance: float = 1e-6) -> Chain:
    """The exact path of G-code ``text``: every feed move as the curve it states, joined G2.

    ``G1`` moves are lines, ``G2``/``G3`` arcs (in G17, G18 or G19; not helical, at most one
    turn) are arcs and ``G5`` cubic splines are cubic Bézier segments with the spline's own
    control points, so a program written by ``spiral_cad.io.gcode_write`` reads back as its
    chain (control points equal to the printed decimals). A G5 cubic may be any cubic: it is
    split at its inflections and curvature extrema (``bezier.monotone_pieces``) into spiral pieces
    whose curvature is one-signed and monotone, so the chain's curvatures are the cubic's own.
    The rapids (``G0``) before the first feed move lead to the path's start and those after
    the last (a retract) are left out; the path is every feed move between them. The chain lies
    in the plane when every Z is 0, else in space. The built-in reader's rules hold (see the
    module docstring).

    Args:
        text: the program.
        source: its name, for messages.
        units: the chain's unit (mm, cm, m, km, in, ft); default the program's (G20/G21).
        tolerance: the chain's relative join tolerance (``Chain``): the printed decimals of a
            program leave ~1e-9 mm, so joints are checked to 1e-6 by default.

    Raises:
        ValueError: what the built-in reader refuses; a rapid between feed moves, a helical or
            multi-turn arc, a G5 cubic with a cusp, no feed move, or a joint that is not G2 (naming the lines).
    """
    from ..core.chain import Chain
    from ..core.errors import JointError
    from ..core.segments import Arc, Line
    from ..core.spiral import BezierSpiral
    from ..core.units import MM_PER_UNIT, length_unit

    reader = _read_exact(text, source)
    pieces = reader.pieces
    first = next((k for k, piece in enumerate(pieces) if not piece[2]), None)
    if first is None or reader.units is None:
        raise ValueError(f"{source}: no feed move (G1, G2, G3, G5); a path is its feed moves")
    target = reader.units if units is None else length_unit(units)
    factor = MM_PER_UNIT[reader.units] / MM_PER_UNIT[target]
    last = max(k for k, piece in enumerate(pieces) if not piece[2])
    pieces = pieces[first : last + 1]  # the rapids after the last feed move (the retract) leave the path, as with G1
    flat = all(p[3][2] == 0.0 and (p[0] == "cubic" or p[4][2] == 0.0) and (p[0] != "arc" or p[5] == 170) for p in pieces)
    dim = 2 if flat else 3
    segments: list[Line | Arc | BezierSpiral] = []
    owners: list[int] = []
    plain = plain_cubics(pieces, factor)
    for k, (kind, number, rapid, start, *data) in enumerate(pieces):
        if rapid:
            raise ValueError(f"{source} line {number}: a rapid move (G0) between feed moves; the path is the feed moves "
                             "after the rapids to its start")  # fmt: skip
        try:
            segment = piece_segments(kind, start, data, factor, dim, k in plain)
        except ValueError as error:
            raise ValueError(f"{source} line {number}: {error}") from None
        for piece in segment or ():
            segments.append(piece)
            owners.append(number)
    if not segments:
        raise ValueError(f"{source}: no feed move to a new position; a path needs one")
    try:
        return Chain(segments, tolerance=tolerance, units=target)
    except JointError as error:
        joint = error.joint
        raise ValueError(
            f"{source} lines {owners[joint]} and {owners[joint + 1]}: {error}; the program's curves do not join G2 "
            "(arcs that approximate a curve, such as biarcs, never do)"
        ) from None
    except ValueError as error:
        raise ValueError(f"{source}: {error}") from None


def _read_exact(text: str, source: str, units: str | None = None) -> _Reader:
    """The built-in reader after reading ``text`` with arcs and splines kept as pieces (``units``: the unit of a
    program that states none, ``"mm"`` or ``"in"``; None refuses it)."""
    if not isinstance(text, str):
        raise ValueError(f"text must be the program as str; got {type(text).__name__}")
    reader = _Reader(source)
    reader.exact = True
    reader.assumed_units = units
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), 1):
        reader.read_line(number, line)
    return reader


def program_feeds(path: str | os.PathLike) -> tuple[tuple[float, ...], str | None]:
    """The feed rates a G-code program's feed moves run at, and the program's unit.

    Args:
        path: the program (read by the built-in reader, arcs and splines as they are).

    Returns:
        The distinct F values in force on the feed moves (G1, G2, G3, G5) under ``G94``
        (program unit per minute), in the order they are first used (empty: none, or only
        inverse-time ``G93`` or per-revolution ``G95`` feeds), and ``"mm"`` or ``"in"``
        (None: the program has no move).

    Raises:
        ValueError: as ``read_gcode_chain``'s reading.
        OSError: the file could not be read.
    """
    text, label = _program_text(path)
    reader = _read_exact(text, label)
    return tuple(reader.feeds), reader.units


def read_gcode_chain(path: str | os.PathLike, *, units: str | None = None, tolerance: float = 1e-6) -> Chain:
    """The exact path of a G-code file (``parse_gcode_chain``), named as ``read_gcode`` requires.

    Raises:
        ValueError: as ``read_gcode`` and ``parse_gcode_chain``.
        OSError: the file could not be read.
    """
    text, label = _program_text(path)
    return parse_gcode_chain(text, label, units=units, tolerance=tolerance)
