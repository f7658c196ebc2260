"""ASAM OpenDRIVE 1.8: exact export of chains and alignments, reading and checking planViews.

Export (``write_opendrive``, public as ``spiral_cad.export.export_opendrive``):
every chain becomes one ``<road>`` whose ``planView`` holds its segments in
travel order:

* ``Line`` → ``<line/>``;
* ``Arc`` → ``<arc curvature="κ"/>`` (signed, left positive);
* ``BezierSpiral`` → ``<paramPoly3 pRange="normalized">``: the cubic itself,
  in the local frame at the spiral's start (x, y) and start heading (hdg),
  so that ``aU = aV = bV = 0`` and ``bU > 0``; ``@length`` is the true arc
  length (composite Gauss–Legendre, ≤ 1e-13 relative).

OpenDRIVE lengths are metres: a design in another unit is converted (and
says so in the header's ``userData``). ``@s`` runs from 0 at the start of
each road; the design's start station is recorded as ``userData``
(chainage = start station + s). Every number is written as the shortest
decimal that reads back to the same double (at most 17 significant digits).

A road a simulator can drive: a flat ``elevationProfile``, ``lanes`` from a
:class:`CrossSection` (default: one 3.5 m driving lane each way and 2.5 m
shoulders, right-hand traffic) and, when the superelevation of each curve is
known, a ``lateralProfile`` that ramps it linearly along each spiral.

Reading (``read_opendrive``) returns every road's planView as evaluable
geometries — lines, arcs, clothoid spirals (Fresnel integrals from scipy),
``paramPoly3`` in both ``pRange`` and the deprecated ``poly3`` — and, when a
planView is made of lines, arcs and ``paramPoly3`` only, as a ``Chain``.
``check_opendrive`` classifies every joint between consecutive geometries
G0/G1/G2 with the same measures as the STEP checker.

Needs no CAD kernel.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import fresnel

from ..core import bezier
from ..core.chain import Chain
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..core.units import to_metres
from .decimals import shortest_decimal
from .joints import ContinuityReport, Frame, check_tolerances, classify_pieces, model_size

REV_MAJOR, REV_MINOR = 1, 8


def number(value: float) -> str:
    """An OpenDRIVE number: the shortest round-trip decimal."""
    return shortest_decimal(value, "OpenDRIVE")


# ------------------------------------------------------------------ export


@dataclass(frozen=True)
class CrossSection:
    """The lanes written to every road (metres; OpenDRIVE lane widths are always metres).

    Attributes:
        driving_lanes: driving lanes on each side of the reference line.
        lane_width: width of each driving lane.
        shoulder_width: width of the shoulder outside the driving lanes (0: none).
        rule: ``"RHT"`` (right-hand traffic) or ``"LHT"``.
    """

    driving_lanes: int = 1
    lane_width: float = 3.5
    shoulder_width: float = 2.5
    rule: str = "RHT"

    def __post_init__(self) -> None:
        if not (isinstance(self.driving_lanes, int) and self.driving_lanes >= 1):
            raise ValueError(f"driving_lanes must be a positive integer; got {self.driving_lanes!r}")
        for name in ("lane_width", "shoulder_width"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite width ≥ 0 (m); got {value!r}")
        if not self.lane_width > 0:
            raise ValueError(f"lane_width must be positive (m); got {self.lane_width!r}")
        if self.rule not in ("RHT", "LHT"):
            raise ValueError(f"rule must be 'RHT' or 'LHT'; got {self.rule!r}")


@dataclass(frozen=True)
class Banking:
    """Superelevation of one curve: the cross slope ``e`` (m/m, ≥ 0) reached at SC and held to CS.

    The stations are local ``s`` along the road (its start at 0), in the
    chain's units; the slope ramps linearly from 0 at TS to e at SC and back
    to 0 at ST, falling towards the curve's centre (``turn`` +1 left, −1 right).
    """

    ts: float
    sc: float
    cs: float
    st: float
    e: float
    turn: float


@dataclass
class RoadToWrite:
    """One road to write: its chain and what goes with it."""

    chain: Chain
    name: str
    start_station: float = 0.0
    banking: list[Banking] = field(default_factory=list)


def _segment_record(segment: Segment, scale: float) -> tuple[tuple[float, float, float, float], str, dict[str, float]]:
    """((x, y, hdg, length) in metres, element name, element attributes) of one segment."""
    (x, y, tx, ty, _), _ = segment.ends
    hdg = math.atan2(ty, tx)
    if isinstance(segment, Line):
        return (x * scale, y * scale, hdg, segment.length * scale), "line", {}
    if isinstance(segment, Arc):
        return (x * scale, y * scale, hdg, segment.length * scale), "arc", {"curvature": 1.0 / (segment.radius * scale)}
    if isinstance(segment, BezierSpiral):
        cp = segment.control_points * scale
        local = (cp - cp[0]) @ np.array([[math.cos(hdg), -math.sin(hdg)], [math.sin(hdg), math.cos(hdg)]])
        u, v = local[:, 0], local[:, 1]
        coefficients = {
            "aU": 0.0, "bU": 3.0 * u[1], "cU": 3.0 * (u[2] - 2.0 * u[1]), "dU": u[3] - 3.0 * u[2] + 3.0 * u[1],
            "aV": 0.0, "bV": 0.0, "cV": 3.0 * (v[2] - 2.0 * v[1]), "dV": v[3] - 3.0 * v[2] + 3.0 * v[1],
        }  # fmt: skip
        return (cp[0, 0], cp[0, 1], hdg, bezier.arc_length(cp)), "paramPoly3", coefficients
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {segment!r}")


def _superelevation(road: RoadToWrite, scale: float) -> list[tuple[float, float, float]]:
    """(s, a, b) records of the roll angle: linear ramps along the spirals, constant on the arcs.

    OpenDRIVE's superelevation is the roll angle, positive when the road falls
    to the right: a left-turning curve (centre on the left) falls to the left.
    """
    records = [(0.0, 0.0, 0.0)]
    for bank in road.banking:
        roll = -bank.turn * math.atan(bank.e)
        ts, sc, cs, st = (scale * s for s in (bank.ts, bank.sc, bank.cs, bank.st))
        if sc > ts:
            records.append((ts, 0.0, roll / (sc - ts)))
        records.append((sc, roll, 0.0))
        if st > cs:
            records.append((cs, roll, -roll / (st - cs)))
        records.append((st, 0.0, 0.0))
    kept: list[tuple[float, float, float]] = []
    for record in records:  # a later record at the same s replaces the earlier one
        if kept and record[0] <= kept[-1][0]:
            kept[-1] = record
        else:
            kept.append(record)
    return kept


def _lanes(parent: ET.Element, section: CrossSection) -> None:
    lanes = ET.SubElement(parent, "lanes")
    lane_section = ET.SubElement(lanes, "laneSection", s="0.0")

    def lane(side: ET.Element, lane_id: int, kind: str, width: float, mark: str) -> None:
        element = ET.SubElement(side, "lane", id=str(lane_id), type=kind, level="false")
        ET.SubElement(element, "width", sOffset="0.0", a=number(width), b="0.0", c="0.0", d="0.0")
        ET.SubElement(element, "roadMark", sOffset="0.0", type=mark, weight="standard", color="standard", width="0.12")

    left = ET.SubElement(lane_section, "left")
    kinds = [("driving", section.lane_width)] * section.driving_lanes
    if section.shoulder_width > 0:
        kinds.append(("shoulder", section.shoulder_width))
    for k, (kind, width) in reversed(list(enumerate(kinds, 1))):
        lane(left, k, kind, width, "solid" if k == section.driving_lanes else "broken" if kind == "driving" else "none")
    center = ET.SubElement(lane_section, "center")
    middle = ET.SubElement(center, "lane", id="0", type="none", level="false")
    ET.SubElement(middle, "roadMark", sOffset="0.0", type="broken" if section.driving_lanes == 1 else "solid",
                  weight="standard", color="standard", width="0.12")  # fmt: skip
    right = ET.SubElement(lane_section, "right")
    for k, (kind, width) in enumerate(kinds, 1):
        lane(right, -k, kind, width, "solid" if k == section.driving_lanes else "broken" if kind == "driving" else "none")


def opendrive_tree(
    roads: Sequence[RoadToWrite],
    name: str,
    units: str,
    originating_system: str,
    cross_section: CrossSection = CrossSection(),
    geo_reference: str | None = None,
) -> ET.ElementTree:
    """The OpenDRIVE document for ``roads`` (see the module docstring)."""
    scale = to_metres(units)
    root = ET.Element("OpenDRIVE")
    points = np.vstack([r.chain.sample(8) for r in roads]) * scale
    (west, south), (east, north) = points.min(axis=0), points.max(axis=0)
    header = ET.SubElement(
        root, "header", revMajor=str(REV_MAJOR), revMinor=str(REV_MINOR), name=name, version="1",
        date=datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S"), north=number(north), south=number(south),
        east=number(east), west=number(west), vendor=originating_system,
    )  # fmt: skip
    if geo_reference:
        ET.SubElement(header, "geoReference").text = geo_reference
    note = f"design units: {units}; written in metres" + ("" if units == "m" else f" (× {number(scale)})")
    ET.SubElement(header, "userData", code="spiral_cad:units", value=note)
    for index, road in enumerate(roads, 1):
        records = [_segment_record(seg, scale) for seg in road.chain]
        length = sum(r[0][3] for r in records)
        element = ET.SubElement(
            root, "road", id=str(index), junction="-1", length=number(length), name=road.name, rule=cross_section.rule
        )
        plan = ET.SubElement(element, "planView")
        s = 0.0
        for (x, y, hdg, seg_length), kind, attributes in records:
            geometry = ET.SubElement(plan, "geometry", s=number(s), x=number(x), y=number(y), hdg=number(hdg),
                                     length=number(seg_length))  # fmt: skip
            child = ET.SubElement(geometry, kind, {k: number(v) for k, v in attributes.items()})
            if kind == "paramPoly3":
                child.set("pRange", "normalized")
            s += seg_length
        elevation = ET.SubElement(element, "elevationProfile")
        ET.SubElement(elevation, "elevation", s="0.0", a="0.0", b="0.0", c="0.0", d="0.0")
        if road.banking:
            lateral = ET.SubElement(element, "lateralProfile")
            for s0, a, b in _superelevation(road, scale):
                ET.SubElement(lateral, "superelevation", s=number(s0), a=number(a), b=number(b), c="0.0", d="0.0")
        _lanes(element, cross_section)
        ET.SubElement(element, "userData", code="spiral_cad:startStation", value=number(road.start_station * scale))
    ET.indent(root)
    return ET.ElementTree(root)


def write_opendrive(roads: Sequence[RoadToWrite], path: str | os.PathLike, name: str, units: str, originating_system: str,
                    cross_section: CrossSection = CrossSection(), geo_reference: str | None = None) -> None:  # fmt: skip
    """Write ``roads`` as one .xodr file (UTF-8, XML declaration)."""
    tree = opendrive_tree(roads, name, units, originating_system, cross_section, geo_reference)
    tree.write(os.fspath(path), encoding="utf-8", xml_declaration=True)


# ------------------------------------------------------------------ import


@dataclass(frozen=True)
class Geometry:
    """One planView ``<geometry>``: start (x, y, hdg) at road position ``s``, its ``length`` and shape.

    Attributes:
        road: id of the road it belongs to.
        index: its position in the planView.
        s, x, y, hdg, length: the element's attributes (metres, radians).
        kind: ``"line"``, ``"arc"``, ``"spiral"``, ``"paramPoly3"`` or ``"poly3"``.
        params: the shape's attributes (curvature, curvStart/curvEnd, aU…dV
            and pRange, a…d).
    """

    road: str
    index: int
    s: float
    x: float
    y: float
    hdg: float
    length: float
    kind: str
    params: dict

    def local(self, t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Points, unit tangents and signed curvature at ``t`` ∈ [0, 1] of the element's
        own parameter (arc length for lines, arcs and spirals; p for the polynomials),
        in the local frame at (x, y) with heading hdg."""
        t = np.asarray(t, dtype=float)
        L, p = self.length, self.params
        if self.kind in ("line", "arc", "spiral"):
            k0, k1 = (0.0, 0.0) if self.kind == "line" else (p["curvature"],) * 2 if self.kind == "arc" else (p["curvStart"], p["curvEnd"])
            return _clothoid(t * L, k0, (k1 - k0) / L)
        if self.kind == "paramPoly3":
            top = 1.0 if p["pRange"] == "normalized" else L
            u = (p["aU"], p["bU"], p["cU"], p["dU"])
            v = (p["aV"], p["bV"], p["cV"], p["dV"])
            return _parametric(u, v, t * top)
        return _parametric((0.0, 1.0, 0.0, 0.0), (p["a"], p["b"], p["c"], p["d"]), t * self._poly3_end())

    def _poly3_end(self) -> float:
        """The u where the deprecated poly3's arc length reaches ``length``."""
        b, c, d = self.params["b"], self.params["c"], self.params["d"]

        def arc(u_end: float) -> float:
            return quad(lambda u: math.hypot(1.0, b + u * (2 * c + 3 * d * u)), 0.0, u_end, epsabs=0.0, epsrel=1e-13)[0] - self.length

        return brentq(arc, 0.0, self.length, xtol=1e-15 * self.length, rtol=1e-15)

    def evaluate(self, t) -> tuple[NDArray, NDArray, NDArray]:
        """World points, unit tangents and signed curvature at ``t`` ∈ [0, 1] (see ``local``)."""
        points, tangents, curvature = self.local(t)
        c, s = math.cos(self.hdg), math.sin(self.hdg)
        rotation = np.array([[c, s], [-s, c]])  # row vectors times this rotate by hdg
        return points @ rotation + (self.x, self.y), tangents @ rotation, curvature

    @cached_property
    def _start_end_middle(self) -> tuple[Frame, Frame, Frame]:
        """Start, end and middle frames, evaluated once (NaN where a tangent or curvature is not defined)."""
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy's quad on a poly3 that is not a function of u
            points, tangents, curvature = self.evaluate([0.0, 1.0, 0.5])
        return tuple(
            (p[0], p[1], 0.0, t[0], t[1], 0.0, -t[1] * k, t[0] * k, 0.0)
            for p, t, k in zip(points.tolist(), tangents.tolist(), curvature.tolist())
        )

    def frames(self) -> tuple[Frame, Frame]:
        """Start and end frames (point, unit tangent, curvature vector; z = 0) for the joint checks."""
        return self._start_end_middle[0], self._start_end_middle[1]

    def segment(self) -> Segment | None:
        """The exact segment (Line, Arc, BezierSpiral for paramPoly3), or None (clothoid, poly3)."""
        if self.kind not in ("line", "arc"):
            return self._bezier() if self.kind == "paramPoly3" else None
        (start, end), (t0, _), _ = self.evaluate([0.0, 1.0])
        k = self.params.get("curvature", 0.0)
        if k == 0.0:
            return Line(start, end)
        center = start + np.array([-t0[1], t0[0]]) / k
        angle = math.atan2(start[1] - center[1], start[0] - center[0])
        return Arc(center, 1.0 / k, angle, abs(k) * self.length)

    def _bezier(self) -> BezierSpiral:
        """A paramPoly3 as the cubic Bézier it is: power basis → control points, then placed."""
        p = self.params
        top = 1.0 if p["pRange"] == "normalized" else self.length
        local = np.empty((4, 2))
        for j, axis in enumerate("UV"):
            a, b, c, d = (p[f"{name}{axis}"] * top**n for n, name in enumerate("abcd"))
            local[:, j] = (a, a + b / 3.0, a + 2.0 * b / 3.0 + c / 3.0, a + b + c + d)
        c, s = math.cos(self.hdg), math.sin(self.hdg)
        return BezierSpiral.from_control_points(local @ np.array([[c, s], [-s, c]]) + (self.x, self.y))


