"""Full NGC through LinuxCNC's own interpreter: ``rs274``'s canonical moves as a toolpath.

LinuxCNC's standalone interpreter (``rs274``, Debian package ``linuxcnc-uspace``) reads
everything the machine controller would: parameters, expressions, O-word subroutines and
loops, canned cycles. Run in batch mode (``rs274 -g program.ngc output``) it prints one
canonical call a line, for instance::

       8 N..... STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)
      11 N40    ARC_FEED(7.0000, 4.0000, 7.0000, 2.0000, -1, 3.0000, 0.0000, 0.0000, 0.0000)

(the call's count, the line's N word or ``N.....``, the call). An error goes to stderr (the
message, then the line's text) with exit status 1.

How the moves are read back:

* ``STRAIGHT_TRAVERSE``/``STRAIGHT_FEED(x, y, z, a, b, c)``: a rapid or feed move to x, y, z;
* ``ARC_FEED(first_end, second_end, first_centre, second_centre, rotation, normal_end, a, b, c)``
  in the plane of the last ``SELECT_PLANE`` (XY: first X, second Y; XZ: first Z, second X;
  YZ: first Y, second Z): chords within ``arc_tolerance`` (refused without it, as the built-in
  reader does) by ``run_rs274``; kept arcs by ``rs274_pieces`` (``spiral_cad.io.gcode_paths``);
* ``SET_FEED_RATE`` and ``SET_FEED_MODE``: the feed of every piece (``rs274_pieces``);
* ``USE_LENGTH_UNITS``: the unit (rs274 prints positions in the program's unit; its own
  default, before any G20/G21, is mm);
* ``NURBS_FEED``, ``SPLINE_FEED``, ``STRAIGHT_PROBE``, ``RIGID_TAP`` and moves of the
  rotary axes A, B, C are refused by name.

The G-code line of every move: the program is handed to rs274 with its line number as the N
word of each line (an N word only labels a line), and rs274 prints it with each call. Moves
from a subroutine in another file keep the last line printed before them (O-word lines carry no N
word). ``folder`` runs rs274 in the program's folder, where it finds those subroutine files.

Precision: rs274 prints 4 decimals, so positions agree with the program to 0.00005 of its unit
(exactly, for programs written with at most 4 decimals in absolute coordinates).
"""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import IO, Any

import numpy as np

from .progress import Progress, ticking
from .toolpath import PLANES, GcodePath, arc_points, in_program_unit

#: The Debian package that has ``rs274``.
PACKAGE = "linuxcnc-uspace"

_CALL = re.compile(r"\s*\d+\s+N([0-9]*)\.*\s*([A-Z_]+)\((.*)\)\s*$")
_N_WORD = re.compile(r"(\s*/?\s*)[Nn]\s*[0-9]+")
_PLANES = {"CANON_PLANE_XY": 170, "CANON_PLANE_XZ": 180, "CANON_PLANE_YZ": 190}
_REFUSED = {"NURBS_FEED": "a NURBS curve (G5.2/G6.2)", "SPLINE_FEED": "a spline (G5/G5.1)",
            "STRAIGHT_PROBE": "a probing move (G38)", "RIGID_TAP": "rigid tapping (G33.1)"}  # fmt: skip


def rs274_executable() -> str | None:
    """The path of LinuxCNC's ``rs274``, or None when it is not installed."""
    return shutil.which("rs274")


def numbered(text: str) -> str:
    """``text`` with each line's number as its N word (in place of any N word it had), so that
    rs274 prints the line with each canonical call; %, O-word and blank lines are left as they are."""
    out = []
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), 1):
        head = line.lstrip(" \t/")
        if not head or head[0] in "%Oo":
            out.append(line)
            continue
        match = _N_WORD.match(line)
        if match:
            out.append(f"{match.group(1)}N{number} {line[match.end() :]}")
        else:
            slash = line[: len(line) - len(line.lstrip(" \t/"))]
            out.append(f"{slash}N{number} {head}")
    return "\n".join(out)


