"""A CNC program made G2 in place: the same program back, its cutting runs G2 within a bound (as ArcWelder does for printers).

``gcode_g2`` reads the program line by line, keeping LinuxCNC's modal state (unit, plane, distance
mode, arc centre mode, feed mode, cutter compensation, motion mode, feed and position), and:

* keeps every line that is not a cutting move **verbatim and in order**: comments, units, planes,
  offsets, tool changes, spindle, coolant, dwells, stops, probes (``G38``), rapids (``G0``: the output
  has exactly the input's rapids), plunges and retracts (a feed move that changes Z), splines;
* makes each **run** of consecutive cutting lines G2 with ``spiral_cad.design.make_g2`` within
  ``max_deviation`` (the program's own unit), arcs kept true arcs. A cutting line is a ``G1``, ``G2``
  or ``G3`` move in the XY plane (``G17``) at constant Z under ``G90``, ``G91.1`` and ``G94``, without
  cutter compensation, whose words are only ``G1``–``G3``, ``N``, ``X``, ``Y``, ``Z``, ``I``, ``J``,
  ``R`` and ``F`` (no comment, no other code on the line); a run is such lines one after another at
  one Z and one feed (a feed change starts a new run, so every move keeps its feed and no feed the
  input does not use is written);
* fixes each run's first and last points: the run starts where the input's does (the entry, after
  the plunge) and ends where it does (before the retract). A closed run whose entry lies on a
  straight part the transitions leave is made G2 all round and started there; otherwise the run is
  made G2 as an open path and, when its last arc was shrunk, a straight step (no longer than the
  arc's shift, so within the bound) returns to the input's end;
* splits a run at a joint ``make_g2`` refuses: that joint is left as it was (named in ``GcodeRun.refused``
  by its line, point and reason) and the parts on either side are made G2 on their own; keeps a part
  verbatim, naming why, when it cannot be written within the bound. A run ``make_g2`` splits (a
  reversal, a corner too sharp for the bound) is written part after part, its splits counted.

A LinuxCNC NURBS block (``G5.2`` … ``G5.3``) in G17, G90, G94 and G40 whose lines hold only plain words is
made G2 within the bound (``gcode_nurbs.nurbs_g2``) from its first point to its last, at its feed; another
is kept as it is (named), and the tool ends on its last control point, so the cuts after it are rewritten. From the first line that uses parameters, expressions, O-words, or text the reader cannot parse, the
rest of the program is kept verbatim (its positions are not known without an interpreter); a move of
a rotary axis (``A``, ``B``, ``C``, ``U``, ``V``, ``W``) is never a cutting line.

The output dialect is ``spiral_cad.io.gcode_write``'s: ``"linuxcnc"`` (transitions as ``G5`` cubics,
exact) or ``"generic"`` (biarcs ``G2``/``G3``, for grbl or Klipper, within a fifth of the bound; the
transitions are then made within the rest). Header comments (after a first ``%``) state the bound,
the measured deviation and the counts.
"""

from __future__ import annotations

import math
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.chain import Chain
from ..core.errors import NoSolutionError
from ..core.segments import Line, Segment
from .gcode import exponent_word
from .gcode_paths import _arc
from .gcode_processes import PARALLEL_MOVES, in_processes, processes
from .gcode_report import GcodeG2Report, GcodeRun
from .gcode_write import DIALECTS, gcode_program
from .progress import Progress

__all__ = ["gcode_g2", "rewrite_gcode_g2"]

#: Suffixes of the G-code programs ``rewrite_gcode_g2`` takes.
GCODE_SUFFIXES = (".nc", ".ngc", ".gcode", ".tap")
#: The share of the bound left to biarcs in the generic dialect.
BIARC_SHARE = 0.2
#: The most joints a run is split at where ``make_g2`` refuses them (each costs a build of the rest); the rest is kept.
MAX_REFUSED = 20
#: The least time the splits of one run may take (seconds; else twice its first build).
SPLIT_SECONDS = 5.0
#: Decimals of the numbers written (far below any bound a machine holds).
DECIMALS = 10

