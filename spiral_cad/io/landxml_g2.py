"""A LandXML file rewritten G2 in place: one file in, the same file out (``rewrite_landxml_g2``).

Every alignment whose ``CoordGeom`` is lines and arcs is made G2 by ``spiral_cad.design.make_g2``
within the bound (spirals inserted at every joint, the arcs shifted about their centres as make_g2
does), and its ``CoordGeom`` elements are replaced by the G2 chain's ``Line``, ``Spiral`` and
``Curve`` elements as ``spiral_cad.io.landxml`` writes them (each spiral a ``clothoid`` of its length
and end radii, with its cubic's control points in a ``Feature`` that ``read_landxml`` rebuilds exactly),
their ``staStart`` recomputed from the alignment's own ``staStart`` and the alignment's ``length``
updated. Directions are written in the file's ``directionUnit`` and the way the file counts them
(counter-clockwise from east, or clockwise from north). Everything else is kept as it was: the
alignment's name and attributes, its profiles, station equations, the ``CoordGeom``'s ``Feature``
elements, the other alignments and all the rest of the document (the XML tree is edited, not
regenerated; comments are kept).

An alignment that is G2 already (a file's clothoids between its lines and arcs), an alignment with
spirals that is not G2 (make_g2 takes lines and arcs), and one make_g2 refuses are kept as they are,
and the report says why. The bound is in the file's linear unit.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

from ..core.chain import Chain
from ..core.segments import Arc, Line
from ..design import make_g2
from .document_report import DocumentReport, PathReport
from .g2_ends import straight_ends
from .landxml import _coord_geom, _text
from .landxml_read import _child, _children, _local, _Reader, read_landxml
from .staging import temporary_beside

__all__ = ["GEOMETRY", "parse_keeping", "rewrite_landxml_g2", "write_tree"]

#: The CoordGeom children that are the alignment's geometry (replaced); the others (``Feature``) are kept.
GEOMETRY = ("Line", "IrregularLine", "Curve", "Spiral", "Chain")
#: Direction attributes our writer puts in decimal degrees counter-clockwise from east.
DIRECTIONS = ("dir", "dirStart", "dirEnd")


def _namespaces(source: Path) -> list[tuple[str, str]]:
    """The (prefix, uri) pairs the document declares, so the written file keeps its prefixes."""
    found: list[tuple[str, str]] = []
    for _, pair in ET.iterparse(source, events=("start-ns",)):
        if pair not in found:
            found.append(pair)
    return found


def parse_keeping(source: Path) -> ET.ElementTree[ET.Element]:
    """An XML document with its comments and processing instructions, its namespace prefixes registered to be written back."""
    for prefix, uri in _namespaces(source):
        try:
            ET.register_namespace(prefix, uri)
        except ValueError:  # a reserved prefix (ns0 …): ElementTree names it itself
            pass
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True, insert_pis=True))
    return ET.parse(source, parser)


def write_tree(tree: ET.ElementTree[ET.Element], target: Path) -> None:
    """Write an XML document whole or not at all: an existing target (the source itself, in place) is replaced
    only by a complete file (UTF-8, with an XML declaration)."""
    temporary = temporary_beside(target, ".tmp")
    try:
        tree.write(temporary, encoding="utf-8", xml_declaration=True)
        os.replace(temporary, target)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _direction_text(degrees: float, unit: str, convention: str) -> str:
    """A direction our writer gave (decimal degrees, counter-clockwise from east) in the file's unit and convention."""
    angle = math.radians(degrees)
    if convention == "north-cw":
        angle = math.pi / 2 - angle
    angle %= 2 * math.pi
    if unit == "radians":
        return _text(angle)
    if unit == "grads":
        return _text(angle * 200.0 / math.pi)
    value = math.degrees(angle)
    if unit != "decimal dd.mm.ss":
        return _text(value)
    seconds = round(value * 3600.0, 6)  # dd.mmss: degrees, then minutes and seconds as digits
    whole, rest = divmod(seconds, 3600.0)
    minutes, seconds = divmod(rest, 60.0)
    return _text(whole + minutes / 100.0 + seconds / 10000.0)


def _written(chain: Chain, start_station: float, scale: float, unit: str, namespace: str, direction_unit: str,
             convention: str) -> list[ET.Element]:  # fmt: skip
    """The CoordGeom children of a chain, in the file's namespace, unit and direction convention."""
    lines = _coord_geom(chain, start_station, scale, unit)
    lines[0] = f'<CoordGeom xmlns="{namespace}">' if namespace else "<CoordGeom>"
    made = list(ET.fromstring("\n".join(lines)))
    for element in made:
        for name in DIRECTIONS:
            if name in element.attrib:
                element.set(name, _direction_text(float(element.attrib[name]), direction_unit, convention))
    return made


