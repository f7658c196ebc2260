"""A DXF drawing rewritten G2 in place: one drawing in, the same drawing out (``rewrite_dxf_g2``).

The drawing is opened with ezdxf (``ezdxf.recover`` where the plain reader refuses it, as for LibreCAD's
library drawings; the report says so). Its model space's ``LINE``, ``ARC``, ``CIRCLE``, ``LWPOLYLINE``
and ``POLYLINE`` entities are chained into paths as ``spiral_cad.io.dxf_read`` chains them, and every
path is made G2 by ``spiral_cad.design.make_g2`` within the bound, its arcs kept true arcs (its runs of lines
drawn as fewer lines within ``FEWER_SHARE`` of the bound first: a curve plotted as micrometre chords). The
entities of a path made G2 are deleted and its G2 path written in their place: ``LINE``, ``ARC`` and one
degree-3 ``SPLINE`` per spiral (its Bézier control points exact), on the layer and with the colour,
linetype, lineweight and linetype scale of the path's first entity. A path that is G2 already (a lone
circle) and a path ``make_g2`` refuses are kept as they are, and the report says why.

Every other entity is kept untouched: text, dimensions, hatches, points, ``SPLINE`` and ``ELLIPSE``
(counted in the notes: not made G2 here), and block references. A block reference (``INSERT``) whose
block holds lines or arcs is exploded first (ezdxf's ``explode``, through its virtual entities), so its
paths are made G2 too; the report names the blocks. The header (``$INSUNITS`` and the rest), the
layers, linetypes, styles and blocks stay as they were (ezdxf's ``audit`` is not run on them: an input's
faults are kept, and named in the report; one ezdxf's writer cannot write is fixed by its audit first,
and named). The result is written beside the target, read back by ezdxf without recover mode and audited;
an issue the input did not have, or an entity of the model space missing, refuses the write. An R12
drawing holding paths is written as R2000 (R12 has no ``SPLINE`` for the spirals).

The bound is in the drawing's unit (``$INSUNITS``); ``units=`` states it in another unit. A unitless
drawing takes the bound in drawing units (``units=`` then names them), and the report says so.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from ..core.fit import douglas_peucker
from ..core.segments import Line
from ..core.spiral import BezierSpiral
from ..core.units import MM_PER_UNIT, length_unit
from ..design import make_g2
from .curve_biarcs import BIARC_SHARE
from .document_report import DocumentReport, PathReport
from .dxf import _add
from .dxf_curves import CURVES, curve_parts
from .dxf_read import DXF_UNITS, JOIN_TOLERANCE, READ, _chains, _entity_parts, _segments, drop_unstated_units
from .staging import temporary_beside

__all__ = ["ATTRIBUTES", "open_drawing", "rewrite_dxf_g2"]

#: The graphic attributes a G2 path takes from its path's first entity (besides the layer).
ATTRIBUTES = ("color", "true_color", "linetype", "lineweight", "ltscale", "transparency", "invisible")
#: A run of lines is drawn as fewer lines within this share of the bound before it is made G2 (a curve a program
#: plotted as chords a few micrometres long, as KiCad does: spirals at its micrometre corners would be so short that
#: float64's rounding of their control points shows in their curvature).
FEWER_SHARE = 0.2
#: The parts of a split path must meet within this share of the bound (else the path is kept whole).
MEET = 1e-6
#: Rounds of exploding block references that hold paths (blocks inside blocks).
EXPLODE_DEPTH = 8


def open_drawing(source: Path) -> tuple[Any, str]:
    """The drawing, and a note when only ezdxf's recover mode reads it ("" when the plain reader does).

    Raises:
        ValueError: a missing file or a folder, or a file neither of ezdxf's readers reads (both reasons).
    """
    import ezdxf
    from ezdxf import recover

    if not source.is_file():
        raise ValueError(f"{source.name}: the DXF file is {'a folder' if source.is_dir() else 'missing'}")
    try:
        doc, note = ezdxf.readfile(source), ""
    except OSError as error:  # ezdxf says "not a DXF file" with an OSError
        raise ValueError(f"{source.name}: not a DXF file ezdxf can read ({error})") from None
    except Exception as plain:  # noqa: BLE001 - any fault of the plain reader (a DXFError, a KeyError on a bad handle): recover
        try:
            doc, auditor = recover.readfile(source)
        except Exception as error:  # noqa: BLE001 - the recover reader failing too: named, never a crash
            raise ValueError(f"{source.name}: not a DXF file ezdxf can read ({plain or type(plain).__name__}; recover: "
                             f"{error or type(error).__name__})") from None  # fmt: skip
        note = f"read with ezdxf's recover mode ({plain or type(plain).__name__}; {len(auditor.fixes)} fix(es))"
    drop_unstated_units(doc, source)
    return doc, note


def _as_r2000(doc, issues: set[tuple[int, str]], notes: list[str]) -> Any:
    """An R12 drawing holding paths as the same drawing in DXF R2000 (R12 has no SPLINE for the spirals): its
    tables, blocks, model and paper space imported by ezdxf's ``Importer``, the entities' XDATA and their
    application names, the header variables copied (a unit it does not state is not stated). The drawing as it
    is (its paths then kept, named) when not every entity comes along, a block entity has XDATA, or ezdxf's
    audit finds an issue in the R2000 drawing that the drawing has not (``issues``)."""
    import ezdxf
    from ezdxf.addons import Importer

    if doc.dxfversion >= "AC1015" or not any(entity.dxftype() in READ for entity in doc.modelspace()):
        return doc
    if any(entity.xdata for block in doc.blocks if not block.is_any_layout for entity in block):
        return doc
    new = ezdxf.new("R2000", setup=False)
    importer = Importer(doc, new)
    importer.import_tables()
    importer.import_blocks([block.name for block in doc.blocks if not block.is_any_layout])
    importer.import_modelspace()
    importer.import_entities(doc.paperspace(), new.paperspace())
    importer.finalize()
    for space, into in ((doc.modelspace(), new.modelspace()), (doc.paperspace(), new.paperspace())):
        if [e.dxftype() for e in space] != [e.dxftype() for e in into]:
            return doc
        for entity, imported in zip(space, into):  # the Importer leaves XDATA behind
            for name, tags in entity.xdata.data.items() if entity.xdata else ():
                if name not in new.appids:
                    new.appids.new(name)
                imported.set_xdata(name, list(tags))
    for name in doc.header.varnames():
        try:
            new.header[name] = doc.header[name]
        except (ezdxf.DXFError, ValueError, TypeError):  # a variable R2000 does not have ($BLIPMODE …)
            pass
    for name in ("$INSUNITS", "$MEASUREMENT"):
        if name not in doc.header and name in new.header:
            del new.header[name]
    handle, temporary = tempfile.mkstemp(suffix=".dxf")
    os.close(handle)
    try:
        new.saveas(temporary)
        contents, found = _read_back(temporary)
    finally:
        os.unlink(temporary)
    if contents != _contents(doc.modelspace()) or _issue_kinds(found) - issues:
        return doc
    notes.append("a DXF R12 drawing (R12 holds no SPLINE for the spirals): written as DXF R2000, every entity, "
                 "table, block, XDATA and header variable taken along")  # fmt: skip
    return new


def _holds_paths(block, blocks, depth: int = 0) -> bool:
    """Whether a block holds lines or arcs (itself, or through the blocks it references)."""
    for entity in block:
        kind = entity.dxftype()
        if kind in READ:
            return True
        if kind == "INSERT" and depth < EXPLODE_DEPTH:
            inner = blocks.get(entity.dxf.name)
            if inner is not None and _holds_paths(inner, blocks, depth + 1):
                return True
    return False


def _explode(doc, msp) -> list[str]:
    """Explode every block reference of the model space whose block holds paths; notes naming the blocks."""
    exploded: Counter[str] = Counter()
    failed: list[str] = []
    for _ in range(EXPLODE_DEPTH):
        todo = [e for e in msp.query("INSERT") if (b := doc.blocks.get(e.dxf.name)) is not None and _holds_paths(b, doc.blocks)]
        if not todo:
            break
        for insert in todo:
            name = insert.dxf.name
            try:
                insert.explode()
                exploded[name] += 1
            except Exception as error:  # noqa: BLE001 - ezdxf raises several kinds; the reference is then kept
                failed.append(f"INSERT {insert.dxf.handle} of block {name!r} kept: ezdxf cannot explode it ({error})")
    notes = [
        f"exploded {n} INSERT(s) of block {name!r} (its lines and arcs made G2 in the model space)" for name, n in sorted(exploded.items())
    ]
    return notes + failed


def _bound(doc, max_deviation: float, units: str | None, label: str) -> tuple[float, str, str, list[str]]:
    """The bound in drawing units, the report's unit name, the unit handed to make_g2, and notes."""
    if not (isinstance(max_deviation, (int, float)) and math.isfinite(max_deviation) and max_deviation > 0.0):
        raise ValueError(f"max_deviation must be a positive length; got {max_deviation!r}")
    stated = None if units is None else length_unit(units)
    code = int(doc.header.get("$INSUNITS", 0))
    if code == 0:
        if stated is None:
            note = "the drawing is unitless ($INSUNITS 0 or missing): max_deviation taken in drawing units"
            return float(max_deviation), "drawing units", "mm", [note]
        return float(max_deviation), stated, stated, [f"the drawing is unitless: its units taken as {stated}, as stated"]
    if code not in DXF_UNITS:
        raise ValueError(f"{label}: $INSUNITS {code} is not a unit read here ({', '.join(f'{k} {u}' for k, u in DXF_UNITS.items())})")
    drawing = DXF_UNITS[code]
    if stated is None or stated == drawing:
        return float(max_deviation), drawing, drawing, []
    bound = float(max_deviation) * MM_PER_UNIT[stated] / MM_PER_UNIT[drawing]
    return bound, drawing, drawing, [f"max_deviation {max_deviation:g} {stated} is {bound:.6g} {drawing}, the drawing's unit"]


