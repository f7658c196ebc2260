"""A CNC program's cutting paths as exact OCCT wires, so that the STEP checker judges them joint by
joint, as it judges a drawing (``dxf_shape``). (A LandXML file is judged on its own numbers:
``spiral_cad.io.landxml_check``.)

A program's feed moves are read as the curves they state (``io.gcode_paths.read_gcode_runs``: G1 lines,
G2/G3 arcs, G5 cubics; by LinuxCNC's ``rs274`` as lines and arcs where the built-in reader refuses the
program and rs274 is installed), in the program's unit; every run between two rapids is one wire in program order, so a joint is judged where
the tool goes on cutting, and never across a rapid. A helical move is not judged: OCCT has no exact
helix edge (and rs274's chords of one would be kinks of the reading, not of the program); it parts the
run and is counted in the notes.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from OCP.BRep import BRep_Builder
from OCP.TopoDS import TopoDS_Compound

from .occ import chain_wire

__all__ = ["document_shape", "program_shape"]

#: How many cutting paths are named by their program lines.
_LISTED = 50


def document_shape(path: str | os.PathLike, *, units: str | None = None) -> tuple[TopoDS_Compound, str, list[str]]:
    """The curves of a DXF drawing (``dxf_shape``) or a G-code program (``program_shape``), chosen by the
    suffix: the compound, its unit and the notes.

    Args:
        path: the file.
        units: the unit of a file that states none (a program without G20/G21: ``"mm"`` or ``"in"``; a
            drawing without ``$INSUNITS``); a file that states another is refused, never relabelled.

    Raises:
        ValueError: another suffix, a ``units`` the file contradicts, or what the chosen reader refuses.
    """
    from ..core.units import length_unit
    from ..io.gcode import SUFFIXES

    suffix = Path(path).suffix.lower()
    if suffix in SUFFIXES:
        shape, found, notes = program_shape(path, units=units)
    elif suffix == ".dxf":
        from .dxf_shape import DRAWING_UNITS, dxf_shape

        shape, found, notes = dxf_shape(path)
        if found == DRAWING_UNITS and units is not None:
            return shape, length_unit(units), [*notes, f"the drawing states no unit ($INSUNITS): read in {length_unit(units)} as stated"]
    else:
        raise ValueError(f"{Path(path).name}: a drawing (.dxf) or a G-code program ({' '.join(SUFFIXES)}) was expected; "
                         f"got {suffix or 'no suffix'!r}")  # fmt: skip
    if units is not None and length_unit(units) != found:
        raise ValueError(f"{Path(path).name} states its unit, {found}; the unit given ({units}) would relabel it: leave it out")
    return shape, found, notes


def _compound(paths: list[list[Any]], lines: list[list[int]] | None = None) -> TopoDS_Compound:
    """The paths as wires (a program's runs, ``lines`` their program lines: kept open where they end as
    they began, and a run OCCT cannot make a wire of named by its lines)."""
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for k, segments in enumerate(paths):
        try:
            builder.Add(compound, chain_wire(segments, closes=lines is None))
        except ValueError as error:
            if lines is None:
                raise
            raise ValueError(f"the cut of program lines {lines[k][0]}–{lines[k][-1]}: {error}") from None
    return compound


def program_shape(path: str | os.PathLike, *, units: str | None = None) -> tuple[TopoDS_Compound, str, list[str]]:
    """The cutting paths of the G-code program ``path`` (each run of feed moves between rapids one wire),
    their unit and notes for the reader (moves left out, what the reader noted).

    Args:
        path: the program.
        units: the unit of a program that states neither G20 nor G21 (``read_gcode_moves``'s ``program_units``).

    Raises:
        ValueError: a program the reader refuses (naming the line), or one without a feed move.
    """
    from ..io.gcode_paths import read_gcode_runs

    name = Path(path).name
    if units is not None and units not in ("mm", "in"):
        raise ValueError(f"{name}: a program's unit is mm (G21) or in (G20); got {units!r}")
    read = read_gcode_runs(path, units=units)  # LinuxCNC's rs274 reads what the built-in reader refuses
    runs, lines, unit, notes = [list(r) for r in read.runs], [list(n) for n in read.lines], read.units, list(read.notes)
    notes.append(f"{len(runs)} cutting path(s): each run of feed moves between rapids, in program order; rapids are not judged")
    notes += [f"wire {k}: the moves of program lines {numbers[0]}–{numbers[-1]}" for k, numbers in enumerate(lines[:_LISTED])]
    if len(lines) > _LISTED:
        notes.append(f"… and {len(lines) - _LISTED} more cutting paths")
    return _compound(runs, lines), unit, notes
