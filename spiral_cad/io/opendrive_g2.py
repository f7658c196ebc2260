"""An OpenDRIVE file rewritten G2 in place: one file in, the same file out (``rewrite_opendrive_g2``).

Every road whose planView is lines, arcs and ``paramPoly3`` geometries and is not G2 at every joint is
made G2 by ``spiral_cad.design.make_g2`` within the bound (spirals inserted at every joint, the arcs shifted
about their centres; a ``paramPoly3`` whose joints are G2 already is kept), and its planView's
``<geometry>`` records are replaced by the G2 reference line's, as ``spiral_cad.io.opendrive`` writes
them: ``<line/>``, ``<arc curvature>`` and each Bézier spiral exactly as a ``<paramPoly3
pRange="normalized">`` in the frame of its start (one home: ``plan_records``). Their ``s`` run from the
road's first ``s`` and the road's ``length`` is the new one.

The road's ends are fixed: its first and last point and heading stay as they were, so its links and
junction connections stay valid. make_g2 keeps a road's first and last line where they are (it shortens
them at their inner ends); an arc at an end is shifted about its centre, which would move the end across
the road, so it is turned about the end point instead (``spiral_cad.io.opendrive_ends``: the arc through
the end, along its heading, a little tighter, and its transition solved again; the report names the new
radius). Where that finds no transition the road is kept as it is and the report says by how much its end
would move.

Everything placed along a road by ``s`` outside its planView (lane sections, lane offsets, elevation,
superelevation and shape records, objects, signals and their references, road types) is carried to the
new reference line: each ``s`` to the station of the point of the new line nearest the old point at that
``s`` (``spiral_cad.io.opendrive_remap``), the cubic records rescaled to their new intervals; the report
gives each road's new length and the largest move. Everything else is kept as it was: the header
(``geoReference``, offsets, bounding box), junctions, controllers, lanes, the other roads, element order,
comments and attributes this module does not know (the XML tree is edited, not regenerated).

A road that is G2 already, a road with clothoid (``spiral``) or ``poly3`` geometries (make_g2 takes
lines, arcs and G2 Bézier pieces), one make_g2 refuses, one whose end would move and one whose measured
deviation would pass the bound are kept as they are, and the report names each with its reason and
numbers. The bound is in metres (OpenDRIVE's unit).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from ..continuity.joints import Continuity, classify_pieces, model_size
from ..core.chain import Chain
from ..core.segments import Segment
from ..design import make_g2
from .document_report import DocumentReport, PathReport
from .g2_ends import straight_ends
from .landxml_g2 import parse_keeping, write_tree
from .opendrive import _plan_view, plan_records
from .opendrive_ends import fixed_ends
from .opendrive_read import Road, read_network
from .opendrive_remap import new_stations, remap_road

__all__ = ["END_ANGLE", "END_GAP", "rewrite_opendrive_g2"]

#: A road end counts as kept when it moves at most this far (m) …
END_GAP = 1e-9
#: … and its heading turns at most this much (rad; a tenth of ``check_opendrive``'s angle tolerance).
END_ANGLE = 1e-8
#: The file's joints are judged G2 with ``check_opendrive``'s default tolerances: gap (m), angle (rad), relative curvature jump.
GAP_TOL, ANGLE_TOL, CURVATURE_TOL = 1e-7, 1e-7, 1e-6
#: Samples per piece where the deviation between the old and the new reference line is measured (both ways).
SAMPLES = 65
#: The planView kinds make_g2 takes (a paramPoly3 as the Bézier cubic it is).
TAKEN = ("line", "arc", "paramPoly3")


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _breaks(road: Road) -> list[str]:
    """The road's planView joints that are not G2, in words (index and what jumps)."""
    frames = road.plan.frames[:, :2, :]
    size = max(model_size(road.plan.frames[:, :, :3].reshape(-1, 3)), 1.0)
    report = classify_pieces(
        [("road", frames.tolist(), False, road.id)],
        size,
        gap_tol=GAP_TOL,
        angle_tol=ANGLE_TOL,
        curvature_tol=CURVATURE_TOL,
        element="geometry",
        units="m",
    )
    out = []
    for joint in report.wires[0].joints:
        if joint.level < Continuity.G2:
            out.append(f"joint {joint.index} ({road.plan.kinds[joint.index]} → {road.plan.kinds[joint.index + 1]}): "
                       f"{joint.level.name}, gap {joint.gap:.3g} m, angle {joint.angle:.3g} rad, curvature jump {joint.curvature_jump:.3g} 1/m")  # fmt: skip
    return out