def _clothoid(s: NDArray, k0: float, rate: float) -> tuple[NDArray, NDArray, NDArray]:
    """Local points, tangents and curvature at arc lengths ``s`` of the curve with κ = k0 + rate·s.

    Lines and arcs in closed form; a clothoid by Fresnel integrals after
    completing the square of its heading k0·s + rate·s²/2.
    """
    heading = k0 * s + 0.5 * rate * s * s
    tangents = np.stack([np.cos(heading), np.sin(heading)], axis=-1)
    curvature = k0 + rate * s
    if rate == 0.0:
        if k0 == 0.0:
            points = np.stack([s, np.zeros_like(s)], axis=-1)
        else:
            points = np.stack([np.sin(k0 * s) / k0, (1.0 - np.cos(k0 * s)) / k0], axis=-1)
        return points, tangents, curvature
    sign = math.copysign(1.0, rate)
    a = math.sqrt(math.pi / abs(rate))
    phase = k0 * k0 / (2.0 * rate)  # heading = (rate/2)(s + k0/rate)² − phase
    w0 = (k0 / rate) / a
    w = (s + k0 / rate) / a
    S, C = fresnel(w)
    S0, C0 = fresnel(w0)
    dC, dS = C - C0, S - S0
    x = a * (math.cos(phase) * dC + sign * math.sin(phase) * dS)
    y = a * (sign * math.cos(phase) * dS - math.sin(phase) * dC)
    return np.stack([x, y], axis=-1), tangents, curvature