_WORD = re.compile(r"\s*([A-Za-z])\s*([+-]?\s*(?:\d+\.?\d*|\.\d+))", re.ASCII)
_WORDS = re.compile(r"(?:\s*[A-Za-z]\s*[+-]?\s*(?:\d+\.?\d*|\.\d+))*\s*", re.ASCII)
_COMMENT = re.compile(r"\([^()]*\)|;.*$")
_FULL_NGC = re.compile(r"[#\[<@^]|^\s*/?\s*(?:[Nn]\s*\d+\s*)?[Oo]")
_ROTARY = set("ABCUVW")
_CUTTING_WORDS = set("GNXYZIJRF")
#: Motion codes (times ten) that leave the position unknown to this reader.
_UNKNOWN_AFTER = {280, 300, 382, 383, 384, 385, 330, 331, 62, 730, 760, *range(810, 900, 10)}
_NON_MODAL_UNKNOWN = {280, 300, 100, 520, 530, 921, 922, 923}


@dataclass
class _State:
    units: str | None = None
    plane: int = 170
    absolute: bool = True
    arc_absolute: bool = False
    feed_mode: int = 940
    comp: int = 400
    motion: int | None = None
    feed: float = math.nan
    feed_word: str = ""
    position: list[float | None] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class _Block:
    """A NURBS block (``G5.2`` … ``G5.3``) being read: where it starts, whether its modes allow a rewrite, its lines."""

    start: list[float | None]
    plain: bool
    feed: float
    feed_word: str
    units: str | None
    lines: list[tuple[int, str, list[tuple[str, float, str]], bool]] = field(default_factory=list)


@dataclass
class _Move:
    number: int
    segments: list[Segment]
    start: tuple[float, float]
    end: tuple[float, float]
    z: float
    feed: float
    feed_word: str
    units: str
    motion: int


def _number(value: float) -> str:
    text = f"{value:.{DECIMALS}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "", "-") else text


def _parse(line: str) -> tuple[list[tuple[str, float, str]], bool] | None:
    """The words of a line (letter, value, as written) and whether it has a comment; None: not plain words."""
    body = _COMMENT.sub(" ", line)
    if "(" in body or ")" in body or _FULL_NGC.search(body):
        return None
    stripped = body.strip()
    if stripped.startswith("/"):
        stripped = stripped[1:]
    if not _WORDS.fullmatch(stripped):
        return None
    words = [(m.group(1).upper(), float(m.group(2).replace(" ", "")), m.group(2).replace(" ", "")) for m in _WORD.finditer(stripped)]
    return words, body != line


def _code(value: float) -> int:
    return int(round(value * 10))