#: The most canonical output read (bytes): a program's moves, not a loop's.
MAX_OUTPUT = 4 << 30
#: How long rs274 may run (seconds) before the program is taken for one that never ends (an O-word loop).
TIMEOUT = 600.0

#: Runs of rs274 at most when it dies by a signal saying nothing (a crash of the interpreter, not the program's
#: fault: it was seen when two runs shared a tool table, before each run had its own home).
SIGNAL_RUNS = 3


#: A G20 or G21 word (spaces may stand inside words in RS274), and comments, which hide words.
_UNIT_WORD = re.compile(r"[Gg]\s*0*2\s*[01](?![\d.])")
_COMMENTS = re.compile(r"\([^()]*\)|;[^\n]*")


def run_rs274(
    text: str, source: str = "G-code", *, arc_tolerance: float | None = None, timeout: float | None = None,
    arc_tolerance_units: str | None = None, folder: str | os.PathLike | None = None, units: str | None = None,
) -> GcodePath:  # fmt: skip
    """The moves of G-code ``text`` as LinuxCNC's interpreter ``rs274`` executes them.

    Args:
        text, source: the program and its name for messages.
        arc_tolerance: arcs become chords at most this far from them (None: arcs refused).
        timeout: seconds rs274 may run (default ``TIMEOUT``).
        arc_tolerance_units: the unit of ``arc_tolerance`` (None: the program's).
        folder: where rs274 runs, so it finds the subroutine files the program calls
            (``o<name> call``): the program's own folder (None: none are found).
        units: the unit of a program that says neither G20 nor G21, ``"mm"`` or ``"in"``
            (None: such a program is refused).

    Raises:
        ValueError: rs274 is not installed (naming the package), rs274 refused the program
            (its message and the line's text), a call that is not a straight move or an arc,
            an arc without ``arc_tolerance``, fewer than two moves, or rs274 still running after
            ``timeout`` seconds (default ``TIMEOUT``).
    """
    with _canonical(text, source, timeout, folder, units) as (calls, assumed):
        return _moves(calls, source, arc_tolerance, arc_tolerance_units, assumed)


def rs274_pieces(
    text: str, source: str = "G-code", *, timeout: float | None = None, folder: str | os.PathLike | None = None,
    units: str | None = None,
) -> tuple[list[tuple[Any, ...]], list[float], str]:  # fmt: skip
    """The moves of G-code ``text`` as rs274 executes them, arcs kept as arcs: ``(pieces, feeds, unit)``.

    ``pieces`` are the built-in reader's exact pieces (``("line", line, rapid, start, end)`` and
    ``("arc", line, False, start, end, plane, centre_first, centre_second, rotation)``, as
    ``spiral_cad.io.gcode_paths`` reads them), ``feeds`` the F in force on each (NaN: a rapid, or
    not units per minute); the arguments are ``run_rs274``'s.

    Raises:
        ValueError: as ``run_rs274`` (arcs are read, never refused).
    """
    with _canonical(text, source, timeout, folder, units) as (calls, assumed):
        pieces: list[tuple[Any, ...]] = []
        feeds: list[float] = []
        path = _moves(calls, source, None, None, assumed, (pieces, feeds))
    return pieces, feeds, path.units


def _private_home(folder: str) -> dict[str, str]:
    """The environment rs274 runs in: its home in ``folder``. rs274 opens its tool table as ``$HOME/.tool.mmap``
    and empties it first, so with a shared home two runs break each other (SIGBUS, "tool 1 not found") and a run
    would empty the tool table of a LinuxCNC running on the same account."""
    return {**os.environ, "HOME": folder}