def _audit(path: Path, recovered: bool):
    """ezdxf's auditor of a freshly read file (the file itself is not changed)."""
    import ezdxf
    from ezdxf import recover

    if recovered:
        return recover.readfile(path)[1]
    return ezdxf.readfile(path).audit()


def _issues(path: Path, recovered: bool) -> tuple[set[tuple[int, str]], int, str]:
    """What ezdxf's audit fixes or finds in a file: its kinds (``_issue_kinds``), how many, the first one's message."""
    auditor = _audit(path, recovered)
    items = (*auditor.errors, *auditor.fixes)
    return _issue_kinds(items), len(items), next((item.message for item in items), "")


def _issue_kinds(items) -> set[tuple[int, str]]:
    """Audit issues as (code, message without the entities it names): an issue of a kind the input has, on an
    entity written in a path's place (a layer name ezdxf does not accept, on the new spline), is not new."""
    return {_issue_kind(item) for item in items}


def _issue_kind(item) -> tuple[int, str]:
    return int(item.code), _ENTITY.sub("", item.message)


#: An entity named in an audit message: ``LINE(#35)``.
_ENTITY = re.compile(r"\s*\b[A-Z_0-9]+\(#[0-9A-Fa-f]+\)")


def _unique_handles(doc, notes: list[str]) -> None:
    """Give a new handle to each model space entity whose handle another entity has (the database keeps one of
    them: ezdxf would write only that one, or none)."""
    renamed = 0
    for entity in doc.modelspace():
        if doc.entitydb.get(entity.dxf.handle) is not entity:
            entity.update_handle(doc.entitydb.next_handle())
            doc.entitydb.add(entity)
            renamed += 1
    if renamed:
        notes.append(f"{renamed} entit{'y' if renamed == 1 else 'ies'} whose handle another entity has given a new handle")


