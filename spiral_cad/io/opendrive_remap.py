"""Road positions ``s`` carried from an old reference line to its G2 one (``rewrite_opendrive_g2``'s helper).

Where a road's planView is rewritten its length changes (a transition cuts a corner or a curve: millimetres
over hundreds of metres), and everything placed by ``s`` along it — lane sections, lane offsets, elevation,
superelevation and shape records, objects, signals, references, road types — would drift or lie past the new
end. ``new_stations`` maps each old ``s`` to the station of the nearest point of the new reference line to
the old point at ``s`` (``spiral_cad.core.fit_distances.chain_distances``: exact feet on lines, arcs and
spirals), kept in order (a map that never runs backwards), 0 to 0 and the old end to the new end.

``remap_road`` applies it to a road element's subtree outside its ``planView``: every ``s`` (and ``sStart``,
``sEnd``) attribute is moved (by less than ``STILL`` it keeps its text); the cubics of ``elevation``,
``superelevation`` and ``laneOffset`` records and of lanes' ``width`` and ``border`` records (a + b·ds + c·ds² + d·ds³ from their own start) are
rescaled to their new intervals, so each record gives the same value at its start and at its interval's end
as before. An ``sOffset`` inside a lane section (widths, borders, road marks, speeds …) is taken as the road
position it stands for (its nearest positioned ancestor's: a lane section's ``s``, a road mark's
``sOffset``, plus it), moved like the others, and written back from that ancestor's new position. A ``shape`` record's cross-section polynomial (in t) is moved with its ``s``, not stretched.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..core.chain import Chain
from ..core.fit_distances import chain_distances
from ..core.segments import Segment
from .decimals import shortest_decimal

__all__ = ["RemapReport", "new_stations", "old_points", "remap_road"]

#: A position that moves less than this (m) is kept as written (the feet's rounding on an unchanged stretch).
STILL = 1e-9
#: The attributes that hold a road position.
POSITIONS = ("s", "sStart", "sEnd")
#: Records holding a cubic in ds from their own ``s`` (their coefficients rescaled with their interval).
CUBICS = ("elevation", "superelevation", "laneOffset", "width", "border")


def old_points(segments: Sequence[Segment], starts: Sequence[float], s: NDArray) -> NDArray:
    """The points of the old reference line at road positions ``s`` (each in the geometry whose file ``s`` holds it)."""
    starts_array = np.asarray(starts, dtype=float)
    index = np.clip(np.searchsorted(starts_array, s, side="right") - 1, 0, len(segments) - 1)
    out = np.empty((len(s), 2))
    for k in np.unique(index).tolist():
        mine = index == k
        segment = segments[k]
        local = np.clip(s[mine] - starts_array[k], 0.0, segment.length)
        out[mine] = segment.point(segment.parameter_at(local))[:, :2]
    return out


def new_stations(parts: Sequence[Chain], points: NDArray) -> tuple[NDArray, NDArray]:
    """The station on the new reference line (``parts`` one after another) of the foot of each point, and its distance."""
    best = np.full(len(points), np.inf)
    station = np.zeros(len(points))
    offset = 0.0
    for part in parts:
        distance, foot = chain_distances(part, points)
        nearer = distance < best
        best = np.where(nearer, distance, best)
        station = np.where(nearer, foot + offset, station)
        offset += part.length
    return station, best


@dataclass(frozen=True)
class RemapReport:
    """What moving one road's ``s`` positions did.

    Attributes:
        count: the positions found (attributes).
        moved: how many of them moved.
        largest: the largest change of a position (m).
        clamped: positions past the old road's end (put at the new end).
        rescaled: cubic records whose coefficients were rescaled.
    """

    count: int
    moved: int
    largest: float
    clamped: int
    rescaled: int

    def note(self, road: str, old: float, new: float) -> str:
        """The report's note for the road."""
        past = f"; {self.clamped} past the old end put at the new end" if self.clamped else ""
        return (f"{road}: length {old:.6f} → {new:.6f} m; {self.moved} of {self.count} s position(s) moved to the "
                f"nearest point of the new reference line (largest move {self.largest:.3g} m{past}), {self.rescaled} cubic record(s) rescaled to "
                "their new intervals")  # fmt: skip


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


@dataclass
class _Position:
    element: ET.Element
    name: str
    old: float  # the road position (a lane section's start added to an sOffset)
    base: int = -1  # for an sOffset: the position it is measured from


def _number(element: ET.Element, name: str, road: str) -> float:
    text = element.attrib[name]
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"road {road}: <{_local(element.tag)}> {name}={text!r:.40} is not a finite number")
    return value