@contextmanager
def _canonical(text: str, source: str, timeout: float | None, run_in: str | os.PathLike | None,
               units: str | None) -> Iterator[tuple[IO[str], str | None]]:  # fmt: skip
    """rs274's canonical calls of ``text`` (an open file of its output) and the unit to read them in when the program
    states none (``units``; None when it states one)."""
    executable = rs274_executable()
    if executable is None:
        raise ValueError(
            f"interpreter 'rs274' is not installed: it is LinuxCNC's, in the Debian package {PACKAGE} (apt-get install {PACKAGE}); or use the built-in reader"
        )
    stated = _UNIT_WORD.search(_COMMENTS.sub(" ", text)) is not None
    if not stated and units not in ("mm", "in"):
        raise ValueError(
            f"{source}: the program never says G20 (inches) or G21 (mm); rs274 would read it in mm, but a machine may "
            "default to inches, and a path in the wrong unit is worse than none: add G20 or G21, or state the unit "
            "(units='mm' or 'in'; build: --units mm or --units in)"
        )
    with tempfile.TemporaryDirectory(prefix="spiral_cad_rs274_") as folder:
        program = os.path.join(folder, "program.ngc")
        output = os.path.join(folder, "canon.txt")
        with open(program, "w", encoding="utf-8") as file:
            file.write(numbered(text))
        limit = TIMEOUT if timeout is None else timeout
        cwd = folder if run_in is None else os.fspath(run_in)
        for _ in range(SIGNAL_RUNS):
            with ticking(f"rs274 reading {source}"), open(os.path.join(folder, "errors.txt"), "w+") as errors:
                process = subprocess.Popen([executable, "-g", program, output], cwd=cwd, stdin=subprocess.DEVNULL,
                                           stdout=subprocess.DEVNULL, stderr=errors, env=_private_home(folder))  # fmt: skip
                started = time.monotonic()
                try:
                    while process.poll() is None:  # a loop that never ends would fill the disk: watch time and size
                        time.sleep(0.05)
                        if time.monotonic() - started > limit:
                            raise ValueError(f"{source}: rs274 was still running after {limit:g} s (a loop that never ends?); stopped")
                        if os.path.exists(output) and os.path.getsize(output) > MAX_OUTPUT:
                            raise ValueError(
                                f"{source}: rs274 printed more than {MAX_OUTPUT / 1e6:,.0f} MB of moves (a loop that never ends?); stopped"
                            )
                finally:
                    if process.poll() is None:
                        process.kill()
                        process.wait()
                errors.seek(0)
                stderr = errors.read()
            returncode = process.returncode
            messages = [m for m in stderr.splitlines() if m.strip() and m.strip() != "executing"]
            if not (returncode < 0 and not messages):
                break  # done, or refused in its own words; killed by a signal with nothing said: run it again
        if returncode < 0 and not messages:
            name = signal.Signals(-returncode).name if -returncode in signal.valid_signals() else f"signal {-returncode}"
            raise ValueError(f"{source}: rs274 died by {name} {SIGNAL_RUNS} times, saying nothing (LinuxCNC's interpreter crashed)")
        if returncode != 0 or messages:
            where = _N_WORD.match(messages[1]) if len(messages) > 1 else None
            line = f" line {where.group(0).strip(' /Nn')}" if where else ""
            said = messages[0] if messages else f"exit status {returncode}"
            raise ValueError(f"{source}{line}: rs274 refused the program: {said}")
        with open(output, encoding="utf-8", errors="replace") as file:
            yield file, None if stated else units