def _samples(segments: list[Segment] | Chain) -> np.ndarray:
    u = np.linspace(0.0, 1.0, SAMPLES)
    return np.vstack([segment.point(u)[:, :2] for segment in segments])


def _deviation(old: list[Segment], parts: list[Chain]) -> float:
    """The largest distance between the old and the new reference line, measured both ways by sampling each and
    finding exact feet on the other (lines, arcs, spirals)."""
    _, there = new_stations(parts, _samples(old))
    singles = [Chain([segment], tolerance=1e-6, units="m") for segment in old]  # the old line need not be G2: one chain a piece
    _, back = new_stations(singles, np.vstack([_samples(part) for part in parts]))
    return float(max(there.max(), back.max()))


def _planview(parts: list[Chain], first_s: float) -> ET.Element:
    """The new ``<planView>`` (only its geometries are used) of the parts, their ``s`` from ``first_s``."""
    plans = [plan_records(part, 1.0) for part in parts]
    offsets = first_s + np.concatenate([[0.0], np.cumsum([p["total"] for p in plans])])
    merged: dict[str, Any] = {key: np.concatenate([p[key] for p in plans]) for key in ("kind", "x", "y", "hdg", "length", "curvature")}
    merged["s"] = np.concatenate([p["s"] + o for p, o in zip(plans, offsets)])
    merged["poly"] = np.vstack([p["poly"] for p in plans])
    return ET.fromstring("\n".join(_plan_view(merged)))


def _replace_geometries(plan_view: ET.Element, made: ET.Element) -> int:
    """Put the new geometries where the old ones were (other children of the planView kept); how many
    ``userData`` or other children of the old geometries went with them."""
    old = [e for e in plan_view if _local(e.tag) == "geometry"]
    lost = sum(1 for g in old for child in g if _local(child.tag) not in ("line", "arc", "spiral", "paramPoly3", "poly3"))
    at = list(plan_view).index(old[0])
    tail, last_tail = old[0].tail, old[-1].tail
    inner = old[0].text, (old[0][0].tail if len(old[0]) else None)  # the file's indentation inside a geometry
    namespace = old[0].tag[: -len("geometry")]
    for e in old:
        plan_view.remove(e)
    new = list(made)
    for k, e in enumerate(new):
        for sub in e.iter():
            sub.tag = namespace + sub.tag
        e.tail = last_tail if k == len(new) - 1 else tail
        if len(e):
            e.text, e[-1].tail = inner
        plan_view.insert(at + k, e)
    return lost