def _positions(road: ET.Element) -> list[_Position]:
    """Every road position of the road's subtree outside its planView; an ``sOffset`` as the road position it
    stands for: its nearest positioned ancestor's (a lane section's ``s``, a road mark's ``sOffset``) plus it."""
    label = str(road.get("id"))
    found: list[_Position] = []

    def walk(element: ET.Element, base: int) -> None:
        own = base
        for name in POSITIONS:
            if name in element.attrib:
                found.append(_Position(element, name, _number(element, name, label)))
                own = len(found) - 1 if name == "s" else own
        if "sOffset" in element.attrib and base >= 0:
            found.append(_Position(element, "sOffset", found[base].old + _number(element, "sOffset", label), base))
            own = len(found) - 1
        for child in element:
            walk(child, own)

    for child in road:
        if _local(child.tag) != "planView":
            walk(child, -1)
    return found


def remap_road(road: ET.Element, segments: Sequence[Segment], starts: Sequence[float], old_length: float,
               parts: Sequence[Chain]) -> RemapReport:  # fmt: skip
    """Move every road position of ``road`` outside its planView from the old reference line to the new one (see the module docstring).

    Args:
        road: the ``<road>`` element (edited in place).
        segments, starts: the old reference line's geometries and their file ``s``.
        old_length: the old road's length.
        parts: the new reference line (one chain, or the parts of a split one).

    Raises:
        ValueError: a position that is not a finite number (naming the element and attribute).
    """
    new_length = sum(p.length for p in parts)
    found = _positions(road)
    if not found:
        return RemapReport(0, 0, 0.0, 0, 0)
    values = np.array([p.old for p in found])
    clamped = int(np.count_nonzero(values > old_length * (1.0 + 1e-12)))
    grid = np.unique(np.concatenate([np.clip(values, 0.0, old_length), [0.0, old_length]]))
    stations, _ = new_stations(parts, old_points(segments, starts, grid))
    stations = np.clip(np.maximum.accumulate(stations), 0.0, new_length)
    stations[0], stations[-1] = (0.0 if grid[0] == 0.0 else stations[0]), new_length  # the ends are fixed

    def mapped(s: NDArray) -> NDArray:
        out = np.interp(np.clip(s, 0.0, old_length), grid, stations)
        return np.where(s <= 0.0, s, out)  # 0 stays 0

    new = mapped(values)
    new = np.where(np.abs(new - values) < STILL, values, new)
    rescaled = _rescale(road, found, new, (old_length, float(mapped(np.array([old_length]))[0])))
    moved = 0
    for position, value in zip(found, new.tolist()):
        old = position.old
        if position.base >= 0:  # an sOffset: from its lane section's new start
            old, value = old - found[position.base].old, value - float(new[position.base])
        if value != old:  # a position that does not move keeps its text
            position.element.set(position.name, shortest_decimal(value, "OpenDRIVE"))
            moved += 1
    largest = float(np.max(np.abs(new - values)))
    return RemapReport(len(found), moved, largest, clamped, rescaled)


def _rescale(road: ET.Element, found: list[_Position], new: NDArray, road_end: tuple[float, float]) -> int:
    """Rescale each cubic record's b, c, d by its interval's stretch (old span over new span); how many were.

    A record's interval ends at the next record of its kind in the same parent, else at its lane section's
    end (the next lane section, or the road's end) for lane records, else at the road's end."""
    where = {id(p.element): k for k, p in enumerate(found) if p.name in ("s", "sOffset")}
    sections = [k for k, p in enumerate(found) if _local(p.element.tag) == "laneSection" and p.name == "s"]
    section_end = {a: (found[b].old, float(new[b])) for a, b in zip(sections, sections[1:])}
    count = 0
    for parent in road.iter():
        records = [e for e in parent if _local(e.tag) in CUBICS and id(e) in where]
        for kind in sorted({_local(e.tag) for e in records}):
            mine = [e for e in records if _local(e.tag) == kind]
            for k, element in enumerate(mine):
                i = where[id(element)]
                if k + 1 < len(mine):
                    j = where[id(mine[k + 1])]
                    old_span, new_span = found[j].old - found[i].old, float(new[j] - new[i])
                else:
                    end_old, end_new = section_end.get(found[i].base, road_end)
                    old_span, new_span = end_old - found[i].old, end_new - float(new[i])
                if not (old_span > 0.0 and new_span > 0.0) or old_span == new_span:
                    continue
                stretch = old_span / new_span
                changed = False
                for power, name in ((1, "b"), (2, "c"), (3, "d")):
                    if name in element.attrib:
                        value = _number(element, name, str(road.get("id")))
                        if value:
                            element.set(name, shortest_decimal(value * stretch**power, "OpenDRIVE"))
                            changed = True
                count += changed
    return count