def _contents(msp) -> Counter[tuple[str, str]]:
    return Counter((entity.dxftype(), str(entity.dxf.layer)) for entity in msp)


def _read_back(path: str) -> tuple[Counter[tuple[str, str]], list]:
    """A written drawing as ezdxf reads it without recover mode: what its model space holds (``_contents``), and
    what ezdxf's audit then finds in it."""
    import ezdxf

    written = ezdxf.readfile(path)
    contents = _contents(written.modelspace())
    auditor = written.audit()
    return contents, [*auditor.errors, *auditor.fixes]


def _save(doc, target: Path, issues: set[tuple[int, str]], label: str, notes: list[str]) -> None:
    """Write the drawing beside ``target``, check that ezdxf reads it without recover mode, that it holds every
    entity of the model space and that its audit finds nothing the input did not have, then move it onto
    ``target`` (else nothing is written). A drawing ezdxf cannot write as read (a dictionary entry pointing at
    nothing) is written after ezdxf's audit has fixed it, and the report says so."""

    _unique_handles(doc, notes)
    expected = _contents(doc.modelspace())
    temporary = temporary_beside(target, ".dxf")
    try:
        try:
            doc.saveas(temporary)
        except Exception as error:  # noqa: BLE001 - any fault ezdxf's writer meets is the input's; its audit may fix it
            fixed = doc.audit()
            repairs = [*fixed.fixes, *fixed.errors]
            if not repairs:
                raise ValueError(f"{label}: ezdxf cannot write the drawing ({type(error).__name__}: {error}); nothing written") from None
            notes.append(f"ezdxf cannot write the drawing as read ({type(error).__name__}: {error}); written after its audit "
                         f"fixed {len(repairs)} issue(s) ({repairs[0].message})")  # fmt: skip
            issues = issues | _issue_kinds(repairs)
            expected = _contents(doc.modelspace())
            doc.saveas(temporary)
        contents, items = _read_back(temporary)
        lost = expected - contents
        if lost:
            what = ", ".join(f"{n} {kind} on layer {layer}" for (kind, layer), n in sorted(lost.items()))
            why = " (a DXF R12 drawing holds no SPLINE)" if "SPLINE" in what and doc.dxfversion < "AC1015" else ""
            raise ValueError(f"{label}: ezdxf would not write {what}{why}; nothing written")
        new = [item for item in items if _issue_kind(item) not in issues]
        if new:
            raise ValueError(f"{label}: ezdxf's audit finds {len(new)} new issue(s) in the result ({new[0].message}); nothing written")
        os.replace(temporary, target)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _attributes(entity) -> dict:
    return {name: entity.dxf.get(name) for name in ATTRIBUTES if entity.dxf.hasattr(name)}


