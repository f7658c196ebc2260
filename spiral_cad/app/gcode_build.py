"""``build --from-gcode``: a program's moves made G2, one design per G2 path.

The program is read as lines and arcs (``spiral_cad.io.gcode_paths``) and split where it folds
straight back (a plunge and its retract): each part is its own G2 path. A part of straight moves
only has its corners rounded as before (``round_toolpath``: the corner options of the design,
the feed of every move kept); a part with arcs is made G2 by ``spiral_cad.design.make_g2`` within
``max_deviation``, its arcs kept true arcs (make_g2 may split it further, at a reversal it finds).
A part with arcs in space is split further where it leaves its plane (a plunge onto a contour):
``make_g2`` makes plane paths G2. A helix's chords lie within a tenth of ``max_deviation`` of it (or the
stated arc tolerance), and the part is made G2 within the rest, so every point stays within
``max_deviation`` of the program.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .built import Built, BuiltRounded, DesignError, program_feed
from .schema import RoundedPolylineDesign

#: The share of ``max_deviation`` a helix's chords take when no arc tolerance is stated.
HELIX_SHARE = 0.1


def toolpath_designs(d: RoundedPolylineDesign, where: str, units: str, program: Path) -> list[Built]:
    """The G2 paths of the G-code ``program`` of design ``d`` (in ``units``): one ``BuiltRounded`` each,
    named ``NAME`` when there is one, else ``NAME_1``, ``NAME_2`` … in the program's order.

    Raises:
        DesignError: a part with arcs without one ``max_deviation``, or with corner options that apply
            to straight moves only; what the reader, the rounding or ``make_g2`` refuse (named by line).
    """
    from ..core.units import MM_PER_UNIT
    from ..io.gcode import reading_defaults
    from ..io.gcode_paths import read_gcode_moves
    from ..io.gcode_write import PROGRAM_UNIT
    from ..io.toolpath import in_program_unit
    from ..io.toolpath_rounding import round_toolpath, segment_feeds

    deviation = d.max_deviation if isinstance(d.max_deviation, (int, float)) else None
    _, arc_tolerance, arc_units, _ = reading_defaults()
    helix = None
    if arc_tolerance is not None:
        if not 0.0 < arc_tolerance < math.inf:
            raise DesignError(f"{where}: arc_tolerance must be a positive finite length; got {arc_tolerance}")
        helix = in_program_unit(arc_tolerance, arc_units, units)
    elif deviation is not None and HELIX_SHARE * deviation > 0.0:  # (a deviation below float64's reach is refused later)
        helix = HELIX_SHARE * deviation
    if helix is not None and deviation is not None and not helix < deviation:
        raise DesignError(f"{where}: the arc tolerance {helix:g} {units} (a helix's chords) must be below max_deviation {deviation:g}")
    moves = read_gcode_moves(program, units=units, helix_tolerance=helix)
    feed = program_feed(moves.program_feeds, moves.program_units, units)
    to_program = MM_PER_UNIT[units] / MM_PER_UNIT[PROGRAM_UNIT[units]]
    moves_to_units = MM_PER_UNIT[moves.program_units] / MM_PER_UNIT[units]  # feeds: program unit → units per minute
    samples = None if d.samples is None else d.samples.options()
    made: list[tuple[Any, Any, Any]] = []  # (chain, source, feeds per segment)
    corners = 0  # splits at corners next to an arc
    pieces = [run for first, stop in moves.parts() for run in
              ([(first, stop)] if moves.straight(first, stop) else moves.plane_runs(first, stop))]  # fmt: skip
    for first, stop in pieces:
        chorded = moves.chords is not None and bool(moves.chords[first:stop].any())
        bound = None if deviation is None else deviation - (helix or 0.0) * chorded
        if stop - first == 1 and moves.straight(first, stop):  # one move between folds: a line, nothing to round
            from ..core.chain import Chain
            from ..design.rounded_paths import RoundedPath

            chain = Chain([moves.segments[first]], units=units)
            made.append((chain, RoundedPath(chain, [], d.shape), moves.feeds[first : first + 1] * moves_to_units * to_program))
            continue
        if moves.straight(first, stop):
            options = d.rounding() if not chorded else {**d.rounding(), "max_deviation": bound}
            path = moves.toolpath(first, stop)
            result = round_toolpath(path, shape=d.shape, **options)
            per_segment = segment_feeds(result, path)
            made.append((result.chain, result, None if per_segment is None else per_segment * to_program))
            continue
        line = int(moves.lines[first])
        if bound is None:
            raise DesignError(f"{where}: {moves.source} line {line}: a path with arcs is made G2 within one max_deviation "
                              "(--max-deviation); give one number")  # fmt: skip
        others = sorted(set(d.rounding()) - {"max_deviation"})
        if others:
            raise DesignError(f"{where}: {', '.join(others)}: corner options of straight moves; {moves.source} line {line} "
                              "starts a path with arcs, made G2 within max_deviation alone")  # fmt: skip
        parts, cut = _g2_parts(moves, first, stop, bound, d.shape, units)
        made += parts
        corners += cut
    notes = list(moves.notes)
    folds = moves.folds()
    if len(folds):
        shown = ", ".join(str(int(moves.lines[j + 1])) for j in folds[:8]) + (" …" if len(folds) > 8 else "")
        notes.append(f"split where the path folds straight back ({len(folds)}×), at the moves of lines {shown}")
    if corners:
        notes.append(f"split at {corners} corner(s) next to an arc (make_g2 rounds corners between lines)")
    if len(pieces) > len(folds) + 1:
        notes.append(f"split where a path with arcs leaves its plane ({len(pieces) - len(folds) - 1}×): make_g2 makes plane paths G2")
    built: list[Built] = []
    for k, (chain, source, per_segment) in enumerate(made):
        name = d.name if len(made) == 1 else f"{d.name}_{k + 1}"
        built.append(BuiltRounded(name=name, chain=chain, source=source, samples=samples, inputs=(program,), program_feed=feed,
                                  segment_feeds=per_segment, notes=tuple(notes) if k == 0 else ()))  # fmt: skip
    return built


def _g2_parts(moves: Any, first: int, stop: int, bound: float, shape: str, units: str) -> tuple[list[tuple[Any, Any, Any]], int]:
    """The G2 chains ``make_g2`` makes of segments ``first`` to ``stop`` (a part with arcs), within ``bound``, and at how
    many corners next to an arc the part was split."""
    from .g2_build import made_g2

    segments = list(moves.segments[first:stop])
    frame = None
    if segments[0].dim == 3:  # a plane run in space: made G2 in its plane's coordinates, then placed back
        frame, segments = _in_frame(segments)
    where = f"{moves.source} lines {int(moves.lines[first])}–{int(moves.lines[stop - 1])}"
    results, splits = made_g2(segments, bound, shape=_g2_shape(shape), units=units, where=where)
    made = [(chain if frame is None else chain.placed(frame), result, None) for result in results for chain in result.chains]
    return made, splits


def _in_frame(segments: list[Any]) -> tuple[Any, list[Any]]:
    """The frame of the plane of ``segments`` in space (an arc's normal; x along the world's x where it can) and the
    segments in its coordinates (``Chain.placed(frame)`` puts them back)."""
    import math

    import numpy as np

    from ..core.segments import Arc, Line
    from ..core.space import PlaneFrame

    normal = next(s.normal for s in segments if isinstance(s, Arc))
    axis = np.eye(3)[int(np.argmin(np.abs(normal)))] if abs(normal[0]) > 0.9 else np.array([1.0, 0.0, 0.0])
    x_dir = axis - np.dot(axis, normal) * normal
    frame = PlaneFrame(normal * float(np.dot(segments[0].start, normal)), x_dir, normal)  # G17 at z: x, y as they are
    plane: list[Any] = []
    for s in segments:
        if isinstance(s, Line):
            plane.append(Line(*frame.local([s.start, s.end])))
            continue
        centre, start = frame.local([s.center, s.start])
        sense = math.copysign(1.0, s.radius) * math.copysign(1.0, float(np.dot(s.normal, frame.normal)))
        plane.append(Arc(centre, sense * abs(s.radius), math.atan2(start[1] - centre[1], start[0] - centre[0]), s.sweep))
    return frame, plane


def _g2_shape(shape: str) -> str:
    """The spiral shape ``make_g2`` takes for the design's corner shape (g2cbs rounds corners only)."""
    return "near-linear" if shape == "g2cbs" else shape