class _Rewriter:
    def __init__(self, text: str, source: str, bound: float, dialect: str, shape: str, units: str | None, gathering: bool = False):
        self.source, self.bound, self.dialect, self.shape = source, bound, dialect, shape
        self.config = (text, source, bound, dialect, shape, units)
        #: Only reading, to gather the runs (``made_apart``): no run is made G2.
        self.gathering = gathering
        self.gathered: list[tuple[list[str], list[_Move]]] = []
        #: Runs made G2 in other processes, by their order in the program: the run, and each part's length and lines.
        self.made: dict[int, tuple[GcodeRun, list[tuple[int, list[str] | None]]]] = {}
        self.flushed = 0
        self.raw = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        self.state = _State(units=units)
        self.out: list[str] = []
        self.runs: list[GcodeRun] = []
        self.notes: list[str] = []
        self.pending: list[tuple[str, _Move]] = []  # (raw line, move) of the run being gathered
        self.emitted_motion: int | None = None
        self.emitted_feed: float = math.nan
        self.first_unit: str | None = units
        self.rotary: list[int] = []  # lines where a rotary axis moves
        self.unitless: list[int] = []  # feed moves in XY read before any G20/G21 (their unit unknown: kept as they are)
        self.kept_moves: dict[str, list[int]] = {}  # feed moves in XY kept as they are, by why (a word a cut does not have …)
        self.last_control: tuple[float, float] | None = None  # the last control point of a NURBS block being read
        self.block: _Block | None = None  # the NURBS block being read
        self.started = self.deadline = 0.0  # when the run being written started, and its splits' deadline

    # ---------------------------------------------------------------- reading

    def run(self) -> None:
        if not self.gathering:
            self.made = self.made_apart()
        frozen = False
        percent = 0
        progress = Progress(
            f"g2 {self.source}: lines", len(self.raw) if not self.gathering else 0, after=math.inf if self.gathering else 3.0
        )
        for number, line in enumerate(self.raw, 1):
            if not number & 0x3FF:  # a look at the clock every 1 024 lines (Progress prints at most every 2 s)
                progress(number)
            if frozen:
                self.out.append(line)
                continue
            if line.strip() == "%":
                percent += 1
                self.flush()
                self.drop_block()
                self.out.append(line)
                if percent == 2:
                    frozen = True
                continue
            exponent = exponent_word(line)
            if exponent is not None:
                raise ValueError(f"{self.source} line {number}: {exponent}")
            parsed = _parse(line)
            if parsed is None:
                self.flush()
                self.drop_block()
                self.notes.append(f"lines {number}-{len(self.raw)} verbatim: line {number} uses parameters, expressions, "
                                  "O-words or text that is not plain words (its positions need an interpreter)")  # fmt: skip
                self.out.append(line)
                frozen = True
                continue
            words, commented = parsed
            move = self.read(number, words, commented, line.lstrip().startswith("/"))
            if self.block is not None:
                self.flush()
                self.block.lines.append((number, line, words, commented or line.lstrip().startswith("/")))
                if self.state.motion != 52:  # G5.3 (or a block left another way) ends it
                    self.finish_block()
                continue
            if move is not None and self.pending and (move.feed != self.pending[-1][1].feed or move.z != self.pending[-1][1].z
                                                      or move.units != self.pending[-1][1].units):  # fmt: skip
                self.flush()
            if move is not None:
                self.pending.append((line, move))
                continue
            self.flush()
            self.verbatim(line, words)
        self.flush()
        self.drop_block()
        progress.done(len(self.raw))
        if self.unitless:
            self.notes.append(f"{len(self.unitless)} feed move(s) before any G20 or G21 (first on line {self.unitless[0]}) kept as they "
                              "are: the program does not say its unit; give units ('mm' or 'in'; --units) to make them G2")  # fmt: skip
        if self.rotary:
            shown = ", ".join(map(str, self.rotary[:5])) + (", …" if len(self.rotary) > 5 else "")
            self.notes.append(f"{len(self.rotary)} line(s) where a rotary axis moves, as they are (line {shown})")
        for why, numbers in self.kept_moves.items():
            shown = ", ".join(map(str, numbers[:5])) + (", …" if len(numbers) > 5 else "")
            self.notes.append(f"{len(numbers)} feed move(s) {why} kept as they are (line {shown})"
                              + (": LinuxCNC refuses K on an arc in the XY plane" if " K" in why else ""))  # fmt: skip

    def verbatim(self, line: str, words: list[tuple[str, float, str]], move: _Move | None = None) -> None:
        """Keep a line (``move``: a kept cutting line's move); put the input's motion code in front when it moves by the
        modal code and the output's differs."""
        motion = self.state.motion if move is None else move.motion
        feed = self.state.feed if move is None else move.feed
        g = {_code(v) for letter, v, _ in words if letter == "G"}
        has_axes = any(letter in "XYZABCUVW" for letter, _, _ in words)
        motion_codes = {c for c in g if c in (0, 10, 20, 30, 50, 51, 52, 53, 62, 382, 383, 384, 385, 330, 331, 800)
                        or 730 <= c <= 890}  # fmt: skip
        non_modal = g & {40, 100, 280, 300, 520, 530, 920}
        if has_axes and not motion_codes and not non_modal and motion is not None and self.emitted_motion != motion:
            match = re.match(r"(\s*/?\s*(?:[Nn]\s*\d+)?\s*)", line)
            head = match.group(1) if match else ""
            code = motion
            line = f"{head}G{code // 10}{'.' + str(code % 10) if code % 10 else ''} {line[len(head) :]}"
            self.notes.append(f"a motion code put in front of a line that moved by the mode a rewritten run changed: {line.strip()}")
        self.out.append(line)
        if motion_codes or (has_axes and not non_modal):
            self.emitted_motion = motion
        if any(letter == "F" for letter, _, _ in words):
            self.emitted_feed = feed

    def read(self, number: int, words: list[tuple[str, float, str]], commented: bool, deleted: bool) -> _Move | None:
        """Update the state with a line; the line's move when it is a cutting line."""
        s = self.state
        g = [_code(v) for letter, v, _ in words if letter == "G"]
        axes = {letter: v for letter, v, _ in words if letter in "XYZABCUVW"}
        other = {letter: v for letter, v, _ in words if letter in "IJKRP"}
        start = list(s.position)
        for c in g:
            if c in (200, 210):
                s.units = "in" if c == 200 else "mm"
                self.first_unit = self.first_unit or s.units
            elif c in (170, 180, 190):
                s.plane = c
            elif c in (900, 910):
                s.absolute = c == 900
            elif c in (901, 911):
                s.arc_absolute = c == 901
            elif c in (930, 940, 950):
                s.feed_mode = c
            elif c in (400, 410, 411, 420, 421):
                s.comp = c
        for letter, v, written in words:
            if letter == "F":
                s.feed, s.feed_word = v, written
        motion_codes = [c for c in g if c in (0, 10, 20, 30, 50, 51, 52, 53, 62, 800, 330, 331) or 382 <= c <= 385 or 730 <= c <= 890]
        if motion_codes:
            s.motion = motion_codes[-1] if motion_codes[-1] != 800 else None
        if s.motion in (52, 53):  # a NURBS block (G5.2 … G5.3): kept as it is; the tool ends on its last control point
            self.nurbs(axes)
            return None
        non_modal = [c for c in g if c in (40, 100, 280, 300, 520, 530, 920, 921, 922, 923)]
        if any(c in _NON_MODAL_UNKNOWN for c in non_modal) or (s.motion in _UNKNOWN_AFTER and axes):
            s.position = [None, None, None]
            return None
        if 920 in non_modal:
            for k, letter in enumerate("XYZ"):
                if letter in axes:
                    s.position[k] = axes[letter]
            return None
        if 40 in non_modal or not axes or s.motion is None:
            return None
        end: list[float | None] = list(start)
        for k, letter in enumerate("XYZ"):
            if letter in axes:
                if s.absolute:
                    end[k] = axes[letter]
                else:
                    previous = start[k]
                    end[k] = None if previous is None else previous + axes[letter]
        s.position = end
        if s.motion == 50 and s.absolute:  # a G5 cubic moves X and Y only
            return None
        cutting = (
            s.motion in (10, 20, 30) and not commented and not deleted and s.plane == 170 and s.absolute and s.feed_mode == 940
            and s.comp == 400 and s.units is not None and math.isfinite(s.feed) and s.feed > 0.0
            and all(letter in _CUTTING_WORDS for letter, _, _ in words)
            and all(c in (10, 20, 30) for c in g) and None not in start and None not in end and start[2] == end[2]
        )  # fmt: skip
        if any(letter in _ROTARY for letter in axes):
            self.rotary.append(number)
            return None
        if s.units is None and s.motion in (10, 20, 30) and s.plane == 170:
            self.unitless.append(number)
        if not cutting:
            extra = sorted({letter for letter, _, _ in words} - _CUTTING_WORDS)
            if s.motion in (10, 20, 30) and s.plane == 170 and not commented and not deleted and (extra or not s.absolute):
                why = f"with the word(s) {' '.join(extra)}" if extra else "in incremental mode (G91)"
                self.kept_moves.setdefault(why, []).append(number)
            return None
        a = (float(start[0]), float(start[1]))  # type: ignore[arg-type]
        b = (float(end[0]), float(end[1]))  # type: ignore[arg-type]
        z = float(start[2])  # type: ignore[arg-type]
        if s.motion == 10:
            segments: list[Segment] = [] if a == b else [Line(a, b)]
        else:
            centre = self.centre(a, b, other, s.motion == 30)
            if centre is None:
                return None
            segments = list(_arc([a[0], a[1], z], [b[0], b[1], z], 170, centre[0], centre[1], 1 if s.motion == 30 else -1, 1.0, 2, None))
        assert s.units is not None and s.motion is not None
        return _Move(number, segments, a, b, z, s.feed, s.feed_word, s.units, s.motion)

    def nurbs(self, axes: dict[str, float]) -> None:
        """Follow a G5.2 … G5.3 block (LinuxCNC: control points X Y of the XY plane; G5.3 moves to the last one)."""
        s = self.state
        if s.motion == 52 and self.block is None:
            self.block = _Block(list(s.position), s.plane == 170 and s.absolute and s.feed_mode == 940 and s.comp == 400
                                and s.units is not None and math.isfinite(s.feed) and s.feed > 0.0, s.feed, s.feed_word, s.units)  # fmt: skip
        if s.motion == 52 and "X" in axes and "Y" in axes:
            self.last_control = (axes["X"], axes["Y"])
        elif s.motion == 53:
            s.motion = None  # LinuxCNC leaves no motion mode after G5.3
            if s.plane == 170 and self.last_control is not None:
                s.position = [self.last_control[0], self.last_control[1], s.position[2]]
            else:
                s.position = [None, None, None]
            self.last_control = None
        if s.motion == 52 and s.plane != 170:
            s.position = [None, None, None]

    def drop_block(self) -> None:
        """Keep an unfinished NURBS block's lines as they are (a line the reader cannot follow, or the program's end)."""
        if self.block is not None:
            self.out += [line for _, line, _, _ in self.block.lines]
            self.block = None

    def finish_block(self) -> None:
        """Write a NURBS block just read: made G2 within the bound (``gcode_nurbs``), or verbatim (the report says why)."""
        block, self.block = self.block, None
        assert block is not None
        if self.gathering:
            return
        first, last = block.lines[0][0], block.lines[-1][0]
        run = GcodeRun(first, last, 1, nurbs=True)
        self.runs.append(run)
        written: list[str] | None = None
        try:
            written = self.block_g2(block, run)
        except ValueError as error:
            run.reason = f"NURBS block kept as it is: {str(error)[:300]}"
        if written is None:
            motion = self.state.motion
            for _, line, words, _ in block.lines:
                self.state.motion = 52
                self.verbatim(line, words)
            self.state.motion = motion
            self.emitted_motion = None
            return
        run.status, run.lines_written = "G2", len(written)
        if block.feed != self.emitted_feed:
            self.out.append(f"F{block.feed_word}")
            self.emitted_feed = block.feed
        self.out += written
        last_code = written[-1].split()[0] if written else ""
        self.emitted_motion = {"G1": 10, "G2": 20, "G3": 30, "G5": 50}.get(last_code, self.emitted_motion)

    def block_g2(self, block: _Block, run: GcodeRun) -> list[str] | None:
        """The lines of a NURBS block made G2 (see ``gcode_nurbs``).

        Raises:
            ValueError: a block this reader does not take (words other than the plain ones, a comment, another
                plane or mode), or one ``nurbs_g2`` refuses; the message says which.
        """
        from .gcode_nurbs import nurbs_g2

        if not block.plain or None in block.start[:2] or block.units is None:
            raise ValueError("not in G17 G90 G94 G40 with a known unit, feed and position")
        controls = [(float(block.start[0]), float(block.start[1]))]  # type: ignore[arg-type]
        weights = [1.0]
        order = 3
        for k, (number, _, words, commented) in enumerate(block.lines):
            letters = {letter for letter, _, _ in words}
            values = {letter: v for letter, v, _ in words}
            codes = [_code(v) for letter, v, _ in words if letter == "G"]
            allowed = ("GXYPLFN" if k == 0 else "GN") if k in (0, len(block.lines) - 1) else "XYPN"
            if commented or not letters <= set(allowed) or codes != ([52] if k == 0 else [53] if k == len(block.lines) - 1 else []):
                raise ValueError(f"line {number} holds words other than G5.2/G5.3, X, Y, P, L, F, N, or a comment")
            if k == 0 and values.get("L", 0.0) > 3:
                order = int(values["L"])
            if ("X" in letters) != ("Y" in letters):
                raise ValueError(f"line {number} names one of X and Y only")
            if "X" in letters:
                controls.append((values["X"], values["Y"]))
                weights.append(values.get("P", 1.0))
            elif k == 0 and values.get("P", 0.0) > 0.0:
                weights[0] = values["P"]
        units = block.units
        bound = self.bound if self.first_unit in (None, units) else self.bound * (25.4 if self.first_unit == "in" else 1 / 25.4)
        curve_bound = bound * (1.0 - BIARC_SHARE) if self.dialect == "generic" else bound
        made = nurbs_g2(np.array(controls), np.array(weights), order, curve_bound, units=units, shape=self.shape)
        out: list[str] = []
        arc_error = 0.0
        for piece in made.pieces:
            if isinstance(piece, Chain):
                program = gcode_program(piece, dialect=self.dialect, feed=block.feed, units=units, rapid_to_start=False,
                                        arc_tolerance=bound * BIARC_SHARE, decimals=DECIMALS)  # fmt: skip
                arc_error = max(arc_error, program.arc_error)
                out += program.moves
            else:
                out.append(f"G1 X{_number(piece.end[0])} Y{_number(piece.end[1])}")
        deviation = made.deviation + arc_error + math.sqrt(2.0) * 10.0**-DECIMALS
        if deviation > bound:
            raise ValueError(f"measured {deviation:.3g} {units} from the NURBS, beyond the bound {bound:g} {units}")
        run.deviation = deviation
        run.joints_changed = made.joints
        return out

    @staticmethod
    def centre(a: tuple[float, float], b: tuple[float, float], other: dict[str, float], ccw: bool) -> tuple[float, float] | None:
        """An arc's centre from its I J offsets or its R (None: neither, or an R arc that cannot be)."""
        if "R" in other:
            if "I" in other or "J" in other:
                return None
            r = other["R"]
            dx, dy = b[0] - a[0], b[1] - a[1]
            d = math.hypot(dx, dy)
            if d == 0.0 or abs(r) < d / 2:
                return None
            h = math.sqrt(max(r * r - d * d / 4, 0.0))
            left = 1.0 if ccw else -1.0
            if r < 0:
                left = -left
            return (a[0] + dx / 2 - left * h * dy / d, a[1] + dy / 2 + left * h * dx / d)
        if "I" not in other and "J" not in other:
            return None
        return (a[0] + other.get("I", 0.0), a[1] + other.get("J", 0.0))

    # ---------------------------------------------------------------- writing

    def flush(self) -> None:
        """Write the gathered run: made G2 part by part (split at the joints ``make_g2`` refuses), or verbatim."""
        if not self.pending:
            return
        lines = [line for line, _ in self.pending]
        moves = [move for _, move in self.pending]
        self.pending = []
        if self.gathering:
            self.gathered.append((lines, moves))
            return
        made = self.made.pop(self.flushed, None)
        self.flushed += 1
        if made is not None and (made[0].first, made[0].last) == (moves[0].number, moves[-1].number):
            run, at, parts = made[0], 0, []
            for count, part in made[1]:
                parts.append((lines[at : at + count], moves[at : at + count], part))
                at += count
        else:
            run = GcodeRun(moves[0].number, moves[-1].number, len(moves))
            parts = self.made_g2(run, moves, lines)
        self.runs.append(run)
        if any(written is not None for _, _, written in parts):
            run.status = "G2"
        elif run.reason or run.refused:
            run.status, run.reason = "kept", run.reason or "; ".join(run.refused)
        else:
            run.status = "nothing to do"
        for part_lines, part_moves, written in parts:
            if written is None:
                for line, move in zip(part_lines, part_moves):
                    parsed = _parse(line)
                    assert parsed is not None
                    self.verbatim(line, parsed[0], move)
                continue
            run.lines_written += len(written)
            feed = part_moves[0].feed
            if feed != self.emitted_feed:
                self.out.append(f"F{part_moves[0].feed_word}")
            self.out += written
            self.emitted_feed = feed
            last = written[-1].split()[0] if written else ""
            self.emitted_motion = {"G1": 10, "G2": 20, "G3": 30, "G5": 50}.get(last, self.emitted_motion)

    def made_g2(self, run: GcodeRun, moves: list[_Move], lines: list[str]) -> list[tuple[list[str], list[_Move], list[str] | None]]:
        """A run's parts, each with its lines written in its place (``parts``), timed from now."""
        self.started, self.deadline = time.perf_counter(), math.inf
        return self.parts(run, moves, lines)

    def made_apart(self) -> dict[int, tuple[GcodeRun, list[tuple[int, list[str] | None]]]]:
        """The runs of a long program made G2 in one process per core (``gcode_processes``: forked, each holds the
        runs read), by their order; none when the program is short or there is one process to make them in."""
        if processes() < 2:
            return {}
        gatherer = _Rewriter(*self.config, gathering=True)
        gatherer.run()
        if sum(len(moves) for _, moves in gatherer.gathered) < PARALLEL_MOVES:
            return {}
        return in_processes(gatherer.made_run, len(gatherer.gathered), f"g2 {self.source}: runs made G2")

    def made_run(self, index: int) -> tuple[GcodeRun, list[tuple[int, list[str] | None]]]:
        """Gathered run ``index`` made G2: the run, and each part's length and lines."""
        lines, moves = self.gathered[index]
        run = GcodeRun(moves[0].number, moves[-1].number, len(moves))
        parts = self.made_g2(run, moves, lines)
        return run, [(len(part_lines), written) for part_lines, _, written in parts]

    def parts(self, run: GcodeRun, moves: list[_Move], lines: list[str]) -> list[tuple[list[str], list[_Move], list[str] | None]]:
        """A run's parts, each with its lines written in its place (None: kept verbatim): the run made G2 whole, or, where
        ``make_g2`` refuses a joint between two moves, split there (the joint left as it was, named in ``run.refused``) and
        each side made G2 on its own."""
        segments = [s for m in moves for s in m.segments]
        if len(segments) < 2:
            return [(lines, moves, None)]
        try:
            written = self.rewrite(run, moves, segments)
        except NoSolutionError as error:
            found = re.search(r"joint (\d+)", str(error))
            ends = list(np.cumsum([len(m.segments) for m in moves]))
            joint = int(found.group(1)) if found else -1
            at = ends.index(joint + 1) if joint + 1 in ends[:-1] else -1
            now = time.perf_counter()
            if self.deadline == math.inf:  # the splits may take twice the first build (at least SPLIT_SECONDS)
                self.deadline = now + max(SPLIT_SECONDS, 2.0 * (now - self.started))
            if at < 0 or len(run.refused) >= MAX_REFUSED or now > self.deadline:  # the part kept
                many = f"more than {MAX_REFUSED} joints refused or out of time; " if at >= 0 else ""
                run.reason = run.reason or f"make_g2 refused it: {many}{str(error)[:300]}"
                return [(lines, moves, None)]
            x, y = moves[at].end
            run.refused.append(f"line {moves[at].number} (X{_number(x)} Y{_number(y)}): {str(error)[:300]}")
            return self.parts(run, moves[: at + 1], lines[: at + 1]) + self.parts(run, moves[at + 1 :], lines[at + 1 :])
        except ValueError as error:
            run.reason = run.reason or f"make_g2 or the writer refused it: {str(error)[:300]}"
            return [(lines, moves, None)]
        return [(lines, moves, written)]

    def rewrite(self, run: GcodeRun, moves: list[_Move], segments: list[Segment]) -> list[str] | None:
        """The lines of a run (or part of one) made G2, or None: every joint G2 already, or beyond the bound
        (``run.reason`` says so).

        Raises:
            NoSolutionError: ``make_g2`` refused a joint (its message names it).
        """
        from ..design.g2 import make_g2

        units = moves[0].units
        bound = self.bound if self.first_unit in (None, units) else self.bound * (25.4 if self.first_unit == "in" else 1 / 25.4)
        printing = math.sqrt(2.0) * 10.0**-DECIMALS  # the written numbers' rounding, left out of make_g2's share
        g2_bound = (bound * (1.0 - BIARC_SHARE) if self.dialect == "generic" else bound) - 2.0 * printing
        start, end = np.array(moves[0].start), np.array(moves[-1].end)
        size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1.0)
        tiny = 1e-9 * size
        closed = bool(np.linalg.norm(start - end) <= tiny) and _mid_line(segments[-1], segments[0])
        chains: list[Chain] | None = None
        made = None
        if closed:
            try:
                made = make_g2(segments, g2_bound, closed=True, shape=self.shape, units=units, advise=False)
            except (ValueError, NoSolutionError):
                made = None
            if made is not None and len(made.chains) == 1:
                chains = _started_at(made.chains[0], start, tiny)
        if chains is None:
            made = make_g2(segments, g2_bound, closed=False, shape=self.shape, units=units, advise=False)
            chains = list(made.chains)
        assert made is not None
        if all(j.kind == "g2" for j in made.joints):
            return None
        joints_changed = sum(j.kind not in ("g2", "split") for j in made.joints)
        # the run's ends fixed: a step from the input's entry and to its exit where the path's ends moved
        pieces: list[list[Segment] | Chain] = []
        position = start
        steps = 0.0
        for chain in chains:
            gap = float(np.linalg.norm(np.asarray(chain.start) - position))
            if gap > tiny:
                pieces.append([Line(tuple(position), tuple(chain.start))])
                steps = max(steps, gap)
            pieces.append(chain)
            position = np.asarray(chain.end)
        gap = float(np.linalg.norm(end - position))
        if gap > tiny:
            pieces.append([Line(tuple(position), tuple(end))])
            steps = max(steps, gap)
        out: list[str] = []
        arc_error = 0.0
        printing = math.sqrt(2.0) * 10.0**-DECIMALS
        for piece in pieces:
            if isinstance(piece, Chain):
                program = gcode_program(piece, dialect=self.dialect, feed=moves[0].feed, units=units, rapid_to_start=False,
                                        arc_tolerance=bound * BIARC_SHARE, decimals=DECIMALS)  # fmt: skip
                arc_error = max(arc_error, program.arc_error)
                out += program.moves
            else:
                line = piece[0]
                out.append(f"G1 X{_number(line.end[0])} Y{_number(line.end[1])}")
        # the run ends exactly where the input's did, as the input wrote it
        deviation = max(made.deviation, steps) + arc_error + printing  # a step lies within its length of the input's end
        if deviation > bound:
            run.reason = run.reason or f"measured {deviation:.3g} {units} from the input, beyond the bound {bound:g} {units}"
            return None
        run.deviation = max(run.deviation, deviation)
        run.joints_changed += joints_changed
        run.splits += len(made.splits)
        return out