def _cubic(coefficients: tuple[float, float, float, float], p: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """a + b·p + c·p² + d·p³ and its first two derivatives at ``p``."""
    a, b, c, d = coefficients
    return a + p * (b + p * (c + p * d)), b + p * (2.0 * c + 3.0 * d * p), 2.0 * c + 6.0 * d * p


def _parametric(u: tuple, v: tuple, p: NDArray):
    """Points, unit tangents and curvature of the parametric cubic (u(p), v(p))."""
    (x, x1, x2), (y, y1, y2) = _cubic(u, p), _cubic(v, p)
    speed = np.hypot(x1, y1)
    with np.errstate(divide="ignore", invalid="ignore"):  # speed 0 (bU = bV = 0): no tangent, NaN
        return np.stack([x, y], axis=-1), np.stack([x1 / speed, y1 / speed], axis=-1), (x1 * y2 - y1 * x2) / speed**3


@dataclass(frozen=True)
class Road:
    """One road's planView as read from an OpenDRIVE file (metres)."""

    id: str
    name: str
    length: float
    geometries: tuple[Geometry, ...]

    @property
    def exact(self) -> bool:
        """True when the planView holds only lines, arcs and paramPoly3 (it can become a Chain)."""
        return all(g.kind in ("line", "arc", "paramPoly3") for g in self.geometries)

    def chain(self, tolerance: float = 1e-9) -> Chain:
        """The planView as a G2 ``Chain`` in metres.

        Raises:
            ValueError: clothoids or poly3 in the planView, or a joint that is
                not G2 (a Chain is G2 by construction; ``check_opendrive``
                reports such joints).
        """
        if not self.exact:
            kinds = sorted({g.kind for g in self.geometries} - {"line", "arc", "paramPoly3"})
            raise ValueError(f"road {self.id}: {', '.join(kinds)} geometries have no exact Chain form")
        segments = []
        for g in self.geometries:
            try:
                with np.errstate(all="ignore"):
                    segments.append(g.segment())
            except (ValueError, ArithmeticError) as error:  # a geometry at the edge of the float range
                raise ValueError(f"road {self.id}, planView geometry {g.index} <{g.kind}>: no exact segment ({error})") from None
        try:
            with np.errstate(all="ignore"):  # a joint at the edge of the float range is refused, not warned about
                return Chain(segments, tolerance, units="m")
        except (ValueError, ArithmeticError) as error:
            raise ValueError(f"road {self.id}: {error}") from None

    def sample(self, per_geometry: int = 32) -> NDArray:
        """Points along the planView (for plots and comparisons)."""
        t = np.linspace(0.0, 1.0, per_geometry)
        return np.vstack([g.evaluate(t)[0] for g in self.geometries])


_KINDS = {
    "line": (),
    "arc": ("curvature",),
    "spiral": ("curvStart", "curvEnd"),
    "paramPoly3": ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV"),
    "poly3": ("a", "b", "c", "d"),
}


def _real(element: ET.Element, name: str, where: str) -> float:
    text = element.get(name)
    if text is None:
        raise ValueError(f"{where}: missing attribute {name}")
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: {name} must be a number; got {text!r:.40}") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: {name} must be finite; got {text!r:.40}")
    return value


