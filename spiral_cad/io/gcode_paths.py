"""G-code in as lines and arcs: a program's moves as true ``Line`` and ``Arc`` segments, split where it folds back.

Both readers give the same moves: the built-in one (``spiral_cad.io.gcode``) and LinuxCNC's ``rs274``
(``spiral_cad.io.rs274``, run in the program's folder so that it finds the subroutine files the
program calls). Every move to a new position is one segment, rapids (``G0``) included (the path is
where the tool goes); the path starts where the first move ends, as the built-in reader's polyline does
(where the tool stood before it, the readers' 0, is not known):

* ``G0``/``G1`` straight moves are ``Line`` s;
* ``G2``/``G3`` arcs in every plane LinuxCNC allows (``G17`` XY, ``G18`` ZX, ``G19`` YZ) are ``Arc`` s:
  true circles, never chords. An arc's centre is put on the bisector of its chord (LinuxCNC accepts
  end radii that differ slightly, and rs274 prints 4 decimals), so every arc ends where its move does;
  a move of more than one turn (``P``) is one arc per turn; an arc of radius 0 (its ends at its centre: rs274
  runs it as a plunge) is a straight move along the plane's normal;
* a helical arc (``G2``/``G3`` that also moves along the plane's normal) is not a plane curve: it is
  read as chords within ``helix_tolerance`` (refused by name without it);
* ``G5`` cubic splines are refused here: a program with them states its exact path
  (``read_gcode_chain``).

The path lies in the plane (x, y) when every position has z = 0 and every arc is in ``G17``, else in
space. ``GcodeMoves.parts`` splits the moves where the path folds straight back (a plunge and its
retract, a cut that returns along itself): a machine stops there, so each part is its own G2 path.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.segments import Arc, Line
from ..core.units import MM_PER_UNIT, length_unit
from .toolpath import PLANES, GcodePath, arc_points, arc_sweep

__all__ = ["FOLD_SINE", "PLANE_TOLERANCE", "GcodeMoves", "GcodeRuns", "parse_gcode_moves", "read_gcode_moves", "read_gcode_runs"]

#: A joint where a curve (an arc) meets the next going back along it within this sine of the angle folds back.
FOLD_SINE = 1e-9
#: Points within this share of the path's size of a plane lie in it (``GcodeMoves.plane_runs``).
PLANE_TOLERANCE = 1e-10


@dataclass(frozen=True)
class GcodeRuns:
    """The cutting paths of a G-code program as the curves it states (``read_gcode_runs``).

    Attributes:
        runs: every run of feed moves between rapids, in program order: its ``Line``, ``Arc`` and (for
            ``G5``) ``BezierSpiral`` segments end to start, in ``units``, G2 or not; a run's segments all in
            the plane when it lies in z = 0, else its lines and arcs in space.
        lines: the program line of each segment, run by run.
        units: the program's unit (``"mm"`` or ``"in"``).
        source: the file's name, for messages.
        notes: what was left out or read with care (a tool change, an arc moved onto its chord's bisector).
        turns_left_out: the length of the whole turns an arc of more than two turns runs before the two its
            segments hold (the same circle again), in ``units``.
    """

    runs: tuple[tuple[Any, ...], ...]
    lines: tuple[tuple[int, ...], ...]
    units: str
    source: str
    notes: tuple[str, ...] = ()
    turns_left_out: float = 0.0

    def __len__(self) -> int:
        return len(self.runs)

    @property
    def length(self) -> float:
        """The length of every run together, in ``units`` (with ``turns_left_out``)."""
        return float(sum(segment.length for run in self.runs for segment in run)) + self.turns_left_out


@dataclass(frozen=True)
class GcodeMoves:
    """The moves of a G-code program as lines and arcs.

    Attributes:
        segments: every move to a new position, in order (``Line`` or ``Arc``; a helix's chords are lines).
        lines: (n,) the G-code line of each segment's move.
        rapid: (n,) True where the move is a rapid (G0).
        feeds: (n,) the feed in force (the program's unit per minute under G94; NaN: a rapid or none).
        units: the segments' unit.
        program_units: the program's own unit (G20/G21, or as stated for a program that says neither).
        source: the file's name, for messages.
        notes: what was read and is worth telling (a unit stated for the program, helices as chords).
        chords: (n,) True where the segment is a chord of a helical arc (within ``helix_tolerance`` of it).
        helix_tolerance: the chords' tolerance (None: the program has no helix).
    """

    segments: tuple[Line | Arc, ...]
    lines: NDArray
    rapid: NDArray
    feeds: NDArray
    units: str
    program_units: str
    source: str = "G-code"
    notes: tuple[str, ...] = ()
    chords: NDArray | None = None
    helix_tolerance: float | None = None

    def __len__(self) -> int:
        return len(self.segments)

    @property
    def program_feeds(self) -> tuple[float, ...]:
        """The distinct feeds of the feed moves (program unit per minute), in the order first used."""
        return tuple(dict.fromkeys(float(f) for f in self.feeds[~self.rapid] if math.isfinite(f)))

    def folds(self) -> NDArray:
        """The joints (index j: segment j ends, j + 1 starts) where the path folds straight back."""
        from ..design.rounding import straight_points

        count = len(self.segments)
        if count < 2:
            return np.zeros(0, dtype=np.int64)
        ends = np.array([s.end_tangent for s in self.segments[:-1]])
        starts = np.array([s.start_tangent for s in self.segments[1:]])
        dot = np.einsum("ij,ij->i", ends, starts)
        sine = np.linalg.norm(ends[:, :, None] * starts[:, None, :] - ends[:, None, :] * starts[:, :, None], axis=(1, 2)) / math.sqrt(2)
        fold = (dot < 0.0) & (sine <= FOLD_SINE)
        straight = np.array([isinstance(s, Line) for s in self.segments])
        both = np.flatnonzero(straight[:-1] & straight[1:])
        if both.size:  # two lines: the rounding's own test (what float64 resolves at their coordinates)
            before = np.array([self.segments[j].start for j in both])
            corner = np.array([self.segments[j].end for j in both])
            after = np.array([self.segments[j + 1].end for j in both])
            fold[both] = straight_points(before, corner, after)[1]
        return np.flatnonzero(fold)

    def parts(self) -> list[tuple[int, int]]:
        """(first, stop) segment ranges of the path split where it folds straight back (``folds``)."""
        cuts = [0, *(int(j) + 1 for j in self.folds()), len(self.segments)]
        return list(zip(cuts[:-1], cuts[1:]))

    def plane_runs(self, first: int, stop: int) -> list[tuple[int, int]]:
        """(first, stop) ranges of segments ``first`` to ``stop`` that each lie in one plane, longest first in
        travel order: a path in space (a plunge, then a contour) is split where it leaves its plane."""
        if self.segments[first].dim == 2:
            return [(first, stop)]
        ends = np.array([p for s in self.segments[first:stop] for p in (s.start, s.end)])
        tolerance = PLANE_TOLERANCE * max(float(np.abs(ends - ends[0]).max()), float(np.abs(ends).max()) * 1e-3)
        runs, begin = [], first
        points: list[NDArray] = []
        normal: NDArray | None = None
        for k in range(first, stop):
            segment = self.segments[k]
            new = [segment.start, segment.end] + ([segment.point(0.5)] if isinstance(segment, Arc) else [])
            fits, found = _in_plane(points, normal, new, segment.normal if isinstance(segment, Arc) else None, tolerance)
            if not fits:  # a new plane: cut at the corner before the lines tangent to this segment, if they lie in it
                cut = k
                while cut - 1 > begin and isinstance(self.segments[cut - 1], Line) and _tangent(self.segments[cut - 1], self.segments[cut]):
                    cut -= 1
                points, found = [], None
                for j in range(cut, k + 1):
                    other = self.segments[j]
                    extra = [other.start, other.end] + ([other.point(0.5)] if isinstance(other, Arc) else [])
                    fits, found = _in_plane(points, found, extra, other.normal if isinstance(other, Arc) else None, tolerance)
                    if not fits:
                        break
                    points += extra
                if not fits or cut == k:
                    cut, points = k, []
                    fits, found = _in_plane([], None, new, segment.normal if isinstance(segment, Arc) else None, tolerance)
                    points += new
                runs.append((begin, cut))
                begin = cut
                normal = found
                continue
            points += new
            normal = found
        runs.append((begin, stop))
        return runs

    def straight(self, first: int, stop: int) -> bool:
        """Whether segments ``first`` to ``stop`` are all lines."""
        return all(isinstance(s, Line) for s in self.segments[first:stop])

    def toolpath(self, first: int, stop: int) -> GcodePath:
        """Straight segments ``first`` to ``stop`` as a ``GcodePath`` (x, y, z; what ``round_toolpath`` rounds)."""
        segments = self.segments[first:stop]
        points = np.array([segments[0].start, *(s.end for s in segments)], dtype=np.float64)
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        lines = np.concatenate([self.lines[first : first + 1], self.lines[first:stop]])
        rapid = np.concatenate([self.rapid[first : first + 1], self.rapid[first:stop]])
        factor = MM_PER_UNIT[self.program_units] / MM_PER_UNIT[self.units]
        feeds = np.concatenate([[math.nan], self.feeds[first:stop]]) * factor
        return GcodePath(points, lines, rapid, self.units, self.source, self.notes, (), feeds)


def parse_gcode_moves(
    text: str, source: str = "G-code", *, interpreter: str = "builtin", units: str | None = None,
    program_units: str | None = None, helix_tolerance: float | None = None, folder: str | os.PathLike | None = None,
) -> GcodeMoves:  # fmt: skip
    """The moves of G-code ``text`` as lines and arcs (see the module docstring).

    Args:
        text: the program.
        source: its name, for messages.
        interpreter: ``"builtin"`` or ``"rs274"`` (LinuxCNC's own: parameters, subroutines, canned cycles).
        units: the segments' unit (mm, cm, m, km, in, ft; default the program's).
        program_units: the unit of a program that says neither G20 nor G21, ``"mm"`` or ``"in"``
            (None: such a program is refused).
        helix_tolerance: helical arcs become chords at most this far from them (in ``units``);
            None refuses them.
        folder: where rs274 looks for subroutine files (the program's folder).

    Raises:
        ValueError: what the reader refuses (naming the line and the word), a helical arc without
            ``helix_tolerance``, a G5 spline, no move to a new position.
    """
    if program_units not in (None, "mm", "in"):
        raise ValueError(f"program_units must be 'mm' or 'in' (G21 or G20); got {program_units!r}")
    if helix_tolerance is not None and not 0.0 < helix_tolerance < math.inf:
        raise ValueError(f"helix_tolerance must be a positive finite length; got {helix_tolerance}")
    if interpreter == "rs274":
        from .rs274 import rs274_pieces

        pieces, feeds, unit = rs274_pieces(text, source, folder=folder, units=program_units)
        notes: list[str] = []
    elif interpreter == "builtin":
        from .gcode import _read_exact

        reader = _read_exact(text, source, program_units)
        if reader.opened is not None and not reader.ended:
            raise ValueError(f"{source}: the program opens with % (line {reader.opened}) but has no closing % or M2/M30; "
                             "LinuxCNC refuses it (file ended with no percent sign)")  # fmt: skip
        pieces, feeds, unit, notes = reader.pieces, reader.piece_feeds, reader.units or "mm", list(reader.notes)
    else:
        raise ValueError(f"interpreter must be 'builtin' or 'rs274'; got {interpreter!r}")
    target = unit if units is None else length_unit(units)
    factor = MM_PER_UNIT[unit] / MM_PER_UNIT[target]
    flat = all(p[3][2] == 0.0 and p[4][2] == 0.0 and (p[0] != "arc" or p[5] == 170) for p in pieces if p[0] != "cubic")
    dim = 2 if flat else 3
    segments: list[Line | Arc] = []
    lines: list[int] = []
    rapid: list[bool] = []
    per_segment: list[float] = []
    chords: list[bool] = []
    helices = 0
    # the first move's start is not known (see the docstring): its end is where the path starts. The built-in
    # reader gives every move, so even one that lands on its 0 (G1 X0 Y0) states the start; rs274 prints
    # no move that stays where it is, so its first move to a new position is that first move
    first = 0 if interpreter == "builtin" else next((k for k, p in enumerate(pieces) if p[3] != p[4]), len(pieces))
    pieces, feeds = pieces[first + 1 :], feeds[first + 1 :]
    for piece, feed in zip(pieces, feeds):
        kind, number, is_rapid, start = piece[:4]
        try:
            if kind == "cubic":
                raise ValueError("a G5 cubic spline: a program with splines states its exact path (read_gcode_chain)")
            if kind == "line":
                made: list[Line | Arc] = [] if start == piece[4] else [_line(start, piece[4], factor, dim)]
            else:
                end, plane, ca, cb, rotation = piece[4:9]
                made = _arc(start, end, plane, ca, cb, rotation, factor, dim, helix_tolerance)
        except ValueError as error:
            raise ValueError(f"{source} line {number}: {error}") from None
        helix = kind == "arc" and start[PLANES[piece[5]][2]] != piece[4][PLANES[piece[5]][2]]
        helices += helix
        chords += [helix] * len(made)
        segments += made
        lines += [number] * len(made)
        rapid += [bool(is_rapid)] * len(made)
        per_segment += [feed] * len(made)
    if not segments:
        raise ValueError(f"{source}: the program has fewer than two moves to a new position; a path starts where the "
                         "first move ends and needs one more")  # fmt: skip
    if helices:
        notes.append(f"{helices} helical arc(s) read as chords within {helix_tolerance:g} {target}")
    return GcodeMoves(tuple(segments), np.array(lines), np.array(rapid), np.array(per_segment, dtype=np.float64), target, unit,
                      source, tuple(notes), np.array(chords), helix_tolerance if helices else None)  # fmt: skip


def read_gcode_moves(
    path: str | os.PathLike, *, interpreter: str | None = None, units: str | None = None, program_units: str | None = None,
    helix_tolerance: float | None = None,
) -> GcodeMoves:  # fmt: skip
    """The moves of a G-code file as lines and arcs (``parse_gcode_moves``; the file is checked as ``read_gcode``
    checks it). ``interpreter`` and ``program_units`` default to what ``reading_options`` set.

    Raises:
        ValueError: as ``read_gcode`` and ``parse_gcode_moves``.
        OSError: the file could not be read.
    """
    from .gcode import _program_text, reading_defaults

    text, label = _program_text(path)
    default_interpreter, _, _, default_units = reading_defaults()
    return parse_gcode_moves(text, label, interpreter=interpreter or default_interpreter, units=units,
                             program_units=program_units or default_units, helix_tolerance=helix_tolerance,
                             folder=os.path.dirname(os.path.abspath(os.fspath(path))))  # fmt: skip


def _tangent(a: Line | Arc, b: Line | Arc) -> bool:
    """Whether ``a`` ends in the direction ``b`` starts (within ``FOLD_SINE``)."""
    t0, t1 = a.end_tangent, b.start_tangent
    return float(np.dot(t0, t1)) > 0.0 and float(np.linalg.norm(np.cross(t0, t1))) <= FOLD_SINE


def _in_plane(points: list[NDArray], normal: NDArray | None, new: list[NDArray], arc_normal: NDArray | None,
              tolerance: float) -> tuple[bool, NDArray | None]:  # fmt: skip
    """Whether ``points`` (in the plane of ``normal``, None while they are on one line) and ``new`` (with an arc's
    ``arc_normal``) lie in one plane within ``tolerance``, and that plane's normal (None: still on one line)."""
    every = np.array([*points, *new])
    origin = every[0]
    if normal is None and arc_normal is not None:
        normal = np.asarray(arc_normal, dtype=np.float64)
    if normal is None:  # lines only so far: the plane of the first point off their line, if any
        direction = every[-1] - origin if not points else points[-1] - origin
        direction = direction / (np.linalg.norm(direction) or 1.0)
        off = (every - origin) - np.outer((every - origin) @ direction, direction)
        far = int(np.argmax(np.linalg.norm(off, axis=1)))
        if np.linalg.norm(off[far]) <= tolerance:
            return True, None
        normal = np.cross(direction, off[far])
        normal = normal / np.linalg.norm(normal)
    elif arc_normal is not None and abs(abs(float(np.dot(arc_normal, normal))) - 1.0) > 1e-9:
        return False, normal
    return bool(np.abs((every - origin) @ normal).max() <= tolerance), normal


def _line(start: list[float], end: list[float], factor: float, dim: int) -> Line:
    """The line of a straight move (in space it stays in space at z = 0, as every segment of the path)."""
    line = Line(np.array(start[:dim]) * factor, np.array(end[:dim]) * factor)
    return Line._of(np.array(start) * factor, np.array(end) * factor) if line.dim != dim else line


def _arc(start: list[float], end: list[float], plane: int, ca: float, cb: float, rotation: int, factor: float, dim: int,
         helix_tolerance: float | None) -> list[Line | Arc]:  # fmt: skip
    """The segments of one arc move: one ``Arc`` a turn, or a helix's chords."""
    first, second, normal = PLANES[plane]
    if start[first] == ca and start[second] == cb and end[first] == ca and end[second] == cb:
        # a helix of radius 0 (rs274 runs it: a hole as wide as the tool): a straight move along the normal
        return [] if start == end else [_line(start, end, factor, dim)]
    if end[normal] != start[normal]:
        if helix_tolerance is None:
            raise ValueError("a helical arc (it also moves along the plane's normal) is not a plane arc: "
                             "give a tolerance for its chords (helix_tolerance; build: --arc-tolerance)")  # fmt: skip
        corners = [list(start), *arc_points(start, end, plane, ca, cb, rotation, helix_tolerance / factor)]
        return [_line(a, b, factor, dim) for a, b in zip(corners[:-1], corners[1:]) if a != b]
    a0, b0 = start[first], start[second]
    ca, cb, _ = _on_bisector(start, end, plane, ca, cb)  # the arc ends where the move does
    t0, sweep = arc_sweep(start, end, plane, ca, cb, rotation)
    radius = math.hypot(a0 - ca, b0 - cb)
    turns = max(1, math.ceil(abs(sweep) / (2 * math.pi) - 1e-12))
    step = math.copysign(min(abs(sweep) / turns, 2 * math.pi), sweep)  # not past a whole turn by rounding
    out: list[Line | Arc] = []
    for k in range(turns):
        angle = t0 + k * step
        if dim == 2:
            out.append(Arc((ca * factor, cb * factor), math.copysign(radius * factor, step), angle, abs(step)))
            continue
        centre = np.array(start, dtype=np.float64)
        centre[first], centre[second] = ca, cb
        begin = centre.copy()
        begin[first], begin[second] = ca + radius * math.cos(angle), cb + radius * math.sin(angle)
        if k == 0:
            begin = np.array(start, dtype=np.float64)
        axis = np.zeros(3)
        axis[normal] = 1.0
        out.append(Arc.in_space(centre * factor, axis, begin * factor, step))
    return out


#: An arc's centre may move onto the bisector of its chord by at most this many times the difference of
#: its end radii, or by ``_BISECTOR_PATH`` (else no circle through both ends lies near it: a nearly whole
#: turn with its ends apart).
_BISECTOR_SHIFTS = 10.0
#: ... or by LinuxCNC's path tolerance (``TOLERANCE_MM``, ``TOLERANCE_INCH`` of rs274ngc), in the program's
#: unit: a short arc printed to a few decimals needs its centre moved many times its ends' radius difference
#: (1e-5 mm for an arc of 1.5° and radius 10 printed to 6 decimals), which moves the path no more than that.
_BISECTOR_PATH = {"mm": 0.005, "in": 0.0005}


def _on_bisector(start: list[float], end: list[float], plane: int, ca: float, cb: float) -> tuple[float, float, float]:
    """The centre (``ca``, ``cb``) moved to the nearest point of the bisector of the arc's chord, and how far
    it moved (unmoved without a chord)."""
    first, second, _ = PLANES[plane]
    a0, b0, a1, b1 = start[first], start[second], end[first], end[second]
    chord = math.hypot(a1 - a0, b1 - b0)
    if chord == 0.0:
        return ca, cb, 0.0
    ta, tb = (a1 - a0) / chord, (b1 - b0) / chord
    off = (ca - (a0 + a1) / 2) * ta + (cb - (b0 + b1) / 2) * tb  # along the chord: what the move removes
    return ca - off * ta, cb - off * tb, abs(off)


def _first_named(text: str) -> dict[str, int]:
    """The line on which each of X, Y and Z is first named (comments aside)."""
    from .gcode import _COMMENTS

    found: dict[str, int] = {}
    for number, line in enumerate(_COMMENTS.sub(" ", text).replace("\r\n", "\n").replace("\r", "\n").split("\n"), 1):
        for axis in re.findall(r"(?<![A-Z#])([XYZ])\s*[-+.\d]", line.upper()):
            found.setdefault(axis, number)
        if len(found) == 3:
            break
    return found


def read_gcode_runs(path: str | os.PathLike, *, units: str | None = None) -> GcodeRuns:
    """The exact cutting paths of a G-code file (``_built_in_runs``); a program the built-in reader refuses (a
    subroutine call, a canned cycle) is read by LinuxCNC's ``rs274`` where it is installed, as lines and arcs
    (``read_gcode_moves``), its helical moves left out. The segments of one run are all in the plane or all in
    space.

    Raises:
        ValueError: what both readers refuse (or the built-in one, naming rs274's absence), or no feed move.
        OSError: the file could not be read.
    """
    from .rs274 import rs274_executable

    try:
        read = _built_in_runs(path, units=units)
    except ValueError as refused:
        if rs274_executable() is None:
            raise ValueError(f"{refused}; LinuxCNC's rs274, which reads more programs, is not installed") from None
        read = _rs274_runs(path, units, refused)
    return replace(read, runs=tuple(_one_dimension(run) for run in read.runs))


#: The chords rs274's helical moves are read as are left out, so any tolerance serves (the program's unit).
_HELIX_CHORDS = 1e-3


def _rs274_runs(path: str | os.PathLike, units: str | None, refused: ValueError) -> GcodeRuns:
    """The runs of feed moves of a program as LinuxCNC's rs274 runs it (lines and arcs; helices left out)."""
    name = os.path.basename(os.fspath(path))
    try:
        moves = read_gcode_moves(path, interpreter="rs274", program_units=units, helix_tolerance=_HELIX_CHORDS)
    except ValueError as also:
        raise ValueError(f"{refused}; LinuxCNC's rs274 did not read it either: {also}") from None
    chords = moves.chords if moves.chords is not None else np.zeros(len(moves), dtype=bool)
    runs: list[list[Any]] = [[]]
    lines: list[list[int]] = [[]]
    for segment, line, cut in zip(moves.segments, moves.lines.tolist(), (~moves.rapid & ~chords).tolist()):
        if cut:
            runs[-1].append(segment)
            lines[-1].append(line)
        elif runs[-1]:
            runs.append([])
            lines.append([])
    kept = [k for k, run in enumerate(runs) if run]
    if not kept:
        raise ValueError(f"{name}: the program has no feed move (G1, G2, G3) to judge") from None
    why = str(refused).split("; use interpreter=")[0].split(" (have the CAM expand")[0]  # rs274 did: no advice to use it
    notes = [f"read by LinuxCNC's rs274 (the built-in reader refused it: {why})", *moves.notes,
             "the first move starts where the machine is, which the program does not say: not judged"]  # fmt: skip
    if chords.any():
        notes.append(f"{len({int(k) for k in moves.lines[chords].tolist()})} helical move(s) left out: each parts its path")
    return GcodeRuns(tuple(tuple(runs[k]) for k in kept), tuple(tuple(lines[k]) for k in kept), moves.units, name, tuple(notes))


def _one_dimension(run: tuple[Any, ...]) -> tuple[Any, ...]:
    """``run`` with every segment in the plane when all lie in z = 0 (an XY arc read in space among plane lines),
    else every line and arc in space."""
    if all(segment.dim == 2 for segment in run):
        return run
    flat = all(segment.dim == 2 or (not segment.start[2] and not segment.end[2] and (not isinstance(segment, Arc)
               or abs(segment.normal[2]) == 1.0)) for segment in run)  # fmt: skip
    out = []
    for segment in run:
        if flat and isinstance(segment, Arc) and segment.dim == 3:
            turn = float(segment.normal[2])  # +1: counterclockwise seen from +z
            angle = math.atan2(segment.start[1] - segment.center[1], segment.start[0] - segment.center[0])
            segment = Arc(segment.center[:2], math.copysign(abs(segment.radius), turn), angle, segment.sweep)
        elif flat and isinstance(segment, Line) and segment.dim == 3:
            segment = Line(segment.start[:2], segment.end[:2])
        elif not flat and isinstance(segment, Line) and segment.dim == 2:
            segment = Line._of(np.r_[segment.start, 0.0], np.r_[segment.end, 0.0])
        elif not flat and isinstance(segment, Arc) and segment.dim == 2:
            segment = Arc.in_space(np.r_[segment.center, 0.0], (0.0, 0.0, math.copysign(1.0, segment.radius)),
                                   np.r_[segment.start, 0.0], segment.sweep)  # fmt: skip
        out.append(segment)
    return tuple(out)


def _built_in_runs(path: str | os.PathLike, *, units: str | None = None) -> GcodeRuns:
    """The exact cutting paths of a G-code file: every run of feed moves between rapids as the curves it
    states (G1 lines, G2/G3 arcs, G5 cubics as ``parse_gcode_chain``'s spiral pieces), in space and in the
    program's unit, whether or not they join G2.

    A move that changes an axis the program has not named on an earlier line starts where the machine
    happens to be on it (the first move, a first cut after ``G0 Z5``): it is no segment (noted when it is
    a cut); an arc whose end lies off its circle (within what the program's
    decimals leave) is the arc about the centre moved onto the bisector of its chord, so that it ends
    where the move does (noted when that moves its centre), unless that moves the centre farther than
    ``_BISECTOR_SHIFTS`` times the difference of its radii and than LinuxCNC's path tolerance (0.005 mm,
    0.0005 in) both (a nearly whole turn whose ends are apart is no arc: left out, noted); an arc of more than two turns is judged on its last two (noted); a helical
    arc is left out and parts its run (counted in the notes).

    Args:
        path: the program.
        units: the unit of a program that states neither G20 nor G21 (``"mm"`` or ``"in"``); None refuses one.

    Returns:
        The runs (``GcodeRuns``): their segments, the program line of each, the unit and the reader's notes.

    Raises:
        ValueError: what the built-in reader refuses (naming the line), or no feed move.
        OSError: the file could not be read.
    """
    from .gcode import _program_text, _read_exact
    from .gcode_pieces import piece_segments, plain_cubics
    from .toolpath import PLANES

    text, label = _program_text(path)
    reader = _read_exact(text, label, units)
    runs: list[list[Any]] = [[]]
    lines: list[list[int]] = [[]]
    notes: list[str] = list(reader.notes)
    helical = 0
    left_out = 0.0
    named = _first_named(text)
    plain = plain_cubics(reader.pieces, 1.0)
    for k, (kind, number, rapid, start, *data) in enumerate(reader.pieces):
        helix = kind == "arc" and data[0][PLANES[data[1]][2]] != start[PLANES[data[1]][2]]
        ends_at = data[0] if kind != "cubic" else data[0][-1]
        unknown = [axis for k, axis in enumerate("XYZ") if ends_at[k] != start[k] and not named.get(axis, number) < number]
        if unknown:  # it starts where the machine happens to be on those axes
            if not rapid:
                notes.append(f"line {number}: the move starts where the program has not said ({', '.join(unknown)} not named "
                             "before it): not judged")  # fmt: skip
            runs.append([])
            lines.append([])
            continue
        if rapid or helix:
            helical += helix
            runs.append([])
            lines.append([])
            continue
        try:
            if kind == "arc":
                end, plane, ca, cb, rotation = data
                a, b, _ = PLANES[plane]
                r0, r1 = math.hypot(start[a] - ca, start[b] - cb), math.hypot(end[a] - ca, end[b] - cb)
                moved = _on_bisector(start, end, plane, ca, cb)[2]
                if moved > max(_BISECTOR_SHIFTS * abs(r0 - r1) + 1e-12 * max(r0, r1), _BISECTOR_PATH.get(reader.units or "mm", 0.005)):
                    # ends so close that no circle through both lies near the centre: not an arc (rs274 runs a spiral)
                    notes.append(f"line {number}: an arc whose end lies {abs(r0 - r1):.3g} off its circle with ends "
                                 f"{math.hypot(end[a] - start[a], end[b] - start[b]):.3g} apart is no arc: left out, it parts its path")  # fmt: skip
                    runs.append([])
                    lines.append([])
                    continue
                segments = _arc(start, end, plane, ca, cb, max(-2, min(2, rotation)), 1.0, 3, None)
                if abs(r0 - r1) > 1e-9 * max(r0, r1):
                    notes.append(f"line {number}: the arc's end lies {abs(r0 - r1):.3g} off its circle: judged about the "
                                 f"centre moved {moved:.3g} onto the bisector of its chord")  # fmt: skip
                if abs(rotation) > 1:
                    notes.append(f"line {number}: an arc of {abs(rotation)} turns, judged on its last two (the turns before "
                                 "run on the same circle)")  # fmt: skip
                    left_out += max(0, abs(rotation) - 2) * 2.0 * math.pi * 0.5 * (r0 + r1)
            else:
                segments = piece_segments(kind, start, data, 1.0, 3, k in plain) or []
        except ValueError as error:
            raise ValueError(f"{label} line {number}: {error}") from None
        for segment in segments:
            runs[-1].append(segment)
            lines[-1].append(number)
    kept = [k for k, run in enumerate(runs) if run]
    if not kept or reader.units is None:
        raise ValueError(f"{label}: no feed move (G1, G2, G3, G5) to a new position after the first move")
    if helical:
        notes.append(f"{helical} helical arc(s) left out: each parts its path")
    return GcodeRuns(tuple(tuple(runs[k]) for k in kept), tuple(tuple(lines[k]) for k in kept), reader.units, label, tuple(notes),
                     left_out)  # fmt: skip