def _road_g2(road: Road, element: ET.Element, bound: float, shape: str, notes: list[str]) -> PathReport:
    """Make one road G2 in place (its element edited), or say why it is kept."""
    name = f"road {road.id}" + (f" ({road.name})" if road.name else "")
    kinds = road.plan.kinds
    joints = len(kinds) - 1
    if joints == 0:
        return PathReport(name, 0, kept="one geometry: no joint to make G2", g2=True)
    breaks = _breaks(road)
    others = sorted(set(kinds) - set(TAKEN))
    if not breaks:
        return PathReport(name, joints, kept="G2 already" + (f" (its {', '.join(others)} geometries included)" if others else ""), g2=True)
    if others:
        return PathReport(name, joints, kept=f"it has {', '.join(others)} geometries, which make_g2 does not take, and is not G2 at "
                                             f"{len(breaks)} joint(s) ({breaks[0]})")  # fmt: skip
    segments: list[Segment] = []
    for g in road.geometries:
        try:
            with np.errstate(all="ignore"):
                segment = g.segment()
        except (ValueError, ArithmeticError) as error:
            return PathReport(name, joints, kept=f"planView geometry {g.index} <{g.kind}> has no exact segment ({error})")
        assert segment is not None  # lines, arcs and paramPoly3 have one
        segments.append(segment)
    try:
        result = make_g2(segments, bound, closed=False, shape=shape, units="m")
    except ValueError as error:
        return PathReport(name, joints, kept=f"make_g2 refuses it: {error}")
    changed = sum(j.kind not in ("g2", "split") for j in result.joints)
    if not changed and not result.splits:
        return PathReport(name, joints, kept="G2 already (make_g2 changed no joint)", g2=True)
    parts = [Chain(straight_ends(list(chain))[0], tolerance=1e-6, units="m") for chain in result.chains]
    for k, (a, b) in enumerate(zip(parts, parts[1:])):
        gap = float(np.hypot(*(np.asarray(b.start[:2]) - np.asarray(a.end[:2]))))
        if gap > END_GAP:
            return PathReport(name, joints, kept=f"make_g2 splits it ({result.describe_splits()}) and its parts {k} and {k + 1} are "
                                                 f"{gap:.3g} m apart")  # fmt: skip
    ends_fixed: list[str] = []
    if len(parts) == 1:
        fixed, ends_fixed = fixed_ends(segments, list(parts[0]), shape)
        if ends_fixed:
            try:
                parts = [Chain(fixed, tolerance=1e-6, units="m")]
            except ValueError as error:  # a joint the splice did not make G2: the ends stay as make_g2 left them (named below)
                ends_fixed = [f"no end arc turned ({error})"]
    old_start, old_end = segments[0].ends[0], segments[-1].ends[1]
    new_start, new_end = parts[0].segments[0].ends[0], parts[-1].segments[-1].ends[1]
    for which, was, now in (("start", old_start, new_start), ("end", old_end, new_end)):
        moved = math.hypot(now[0] - was[0], now[1] - was[1])
        turned = abs(math.atan2(was[2] * now[3] - was[3] * now[2], was[2] * now[2] + was[3] * now[3]))
        if moved > END_GAP or turned > END_ANGLE:
            piece = 0 if which == "start" else len(kinds) - 1
            return PathReport(name, joints, kept=f"its {which} would move {moved:.3g} m and turn {turned:.3g} rad (make_g2 shifts the "
                                                 f"{kinds[piece]} it {which}s on: geometry {piece}); the road's ends are kept fixed "
                                                 "for its links")  # fmt: skip
    deviation = max(_deviation(segments, parts), float(result.deviation))
    if deviation > bound * (1.0 + 1e-9):
        return PathReport(
            name, joints, kept=f"its G2 reference line measures {deviation:.3g} m from the file's, beyond the bound {bound:g} m"
        )
    plan_view = next(e for e in element if _local(e.tag) == "planView")
    first_s = float(road.plan.head["s"][0])
    lost = _replace_geometries(plan_view, _planview(parts, first_s))
    new_length = first_s + sum(p.length for p in parts)
    remapped = remap_road(element, segments, road.plan.head["s"].tolist(), road.length, parts)
    element.set("length", repr(float(new_length)))
    notes.append(remapped.note(name, road.length, new_length))
    notes += [f"{name}: {done}" for done in ends_fixed]
    if lost:
        notes.append(f"{name}: {lost} child element(s) of its old planView geometries (userData …) went with them")
    curvature = [(w, a[4], b[4]) for w, a, b in (("start", old_start, new_start), ("end", old_end, new_end)) if abs(a[4] - b[4]) > 1e-12]
    notes += [f"{name}: curvature at its {w} {a:.6g} → {b:.6g} 1/m (point and heading kept)" for w, a, b in curvature]
    pieces = sum(len(p) for p in parts)
    return PathReport(name, joints, changed, deviation, len(result.splits), pieces=pieces, g2=True)


def rewrite_opendrive_g2(source: Path, target: Path, max_deviation: float, *, shape: str | None = None) -> DocumentReport:
    """Rewrite an OpenDRIVE file with every road of lines and arcs made G2 within ``max_deviation`` (see the module docstring).

    Args:
        source: the OpenDRIVE file.
        target: the file to write (may be ``source``).
        max_deviation: the largest distance between a road's reference line and its G2 one, in metres.
        shape: the spiral shape (``"near-linear"``, the default, or ``"walton-meek"``).

    Returns:
        The report: per road its measured deviation, joints changed and splits, or why it was kept; the
        notes give each rewritten road's new length and how its ``s`` positions moved.

    Raises:
        ValueError: not OpenDRIVE, a road the reader refuses (named with its numbers), or a bad bound.
        OSError: the file could not be read or written.
    """
    source, target = Path(source), Path(target)
    if isinstance(max_deviation, bool) or not (isinstance(max_deviation, (int, float)) and math.isfinite(max_deviation)
                                               and max_deviation > 0.0):  # fmt: skip
        raise ValueError(f"max_deviation must be a positive length (m); got {max_deviation!r}")
    network = read_network(source)  # names the file, the road and the numbers it refuses
    try:
        tree = parse_keeping(source)
    except ET.ParseError as error:
        raise ValueError(f"{source.name}: not an XML document: {error}") from None
    root = tree.getroot()
    elements = [e for e in root if _local(e.tag) == "road"]
    if len(elements) != len(network.roads):
        raise ValueError(f"{source.name}: {len(elements)} <road> elements under the root, {len(network.roads)} roads read")
    reports: list[PathReport] = []
    notes: list[str] = []
    for road, element in zip(network.roads, elements):
        reports.append(_road_g2(road, element, float(max_deviation), shape or "near-linear", notes))
    write_tree(tree, target)
    return DocumentReport(source.name, target.name, "OpenDRIVE file", "m", float(max_deviation), tuple(reports), tuple(notes))