def rewrite_dxf_g2(
    source: Path, target: Path, max_deviation: float, *, units: str | None = None, shape: str | None = None
) -> DocumentReport:
    """Rewrite a DXF drawing with every path of lines and arcs made G2 within ``max_deviation`` (see the module docstring).

    Args:
        source: the drawing (.dxf).
        target: the file to write (may be ``source``).
        max_deviation: the largest distance between a path and its G2 path, in the drawing's unit (or ``units``).
        units: the unit of ``max_deviation`` (default: the drawing's ``$INSUNITS``); for a unitless drawing, the
            unit its numbers are in.
        shape: the spiral shape (``"near-linear"``, the default, or ``"walton-meek"``).

    Returns:
        The report: per path its measured deviation, joints changed and splits, or why it was kept.

    Raises:
        ValueError: not a DXF file ezdxf reads, a bad bound or unit, an ``$INSUNITS`` not read here, or a result
            ezdxf's audit finds errors in (nothing is written then).
        OSError: the file could not be read or written.
    """
    source, target = Path(source), Path(target)
    label = source.name
    doc, recovered = open_drawing(source)
    bound, unit_name, g2_units, notes = _bound(doc, max_deviation, units, label)
    if recovered:
        notes.insert(0, f"{recovered}; written as a plain DXF")
    issues, count, first = _issues(source, bool(recovered))
    doc = _as_r2000(doc, issues, notes)
    msp = doc.modelspace()
    notes += _explode(doc, msp)
    pieces: list[tuple[list[tuple], str]] = []
    owners: list[Any] = []
    foreign: list[np.ndarray] = []  # the ends of the curves kept as they are (splines, ellipses): paths stay joined to them
    kept: Counter[str] = Counter()
    curved: set[int] = set()  # the pieces that are biarcs along a SPLINE or ELLIPSE
    alone = 0  # of them, those that make a path on their own (kept as drawn)
    for entity in msp:
        kind = entity.dxftype()
        if kind in CURVES:
            try:
                along = curve_parts(entity, kind, BIARC_SHARE * bound)
            except ValueError as error:
                along = None
                notes.append(f"{kind} {entity.dxf.handle} kept as is: {error}")
            if along:
                curved.add(len(pieces))
                pieces.append((along, str(entity.dxf.handle)))
                owners.append(entity)
                continue
        if kind not in READ or (kind == "POLYLINE" and not (entity.is_2d_polyline or entity.is_3d_polyline)):
            kept[kind] += 1
            foreign += _curve_ends(entity, kind)
            continue
        try:
            parts = _entity_parts(entity, kind)
        except ValueError as error:
            kept[kind] += 1
            notes.append(f"{kind} {entity.dxf.handle} kept as is: {error}")
            continue
        if parts:
            pieces.append((parts, str(entity.dxf.handle)))
            owners.append(entity)
    reports: list[PathReport] = []
    if pieces:
        ends = np.array([p for parts, _ in pieces for part in (parts[0], parts[-1]) for p in (part[1], part[2])])
        size = float(np.linalg.norm(ends.max(axis=0) - ends.min(axis=0))) or 1.0
        from scipy.spatial import cKDTree

        tolerance = JOIN_TOLERANCE * size
        own = [point for parts, _ in pieces for point in (parts[0][1], parts[-1][2])]  # 2k, 2k + 1: piece k
        tree = cKDTree(np.array(own + foreign))  # then the ends of the curves kept as they are
        for number, (order, closed) in enumerate(_chains(pieces, tolerance), 1):
            touched = _touched(pieces, order, tree, tolerance)
            if touched is not None:
                first = owners[order[0][0]]
                name = f"path {number} ({first.dxftype()} {first.dxf.handle}, layer {first.dxf.layer})"
                where = ", ".join(f"{v:.6g}" for v in touched[:2])
                reports.append(PathReport(name, sum(len(pieces[i][0]) for i, _ in order) - (0 if closed else 1),
                                          kept=f"another entity ends at its vertex ({where}): rounding it would detach that entity"))  # fmt: skip
                continue
            if len(order) == 1 and order[0][0] in curved:  # a SPLINE or ELLIPSE alone: smooth as drawn, kept exact
                curved.discard(order[0][0])
                alone += 1
                continue
            branches = _branch_ends(pieces, order, tree, tolerance) if not closed else []
            share = BIARC_SHARE if any(index in curved for index, _ in order) else 0.0
            reports.append(_path(msp, pieces, owners, order, closed, number, bound, g2_units, shape or "near-linear", notes, branches,
                                 share))  # fmt: skip
    if kept:
        notes.append("kept as is: " + ", ".join(f"{n} {kind}" for kind, n in sorted(kept.items())))
    if alone:
        notes.append(f"{alone} SPLINE or ELLIPSE entit{'y' if alone == 1 else 'ies'} meeting no other path kept as drawn")
    if curved:
        notes.append(f"{len(curved)} SPLINE or ELLIPSE entit{'y' if len(curved) == 1 else 'ies'} read as biarcs within "
                     f"{BIARC_SHARE:g} of the bound, their paths made G2 within the rest")  # fmt: skip
    for kind, why in (("SPLINE", "one cubic Bézier span, or out of the plane z = 0"), ("ELLIPSE", "out of the plane z = 0"),
                      ("HELIX", "a curve in space")):  # fmt: skip
        if kept[kind]:
            notes.append(f"{kept[kind]} {kind} entit{'y' if kept[kind] == 1 else 'ies'} not made G2 ({why})")
    if count:
        notes.append(f"ezdxf's audit finds {count} issue(s) in the input ({first}); kept as they were")
    _save(doc, target, issues, label, notes)
    return DocumentReport(label, target.name, "DXF drawing", unit_name, float(max_deviation) if units is None else bound,
                          tuple(reports), tuple(notes))  # fmt: skip


