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
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timezone
from xml.sax.saxutils import escape

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
from .joints import ContinuityReport, Frame, check_tolerances, classify_pieces

REV_MAJOR, REV_MINOR = 1, 8


def number(value: float) -> str:
    """An OpenDRIVE number: the shortest round-trip decimal."""
    return shortest_decimal(value, "OpenDRIVE")


# ------------------------------------------------------------------ export


@dataclass(frozen=True)
class CrossSection:
    """A road's cross-section (metres; OpenDRIVE lane widths are always metres).

    Attributes:
        driving_lanes: driving lanes on each side of the reference line.
        lane_width: width of each driving lane.
        shoulder_width: width of the shoulder outside the driving lanes (0: none).
        rule: ``"RHT"`` (right-hand traffic) or ``"LHT"``.
        crossfall: the crown's cross slope on tangents (m/m; both sides fall
            outwards). The corridor solid has it; OpenDRIVE gets only the
            superelevation, the roll of the whole road.
        depth: the pavement's thickness under the surface (corridor solids).
    """

    driving_lanes: int = 1
    lane_width: float = 3.5
    shoulder_width: float = 2.5
    rule: str = "RHT"
    crossfall: float = 0.025
    depth: float = 0.5

    def __post_init__(self) -> None:
        if not (isinstance(self.driving_lanes, int) and self.driving_lanes >= 1):
            raise ValueError(f"driving_lanes must be a positive integer; got {self.driving_lanes!r}")
        for name in ("lane_width", "shoulder_width", "crossfall", "depth"):
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number ≥ 0; got {value!r}")
        for name in ("lane_width", "depth"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive (m); got {getattr(self, name)!r}")
        if not self.crossfall < 1:
            raise ValueError(f"crossfall must be below 1 (m/m); got {self.crossfall!r}")
        if self.rule not in ("RHT", "LHT"):
            raise ValueError(f"rule must be 'RHT' or 'LHT'; got {self.rule!r}")


@dataclass
class RoadToWrite:
    """One road to write: its chain and what goes with it.

    Attributes:
        chain: the reference line.
        name: the road's name.
        start_station: the chainage of the chain's start (``userData``).
        elevation: (m, 4) rows (s, a, b, c): z = a + b·d + c·d² from local s
            (0 at the chain's start) on, in the chain's unit; None: level at 0.
        superelevation: (m, 5) rows (s, a, b, c, d): the roll angle (radians)
            as a cubic in the distance from s; None or all zero: none written.
    """

    chain: Chain
    name: str
    start_station: float = 0.0
    elevation: NDArray | None = None
    superelevation: NDArray | None = None


#: Kinds of planView records.
LINE, ARC, SPIRAL = 0, 1, 2


def plan_records(chain: Chain, scale: float) -> dict[str, NDArray]:
    """The planView of ``chain`` in metres, as arrays (one pass over the segments, then vectorised).

    Keys: ``kind`` (LINE, ARC, SPIRAL), ``x``, ``y``, ``hdg``, ``length``,
    ``s`` (the chain's station at the start of each geometry), ``curvature``
    (arcs), ``poly`` (N, 5) the paramPoly3 coefficients bU, cU, dU, cV, dV of
    the spirals in their own frame (aU = aV = bV = 0), ``box`` (west, south,
    east, north) and ``total`` (the road's length).
    """
    segments = chain.segments
    count = len(segments)
    kind = np.empty(count, dtype=np.int8)
    frames = np.empty((count, 4))
    length = np.empty(count)
    radius = np.full(count, np.inf)
    spirals: list[NDArray] = []
    arcs: list[tuple[float, float, float, float, float]] = []
    for k, segment in enumerate(segments):
        frames[k] = segment.ends[0][:4]
        if isinstance(segment, BezierSpiral):
            kind[k] = SPIRAL
            spirals.append(segment.control_points)
        elif isinstance(segment, Arc):
            kind[k] = ARC
            radius[k] = segment.radius
            length[k] = segment.length
            (cx, cy), r = segment.center.tolist(), segment.radius
            arcs.append((cx, cy, abs(r), segment.start_angle, math.copysign(segment.sweep, r)))
        elif isinstance(segment, Line):
            kind[k] = LINE
            length[k] = segment.length
        else:
            raise ValueError(f"segment {k} must be a Line, Arc or BezierSpiral; got {segment!r}")
    hdg = np.arctan2(frames[:, 3], frames[:, 2])
    spiral = kind == SPIRAL
    poly = np.zeros((count, 5))
    points = [frames[:, :2], np.array([s.ends[1][:2] for s in segments])]
    if spirals:
        cp = np.array(spirals)
        length[spiral] = bezier.arc_length(cp)  # one batched quadrature
        c, s = np.cos(hdg[spiral])[:, None], np.sin(hdg[spiral])[:, None]
        delta = cp - cp[:, :1]
        u = delta[..., 0] * c + delta[..., 1] * s  # the spiral in its own frame (start, heading)
        v = delta[..., 1] * c - delta[..., 0] * s
        poly[spiral] = np.stack([3.0 * u[:, 1], 3.0 * (u[:, 2] - 2.0 * u[:, 1]), u[:, 3] - 3.0 * u[:, 2] + 3.0 * u[:, 1],
                                 3.0 * (v[:, 2] - 2.0 * v[:, 1]), v[:, 3] - 3.0 * v[:, 2] + 3.0 * v[:, 1]], axis=1) * scale  # fmt: skip
        points.append(cp.reshape(-1, 2))  # the hull of the control points holds each spiral
    if arcs:
        points.append(_arc_extremes(np.array(arcs)))
    box = np.vstack(points)
    return {
        "kind": kind, "x": frames[:, 0] * scale, "y": frames[:, 1] * scale, "hdg": hdg, "length": length * scale,
        "s": chain.stations[:-1] * scale, "curvature": 1.0 / (radius * scale), "poly": poly,
        "box": np.concatenate([box.min(axis=0), box.max(axis=0)]) * scale, "total": chain.length * scale,
    }  # fmt: skip


def _arc_extremes(arcs: NDArray) -> NDArray:
    """The points of arcs (cx, cy, r, start angle, signed sweep) furthest along ±x and ±y that lie on them."""
    cx, cy, r, a0, sweep = arcs.T
    out = []
    for angle in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
        turned = np.mod(np.sign(sweep) * (angle - a0), 2.0 * math.pi)
        on = turned <= np.abs(sweep)
        out.append(np.stack([cx + r * math.cos(angle), cy + r * math.sin(angle)], axis=1)[on])
    return np.vstack(out) if out else np.empty((0, 2))


def decimals(values: NDArray) -> list[str]:
    """Shortest round-trip decimals of an array (``number`` for many values at once)."""
    values = np.asarray(values, dtype=float)
    if not np.isfinite(values).all():
        number(float(values[~np.isfinite(values)].ravel()[0]))  # raises, naming the value
    return list(map(repr, (values + 0.0).ravel().tolist()))


def _attribute(text: str) -> str:
    """``text`` as a double-quoted XML attribute value."""
    return '"' + escape(text, {'"': "&quot;", "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}) + '"'


def _plan_view(plan: dict[str, NDArray]) -> list[str]:
    """The ``<planView>`` lines of one road."""
    s, x, y, hdg, length = (decimals(plan[key]) for key in ("s", "x", "y", "hdg", "length"))
    kind = plan["kind"].tolist()
    arcs = iter(decimals(plan["curvature"][plan["kind"] == ARC]))
    polys = iter(zip(*(iter(decimals(plan["poly"][plan["kind"] == SPIRAL])),) * 5))
    lines = ["    <planView>"]
    for k in range(len(kind)):
        lines.append(f'      <geometry s="{s[k]}" x="{x[k]}" y="{y[k]}" hdg="{hdg[k]}" length="{length[k]}">')
        if kind[k] == LINE:
            lines.append("        <line />")
        elif kind[k] == ARC:
            lines.append(f'        <arc curvature="{next(arcs)}" />')
        else:
            bu, cu, du, cv, dv = next(polys)
            lines.append(f'        <paramPoly3 aU="0.0" bU="{bu}" cU="{cu}" dU="{du}" aV="0.0" bV="0.0" cV="{cv}" dV="{dv}" pRange="normalized" />')
        lines.append("      </geometry>")
    lines.append("    </planView>")
    return lines


def _polynomials(tag: str, element: str, rows: NDArray) -> list[str]:
    """``<tag>`` holding one ``<element s a b c d>`` per row."""
    cells = np.asarray(rows, dtype=float)
    cells = np.hstack([cells, np.zeros((len(cells), 5 - cells.shape[1]))])
    text = iter(decimals(cells))
    lines = [f"    <{tag}>"]
    for _ in range(len(cells)):
        s, a, b, c, d = (next(text) for _ in range(5))
        lines.append(f'      <{element} s="{s}" a="{a}" b="{b}" c="{c}" d="{d}" />')
    return lines + [f"    </{tag}>"]


def _scaled(rows: NDArray | None, scale: float, powers: tuple[int, ...]) -> NDArray | None:
    """Polynomial rows (s, a, b, …) in the design's unit converted to metres: s·scale and each
    coefficient times scale**power (a value is a length: 1; a roll angle: 0)."""
    if rows is None:
        return None
    rows = np.asarray(rows, dtype=float)
    return rows * (scale ** np.array((1, *powers), dtype=float))


def _lanes(section: CrossSection) -> list[str]:
    kinds = [("driving", section.lane_width)] * section.driving_lanes
    if section.shoulder_width > 0:
        kinds.append(("shoulder", section.shoulder_width))

    def lane(lane_id: int, kind: str, width: float, mark: str) -> list[str]:
        return [
            f'            <lane id="{lane_id}" type="{kind}" level="false">',
            f'              <width sOffset="0.0" a="{number(width)}" b="0.0" c="0.0" d="0.0" />',
            f'              <roadMark sOffset="0.0" type="{mark}" weight="standard" color="standard" width="0.12" />',
            "            </lane>",
        ]

    def mark(k: int, kind: str) -> str:
        return "solid" if k == section.driving_lanes else "broken" if kind == "driving" else "none"

    lines = ["    <lanes>", '      <laneSection s="0.0">', "        <left>"]
    for k, (kind, width) in reversed(list(enumerate(kinds, 1))):
        lines += lane(k, kind, width, mark(k, kind))
    centre = "broken" if section.driving_lanes == 1 else "solid"
    lines += ["        </left>", "        <center>", '          <lane id="0" type="none" level="false">',
              f'            <roadMark sOffset="0.0" type="{centre}" weight="standard" color="standard" width="0.12" />',
              "          </lane>", "        </center>", "        <right>"]  # fmt: skip
    for k, (kind, width) in enumerate(kinds, 1):
        lines += lane(-k, kind, width, mark(k, kind))
    return lines + ["        </right>", "      </laneSection>", "    </lanes>"]


def opendrive_text(
    roads: Sequence[RoadToWrite],
    name: str,
    units: str,
    originating_system: str,
    cross_section: CrossSection = CrossSection(),
    geo_reference: str | None = None,
) -> str:
    """The OpenDRIVE document for ``roads`` as text (see the module docstring)."""
    scale = to_metres(units)
    plans = [plan_records(road.chain, scale) for road in roads]
    boxes = np.array([plan["box"] for plan in plans])
    west, south = boxes[:, :2].min(axis=0)
    east, north = boxes[:, 2:].max(axis=0)
    date = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S")
    lines = [
        "<?xml version='1.0' encoding='utf-8'?>",
        "<OpenDRIVE>",
        f'  <header revMajor="{REV_MAJOR}" revMinor="{REV_MINOR}" name={_attribute(name)} version="1" date="{date}" '
        f'north="{number(north)}" south="{number(south)}" east="{number(east)}" west="{number(west)}" '
        f"vendor={_attribute(originating_system)}>",
    ]
    if geo_reference:
        lines.append(f"    <geoReference>{escape(geo_reference)}</geoReference>")
    note = f"design units: {units}; written in metres" + ("" if units == "m" else f" (× {number(scale)})")
    lines += [f'    <userData code="spiral_cad:units" value={_attribute(note)} />', "  </header>"]
    lanes = _lanes(cross_section)
    for index, (road, plan) in enumerate(zip(roads, plans), 1):
        lines.append(f'  <road id="{index}" junction="-1" length="{number(plan["total"])}" name={_attribute(road.name)} '
                     f'rule="{cross_section.rule}">')  # fmt: skip
        lines += _plan_view(plan)
        elevation = _scaled(road.elevation, scale, (1, 0, -1)) if road.elevation is not None else np.zeros((1, 4))
        lines += _polynomials("elevationProfile", "elevation", elevation)
        roll = _scaled(road.superelevation, scale, (0, -1, -2, -3))
        if roll is not None and roll[:, 1:].any():
            lines += _polynomials("lateralProfile", "superelevation", roll)
        lines += lanes
        lines.append(f'    <userData code="spiral_cad:startStation" value="{number(road.start_station * scale)}" />')
        lines.append("  </road>")
    lines.append("</OpenDRIVE>\n")
    return "\n".join(lines)


def write_opendrive(roads: Sequence[RoadToWrite], path: str | os.PathLike, name: str, units: str, originating_system: str,
                    cross_section: CrossSection = CrossSection(), geo_reference: str | None = None) -> None:  # fmt: skip
    """Write ``roads`` as one .xodr file (UTF-8, XML declaration)."""
    text = opendrive_text(roads, name, units, originating_system, cross_section, geo_reference)
    with open(os.fspath(path), "w", encoding="utf-8", newline="\n") as handle:
        handle.write(text)


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

    def frames(self) -> tuple[Frame, Frame]:
        """Start and end frames (point, unit tangent, curvature vector; z = 0) for the joint checks."""
        points, tangents, curvature = self.evaluate([0.0, 1.0])
        return tuple(
            (p[0], p[1], 0.0, t[0], t[1], 0.0, -t[1] * k, t[0] * k, 0.0) for p, t, k in zip(points, tangents, curvature)
        )

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
        try:
            return Chain([g.segment() for g in self.geometries], tolerance, units="m")
        except ValueError as error:
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
    return Geometry(road, index, s, x, y, hdg, length, shape.tag, params)


def read_opendrive(path: str | os.PathLike) -> list[Road]:
    """Every road's planView of an OpenDRIVE file (any revision), in metres.

    Raises:
        ValueError: unreadable or malformed XML, a root that is not
            ``OpenDRIVE``, a road without a planView, an unknown or missing
            geometry element, a non-finite or non-positive length, or
            geometries out of ``s`` order — naming the road id and the element.
    """
    label = os.path.basename(os.fspath(path))
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
        road_id = element.get("id", f"#{number_}")
        plan = element.find("planView")
        if plan is None:
            raise ValueError(f"{label}: road {road_id} has no planView")
        geometries = tuple(_geometry(road_id, i, g) for i, g in enumerate(plan.findall("geometry")))
        if not geometries:
            raise ValueError(f"{label}: road {road_id}: the planView has no geometry")
        for a, b in zip(geometries, geometries[1:]):
            if not b.s > a.s:
                raise ValueError(f"{label}: road {road_id}, planView geometry {b.index}: s = {b.s!r} is not after s = {a.s!r} of geometry {a.index}")
        length = element.get("length")
        roads.append(Road(road_id, element.get("name", ""), float(length) if length else sum(g.length for g in geometries), geometries))
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
    pieces, points = [], []
    for road in roads:
        frames = [g.frames() for g in road.geometries]
        pieces.append(("road", frames, False))
        for g, (start, end) in zip(road.geometries, frames):
            middle = g.evaluate([0.5])[0][0]
            points += [start[:3], end[:3], (middle[0], middle[1], 0.0)]
    return classify_pieces(
        pieces, points, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
        source=os.path.basename(os.fspath(path)), element="geometry",
    )  # fmt: skip
