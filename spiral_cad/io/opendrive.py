"""ASAM OpenDRIVE 1.8: exact export of roads in 3-D; reading and checking (their public names).

Export (``write_opendrive``, public as ``spiral_cad.cad.export.export_opendrive``):
every chain becomes one ``<road>`` whose ``planView`` holds its segments in
travel order:

* ``Line`` → ``<line/>``;
* ``Arc`` → ``<arc curvature="κ"/>`` (signed, left positive);
* ``BezierSpiral`` → ``<paramPoly3 pRange="normalized">``: the cubic itself,
  in the local frame at the spiral's start (x, y) and start heading (hdg),
  so that ``aU = aV = bV = 0`` and ``bU > 0``; ``@length`` is the true arc
  length (composite Gauss–Legendre, ≤ 1e-13 relative, all spirals at once).

OpenDRIVE lengths are metres: a design in another unit is converted (and
says so in the header's ``userData``). ``@s`` runs from 0 at the start of
each road (the chain's own stations); the design's start station is
recorded as ``userData`` (chainage = start station + s). Every number is
written as the shortest decimal that reads back to the same double (at most
17 significant digits), converted an array at a time.

A road a simulator can drive: ``lanes`` from a :class:`CrossSection`
(default: one 3.5 m driving lane each way and 2.5 m shoulders, right-hand
traffic); an ``elevationProfile`` of the profile's exact pieces (grades and
parabolas: ``c`` set, ``d`` = 0; level at 0 without a profile); and, when
the superelevation is known, a ``lateralProfile`` of its exact cubics
(``spiral_cad.design.superelevation``: C1 at every ramp end). The document
is written as text in one pass over arrays.

Reading (``read_opendrive``, ``read_network``: ``opendrive_read``) and
checking (``check_opendrive``: ``opendrive_check``) are imported here under
their public names.

Needs no CAD kernel.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any, overload
from xml.sax.saxutils import escape

import numpy as np
from numpy.typing import NDArray

from ..core.chain import Chain
from ..core.inputs import shown
from ..core.kinds import ARC, LINE, SPIRAL
from ..core.segments import row_frames
from ..core.units import to_metres
from .decimals import shortest_decimal
from .opendrive_check import LinkReport, OpenDriveReport, ProfileReport, check_opendrive
from .opendrive_read import (
    Connection,
    Geometry,
    Junction,
    Link,
    Network,
    Plan,
    Road,
    read_network,
    read_opendrive,
    records_at,
)

__all__ = [
    "Connection", "CrossSection", "Geometry", "Junction", "Link", "LinkReport", "Network", "OpenDriveReport", "Plan",
    "ProfileReport", "Road", "RoadToWrite", "check_opendrive", "read_network", "read_opendrive",
    "records_at", "write_opendrive",
]  # fmt: skip

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
            raise ValueError(f"driving_lanes must be a positive integer; got {shown(self.driving_lanes)}")
        for name in ("lane_width", "shoulder_width", "crossfall", "depth"):
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number ≥ 0; got {shown(value)}")
        for name in ("lane_width", "depth"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive (m); got {shown(getattr(self, name))}")
        if not self.crossfall < 1:
            raise ValueError(f"crossfall must be below 1 (m/m); got {shown(self.crossfall)}")
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


def plan_records(chain: Chain, scale: float) -> dict[str, Any]:
    """The planView of ``chain`` in metres, as arrays, from the chain's own rows (no segment objects).

    Keys: ``kind`` (``LINE``, ``ARC``, ``SPIRAL`` of ``spiral_cad.core.rows``),
    ``x``, ``y``, ``hdg``, ``length``, ``s`` (the chain's station at the start
    of each geometry), ``curvature`` (arcs), ``poly`` (N, 5) the paramPoly3
    coefficients bU, cU, dU, cV, dV of the spirals in their own frame
    (aU = aV = bV = 0), ``box`` (west, south, east, north) and ``total`` (the
    road's length).

    Raises:
        ValueError: a chain in space (OpenDRIVE's planView is plane).
    """
    if chain.dim != 2:
        raise ValueError("OpenDRIVE's planView holds plane chains; this chain lies in space")
    rows = chain.rows
    kind = np.array(rows.kind)
    # writable copies: the compiled kernel the chain itself ran (read-only views would compile another)
    frames, _, _ = row_frames(kind, np.array(rows.geometry), np.array(rows.params), rows.dim)
    hdg = np.arctan2(frames[:, 0, 4], frames[:, 0, 3])
    length = chain.lengths  # spirals measured once, by the chain (composite Gauss–Legendre)
    spiral, arc = kind == SPIRAL, kind == ARC
    poly = np.zeros((len(kind), 5))
    points = [frames[:, 0, :2], frames[:, 1, :2]]
    if spiral.any():
        cp = rows.geometry[spiral, :, :2]
        c, s = np.cos(hdg[spiral])[:, None], np.sin(hdg[spiral])[:, None]
        delta = cp - cp[:, :1]
        u = delta[..., 0] * c + delta[..., 1] * s  # the spiral in its own frame (start, heading)
        v = delta[..., 1] * c - delta[..., 0] * s
        poly[spiral] = np.stack([3.0 * u[:, 1], 3.0 * (u[:, 2] - 2.0 * u[:, 1]), u[:, 3] - 3.0 * u[:, 2] + 3.0 * u[:, 1],
                                 3.0 * (v[:, 2] - 2.0 * v[:, 1]), v[:, 3] - 3.0 * v[:, 2] + 3.0 * v[:, 1]], axis=1) * scale  # fmt: skip
        points.append(cp.reshape(-1, 2))  # the hull of the control points holds each spiral
    radius = np.where(arc, rows.params[:, 0], np.inf)
    if arc.any():
        r, a0, sweep = rows.params[arc].T
        points.append(_arc_extremes(np.column_stack([rows.geometry[arc, 0, :2], np.abs(r), a0, np.copysign(sweep, r)])))
    box = np.vstack(points)
    return {
        "kind": kind, "x": frames[:, 0, 0] * scale, "y": frames[:, 0, 1] * scale, "hdg": hdg, "length": length * scale,
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
            lines.append(
                f'        <paramPoly3 aU="0.0" bU="{bu}" cU="{cu}" dU="{du}" aV="0.0" bV="0.0" cV="{cv}" dV="{dv}" pRange="normalized" />'
            )
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


@overload
def _scaled(rows: NDArray, scale: float, powers: tuple[int, ...]) -> NDArray: ...
@overload
def _scaled(rows: None, scale: float, powers: tuple[int, ...]) -> None: ...
@overload
def _scaled(rows: NDArray | None, scale: float, powers: tuple[int, ...]) -> NDArray | None: ...
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
    date = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%S")
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
        lines.append(f'  <road id="{index}" junction="-1" length="{number(float(plan["total"]))}" name={_attribute(road.name)} '
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