def _moves(calls: Iterable[str], source: str, arc_tolerance: float | None, arc_units: str | None = None,
           assumed: str | None = None, exact: tuple[list[tuple[Any, ...]], list[float]] | None = None) -> GcodePath:  # fmt: skip
    """The toolpath of rs274's canonical calls (an iterable of its output lines); ``assumed``: the program's unit when
    it states none; with ``exact`` (two lists), every move is also added to it as a piece and its feed."""
    progress = Progress(f"reading rs274's moves of {source}")
    points: list[list[float]] = []
    lines: list[int] = []
    rapid: list[bool] = []
    position = [0.0, 0.0, 0.0]
    plane, units, line = 170, assumed or "mm", 0
    feed, feed_mode = math.nan, 0

    def error(text: str) -> ValueError:
        return ValueError(f"{source} line {line}: {text}")

    def add(point: list[float], is_rapid: bool) -> None:
        if point != position or not points:
            points.append(point)
            lines.append(line)
            rapid.append(is_rapid)

    for count, raw in enumerate(calls):
        match = _CALL.match(raw)
        if match is None:
            continue
        if match.group(1):
            line = int(match.group(1))
        name, arguments = match.group(2), match.group(3)
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            values = [float(v) for v in arguments.split(",")]
            if any(values[3:6]):
                raise error(f"{name} moves a rotary axis (A, B, C = {values[3]:g}, {values[4]:g}, {values[5]:g}); only X, Y, Z are read")
            point = values[:3]
            if exact is not None and point != position:
                exact[0].append(("line", line, name == "STRAIGHT_TRAVERSE", position, point))
                exact[1].append(math.nan if name == "STRAIGHT_TRAVERSE" or feed_mode else feed)
            add(point, name == "STRAIGHT_TRAVERSE")
            position = point
        elif name == "ARC_FEED" and exact is not None:
            values = [float(v) for v in arguments.split(",")]
            if any(values[6:9]):
                raise error("ARC_FEED moves a rotary axis; only X, Y, Z are read")
            first, second, normal = PLANES[plane]
            end = [0.0, 0.0, 0.0]
            end[first], end[second], end[normal] = values[0], values[1], values[5]
            exact[0].append(("arc", line, False, position, end, plane, values[2], values[3], int(values[4])))
            exact[1].append(math.nan if feed_mode else feed)
            add(end, False)
            position = end
        elif name == "SET_FEED_RATE":
            feed = float(arguments)
        elif name == "SET_FEED_MODE":  # (spindle, mode): 0 units per minute, 1 inverse time, 2 per revolution
            feed_mode = int(arguments.split(",")[-1])
        elif name == "ARC_FEED":
            values = [float(v) for v in arguments.split(",")]
            if arc_tolerance is None:
                raise error(
                    "an arc (ARC_FEED) is refused: only straight moves are read unless arc_tolerance is given (arcs become chords within it)"
                )
            if any(values[6:9]):
                raise error("ARC_FEED moves a rotary axis; only X, Y, Z are read")
            first, second, normal = PLANES[plane]
            end = [0.0, 0.0, 0.0]
            end[first], end[second], end[normal] = values[0], values[1], values[5]
            tolerance = in_program_unit(arc_tolerance, arc_units, units or "mm")
            for point in arc_points(position, end, plane, values[2], values[3], int(values[4]), tolerance):
                add(point, False)
                position = point
        elif name == "SELECT_PLANE":
            if arguments.strip() not in _PLANES:
                raise error(f"the plane {arguments.strip()} is not XY, XZ or YZ")
            plane = _PLANES[arguments.strip()]
        elif name == "USE_LENGTH_UNITS":
            unit = "in" if "INCH" in arguments else "mm" if "MM" in arguments else None
            if unit is None:
                raise error(f"the unit {arguments.strip()} is not inch or mm")
            if assumed is not None:  # rs274's own default (mm), printed for a program that states no unit
                continue
            if points and unit != units:
                raise error("the unit changes after the first move; one unit per program")
            units = unit
        elif name in _REFUSED:
            raise error(f"{_REFUSED[name]} ({name}) is refused: not a straight move or an arc")
        if not count & 0xFFFF:
            progress(count)
    if not all(math.isfinite(v) for p in points for v in p):
        raise ValueError(f"{source}: rs274 printed a position that is not a finite number")
    if len(points) < 2 and (exact is None or not exact[0]):  # as pieces, one move from the start is a path
        raise ValueError(f"{source}: rs274 executed {len(points)} move(s) to a new position; a path needs at least two")
    return GcodePath(np.array(points), np.array(lines), np.array(rapid), units, source)