def _label(value: str) -> str:
    """A road id for messages: as written if short and printable, else quoted and cut."""
    return value if value.isprintable() and 0 < len(value) <= 64 else repr(value[:40]) + ("…" if len(value) > 40 else "")


def _geometry(road: str, index: int, element: ET.Element) -> Geometry:
    where = f"road {road}, planView geometry {index}"
    s, x, y, hdg, length = (_real(element, name, where) for name in ("s", "x", "y", "hdg", "length"))
    if not length > 0.0:
        raise ValueError(f"{where}: length must be positive; got {length!r}")
    if s < 0.0:
        raise ValueError(f"{where}: s must be ≥ 0; got {s!r}")
    shapes = [child for child in element if child.tag in _KINDS]
    others = [child.tag for child in element if child.tag not in _KINDS and child.tag not in ("userData", "include", "dataQuality")]
    if others or len(shapes) != 1:
        raise ValueError(
            f"{where}: needs exactly one of {', '.join(_KINDS)}; found {', '.join(others + [c.tag for c in shapes]) or 'none'}"
        )
    (shape,) = shapes
    params: dict = {name: _real(shape, name, f"{where} <{shape.tag}>") for name in _KINDS[shape.tag]}
    if shape.tag == "paramPoly3":
        params["pRange"] = shape.get("pRange", "normalized")
        if params["pRange"] not in ("normalized", "arcLength"):
            raise ValueError(f"{where} <paramPoly3>: pRange must be normalized or arcLength; got {params['pRange']!r:.40}")
    geometry = Geometry(road, index, s, x, y, hdg, length, shape.tag, params)
    numbers = ", ".join(f"{k}={v!r}" for k, v in {"x": x, "y": y, "hdg": hdg, "length": length, **params}.items())
    try:
        ends = geometry._start_end_middle
    except (ValueError, ArithmeticError, RuntimeError) as error:  # e.g. a clothoid whose phase overflows
        raise ValueError(f"{where} <{shape.tag}>: cannot be evaluated ({error}; {numbers})") from None
    bad = next((name for name, f in zip(("start", "end", "middle"), ends) if not all(map(math.isfinite, f[:2]))), None)
    if bad is not None:
        raise ValueError(f"{where} <{shape.tag}>: its {bad} point is not a finite number ({numbers})")
    return geometry