def _path(msp, pieces: list, owners: list, order: list[tuple[int, bool]], closed: bool, number: int, bound: float, units: str,
          shape: str, notes: list[str], branches: list[np.ndarray], share: float = 0.0) -> PathReport:  # fmt: skip
    """Make one chained path G2 and write it in place of its entities; its report. ``share`` of the bound is
    taken by biarcs along its curves already (``make_g2`` gets the rest; the deviation reported includes it)."""
    import ezdxf

    entities = [owners[index] for index, _ in order]
    first = entities[0]
    name = f"path {number} ({first.dxftype()} {first.dxf.handle}, layer {first.dxf.layer})"
    parts = [(part, reverse) for index, reverse in order for part in (reversed(pieces[index][0]) if reverse else pieces[index][0])]
    flat = all(p[1][2] == 0.0 and p[2][2] == 0.0 and (p[0] == "line" or abs(p[3][1][:2]).max() == 0.0) for p, _ in parts)
    segments = []
    for part, reverse in parts:
        (segment,) = _segments(part, 1.0, 2 if flat else 3)  # a line or an arc: one segment
        segments.append(segment.reversed() if reverse else segment)
    joints = len(segments) - (0 if closed else 1)
    if not joints:
        return PathReport(name, joints, kept="one entity, no joint", g2=True)
    fewer = _fewer_lines(segments, FEWER_SHARE * bound) if flat else segments
    if len(fewer) < len(segments):  # a curve plotted as chords a few micrometres long: its spirals float64 holds
        share += FEWER_SHARE
        segments = fewer
    try:
        result = make_g2(segments, bound * (1.0 - share), closed=closed, shape=shape, units=units)
    except ValueError as error:
        return PathReport(name, joints, kept=f"make_g2 refuses it: {error}")
    changed = sum(j.kind not in ("g2", "split") for j in result.joints)
    splits = len(result.splits)
    if not changed:
        why = f"split at every joint ({splits}): corners too sharp for a spiral pair within the bound" if splits else "G2 already"
        return PathReport(name, joints, splits=splits, kept=why, g2=not splits)
    gap = _split_gap(result.chains, closed)
    if gap > MEET * bound:
        return PathReport(name, joints, splits=splits, kept=f"make_g2 splits it at {splits} joint(s) and its parts no longer meet "
                          f"there (a gap of {gap:.3g}): kept whole rather than opened")  # fmt: skip
    for point in branches:  # an end where other entities meet stays where it was
        moved = min(float(np.linalg.norm(np.asarray(end)[:2] - point[:2])) for end in (result.chains[0].start, result.chains[-1].end))
        if moved > MEET * bound:
            where = ", ".join(f"{v:.6g}" for v in point[:2])
            return PathReport(name, joints, splits=splits, kept=f"its end at ({where}), where other entities meet it, would move by "
                              f"{moved:.3g}: kept rather than detached")  # fmt: skip
    if any(isinstance(s, BezierSpiral) for c in result.chains for s in c) and msp.doc.dxfversion < "AC1015":
        return PathReport(name, joints, splits=splits, kept="an R12 drawing holds no SPLINE for its spirals (save it as R2000 or later)")
    attributes = _attributes(first)
    layers = {e.dxf.layer for e in entities}
    if len(layers) > 1 or any(_attributes(e) != attributes for e in entities):
        notes.append(f"{name}: its entities differ in layer, colour or linetype; its G2 path takes the first's")
    added = []
    try:
        for piece in (s for chain in result.chains for s in chain):
            added.append(_add_on_layer(msp, piece, first.dxf.layer, attributes))
    except ezdxf.DXFError as error:
        for entity in added:
            msp.delete_entity(entity)
        return PathReport(name, joints, splits=splits, kept=f"ezdxf cannot write its G2 path ({error})")
    for entity in entities:
        msp.delete_entity(entity)
    return PathReport(name, joints, changed, float(result.deviation) + share * bound, splits, pieces=len(added), g2=True)


