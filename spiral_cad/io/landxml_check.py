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

__all__ = ["PRECISION_GAPS", "RELATIVE_GAP", "SLIVER_SHARE", "check_landxml"]

#: A default gap tolerance in units of the file's last printed decimal (two points each rounded, then a
#: length and a direction that are rounded too).
PRECISION_GAPS = 5.0
#: The default gap tolerance's floor relative to the model's size (1 mm on a 1 km road: what exporters' clothoid series leave).
RELATIVE_GAP = 1e-6
#: Elements shorter than this share of the longest are slivers: the angle tolerance is not taken from them.
SLIVER_SHARE = 1e-3
#: The elements whose text holds coordinates (``Start``, ``End``, ``Center``, ``PI``).
_POINTS = {"Start", "End", "Center", "PI"}


def check_landxml(path: str | os.PathLike, *, gap_tol: float | None = None, angle_tol: float | None = None,
                  curvature_tol: float | None = None) -> ContinuityReport:  # fmt: skip
    """Every joint of every alignment of the LandXML file ``path``, in the file's unit.

    A file's elements meet only as well as its numbers resolve them: by default the tolerances are those
    numbers' own, stated in the notes. The printed precision is the decimals its alignments print their
    coordinates to (where most are printed to a fixed number of them; else the numbers are taken as
    exact). A gap is judged against ``PRECISION_GAPS`` units of that last decimal, at least
    ``RELATIVE_GAP`` of the model's size (an exporter's clothoid series lands an End about that close)
    and 1e-7; an angle against twice that gap over the shortest element (at least 1e-7 rad); a curvature
    jump, relative, against ``PRECISION_GAPS`` units of that decimal over the smallest radius (at least
    1e-6).

    Args:
        path: the file.
        gap_tol: largest G0 gap (the file's unit); None: from the file's numbers.
        angle_tol: largest G1 tangent angle (radians); None: from the gap and the elements' lengths.
        curvature_tol: largest G2 curvature jump, relative to ``max(|κa|, |κb|, 1/size)``; None: from the
            radii's precision.

    Returns:
        A ``ContinuityReport`` with one piece per alignment (named), its ``notes`` saying how the file
        was read and which tolerances were used.

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
    frames = [alignment.element_frames for alignment in alignments]
    points = np.vstack([f[:, :, :3].reshape(-1, 3) for f in frames])
    size = model_size(points.tolist(), source)
    decimals = _printed_decimals(root)
    lengths = np.concatenate([alignment.file_lengths for alignment in alignments])
    shortest = float(lengths[lengths > SLIVER_SHARE * lengths.max()].min())
    curvatures = np.abs(np.concatenate([f[:, :, 6:9].reshape(-1, 3) for f in frames]))
    sharpest = float(np.hypot(curvatures[:, 0], curvatures[:, 1]).max())
    unit = 10.0**-decimals if decimals is not None else 0.0
    stated = []
    if gap_tol is None:
        gap_tol = max(1e-7, PRECISION_GAPS * unit, RELATIVE_GAP * size)
        stated.append(f"gap {gap_tol:.3g}")
    if angle_tol is None:
        angle_tol = max(1e-7, 2.0 * gap_tol / shortest)
        stated.append(f"angle {angle_tol:.3g} rad")
    if curvature_tol is None:
        curvature_tol = max(1e-6, PRECISION_GAPS * unit * sharpest)
        stated.append(f"curvature jump {curvature_tol:.3g} relative")
    pieces = [
        ("alignment", [(tuple(a), tuple(b)) for a, b in f.tolist()], False, alignment.name) for f, alignment in zip(frames, alignments)
    ]
    report = classify_pieces(pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, source=source,
                             element="element", units=alignments[0].units)  # fmt: skip
    notes = [
        "judged on the file's own numbers: each element from its Start and direction (else where the one before ends) "
        "to its End (else where its length takes it), turned by its length and end radii; a spiral is a clothoid, G2 inside",
        *(f"alignment {alignment.name!r}: {note}" for alignment in alignments for note in alignment.notes if not note.startswith("joint ")),
    ]  # fmt: skip
    ours = sum(method == "spiral_cad cubic" for alignment in alignments for method in alignment.methods)
    if ours:
        notes.append(f"{ours} spiral(s) this package wrote are judged as the clothoids their attributes state, as other "
                     "readers take them (their cubic, in the Feature, may lie apart: see each Spiral's desc)")  # fmt: skip
    misses = [(float(a.end_misses.max()), a.name, int(a.end_misses.argmax())) for a in alignments if len(a.end_misses)]
    worst = max(misses, default=(0.0, "", 0))
    if worst[0] > gap_tol:
        notes.append(f"alignment {worst[1]!r}: element {worst[2]}'s End lies {worst[0]:.3g} from where its Start, direction, "
                     "length and radii take it (the largest such; the joints use the End)")  # fmt: skip
    if stated:
        whence = (f"the file's numbers ({decimals} printed decimals)" if decimals is not None
                  else "the file's numbers (no fixed printed decimals: taken as exact)")  # fmt: skip
        notes.append(f"tolerances from {whence} and its size: {', '.join(stated)}; give them to judge otherwise")
    if not any(element.tag.rsplit("}", 1)[-1] == "Units" for element in root):
        notes.append(f"the file states no unit (<Units>): read in {alignments[0].units}")
    return replace(report, notes=tuple(notes))


def _printed_decimals(root: ET.Element) -> int | None:
    """The decimals the alignments print their coordinates to, where most of them are printed to one fixed
    number of them (as a program writes them), else None (the numbers taken as exact: a hand-written
    ``0 100`` is not a precision of one metre)."""
    counts = Counter(len(n.split(".", 1)[1]) if "." in n else 0 for n in _coordinates(root) if "e" not in n.lower())
    if not counts:
        return None
    decimals, seen = counts.most_common(1)[0]
    return decimals if decimals >= 1 and 2 * seen >= sum(counts.values()) else None


def _geometry(root: ET.Element) -> list[ET.Element]:
    """The elements inside the alignments' ``CoordGeom`` (not a parcel's)."""
    return [e for a in root.iter() if a.tag.rsplit("}", 1)[-1] == "Alignment"
            for g in a if g.tag.rsplit("}", 1)[-1] == "CoordGeom" for e in g.iter()]  # fmt: skip


def _coordinates(root: ET.Element) -> list[str]:
    return [n for e in _geometry(root) if e.tag.rsplit("}", 1)[-1] in _POINTS for n in (e.text or "").split()]