def read_opendrive(path: str | os.PathLike) -> list[Road]:
    """Every road's planView of an OpenDRIVE file (any revision), in metres.

    Every geometry is evaluated at its start, middle and end as it is read,
    so a road whose points are not finite numbers (a line at 1e308, an arc
    of curvature 1e308) is refused here rather than measured as NaN.

    Raises:
        ValueError: unreadable or malformed XML, a root that is not
            ``OpenDRIVE``, a road without a planView, an unknown or missing
            geometry element, a number that is not finite, a non-positive
            length, geometries out of ``s`` order, or a geometry that does
            not evaluate to finite points — naming the road id and the element.
    """
    label = os.path.basename(os.fspath(path))
    if not os.path.isfile(path):
        raise ValueError(f"cannot read {label}: " + ("not a regular file" if os.path.exists(path) else "no such file"))
    try:
        root = ET.parse(os.fspath(path)).getroot()
    except ET.ParseError as error:
        raise ValueError(f"{label}: not well-formed XML ({error})") from None
    except OSError as error:
        raise ValueError(f"cannot read {label}: {error.strerror}") from None
    if root.tag != "OpenDRIVE":
        raise ValueError(f"{label}: the root element is <{root.tag}>, not <OpenDRIVE>")
    roads = []
    for number_, element in enumerate(root.findall("road")):
        road_id = _label(element.get("id", f"#{number_}"))
        plan = element.find("planView")
        if plan is None:
            raise ValueError(f"{label}: road {road_id} has no planView")
        geometries = tuple(_geometry(road_id, i, g) for i, g in enumerate(plan.findall("geometry")))
        if not geometries:
            raise ValueError(f"{label}: road {road_id}: the planView has no geometry")
        for a, b in zip(geometries, geometries[1:]):
            if not b.s > a.s:
                raise ValueError(f"{label}: road {road_id}, planView geometry {b.index}: s = {b.s!r} is not after s = {a.s!r} of geometry {a.index}")
        length = _real(element, "length", f"{label}: road {road_id}") if element.get("length") else sum(g.length for g in geometries)
        if not length > 0.0:
            raise ValueError(f"{label}: road {road_id}: length must be positive; got {length!r}")
        roads.append(Road(road_id, element.get("name", ""), length, geometries))
    if not roads:
        raise ValueError(f"{label}: no <road> elements")
    return roads


def check_opendrive(
    path: str | os.PathLike, *, gap_tol: float = 1e-7, angle_tol: float = 1e-7, curvature_tol: float = 1e-6
) -> ContinuityReport:
    """G0/G1/G2 at every joint between consecutive geometries of every road (metres).

    Each road is one piece; the measures and tolerances are those of the
    STEP/IGES checker (``spiral_cad.formats.joints``).

    Raises:
        ValueError: an unreadable file (see ``read_opendrive``) or a bad tolerance.
    """
    check_tolerances(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol)
    roads = read_opendrive(path)
    source = os.path.basename(os.fspath(path))
    pieces = [("road", [g.frames() for g in road.geometries], False, road.id) for road in roads]
    points = [f[:3] for road in roads for g in road.geometries for f in g._start_end_middle]
    return classify_pieces(
        pieces, model_size(points, source), gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
        source=source, element="geometry", units="m",
    )  # fmt: skip
