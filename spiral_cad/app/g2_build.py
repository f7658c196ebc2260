"""Lines and arcs from a drawing or an alignment file made G2: ``build FILE.dxf``, ``build FILE.xml --max-deviation D``,
``build FILE.xodr --max-deviation D`` and the design type ``g2_path``.

Every path is made G2 by ``spiral_cad.design.make_g2`` within the stated deviation, its arcs kept
true arcs: a DXF drawing's chained paths (``spiral_cad.io.dxf_read``), a LandXML alignment of lines
and arcs (``read_landxml``: the file's elements as read, one path from its start to its end), an
OpenDRIVE road whose planView is lines and arcs. Each G2 path is one design, named after the
drawing or the alignment (``NAME_1``, ``NAME_2`` … when there are several: a drawing's paths, or
a path split where it folds back).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core.segments import Arc, Line
from .built import Built, DesignError

#: The suffixes of the files a ``g2_path`` reads, and what they are.
SOURCES = {".dxf": "DXF drawing", ".xml": "LandXML file", ".xodr": "OpenDRIVE file"}


@dataclass(kw_only=True)
class BuiltG2(Built):
    """One G2 path made by ``make_g2`` (``source``: its ``G2Path``), from a drawing or an alignment file.

    ``what``: the file's kind; ``notes``: how it was read and made (the summary prints them); ``road``:
    an alignment's path, written also as OpenDRIVE.
    """

    what: str
    notes: tuple[str, ...] = ()
    road: bool = False
    #: The joints where the path this design is a part of was split (G0 there), in words; empty: made whole.
    split_at: tuple[str, ...] = ()

    @property
    def kind(self) -> str:
        return f"G2 path ({self.what})" if not self.split_at else f"part of a split path ({self.what})"

    @property
    def shown_continuity(self) -> str:
        """The continuity to print: the part's own, and G0 at the splits of its path (never "G2" alone for a
        part whose path was split)."""
        own = self.continuity or "-"
        if not self.split_at:
            return own
        return f"G0 at {len(self.split_at)} split(s) of its path; this part {own}"


def g2_designs(path: str | Path, max_deviation: float, *, name: str | None = None, units: str | None = None,
               source_units: str | None = None, shape: str = "near-linear") -> tuple[str, list[Built]]:  # fmt: skip
    """The G2 paths of a DXF, LandXML or OpenDRIVE file, each within ``max_deviation`` of the file's (in ``units``).

    Args:
        path: the file (.dxf, .xml, .xodr).
        max_deviation: the largest distance between the file's path and the G2 path (in ``units``).
        name: the designs' name (default: the drawing's file name, an alignment's or road's own name).
        units: the designs' unit (default the file's; a LandXML or OpenDRIVE file's must be its own).
        source_units: DXF: the unit of a unitless drawing (default: refused).
        shape: the spiral shape (near-linear or walton-meek).

    Returns:
        (units, built designs).

    Raises:
        DesignError: the file cannot be read, holds what is refused, or a path cannot be made G2 within the bound.
    """
    source = Path(path)
    suffix = source.suffix.lower()
    if suffix not in SOURCES:
        raise DesignError(f"{source.name}: a G2 path reads {', '.join(SOURCES)} files")
    try:
        if suffix == ".dxf":
            return _dxf(source, max_deviation, name, units, source_units, shape)
        if source_units is not None:
            raise DesignError(f"{source.name}: source_units (--units for a unitless drawing) is for DXF files")
        paths = _landxml(source) if suffix == ".xml" else _opendrive(source)
    except (OSError, ValueError) as error:  # named once: the readers' messages may start with the file's name
        message = str(error)
        raise DesignError(message if message.startswith(f"{source.name}:") else f"{source.name}: {message}") from None
    own = paths[0][3] if paths else "m"
    if units is not None and units != own:
        raise DesignError(f"{source.name}: the file's alignments are in {own}; the designs' unit must be the same (got {units})")
    built: list[Built] = []
    for label, segments, closed, _ in paths:
        made = _made(segments, max_deviation, closed, shape, own, f"{source.name}: {label}")
        built += _named(made, name or label, SOURCES[suffix], road=True)
    return own, _unique(built)


def _dxf(source: Path, deviation: float, name: str | None, units: str | None, source_units: str | None,
         shape: str) -> tuple[str, list[Built]]:  # fmt: skip
    from ..io.dxf_read import read_dxf_paths

    drawing = read_dxf_paths(source, units=units, drawing_units=source_units)
    stem = name or _stem(source.stem, "drawing")
    made: list[tuple[Any, Any, list[str], tuple[str, ...]]] = []
    for k, p in enumerate(drawing.paths):
        made += _made(
            list(p.segments), deviation, p.closed, shape, drawing.units, f"{drawing.source}: path {k + 1} (entity {p.handles[0]})"
        )
    built = _named(made, stem, "DXF drawing", notes=drawing.notes)
    return drawing.units, built


def _made(
    segments: list, deviation: float, closed: bool, shape: str, units: str, where: str
) -> list[tuple[Any, Any, list[str], tuple[str, ...]]]:
    """(chain, G2Path, notes, splits named) of every G2 path ``make_g2`` makes of ``segments``."""
    named: list[str] = []
    try:
        results, splits = made_g2(segments, deviation, closed=closed, shape=shape, units=units, where=where, named=named)
    except ValueError as error:
        raise DesignError(str(error)) from None
    worst = max(r.deviation for r in results)
    notes = [f"within {worst:.3g} {units} of {where} (max_deviation {deviation:g})"]
    named += [f"{where}: {r.describe_splits()}" for r in results if r.split_joints]
    notes += [f"SPLIT, G0 at the split: {name}" for name in named]
    chains = [(chain, r) for r in results for chain in r.chains]
    return [(chain, r, notes if k == 0 else [], tuple(named)) for k, (chain, r) in enumerate(chains)]


def made_g2(segments: list, bound: float, *, closed: bool | None = None, shape: str = "near-linear", units: str = "mm",
            where: str = "path", named: list[str] | None = None) -> tuple[list[Any], int]:  # fmt: skip
    """``make_g2`` of ``segments``; where it refuses, the path split at every corner next to an arc (a corner
    ``make_g2`` does not round: the machine or the reader stops there) and each part made G2 on its own.

    Args:
        segments, bound, closed, shape, units: as for ``make_g2``.
        where: the path's name in messages.
        named: if given, each such split is appended to it in words (joint, point and why).

    Returns:
        The ``G2Path`` of each part, and how many such corners split the path (0: made whole).

    Raises:
        ValueError, NoSolutionError: ``make_g2``'s refusal (of the whole path, or of a part), after ``where``.
    """
    from ..design import make_g2

    try:
        return [make_g2(segments, bound, closed=closed, shape=shape, units=units)], 0
    except ValueError as refused:
        corners = _arc_corners(segments, closed=bool(closed))
        if not corners:
            raise type(refused)(f"{where}: {refused}") from None
        why = str(refused)
    if named is not None:
        named += [f"{where}: joint {j} at ({segments[j].end[0]:.10g}, {segments[j].end[1]:.10g}), a corner next to an arc, "
                  f"split because the whole path was refused ({why})" for j in corners]  # fmt: skip
    if closed:  # open the loop at the first such corner
        first = corners[0] + 1
        segments = segments[first:] + segments[:first]
        corners = [(j - first) % len(segments) for j in corners[1:]] + [len(segments) - 1]
    cuts = [0, *(j + 1 for j in corners if j + 1 < len(segments)), len(segments)]
    results = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        try:
            results.append(make_g2(segments[a:b], bound, closed=False, shape=shape, units=units))
        except ValueError as error:
            raise type(error)(f"{where} (segments {a} to {b - 1}): {error}") from None
    return results, len(corners)


def _arc_corners(segments: list, closed: bool = False) -> list[int]:
    """The joints (j: segment j ends) next to an arc that turn by more than ``make_g2``'s tangent tolerance."""
    import numpy as np

    from ..design.g2 import TANGENT_TOL

    pairs = list(zip(segments, segments[1:] + (segments[:1] if closed else [])))
    found = []
    for j, (a, b) in enumerate(pairs):
        if isinstance(a, Arc) or isinstance(b, Arc):
            t0, t1 = a.end_tangent, b.start_tangent
            if abs(float(np.arctan2(t0[0] * t1[1] - t0[1] * t1[0], np.dot(t0, t1)))) > TANGENT_TOL:
                found.append(j)
    return found


