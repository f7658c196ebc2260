"""G0/G1/G2 at every joint of a LandXML file's alignments, on the file's own numbers.

Each alignment is one piece; its joints are where one ``CoordGeom`` element ends and the next begins,
each element as the file states it (``LandXMLAlignment.element_frames``): placed by its ``Start`` and
direction (else where the element before ends), run by its length and its end radii (a line: none; an
arc: its radius; a spiral: a clothoid, its curvature linear in length from ``radiusStart`` to
``radiusEnd``, so G2 inside). A gap or a kink between elements is a G0 joint, a radius that differs
from its neighbour's a G1 one, whatever the rebuild of ``read_landxml`` would make of them. The
measures and tolerances are those of every checker (``spiral_cad.continuity.joints``).
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import replace

import numpy as np

from ..continuity.joints import ContinuityReport, check_tolerances, classify_pieces, model_size
from .landxml_read import read_landxml

__all__ = ["PRECISION_GAPS", "check_landxml"]

#: A default gap tolerance in units of the file's last printed decimal (two points each rounded, then a
#: length and a direction that are rounded too).
PRECISION_GAPS = 5.0
#: The fewest decimals taken as a fixed printed precision.
_FIXED_DECIMALS = 3
#: The elements whose text holds coordinates (``Start``, ``End``, ``Center``, ``PI``).
_POINTS = {"Start", "End", "Center", "PI"}


def check_landxml(path: str | os.PathLike, *, gap_tol: float | None = None, angle_tol: float | None = None,
                  curvature_tol: float = 1e-6) -> ContinuityReport:  # fmt: skip
    """Every joint of every alignment of the LandXML file ``path``, in the file's unit.

    A file that prints its coordinates to a fixed number of decimals has its elements meet only to that
    precision: by default a gap is judged against what the file resolves (``PRECISION_GAPS`` units of its last printed
    decimal, at least 1e-7) and an angle against twice that gap over the median element's length (at
    least 1e-7 rad), both stated in the notes.

    Args:
        path: the file.
        gap_tol: largest G0 gap (the file's unit); None: from the file's decimals.
        angle_tol: largest G1 tangent angle (radians); None: from the gap and the elements' lengths.
        curvature_tol: largest G2 curvature jump, relative to ``max(|κa|, |κb|, 1/size)``.

    Returns:
        A ``ContinuityReport`` with one piece per alignment (named), its ``notes`` saying how the file
        was read.

    Raises:
        ValueError: what ``read_landxml`` refuses (not LandXML, no alignment, an element it cannot
            read), named with the file, or a bad tolerance.
    """
    check_tolerances(**{k: v for k, v in (("gap_tol", gap_tol), ("angle_tol", angle_tol), ("curvature_tol", curvature_tol))
                        if v is not None})  # fmt: skip
    source = os.path.basename(os.fspath(path))
    try:
        alignments = read_landxml(path, max_offset=math.inf)  # the file's numbers are judged, not the rebuild
        root = ET.parse(path).getroot()
    except ValueError as error:
        raise ValueError(f"{source}: {error}") from None
    decimals = _printed_decimals(root)
    typical = float(np.median(np.concatenate([alignment.file_lengths for alignment in alignments])))
    stated = []
    if gap_tol is None:
        gap_tol = max(1e-7, PRECISION_GAPS * 10.0**-decimals) if decimals else 1e-7
        stated.append(f"gap {gap_tol:.3g}")
    if angle_tol is None:
        angle_tol = max(1e-7, 2.0 * gap_tol / typical) if typical > 0.0 else 1e-7
        stated.append(f"angle {angle_tol:.3g} rad")
    pieces = [("alignment", [(tuple(a), tuple(b)) for a, b in alignment.element_frames.tolist()], False, alignment.name)
              for alignment in alignments]  # fmt: skip
    points = np.vstack([alignment.element_frames[:, :, :3].reshape(-1, 3) for alignment in alignments])
    report = classify_pieces(pieces, model_size(points.tolist(), source), gap_tol=gap_tol, angle_tol=angle_tol,
                             curvature_tol=curvature_tol, source=source, element="element", units=alignments[0].units)  # fmt: skip
    notes = [
        "judged on the file's own numbers: each element placed by its Start and direction (else where the one before "
        "ends) and run by its length and end radii; a spiral is a clothoid, G2 inside",
        *(f"alignment {alignment.name!r}: {note}" for alignment in alignments for note in alignment.notes if not note.startswith("joint ")),
    ]  # fmt: skip
    ours = sum(method == "spiral_cad cubic" for alignment in alignments for method in alignment.methods)
    if ours:
        notes.append(f"{ours} spiral(s) this package wrote are judged as the clothoids their attributes state, as other "
                     "readers take them (their cubic, in the Feature, may lie apart: see each Spiral's desc)")  # fmt: skip
    if stated:
        whence = (f"from the file's {decimals} printed decimals" if decimals
                  else "by default (the file prints no fixed number of decimals: its numbers taken as exact)")  # fmt: skip
        notes.append(f"tolerances {whence}: {', '.join(stated)}; give them to judge otherwise")
    if not any(element.tag.rsplit("}", 1)[-1] == "Units" for element in root):
        notes.append(f"the file states no unit (<Units>): read in {alignments[0].units}")
    return replace(report, notes=tuple(notes))


def _printed_decimals(root: ET.Element) -> int:
    """The decimals a file prints its coordinates to, when it prints them to a fixed number (as a program
    writes them: at least half of them with the same count, at least ``_FIXED_DECIMALS``), else 0 (the
    numbers taken as exact: a hand-written ``0 100`` is not a precision of one metre)."""
    counts = Counter(len(number.split(".", 1)[1]) if "." in number else 0
                     for element in root.iter() if element.tag.rsplit("}", 1)[-1] in _POINTS
                     for number in (element.text or "").split() if "e" not in number.lower())  # fmt: skip
    if not counts:
        return 0
    decimals, seen = counts.most_common(1)[0]
    return decimals if decimals >= _FIXED_DECIMALS and 2 * seen >= sum(counts.values()) else 0