def rewrite_landxml_g2(source: Path, target: Path, max_deviation: float, *, shape: str | None = None) -> DocumentReport:
    """Rewrite a LandXML file with every alignment of lines and arcs made G2 within ``max_deviation`` (see the module docstring).

    Args:
        source: the LandXML file.
        target: the file to write (may be ``source``).
        max_deviation: the largest distance between an alignment and its G2 alignment, in the file's linear unit.
        shape: the spiral shape (``"near-linear"``, the default, or ``"walton-meek"``).

    Returns:
        The report: per alignment its measured deviation, joints changed and splits, or why it was kept.

    Raises:
        ValueError: not LandXML, an alignment the reader refuses (named), or a bad bound.
        OSError: the file could not be read or written.
    """
    source, target = Path(source), Path(target)
    if not (isinstance(max_deviation, (int, float)) and math.isfinite(max_deviation) and max_deviation > 0.0):
        raise ValueError(f"max_deviation must be a positive length; got {max_deviation!r}")
    shape = shape or "near-linear"
    try:
        tree = parse_keeping(source)
    except ET.ParseError as error:
        raise ValueError(f"{source.name}: not an XML document: {error}") from None
    root = tree.getroot()
    if root is None:
        raise ValueError(f"{source.name}: an empty XML document")
    try:
        read = read_landxml(source, shape=shape)
        reader = _Reader(root, shape)
    except ValueError as error:
        raise ValueError(f"{source.name}: {error}") from None
    elements = [a for group in _children(root, "Alignments") for a in _children(group, "Alignment")]
    scale = 1.0 / reader.scale  # our unit → the file's numbers (US survey feet are read as feet)
    unit = "US survey ft" if reader.scale != 1.0 else reader.units
    reports, notes = [], []
    for number, (alignment, element) in enumerate(zip(read, elements), 1):
        name = alignment.name or f"alignment {number}"
        segments = [s for chain in alignment.chains for s in chain]
        joints = len(segments) - 1
        if not all(isinstance(s, (Line, Arc)) for s in segments):
            why = ("G2 already (its spirals between the lines and arcs)" if len(alignment.chains) == 1
                   else f"it has spirals and is not G2 at {len(alignment.chains) - 1} joint(s) ({alignment.breaks[0]}); make_g2 takes lines and arcs")  # fmt: skip
            reports.append(PathReport(name, joints, kept=why, g2=len(alignment.chains) == 1))
            continue
        try:
            result = make_g2(segments, max_deviation, closed=False, shape=shape, units=alignment.units)
        except ValueError as error:
            reports.append(PathReport(name, joints, kept=f"make_g2 refuses it: {error}"))
            continue
        changed = sum(j.kind not in ("g2", "split") for j in result.joints)
        if not changed and not result.splits:
            reports.append(PathReport(name, joints, kept="G2 already", g2=True))
            continue
        pieces, _ = straight_ends([s for c in result.chains for s in c])
        chain = Chain(pieces, tolerance=1e-6, units=alignment.units)
        geometry = _child(element, "CoordGeom")
        assert geometry is not None  # the reader refuses an alignment without one
        namespace = geometry.tag[1:].split("}")[0] if geometry.tag.startswith("{") else ""
        try:
            made = _written(chain, alignment.start_station, scale, unit, namespace, reader.direction_unit, alignment.directions)
        except ValueError as error:
            reports.append(PathReport(name, joints, kept=f"its G2 chain cannot be written as LandXML: {error}"))
            continue
        kept = [e for e in geometry if not (isinstance(e.tag, str) and _local(e.tag) in GEOMETRY)]
        for e in list(geometry):
            geometry.remove(e)
        geometry.extend(made + kept)
        geometry.text, geometry.tail = geometry.text or "\n", geometry.tail
        if "length" in element.attrib:
            element.set("length", _text(chain.length * scale))
        shift = chain.length - sum(float(c.length) for c in alignment.chains)
        if alignment.profile is not None or _child(element, "Profile") is not None:
            notes.append(f"{name}: profile kept as it was; the alignment's end station moved by {shift * scale:.3g} {unit}")
        reports.append(PathReport(name, joints, changed, float(result.deviation), len(result.splits), pieces=len(chain), g2=True))
    write_tree(tree, target)
    return DocumentReport(source.name, target.name, "LandXML file", unit, float(max_deviation), tuple(reports), tuple(notes))