def _mid_line(last: Segment, first: Segment) -> bool:
    """Whether a closed run's entry lies inside a straight side (its last and first moves lines of one direction):
    only then can the run be made G2 all round and still start there."""
    if not (isinstance(last, Line) and isinstance(first, Line)):
        return False
    a, b = np.asarray(last.end) - np.asarray(last.start), np.asarray(first.end) - np.asarray(first.start)
    return bool(np.dot(a, b) > 0.0 and abs(a[0] * b[1] - a[1] * b[0]) <= 1e-12 * float(np.dot(a, a) + np.dot(b, b)))


def _started_at(chain: Chain, point: Any, tiny: float) -> list[Chain] | None:
    """A closed chain started at ``point`` when it lies on one of its lines (None: it does not)."""
    segments = list(chain)
    for k, s in enumerate(segments):
        if not isinstance(s, Line):
            continue
        a, b = np.asarray(s.start), np.asarray(s.end)
        d = b - a
        t = float(np.dot(np.asarray(point) - a, d) / np.dot(d, d))
        if not 0.0 <= t <= 1.0 or np.linalg.norm(a + t * d - point) > tiny:
            continue
        p = tuple(float(v) for v in point)
        after = [] if np.linalg.norm(b - point) <= tiny else [Line(p, tuple(b))]
        before = [] if np.linalg.norm(point - a) <= tiny else [Line(tuple(a), p)]
        ordered = after + segments[k + 1 :] + segments[:k] + before
        return [Chain(ordered, chain.tolerance, chain.units)]
    return None


