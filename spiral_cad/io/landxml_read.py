"""LandXML in: every ``<Alignment>`` of a file rebuilt as our G2 chain (``read_landxml``).

Reads LandXML 1.0–1.2 (any namespace) as Civil 3D, OpenRoads, Carlson, MDT
and others write it: ``Metric``/``Imperial`` units (metres, millimetres,
feet, US survey feet, inches — US survey feet become feet), angles and
directions in radians, grads, decimal degrees or ``decimal dd.mm.ss``,
points northing before easting. Directions are counted counter-clockwise
from east (Civil 3D, Carlson) or clockwise from north (the XSD's "0 degrees =
north": MDT, Novapoint): which, the file itself tells — every direction whose
element also has the points it joins agrees with them one way — and an
element placed by its direction alone in a file that tells neither, or a file
whose directions agree one way here and the other there, is refused by name
(``directions=`` chooses).

Unit strings are read tolerantly (case and runs of white space: J-LandXML's
``"decimal  dd.mm.ss"``). A ``Curve`` given only by its PI, start direction,
radius and length (FreeCAD) starts one tangent length R·tan(Δ/2) before its PI;
a Curve's sense against its ``dirStart`` and ``dirEnd`` also tells how the file
counts directions.

Each ``<CoordGeom>`` is rebuilt in order (``placement="neighbours"``, the
default): the file's ``Line`` and ``Curve`` elements (``crvType`` arc; also
defined by its chord or by its points only) stay on the file's line or circle,
and each run of ``Spiral spiType="clothoid"`` elements between them becomes
our Bézier spiral(s) (``shape``, default ``"near-linear"``) that the exact
solvers find between the same two neighbours (``spiral_cad.io.landxml_fit``);
the lines and arcs are trimmed to the spirals' contact points, so lengths and
stations follow our chain. Where no solution exists, or the spirals have no
line or arc of the file on either side, a clothoid from κ0 to κ1 is rebuilt
as before with ``placement="length"``: our spiral with the same length and end
curvatures continuing from the element before (0 → κ a spiral, κ → 0 its
reversal, κ0 → κ1 the piece of a longer spiral whose start curvature is κ0,
found by a bracketed root). A spiral this package wrote (its ``desc``) is
rebuilt with its own shape: the very cubic.

No element is ever left out: lines and arcs that follow one another (two arcs of
one centre, collinear lines) are each kept whole, and a rebuild holding nothing
of an element is refused by name. Where the file is not G2 — a kink, a curvature
jump — the joint is reported: a kink of up to ``ABSORBED_KINK`` stays inside the
run (the element after it continues from ours, its offset measured), a curvature
jump at a sliver (an element of at most ``SLIVER`` of the alignment's length) too,
the sliver rebuilt with its neighbour's curvature; other joints part the G2 runs
(``breaks``). An asymmetric S (two clothoids between arcs of opposite senses) is
also solved as two ``line_to_circle`` spirals on the file's inflection tangent,
moved along its normal until they meet (``landxml_fit.solve_inflection``), the
tangent turned by up to 0.02 rad to come nearest the file's pair.

Per element the record keeps the offset between the file's element (placed at
its own Start and start direction; the exact clothoid of
``spiral_cad.core.clothoid``) and ours, measured both ways; the
largest is the record's ``offset``. Elements that cannot be represented —
other spiral types, ``IrregularLine``, ``Chain``, an alignment with no
``CoordGeom`` (``AlignPIs`` only) — are refused with a ValueError naming the
element, its index and station, and the alignment. ``Profile/ProfAlign``
(``PVI``, ``ParaCurve``, ``UnsymParaCurve``, ``CircCurve`` — the last as the
parabola of the same length, noted in ``notes``) becomes a
``spiral_cad.design.Profile`` on the same stations.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.chain import Chain
from ..core.clothoid import clothoid_frames
from ..core.shapes import SHAPE_CODES
from ..core.spiral import BezierSpiral
from .landxml import DESC_PREFIX, FEATURE, US_SURVEY_FOOT
from .landxml_fit import offsets as fit_offsets
from .landxml_place import _Element, _heading, _run, _solve_turns, _unit

__all__ = ["LandXMLAlignment", "read_landxml"]

#: Arc lengths per element at which the offset from the file's element is measured.
SAMPLES = 17
#: Our unit of each LandXML linear unit, and the factor that takes the file's numbers to it.
LINEAR = {"meter": ("m", 1.0), "millimeter": ("mm", 1.0), "centimeter": ("cm", 1.0), "kilometer": ("km", 1.0),
          "foot": ("ft", 1.0), "USSurveyFoot": ("ft", US_SURVEY_FOOT / 0.3048), "inch": ("in", 1.0)}  # fmt: skip
#: Radians per LandXML angular unit.
ANGULAR = {"radians": 1.0, "grads": math.pi / 200.0, "decimal degrees": math.pi / 180.0, "degrees": math.pi / 180.0}
#: The largest offset accepted by default between the file's element and ours, as a fraction of the element's
#: length (``read_landxml(max_offset=None)``): ordinary road spirals stay far below (the Civil 3D spiral of
#: R 63 m over 100 m, turning 45°, is 1.65 m off); a clothoid no cubic spiral follows is metres off.
MAX_OFFSET_FRACTION = 0.05
#: Relative difference of curvature between two elements above which the file's geometry is only G1 there.
_JUMP = 1e-6
#: The largest kink (rad) between two of the file's elements kept inside one G2 run: the element after it
#: continues from ours and its offset from the file is measured (Civil 3D leaves kinks of 2e-4 to 2e-3 rad
#: between elements meant to be tangent). Where that puts an element beyond the limit, the run parts there.
ABSORBED_KINK = 0.005
#: An element of at most this fraction of its alignment's length is a sliver (Civil 3D's sub-millimetre lines
#: at the ends): a curvature jump at it is kept inside the run, the sliver rebuilt with its neighbour's curvature.
SLIVER = 1e-5


@dataclass(frozen=True)
class LandXMLAlignment:
    """One alignment read from LandXML.

    Attributes:
        name: the alignment's name.
        chains: the rebuilt plane G2 chains (in ``units``): one, unless the
            file's elements meet with a jump in curvature (a line onto an arc
            without a spiral), where a new chain starts.
        breaks: each joint that parts two chains (a gap, a kink beyond ``ABSORBED_KINK``
            or a curvature jump), named by station and the numbers; the joints kept inside
            a chain (small kinks, curvature jumps at slivers) are told in ``notes``.
        start_station: the station of the chain's start.
        units: the chain's length unit.
        profile: the ``spiral_cad.design.Profile`` of its first ``ProfAlign``, or None.
        offsets: per CoordGeom element the largest distance, either way, between
            the file's element and ours (see ``spiral_cad.io.landxml_fit``), in ``units``
            (for a spiral this package wrote, between our cubic and the clothoid its attributes state).
        kinds: per element its tag (``Line``, ``Curve``, ``Spiral``).
        stations: per element the station of its start on our chain (from ``start_station``).
        notes: what was read approximately (e.g. a ``CircCurve`` as a parabola,
            a spiral rebuilt with its own length where no transition joins its neighbours).
        file_stations: per element the station of its start in the file (``staStart``, else summed lengths).
        length_changes: per element our length minus the file's.
        methods: per element how it was rebuilt: ``"file"`` (a line or arc on the
            file's carrier), the solver of a spiral (``"line_to_circle"``,
            ``"circle_in_circle"``, ``"circle_to_circle"``, ``"line_to_line"``, with
            the other shape in brackets where the element's own had no solution),
            or ``"length"`` (the file's length and end curvatures, continuing from the element before),
            or ``"spiral_cad cubic"`` (a spiral this package wrote: the cubic of its ``Feature``).
        owners: per chain, the element (an index into ``kinds``) of each of its segments.
        directions: how the file counts its directions, inferred from its elements that have both a
            direction and points (or chosen with ``read_landxml(directions=)``): ``"east-ccw"``
            (counter-clockwise from east) or ``"north-cw"`` (clockwise from north, azimuths);
            ``"unknown"`` when the file tells nothing and no element was placed by its direction.
        file_lengths: per element its length in the file.
        element_frames: (n, 2, 9) per element its start and end as the file states them: point, unit
            tangent and curvature vector (z = 0); placed by its Start and direction (else the end of the
            element before), ending at its End (else where its length takes it), turned by its length and
            end curvatures (``check_landxml`` judges these).
        end_misses: per element how far its End lies from where its Start, direction, length and
            curvatures take it (0 without an End).
    """

    name: str
    chains: tuple[Chain, ...]
    breaks: tuple[str, ...]
    start_station: float
    units: str
    profile: Any
    offsets: NDArray[np.float64]
    kinds: tuple[str, ...]
    stations: NDArray[np.float64]
    notes: tuple[str, ...] = field(default=())
    file_stations: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    length_changes: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    methods: tuple[str, ...] = field(default=())
    owners: tuple[NDArray[np.int64], ...] = field(default=())
    directions: str = "unknown"
    file_lengths: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    element_frames: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2, 9)))
    end_misses: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @property
    def chain(self) -> Chain:
        """The one G2 chain of the alignment.

        Raises:
            ValueError: the file's geometry jumps in curvature (naming the first joint).
        """
        if len(self.chains) > 1:
            raise ValueError(f"alignment {self.name!r} is not G2: {self.breaks[0]} ({len(self.chains)} G2 runs in `chains`)")
        return self.chains[0]

    @property
    def offset(self) -> float:
        """The largest offset between the file's geometry and the rebuilt chain."""
        return float(self.offsets.max()) if len(self.offsets) else 0.0

    @property
    def worst(self) -> str:
        """Where the largest offset is: the element's index, kind and station (the file's), and the offset."""
        if not len(self.offsets):
            return "no element"
        k = int(np.argmax(self.offsets))
        share = f" ({float(self.offsets[k]) / float(self.file_lengths[k]):.2%} of its length)" if len(self.file_lengths) else ""
        station = self.file_stations[k] if len(self.file_stations) else self.stations[k]
        return f"element {k} ({self.kinds[k]}) at station {station:.6g}: {self.offsets[k]:.3g} {self.units}{share}"

    @property
    def station_shift(self) -> float:
        """Our end station minus the file's: how far the stations of the rebuilt chain have moved by its end."""
        if not len(self.stations):
            return 0.0
        return float(self.stations[-1] + self.length_changes[-1] - self.file_stations[-1])


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _children(element: ET.Element, name: str) -> list[ET.Element]:
    return [c for c in element if _local(c.tag) == name]


def _child(element: ET.Element, name: str) -> ET.Element | None:
    found = _children(element, name)
    return found[0] if found else None


def _unit_name(text: str, known: Any) -> str | None:
    """The unit of ``known`` that ``text`` names, read tolerantly: case and runs of white space do not
    matter (J-LandXML writes ``"decimal  dd.mm.ss"``); None if it names none."""
    wanted = " ".join(text.split()).casefold()
    return next((name for name in known if name.casefold() == wanted), None)


def _angle(text: str, unit: str) -> float:
    """An angle in radians from the file's text in ``unit``."""
    if unit == "decimal dd.mm.ss":
        value = float(text)
        sign, value = math.copysign(1.0, value), abs(value)
        degrees = math.floor(value)
        minutes = math.floor(round((value - degrees) * 100.0, 9))
        seconds = ((value - degrees) * 100.0 - minutes) * 100.0
        return sign * math.radians(degrees + minutes / 60.0 + seconds / 3600.0)
    return float(text) * ANGULAR[unit]


class _Reader:
    """The state of one file's read: units, scale and where errors point."""

    def __init__(self, root: ET.Element, shape: str, placement: str = "neighbours"):
        self.shape = shape
        self.placement = placement
        self.directions = "unknown"  # the file's convention of directions (DIRECTIONS), once known
        self.evidence = ""  # why: which elements' points agree with it
        self.used = 0  # directions that placed an element in the alignment being read
        self.max_offset: float | None = None  # the largest offset accepted (None: MAX_OFFSET_FRACTION of each length)
        # the file's named points (a point may be given as pntRef="name"), wherever its CgPoints are
        self.cg_points = {e.get("name", ""): (e.text or "").strip() for e in root.iter() if isinstance(e.tag, str)
                          and _local(e.tag) == "CgPoint" and e.get("name")}  # fmt: skip
        units = _child(root, "Units")
        system = None if units is None else next(iter(units), None)
        linear = "meter" if system is None else system.get("linearUnit", "meter")
        known = _unit_name(linear, LINEAR)
        if known is None:
            raise ValueError(f"LandXML linearUnit {linear!r} is not one of {', '.join(LINEAR)}")
        self.units, self.scale = LINEAR[known]
        angular = [*ANGULAR, "decimal dd.mm.ss"]
        names = []
        for name in ("directionUnit", "angularUnit"):
            unit = "radians" if system is None else system.get(name, "radians")
            found = _unit_name(unit, angular)
            if found is None:
                raise ValueError(f"LandXML {name} {unit!r} is not radians, grads, decimal degrees or decimal dd.mm.ss")
            names.append(found)
        self.direction_unit, self.angular_unit = names

    def number(self, element: ET.Element, name: str, where: str, default: float | None = None) -> float:
        text = element.get(name)
        if text is None:
            if default is None:
                raise ValueError(f"{where}: no {name}")
            return default
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{where}: {name}={text!r} is not a number") from None
        if math.isinf(value) and name.startswith("radius"):
            return value
        if not math.isfinite(value):
            raise ValueError(f"{where}: {name}={text!r} is not finite")
        return value * self.scale if name in ("length", "radius", "radiusStart", "radiusEnd", "chord", "staStart") else value

    def point(self, element: ET.Element, name: str, where: str) -> NDArray[np.float64] | None:
        child = _child(element, name)
        text = "" if child is None else (child.text or "").strip()
        ref = None if child is None else child.get("pntRef")
        if not text and ref is not None:  # the XSD's PointType: a reference to a CgPoint instead of coordinates
            if ref not in self.cg_points or not self.cg_points[ref]:
                raise ValueError(f"{where}: <{name} pntRef={ref!r}> names no CgPoint with coordinates in the file")
            text = self.cg_points[ref]
        if not text:
            return None
        parts = text.split()
        try:
            north, east = float(parts[0]), float(parts[1])
        except (ValueError, IndexError):
            raise ValueError(f"{where}: <{name}> {text!r} is not 'northing easting'") from None
        if not math.isfinite(north + east):
            raise ValueError(f"{where}: <{name}> {text!r} is not finite")
        return np.array([east, north]) * self.scale

    def angle(self, element: ET.Element, name: str, where: str) -> float:
        """An angle attribute (``angularUnit``) in radians."""
        return self.raw_direction(element, name, where, self.angular_unit) or 0.0

    def raw_direction(self, element: ET.Element, name: str, where: str, unit: str | None = None) -> float | None:
        """A direction attribute (``directionUnit``) in radians as the file counts it; None if absent."""
        text = element.get(name)
        if text is None:
            return None
        try:
            angle = _angle(text, unit or self.direction_unit)
        except ValueError:
            raise ValueError(f"{where}: {name}={text!r} is not a number") from None
        if not math.isfinite(angle):
            raise ValueError(f"{where}: {name}={text!r} is not finite")
        return angle

    def direction(self, element: ET.Element, name: str, where: str) -> float | None:
        """A direction attribute in radians counter-clockwise from east (our heading), converted from the
        file's convention (``directions``); None if absent.

        Raises:
            ValueError: the file gives no evidence of its convention (naming the element).
        """
        raw = self.raw_direction(element, name, where)
        if raw is None:
            return None
        if self.directions == "unknown":
            raise ValueError(f"{where}: the element is placed only by its {name}, and no element of the file has both a "
                             "direction and the points it joins, so whether directions count counter-clockwise from east "
                             "or clockwise from north (the XSD's '0 degrees = north') cannot be told; choose with "
                             "read_landxml(directions='east-ccw' or 'north-cw') or build --directions")  # fmt: skip
        self.used += 1
        return raw if self.directions == "east-ccw" else math.pi / 2 - raw


def _curvature(sign: float, radius: float, where: str) -> float:
    """The signed curvature of a radius, refused where it is not positive or overflows."""
    curvature = sign / radius
    if not (radius > 0.0 and math.isfinite(curvature)):
        raise ValueError(f"{where}: radius {radius!r} has no finite positive curvature")
    return curvature


#: The conventions of LandXML directions: counter-clockwise from east (Civil 3D, Carlson, this package's
#: writer) and clockwise from north (azimuths, the XSD's "0 degrees = north": MDT, Novapoint, others).
DIRECTIONS = ("east-ccw", "north-cw")
#: A direction agrees with its element's points within this (rad), and disagrees beyond ``_APART``:
#: between the two an element near the 45° diagonal tells nothing (both conventions give its direction).
_AGREE, _APART = 0.01, 0.05


def _clues(r: _Reader, e: ET.Element, where: str) -> list[tuple[float, float, str]]:
    """What an element tells of the file's direction convention: (its direction as the file counts it,
    the heading its points give, the attribute) for each direction it has with the points to check it."""
    kind = _local(e.tag)
    if kind not in ("Line", "Curve", "Spiral"):
        return []
    start, end = r.point(e, "Start", where), r.point(e, "End", where)
    out: list[tuple[float, float, str]] = []

    def clue(name: str, a: NDArray | None, b: NDArray | None, turn: float = 0.0) -> None:
        raw = r.raw_direction(e, name, where)
        if raw is not None and a is not None and b is not None and np.any(a != b):
            out.append((raw, _heading(b - a) + turn, name))

    if kind == "Line":
        clue("dir", start, end)
        return out
    pi, center = r.point(e, "PI", where), r.point(e, "Center", where)
    clue("dirStart", start, pi)  # the PI is where the end tangents meet
    clue("dirEnd", pi, end)
    if kind == "Curve" and center is not None and e.get("rot") in ("cw", "ccw"):
        quarter = math.pi / 2 if e.get("rot") == "ccw" else -math.pi / 2  # the tangent is the radius turned a quarter
        clue("dirStart", center, start, quarter)
        clue("dirEnd", center, end, quarter)
    start_dir, end_dir = r.raw_direction(e, "dirStart", where), r.raw_direction(e, "dirEnd", where)
    if kind == "Curve" and e.get("rot") in ("cw", "ccw") and start_dir is not None and end_dir is not None:
        # a Curve's sense against its directions: counted from east a left turn increases them, counted from
        # north it decreases them. The pair (change + π/4, turn + π/4) makes _convention's two comparisons
        # |change - turn| (east) and |-change - turn| (north).
        length, radius = (float(e.get(name, "nan")) for name in ("length", "radius"))
        turn = math.copysign(length / radius, 1.0 if e.get("rot") == "ccw" else -1.0) if radius > 0.0 else math.nan
        if _APART < abs(turn) < math.pi - _APART:
            out.append((math.remainder(end_dir - start_dir, 2.0 * math.pi) + math.pi / 4, turn + math.pi / 4, "rot"))
    return out


def _convention(r: _Reader, alignments: list[ET.Element]) -> None:
    """Set ``r.directions`` from the file's own evidence: every direction whose element also has the
    points it joins (a Line's Start→End, a Curve's or Spiral's Start→PI→End, a Curve's Center) agrees
    with the points counted one way or the other.

    Raises:
        ValueError: some directions agree only counted from east and others only from north (naming one of each).
    """
    found: dict[str, list[str]] = {"east-ccw": [], "north-cw": []}
    for k, a in enumerate(alignments):
        geometry = _child(a, "CoordGeom")
        for index, e in enumerate(() if geometry is None else geometry):
            if not isinstance(e.tag, str):
                continue
            where = f"alignment {a.get('name', f'alignment {k + 1}')!r}, CoordGeom element {index} ({_local(e.tag)})"
            try:
                clues = _clues(r, e, where)
            except ValueError:  # a malformed element tells nothing here; the read names it with its station
                continue
            for raw, heading, name in clues:
                off_east = abs(math.remainder(raw - heading, 2.0 * math.pi))
                off_north = abs(math.remainder(math.pi / 2 - raw - heading, 2.0 * math.pi))
                if off_east < _AGREE and off_north > _APART:
                    found["east-ccw"].append(f"{where} {name}")
                elif off_north < _AGREE and off_east > _APART:
                    found["north-cw"].append(f"{where} {name}")
    east, north = found["east-ccw"], found["north-cw"]
    if east and north:
        raise ValueError(f"the file's directions are inconsistent: {east[0]} agrees with its points counted "
                         f"counter-clockwise from east ({len(east)} such), {north[0]} only counted clockwise from north "
                         f"({len(north)} such); choose with read_landxml(directions='east-ccw' or 'north-cw') or build --directions")  # fmt: skip
    if east or north:
        r.directions = "east-ccw" if east else "north-cw"
        r.evidence = (f"{len(east or north)} direction(s) of the file agree with their points only counted "
                      + ("counter-clockwise from east" if east else "clockwise from north"))  # fmt: skip


def _element(r: _Reader, e: ET.Element, where: str) -> _Element:
    kind = _local(e.tag)
    start, end = r.point(e, "Start", where), r.point(e, "End", where)
    station = r.number(e, "staStart", where) if e.get("staStart") is not None else None
    if kind == "Line":
        if start is not None and end is not None:
            d = end - start
            return _Element(kind, start, _heading(d), float(np.hypot(*d)), 0.0, 0.0, station, r.shape)
        heading = r.direction(e, "dir", where)
        if heading is None:
            raise ValueError(f"{where}: a Line needs Start and End, or dir and length")
        return _Element(kind, start, heading, r.number(e, "length", where), 0.0, 0.0, station, r.shape)
    if kind == "Curve":
        if e.get("crvType", "arc") != "arc":
            raise ValueError(f"{where}: Curve crvType {e.get('crvType')!r} is not an arc")
        rot = e.get("rot")
        if rot not in ("cw", "ccw"):
            raise ValueError(f"{where}: Curve rot {rot!r} is not cw or ccw")
        sign = 1.0 if rot == "ccw" else -1.0
        center = r.point(e, "Center", where)
        radius = r.number(e, "radius", where, 0.0) or (
            float(np.hypot(*(start - center))) if start is not None and center is not None else 0.0
        )
        if math.isinf(radius):  # a Curve is an arc: INF would silently make it a line
            raise ValueError(f"{where}: a Curve's radius {e.get('radius')!r} is not finite")
        if not radius > 0.0:
            raise ValueError(f"{where}: a Curve needs a radius (or Start and Center)")
        heading = None
        if start is not None and center is not None:
            heading = _heading(start - center) + sign * math.pi / 2
        elif e.get("dirStart") is not None:
            heading = r.direction(e, "dirStart", where)
        if e.get("length") is not None:
            length = r.number(e, "length", where)
        elif e.get("chord") is not None:  # chord-defined: the minor arc unless delta says more
            chord = r.number(e, "chord", where)
            if not 0.0 < chord <= 2.0 * radius * (1.0 + 1e-9):  # beyond the diameter (up to its rounding) no arc has it
                raise ValueError(f"{where}: chord {chord:.6g} is not in (0, 2 × radius {radius:.6g}]")
            length = 2.0 * radius * math.asin(min(1.0, chord / (2.0 * radius)))
            if e.get("delta") is not None and abs(r.angle(e, "delta", where)) > math.pi:
                length = 2.0 * math.pi * radius - length
        elif start is not None and end is not None and center is not None:
            a0, a1 = _heading(start - center), _heading(end - center)
            length = radius * ((sign * (a1 - a0)) % (2.0 * math.pi))
        else:
            raise ValueError(f"{where}: a Curve needs a length, a chord or Start, Center and End")
        pi = r.point(e, "PI", where)
        if start is None and center is None and pi is not None and heading is not None:
            # given by its PI, start direction, radius and length (FreeCAD): the start is one tangent length before the PI
            if not length < math.pi * radius:
                raise ValueError(f"{where}: a Curve given by its PI turns less than 180°; length {length:.6g} and radius {radius:.6g} turn more")  # fmt: skip
            start = pi - radius * math.tan(length / (2.0 * radius)) * _unit(heading)
        return _Element(kind, start, heading, length, _curvature(sign, radius, where), _curvature(sign, radius, where), station, r.shape)
    if kind == "Spiral":
        spi = e.get("spiType")
        if spi is None:  # required by the XSD and written by every exporter we have seen: not guessed
            raise ValueError(f"{where}: a Spiral needs spiType (required by LandXML; only clothoids can be rebuilt)")
        if spi != "clothoid":
            raise ValueError(f"{where}: spiral type {spi!r} is not a clothoid; only clothoids can be rebuilt")
        rot = e.get("rot")
        if rot not in ("cw", "ccw"):
            raise ValueError(f"{where}: Spiral rot {rot!r} is not cw or ccw")
        sign = 1.0 if rot == "ccw" else -1.0
        for name in ("radiusStart", "radiusEnd"):  # required by the XSD: a missing one is not taken as straight
            if e.get(name) is None:
                raise ValueError(f"{where}: a Spiral needs {name} (INF where straight)")
        k0, k1 = (0.0 if (radius := r.number(e, name, where)) in (0.0, math.inf) else _curvature(sign, radius, where)
                  for name in ("radiusStart", "radiusEnd"))  # fmt: skip
        pi = r.point(e, "PI", where)
        heading = None
        if e.get("dirStart") is not None and (r.directions != "unknown" or pi is None or start is None):
            heading = r.direction(e, "dirStart", where)
        elif start is not None and pi is not None and np.any(pi != start):
            heading = _heading(pi - start)
        shape = r.shape
        desc = e.get("desc", "")
        if desc.startswith(DESC_PREFIX):
            found = re.search(r"\(shape ([a-z0-9-]+)\)", desc)
            if found and found.group(1) in SHAPE_CODES:
                shape = found.group(1)
        item = _Element(kind, start, heading, r.number(e, "length", where), k0, k1, station, shape)
        item.cubic = _our_cubic(r, e, item, shape, end, where)
        return item
    raise ValueError(f"{where}: {kind} cannot be represented as a G2 chain of lines, arcs and spirals")


def _our_cubic(r: _Reader, e: ET.Element, item: _Element, shape: str, end: NDArray | None, where: str) -> BezierSpiral | None:
    """The cubic this package wrote for a Spiral (its ``Feature name="spiral_cad"``), if it is still the
    element's: it starts at Start, ends at End and has the element's length and end curvatures."""
    feature = next((f for f in _children(e, "Feature") if f.get("name") == FEATURE), None)
    value = None if feature is None else next((p.get("value") for p in _children(feature, "Property")
                                               if p.get("label") == "controlPoints"), None)  # fmt: skip
    if value is None:
        return None
    try:
        numbers = np.array([float(v) for v in value.split()]) * r.scale
        cubic = BezierSpiral.from_control_points(numbers.reshape(4, 2)[:, ::-1], shape)  # northing easting → x, y
    except ValueError:
        item.notes.append(f"{where}: the spiral_cad control points {value!r} are not 8 numbers of a spiral; not used")
        return None
    size = max(item.length, 1e-300)
    near = 1e-9 * size
    same = (
        (item.start is None or math.dist(cubic.start[:2], item.start) <= near)
        and (end is None or math.dist(cubic.end[:2], end) <= near)
        and abs(cubic.length - item.length) <= near
        and all(abs(a - b) * size <= 1e-6 for a, b in ((cubic.start_curvature, item.k0), (cubic.end_curvature, item.k1)))
    )
    if not same:
        item.notes.append(f"{where}: the spiral_cad control points do not fit the element (edited since?); not used")
        return None
    return cubic


def _alignment(r: _Reader, a: ET.Element, label: str) -> LandXMLAlignment:
    name = a.get("name", label)
    where = f"alignment {name!r}"
    start_station = r.number(a, "staStart", where, 0.0)
    geometry = _child(a, "CoordGeom")
    if geometry is None:
        raise ValueError(f"{where}: no CoordGeom (geometry given only as {', '.join(sorted({_local(c.tag) for c in a})) or 'nothing'}); "
                         "only CoordGeom alignments can be rebuilt")  # fmt: skip
    items: list[_Element] = []
    ends_at: list[NDArray | None] = []
    skipped: list[str] = []
    r.used = 0
    station = start_station
    for index, e in enumerate(geometry):
        if not isinstance(e.tag, str):
            continue
        place = f"{where}, CoordGeom element {index} ({_local(e.tag)}) at station {station:.6g}"
        item = _element(r, e, place)
        item.where = place
        ends_at.append(r.point(e, "End", place))  # where the file says it ends (None: where its length takes it)
        if item.station is None:
            item.station = station
        if item.length == 0.0:  # MDT writes zero-length curves between spirals: a point, nothing to build
            skipped.append(f"{place}: zero length, skipped")
            ends_at.pop()
            continue
        if not item.length > 0.0:
            raise ValueError(f"{place}: length {item.length!r} is not positive")
        items.append(item)
        station = item.station + item.length
    if not items:
        raise ValueError(f"{where}: CoordGeom holds no elements")
    # The file's own placement of each element: its Start and start direction, else the end of the one before.
    starts, headings, ends = [], [], []
    point, heading = items[0].start, items[0].heading
    if point is None or heading is None:
        raise ValueError(f"{where}: the first element needs a Start point and a direction")
    size = np.array([i.length for i in items])
    bend = np.array([i.k0 for i in items])
    with np.errstate(all="ignore"):
        local, turns, _ = clothoid_frames(size, bend, (np.array([i.k1 for i in items]) - bend) / size, length=size)
    bad = np.flatnonzero(~np.isfinite(local).all(axis=1) | ~np.isfinite(turns))
    if len(bad):
        raise ValueError(f"{items[bad[0]].where}: length {size[bad[0]]:.6g} and curvatures {bend[bad[0]]:.6g}, "
                         f"{items[bad[0]].k1:.6g} give no point in floating point")  # fmt: skip
    for item, (dx, dy), turn in zip(items, local, turns):  # each element's end: its local clothoid turned into place
        point = item.start if item.start is not None else point
        heading = item.heading if item.heading is not None else heading
        starts.append(point)
        headings.append(heading)
        c, n = math.cos(heading), math.sin(heading)
        point, heading = point + np.array([c * dx - n * dy, n * dx + c * dy]), heading + float(turn)
        ends.append((point, heading))
    if r.placement == "length":
        _solve_turns(items)
    k1 = np.array([i.k1 for i in items])
    file = (np.array(starts), np.array(headings), bend, k1, size)
    # a sliver's limit is that of an element of SLIVER × the alignment's length: its own would be below rounding
    largest = float(size.max()) if len(size) else 0.0  # the length summed relative to the longest: lengths near 1e308 do not overflow
    sliver = SLIVER * float((size / largest).sum()) * largest if largest > 0.0 else 0.0
    limits = MAX_OFFSET_FRACTION * np.maximum(size, sliver) if r.max_offset is None else np.full(len(size), r.max_offset)
    tried: list[tuple[NDArray[np.float64], NDArray[np.int64]]] = []
    for kink in (ABSORBED_KINK, 0.0):  # small kinks absorbed where the offsets allow it, else G2 runs apart there
        runs, breaks, joints, continued = _joints(items, starts, headings, ends, r.units, kink)
        placed = [replace(item, k0=continued[k], k1=continued[k]) if k in continued else item for k, item in enumerate(items)]
        chains: list[Chain] = []
        owners: list[NDArray[np.int64]] = []
        methods: dict[int, str] = {}
        for mine in runs:
            segments, owner, found = _run(placed, mine, starts, headings, ends, r.placement, file)
            chains.append(Chain(segments, tolerance=1e-6, units=r.units))
            owners.append(np.array(owner, dtype=np.int64))
            methods.update(found)
        dropped = sorted(set(range(len(items))) - set(np.concatenate(owners).tolist()))
        if dropped:  # never silently: a rebuild that lost an element is a defect, named
            raise ValueError(f"{items[dropped[0]].where}: the rebuilt chain holds nothing of this element ({len(dropped)} such)")
        run_of = np.repeat(np.arange(len(runs)), [len(m) for m in runs])
        try:
            offsets = fit_offsets(chains, owners, *file, run_of)
        except ValueError as e:
            raise ValueError(f"{where}: {e}") from None
        # a spiral this package wrote is the very cubic of its Feature: its offset from the clothoid its
        # attributes describe is reported, not refused
        limits[[k for k in range(len(items)) if methods.get(k) == "spiral_cad cubic"]] = np.inf
        over = np.flatnonzero(offsets > limits)
        tried.append((offsets, over))
        if not len(over) or not any("kink" in j for j in joints):
            break
    if len(over):  # a clothoid none of our spirals follows: refused rather than silently metres away
        offsets, over = tried[0]  # named as the first rebuild (the small kinks inside the runs) found it
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):  # a limit may underflow to 0
            k = int(over[np.argmax(offsets[over] / limits[over])])
        limit = (f"{MAX_OFFSET_FRACTION:g} of its length {size[k]:.6g}" if r.max_offset is None
                 else f"max_offset {r.max_offset:.6g}")  # fmt: skip
        raise ValueError(f"{items[k].where}: ours lies {offsets[k]:.3g} {r.units} from the file's element, more than "
                         f"{limit} ({len(over)} element(s) beyond; max_offset=math.inf, or build --max-offset inf, accepts them)")  # fmt: skip
    ours = np.zeros(len(items))
    for chain, held in zip(chains, owners):
        np.add.at(ours, held, chain.lengths)
    profile, notes = _profile(r, a, where)
    if r.used:  # the directions placed elements: say how they were counted
        how = "counter-clockwise from east" if r.directions == "east-ccw" else "clockwise from north"
        notes = (f"{where}: {r.used} direction(s) placed elements, counted {how} ({r.evidence or 'as chosen'})", *notes)
    notes = (*skipped, *joints, *(note for item in items for note in item.notes), *notes)
    return LandXMLAlignment(name, tuple(chains), tuple(breaks), start_station, r.units, profile, offsets, tuple(i.kind for i in items),
                            start_station + np.concatenate([[0.0], np.cumsum(ours)[:-1]]), notes,
                            np.array([i.station for i in items]), ours - size,
                            tuple(methods.get(k, "file") for k in range(len(items))), tuple(owners), r.directions, size,
                            _element_frames(starts, headings, [(p if at is None else at, h) for (p, h), at in zip(ends, ends_at)],
                                            bend, k1),
                            np.array([0.0 if at is None else float(np.hypot(*(at - p))) for (p, _), at in zip(ends, ends_at)]))  # fmt: skip


def _element_frames(starts: list[NDArray], headings: list[float], ends: list[tuple[NDArray, float]], k0: NDArray,
                    k1: NDArray) -> NDArray[np.float64]:  # fmt: skip
    """(n, 2, 9) start and end frames of the file's elements: point, unit tangent, curvature vector κN (z = 0)."""
    frames = np.zeros((len(starts), 2, 9))
    for side, points, angles, curvature in ((0, np.array(starts), np.array(headings), k0),
                                            (1, np.array([p for p, _ in ends]), np.array([h for _, h in ends]), k1)):  # fmt: skip
        c, s = np.cos(angles), np.sin(angles)
        frames[:, side, 0:2] = points
        frames[:, side, 3], frames[:, side, 4] = c, s
        frames[:, side, 6], frames[:, side, 7] = -s * curvature, c * curvature
    return frames


def _joints(items: list[_Element], starts: list[NDArray], headings: list[float], ends: list[tuple[NDArray, float]], units: str,
            kink: float) -> tuple[list[list[int]], list[str], list[str], dict[int, float]]:  # fmt: skip
    """Where the file's elements are not G2: the G2 runs (element indices), the joints that part them
    (``breaks``), the joints kept inside a run (reported, not parting it: kinks up to ``kink`` rad, where the
    element after continues from ours; curvature jumps at a sliver, an element of at most ``SLIVER`` of the
    alignment's length), and the curvature each sliver is rebuilt with (its neighbour's)."""
    total = sum(i.length for i in items)
    runs: list[list[int]] = [[]]
    breaks: list[str] = []
    joints: list[str] = []
    continued: dict[int, float] = {}
    for k, item in enumerate(items):
        at = f"at station {item.station:.6g} (between elements {k - 1} and {k})"
        if k:
            before = items[k - 1]
            gap = float(np.hypot(*(starts[k] - ends[k - 1][0])))
            turn = abs(math.remainder(headings[k] - ends[k - 1][1], 2.0 * math.pi))
            # after a spiral the chain goes on from our spiral (its offset is reported), not from the clothoid's end
            apart = before.kind != "Spiral" and (gap > _JUMP * max(item.length, before.length) or turn > _JUMP)
            jump = abs(item.k0 - before.k1) > _JUMP * max(abs(item.k0), abs(before.k1))
            sliver = next((m for m in (k, k - 1) if items[m].length <= SLIVER * total), None)
            if jump and sliver is not None and "Spiral" not in (item.kind, before.kind):
                continued[sliver] = before.k1 if sliver == k else item.k0
                joints.append(f"joint {at}: curvature jumps from {before.k1:.6g} to {item.k0:.6g} 1/{units} at element {sliver} "
                              f"of length {items[sliver].length:.3g} {units}, rebuilt with its neighbour's curvature")  # fmt: skip
                jump = False
            if apart and gap <= _JUMP * max(item.length, before.length) and turn <= kink:
                joints.append(f"joint {at}: a kink of {turn:.3g} rad, the element after it continues from ours (its offset measured)")
                apart = False
            if apart:
                breaks.append(f"the file's elements meet with a gap of {gap:.3g} {units} and a kink of {turn:.3g} rad {at}")
                runs.append([])
            elif jump:
                breaks.append(f"curvature jumps from {before.k1:.6g} to {item.k0:.6g} 1/{units} {at}")
                runs.append([])
        runs[-1].append(k)
    return runs, breaks, joints, continued


def _profile(r: _Reader, a: ET.Element, where: str) -> tuple[Any, tuple[str, ...]]:
    """The first ``ProfAlign`` of an alignment as a ``Profile`` (None without one), and notes."""
    node = _child(a, "Profile")
    prof = None if node is None else _child(node, "ProfAlign")
    if prof is None:
        return None, ()
    from ..design import Profile

    points, lengths, notes = [], [], []
    for index, e in enumerate(prof):
        tag = _local(e.tag) if isinstance(e.tag, str) else ""
        if tag not in ("PVI", "ParaCurve", "UnsymParaCurve", "CircCurve"):
            continue
        place = f"{where}, ProfAlign element {index} ({tag})"
        try:
            station, elevation = (float(v) * r.scale for v in (e.text or "").split()[:2])
        except ValueError:
            raise ValueError(f"{place}: {e.text!r} is not 'station elevation'") from None
        points.append((station, elevation))
        if tag == "UnsymParaCurve":
            lengths.append((r.number(e, "lengthIn", place) * r.scale, r.number(e, "lengthOut", place) * r.scale))
        elif tag in ("ParaCurve", "CircCurve"):
            length = r.number(e, "length", place)
            lengths.append((length / 2.0, length / 2.0))
            if tag == "CircCurve":
                notes.append(f"{place}: the circular vertical curve read as the parabola of the same length")
        else:
            lengths.append((0.0, 0.0))
    if len(points) < 2:
        raise ValueError(f"{where}: the ProfAlign has fewer than 2 PVIs")
    try:
        profile = Profile.from_pvis(points, curve_lengths=lengths[1:-1], units=r.units)
    except ValueError as e:  # e.g. a grade break (a PVI without a vertical curve): no Profile holds it
        return None, (*notes, f"{where}: the profile was not read: {e}")
    return profile, tuple(notes)


def read_landxml(source: str | os.PathLike, shape: str = "near-linear", placement: str = "neighbours",
                 directions: str = "auto", max_offset: float | None = None) -> list[LandXMLAlignment]:  # fmt: skip
    """Every alignment of a LandXML file (a path, or the document's text) rebuilt as our G2 chain.

    Args:
        source: a path, or the XML text itself (starting with ``<``).
        shape: the spiral shape of the rebuilt clothoids (``"near-linear"``,
            the nearest, or ``"walton-meek"``); spirals this package wrote keep their own.
        placement: ``"neighbours"`` (the file's lines and arcs kept, each run of
            clothoids replaced by our transition between the same neighbours,
            see ``spiral_cad.io.landxml_fit``) or ``"length"`` (every clothoid
            rebuilt with its own length and end curvatures, continuing from the element before).
        directions: how the file counts its directions: ``"auto"`` (inferred from
            the elements that have both a direction and the points it joins — a
            Line's Start→End, a Curve's Center or PI, a Spiral's PI), ``"east-ccw"``
            (counter-clockwise from east: Civil 3D, Carlson) or ``"north-cw"``
            (clockwise from north, the XSD's "0 degrees = north": MDT, Novapoint).
        max_offset: the largest offset (in the result's ``units``) accepted between
            the file's element and ours; None: ``MAX_OFFSET_FRACTION`` of each
            element's length (of ``SLIVER`` × the alignment's length for a sliver);
            ``math.inf`` accepts any. An element beyond it refuses the read; none is ever left out.

    Returns:
        One ``LandXMLAlignment`` per ``<Alignment>`` in file order.

    Raises:
        ValueError: not LandXML, no alignment, an element that cannot be
            represented (named with its index, station and alignment), directions
            that agree with their points one way in some elements and the other
            way in others, or (``"auto"``) an element placed only by its direction
            in a file whose convention cannot be told, or an element ours lies
            farther from than ``max_offset`` (naming the farthest), or a rebuild that holds
            nothing of some element (naming it: no element is ever left out).
    """
    if shape not in ("near-linear", "walton-meek"):
        raise ValueError(f"shape must be 'near-linear' or 'walton-meek'; got {shape!r}")
    if placement not in ("neighbours", "length"):
        raise ValueError(f"placement must be 'neighbours' or 'length'; got {placement!r}")
    if max_offset is not None and not max_offset >= 0.0:
        raise ValueError(f"max_offset must be a length >= 0 (or None); got {max_offset!r}")
    if directions not in ("auto", *DIRECTIONS):
        raise ValueError(f"directions must be 'auto', 'east-ccw' or 'north-cw'; got {directions!r}")
    text = os.fspath(source)
    try:
        root = ET.fromstring(text) if text.lstrip().startswith("<") else ET.parse(text).getroot()
    except ET.ParseError as e:
        raise ValueError(f"not an XML document: {e}") from None
    if _local(root.tag) != "LandXML":
        raise ValueError(f"not a LandXML document (root element {_local(root.tag)!r})")
    reader = _Reader(root, shape, placement)
    reader.max_offset = None if max_offset is None else float(max_offset)
    alignments = [a for group in _children(root, "Alignments") for a in _children(group, "Alignment")]
    if not alignments:
        raise ValueError("the LandXML document holds no Alignment")
    if directions == "auto":
        _convention(reader, alignments)
    else:
        reader.directions = directions
    return [_alignment(reader, a, f"alignment {k + 1}") for k, a in enumerate(alignments)]