def _named(made: list, stem: str, what: str, notes: tuple[str, ...] = (), road: bool = False) -> list[Built]:
    """One ``BuiltG2`` per chain, named ``stem`` or ``stem_1``, ``stem_2`` …"""
    built: list[Built] = []
    for k, (chain, result, own, split_at) in enumerate(made):
        label = stem if len(made) == 1 else f"{stem}_{k + 1}"
        built.append(BuiltG2(name=label, chain=chain, source=result, what=what, notes=(*(notes if k == 0 else ()), *own), road=road,
                             split_at=split_at))  # fmt: skip
    return built


def _unique(built: list[Built]) -> list[Built]:
    """The designs with names made unique ignoring case (alignments may share a name): ``_2``, ``_3`` … added."""
    taken: set[str] = set()
    for b in built:
        name, suffix = b.name, 1
        while name.lower() in taken:
            suffix += 1
            name = f"{b.name}_{suffix}"
        taken.add(name.lower())
        b.name = name
    return built


def _stem(text: str, default: str) -> str:
    return (re.sub(r"[^A-Za-z0-9_-]", "_", text).strip("_-") or default)[:56]


def _landxml(source: Path) -> list[tuple[str, list, bool, str]]:
    """(name, segments, closed, units) of every alignment of a LandXML file: its elements as read, start to end."""
    from ..io import read_landxml

    out = []
    for k, alignment in enumerate(read_landxml(source)):
        segments = [s for chain in alignment.chains for s in chain]
        spirals = [type(s).__name__ for s in segments if not isinstance(s, (Line, Arc))]
        if spirals:
            raise ValueError(f"alignment {alignment.name!r} has spirals ({len(spirals)}): --max-deviation makes alignments "
                             "of lines and arcs G2; build it without --max-deviation")  # fmt: skip
        out.append((_stem(alignment.name, f"alignment{k + 1}"), segments, False, alignment.units))
    return out


def _opendrive(source: Path) -> list[tuple[str, list, bool, str]]:
    """(name, segments, closed, "m") of every road of an OpenDRIVE file whose planView is lines and arcs."""
    from ..io.opendrive_read import read_opendrive

    out = []
    for road in read_opendrive(source):
        kinds = [g.kind for g in road.geometries if g.kind not in ("line", "arc")]
        if kinds:
            raise ValueError(
                f"road {road.id} has {kinds[0]} geometries: --max-deviation makes roads of lines and arcs G2; "
                "check it with spiral-cad check"
            )
        segments = [g.segment() for g in road.geometries]
        out.append((_stem(road.name or f"road{road.id}", f"road{road.id}"), segments, False, "m"))
    return out