def _fewer_lines(segments: list, tolerance: float) -> list:
    """Each run of consecutive lines as fewer lines through some of its vertices (Douglas–Peucker), when every
    vertex left out lies within ``tolerance`` of its new line and projects inside it, in order: the two then lie
    within ``tolerance`` of each other both ways. A run where that fails stays as it is."""
    out: list = []
    run: list[Line] = []

    def close_run() -> None:
        if len(run) >= 2:
            points = np.array([run[0].start] + [line.end for line in run], dtype=float)
            keep = douglas_peucker(points, tolerance)
            if len(keep) < len(points) and all(_inside_in_order(points[i : j + 1]) for i, j in zip(keep[:-1], keep[1:])):
                out.extend(Line(tuple(points[i]), tuple(points[j])) for i, j in zip(keep[:-1], keep[1:]))
                run.clear()
                return
        out.extend(run)
        run.clear()

    for segment in segments:
        if isinstance(segment, Line):
            run.append(segment)
            continue
        close_run()
        out.append(segment)
    close_run()
    return out


def _inside_in_order(points: np.ndarray) -> bool:
    """Whether the inner points project onto the chord from the first to the last inside it, in order."""
    chord = points[-1] - points[0]
    t = (points - points[0]) @ chord / float(chord @ chord)
    return float(chord @ chord) > 0.0 and bool(np.all(np.diff(t) >= 0.0))


