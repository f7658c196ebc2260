"""Road positions ``s`` carried from an old reference line to its G2 one (``rewrite_opendrive_g2``'s helper).

Where a road's planView is rewritten its length changes (a transition cuts a corner or a curve: millimetres
over hundreds of metres), and everything placed by ``s`` along it — lane sections, lane offsets, elevation,
superelevation and shape records, objects, signals, references, road types — would drift or lie past the new
end. ``new_stations`` maps each old ``s`` to the station of the nearest point of the new reference line to
the old point at ``s`` (``spiral_cad.core.fit_distances.chain_distances``: exact feet on lines, arcs and
spirals), kept in order (a map that never runs backwards), 0 to 0 and the old end to the new end.

``remap_road`` applies it to a road element's subtree outside its ``planView``: every ``s`` (and ``sStart``,
``sEnd``) attribute is moved; the cubics of ``elevation``, ``superelevation``, ``shape`` and ``laneOffset``
records (a + b·ds + c·ds² + d·ds³ from their own ``s``) are rescaled to their new intervals, so each record
gives the same value at its start and at its next record's start as before. Offsets inside a lane section
(``sOffset``) are relative to it and kept.
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

#: The attributes that hold a road position.
POSITIONS = ("s", "sStart", "sEnd")
#: Records holding a cubic in ds from their own ``s`` (their coefficients rescaled with their interval).
CUBICS = ("elevation", "superelevation", "shape", "laneOffset")


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
    found: list[tuple[ET.Element, str, float]] = []
    for child in road:
        if _local(child.tag) == "planView":
            continue
        for element in child.iter():
            for name in POSITIONS:
                if name in element.attrib:
                    text = element.attrib[name]
                    try:
                        value = float(text)
                    except ValueError:
                        value = math.nan
                    if not math.isfinite(value):
                        raise ValueError(f"road {road.get('id')}: <{_local(element.tag)}> {name}={text!r:.40} is not a finite number")
                    found.append((element, name, value))
    if not found:
        return RemapReport(0, 0, 0.0, 0, 0)
    values = np.array([v for _, _, v in found])
    clamped = int(np.count_nonzero(values > old_length * (1.0 + 1e-12)))
    grid = np.unique(np.concatenate([np.clip(values, 0.0, old_length), [0.0, old_length]]))
    stations, _ = new_stations(parts, old_points(segments, starts, grid))
    stations = np.clip(np.maximum.accumulate(stations), 0.0, new_length)
    stations[0], stations[-1] = (0.0 if grid[0] == 0.0 else stations[0]), new_length  # the ends are fixed
    mapped = np.interp(np.clip(values, 0.0, old_length), grid, stations)
    mapped[values <= 0.0] = values[values <= 0.0]  # 0 stays 0
    rescaled = _rescale(road, found, values, mapped, old_length, new_length)
    moved = 0
    for (element, name, old), value in zip(found, mapped.tolist()):
        if value != old:  # a position that does not move keeps its text
            element.set(name, shortest_decimal(value, "OpenDRIVE"))
            moved += 1
    largest = float(np.max(np.abs(mapped - values)))
    return RemapReport(len(found), moved, largest, clamped, rescaled)


def _rescale(road: ET.Element, found: list[tuple[ET.Element, str, float]], old: NDArray, new: NDArray, old_length: float,
             new_length: float) -> int:  # fmt: skip
    """Rescale each cubic record's b, c, d by its interval's stretch (old span over new span); how many were."""
    where = {id(element): k for k, (element, name, _) in enumerate(found) if name == "s"}
    count = 0
    for parent in road.iter():
        records = [e for e in parent if _local(e.tag) in CUBICS and id(e) in where]
        for kind in {_local(e.tag) for e in records}:
            mine = [e for e in records if _local(e.tag) == kind]
            if kind == "shape":  # shapes are cross-section polynomials in t at one s: moved, not stretched
                continue
            for k, element in enumerate(mine):
                i = where[id(element)]
                if k + 1 < len(mine):
                    j = where[id(mine[k + 1])]
                    old_span, new_span = old[j] - old[i], new[j] - new[i]
                else:
                    old_span, new_span = old_length - old[i], new_length - new[i]
                if not (old_span > 0.0 and new_span > 0.0) or old_span == new_span:
                    continue
                stretch = old_span / new_span
                for power, name in ((1, "b"), (2, "c"), (3, "d")):
                    if name in element.attrib:
                        try:
                            value = float(element.attrib[name])
                        except ValueError:
                            raise ValueError(f"road {road.get('id')}: <{kind}> {name}={element.attrib[name]!r:.40} is not a number") from None
                        if value:
                            element.set(name, shortest_decimal(value * stretch**power, "OpenDRIVE"))
                count += 1
    return count