def gcode_g2(
    text: str, max_deviation: float, *, source: str = "G-code", dialect: str = "linuxcnc", shape: str = "near-linear",
    units: str | None = None,
) -> GcodeG2Report:  # fmt: skip
    """A G-code program made G2 in place (see the module docstring): the output text and the report.

    Args:
        text: the program.
        max_deviation: the bound, in the program's unit (its first G20/G21).
        source: its name, for the report.
        dialect: ``"linuxcnc"`` (G5 cubics) or ``"generic"`` (biarcs: grbl, Klipper).
        shape: the transitions' shape (``make_g2``'s).
        units: the unit of a program that states neither G20 nor G21 (``"mm"`` or ``"in"``); None:
            such a program's runs are kept verbatim.

    Raises:
        ValueError: a bound that is not positive and finite, an unknown dialect or unit.
    """
    if isinstance(max_deviation, bool) or not isinstance(max_deviation, (int, float)) or not 0.0 < max_deviation < math.inf:
        raise ValueError(f"max_deviation must be a positive finite length; got {max_deviation!r:.40}")
    if dialect not in DIALECTS:
        raise ValueError(f"dialect must be one of {', '.join(DIALECTS)}; got {dialect!r:.40}")
    if units not in (None, "mm", "in"):
        raise ValueError(f"units must be 'mm' or 'in' (G21 or G20); got {units!r:.40}")
    rewriter = _Rewriter(text, source, float(max_deviation), dialect, shape, units)
    rewriter.run()
    unit = rewriter.first_unit or "mm"
    report = GcodeG2Report(source, "", float(max_deviation), unit, dialect, rewriter.runs, rewriter.notes)
    made = sum(r.status == "G2" for r in report.runs)
    head = [
        f"(spiral-cad g2: made G2 in place within max deviation {max_deviation:g} {unit}; measured {report.deviation:.3g} {unit})",
        f"(spiral-cad g2: {made} of {len(report.runs)} runs of cutting moves rewritten, {len(report.kept)} kept as they were, "
        f"dialect {dialect}; every other line as it was)",
    ]
    out = rewriter.out
    at = 1 if out and out[0].strip() == "%" else 0
    report.text = "\n".join(out[:at] + head + out[at:])
    return report


def rewrite_gcode_g2(
    src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, *, dialect: str = "linuxcnc", shape: str = "near-linear",
    units: str | None = None,
) -> GcodeG2Report:  # fmt: skip
    """Make the G-code program ``src`` G2 in place and write it to ``dst`` (``gcode_g2``): the report.

    Raises:
        ValueError: as ``gcode_g2``; a file that is not UTF-8 text.
        OSError: a file could not be read or written.
    """
    path = Path(src)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"{path.name}: not UTF-8 text ({error.reason} at byte {error.start})") from None
    report = gcode_g2(text, max_deviation, source=path.name, dialect=dialect, shape=shape, units=units)
    Path(dst).write_text(report.text, encoding="utf-8")
    return report