def _add_on_layer(msp, piece, layer: str, attributes: dict):
    """``_add`` on the path's own layer, also one whose name ezdxf reads but will not give a new entity
    (``MILL: 1``, as dxf2gcode names layers): the entity is made on layer 0 and moved there."""
    import ezdxf

    try:
        return _add(msp, piece, layer, attributes)
    except ezdxf.DXFValueError:
        entity = _add(msp, piece, "0", attributes)
        entity.dxf.unprotected_set("layer", layer)
        return entity


def _curve_ends(entity, kind: str) -> list[np.ndarray]:
    """The two ends of a curve entity that is kept as it is (none for other entities)."""
    try:
        if kind == "SPLINE":
            tool = entity.construction_tool()
            ends = [tool.point(0.0), tool.point(tool.max_t)]
        elif kind == "ELLIPSE":
            ends = [entity.start_point, entity.end_point]
        else:
            return []
    except Exception:  # noqa: BLE001 - a malformed curve has no ends to keep joined
        return []
    return [np.array(tuple(point), dtype=float) for point in ends]


def _touched(pieces: list, order: list[tuple[int, bool]], tree: Any, tolerance: float) -> np.ndarray | None:
    """A vertex inside one of the path's polylines where an end of another entity lies (None when there is none):
    the drawing branches there, which the chaining (by entity ends) does not see."""
    mine = {index for index, _ in order}
    for index, _ in order:
        parts = pieces[index][0]
        for part in parts[:-1]:  # each inner vertex: a part's end that is not the entity's end
            for j in tree.query_ball_point(part[2], tolerance):
                if j // 2 not in mine:
                    return np.asarray(part[2])
    return None


def _branch_ends(pieces: list, order: list[tuple[int, bool]], tree: Any, tolerance: float) -> list[np.ndarray]:
    """The ends of an open path where other entities end too (a branch point: the chaining stopped there)."""
    (head, head_reversed), (tail, tail_reversed) = order[0], order[-1]
    start = pieces[head][0][-1][2] if head_reversed else pieces[head][0][0][1]
    end = pieces[tail][0][0][1] if tail_reversed else pieces[tail][0][-1][2]
    return [np.asarray(point) for point in (start, end) if len(tree.query_ball_point(point, tolerance)) > 1]


def _split_gap(chains: list, closed: bool) -> float:
    """The largest distance between the end of one part of a split path and the start of the next."""
    pairs = list(zip(chains[:-1], chains[1:])) + ([(chains[-1], chains[0])] if closed and len(chains) > 1 else [])
    return max((float(np.linalg.norm(a.end - b.start)) for a, b in pairs), default=0.0)
