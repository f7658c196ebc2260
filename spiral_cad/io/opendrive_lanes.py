"""OpenDRIVE lanes at road ends: what a driver follows through a junction.

The lane model needed to judge a junction lane by lane: every road's
``laneOffset`` records, its lane sections and their lanes' ``width``
polynomials, and every junction connection's ``laneLink`` pairs, read in one
pass of expat (``read_lanes``). ``lane_frame`` places the centre of one lane
at one end of a road as a joint-check frame in 3-D: point, unit tangent and
curvature vector.

How the lane centre is placed and differentiated (all in closed form, no
sampling): with the reference line's point C(s), unit tangent T, left normal
N, curvature κ and its rate κ' = dκ/ds, the lane centre lies at the lateral
offset t(s) = laneOffset(s) ± (inner lanes' widths + half the lane's own),
left lanes (id > 0) on +N, right lanes on −N. A superelevation φ(s) tilts
the cross-section about the reference line, so the plan offset is
h = t·cosφ and the height above the reference line g = t·sinφ. Differentiating
P(s) = C + h·N + (e + g)·k (e: elevation, k: up) with T' = κN, N' = −κT:

    P'  = (1 − κh)·T + h'·N + (e' + g')·k
    P'' = (−κ'h − 2κh')·T + (κ(1 − κh) + h'')·N + (e'' + g'')·k

so the unit tangent is P'/|P'| and the curvature vector (P'' − (P''·u)u)/|P'|²
with u the unit tangent: in plan alone this is the offset curve's
κ/(1 − κh) plus the width's second-derivative term. Lane ``border`` records
(instead of widths) are refused by name.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from xml.parsers import expat

import numpy as np
from numpy.typing import NDArray

from ..continuity.joints import Frame
from .opendrive_read import Geometry, Road, _label, records_at


@dataclass(frozen=True)
class Lane:
    """One ``<lane>`` of a lane section: its id, its ``width`` records (sOffset, a, b, c, d), how many
    ``border`` records it has, and the lanes its ``<link>`` names before and after it."""

    id: int
    widths: NDArray
    borders: int = 0
    predecessor: int | None = None
    successor: int | None = None


@dataclass(frozen=True)
class LaneSection:
    """A ``<laneSection>``: where it starts on the road and its lanes by id (the centre lane 0 included)."""

    s: float
    lanes: dict[int, Lane]


@dataclass(frozen=True)
class RoadLanes:
    """A road's ``laneOffset`` records (s, a, b, c, d) and its lane sections in s order."""

    road: str
    offset: NDArray
    sections: tuple[LaneSection, ...]


@dataclass(frozen=True)
class Lanes:
    """Every road's lanes (by road id) and every junction connection's lane links
    (by (junction id, connection id): (from lane of the incoming road, to lane of the connecting road) pairs)."""

    roads: dict[str, RoadLanes]
    links: dict[tuple[str, str], tuple[tuple[int, int], ...]]


def _number(text: str | None, where: str, name: str) -> float:
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"{where}: {name} must be a finite number; got {text!r:.40}")
    return value


def _integer(text: str | None, where: str, name: str) -> int:
    try:
        return int(str(text).strip())
    except ValueError:
        raise ValueError(f"{where}: {name} must be an integer lane id; got {text!r:.40}") from None


def read_lanes(path: str | os.PathLike) -> Lanes:
    """The lanes of every road and the lane links of every junction connection of an OpenDRIVE file.

    Raises:
        ValueError: a number that is not finite or a lane id that is not an
            integer, naming the road (or junction), the element and the attribute.
            (The file's readability and structure are ``read_network``'s to check.)
    """
    label = os.path.basename(os.fspath(path))
    stack: list[str] = []
    roads: dict[str, RoadLanes] = {}
    links: dict[tuple[str, str], tuple[tuple[int, int], ...]] = {}
    state: dict = {}

    def start(tag: str, attributes: dict) -> None:
        stack.append(tag)
        depth = len(stack)
        if depth == 2 and tag == "road":
            road = _label(attributes.get("id", f"#{len(roads)}"))
            state.update(road=road, offset=[], sections=[], lane_links={})
        elif depth == 2 and tag == "junction":
            state.update(junction=_label(attributes.get("id", "?")), count=0)
        elif depth == 3 and tag == "connection" and stack[1] == "junction":
            state["connection"] = attributes.get("id", str(state["count"]))
            state["count"] += 1
            links[(state["junction"], state["connection"])] = ()
        elif depth == 4 and tag == "laneLink" and stack[1] == "junction" and stack[2] == "connection":
            where = f"{label}: junction {state['junction']}, connection {state['connection']} <laneLink>"
            key = (state["junction"], state["connection"])
            links[key] += ((_integer(attributes.get("from"), where, "from"), _integer(attributes.get("to"), where, "to")),)
        elif depth < 4 or stack[1] != "road" or stack[2] != "lanes":
            return
        elif depth == 4 and tag == "laneOffset":
            where = f"{label}: road {state['road']}, laneOffset {len(state['offset'])}"
            state["offset"].append([_number(attributes.get(n), where, n) for n in "sabcd"])
        elif depth == 4 and tag == "laneSection":
            where = f"{label}: road {state['road']}, laneSection {len(state['sections'])}"
            state["sections"].append((_number(attributes.get("s"), where, "s"), {}))
        elif depth == 6 and tag == "lane" and stack[3] == "laneSection":
            where = f"{label}: road {state['road']}, laneSection {len(state['sections']) - 1} <lane>"
            lane = _integer(attributes.get("id"), where, "id")
            state["lane"] = lane
            state["sections"][-1][1][lane] = ([], 0)
            state["lane_links"][(len(state["sections"]) - 1, lane)] = {}
        elif depth == 8 and tag in ("predecessor", "successor") and stack[6] == "link" and stack[5] == "lane" and stack[3] == "laneSection":
            where = f"{label}: road {state['road']}, lane {state['lane']} <{tag}>"
            state["lane_links"][(len(state["sections"]) - 1, state["lane"])][tag] = _integer(attributes.get("id"), where, "id")
        elif depth == 7 and tag in ("width", "border") and stack[5] == "lane" and stack[3] == "laneSection":
            widths, borders = state["sections"][-1][1][state["lane"]]
            if tag == "border":
                state["sections"][-1][1][state["lane"]] = (widths, borders + 1)
                return
            where = f"{label}: road {state['road']}, lane {state['lane']} <width>"
            widths.append([_number(attributes.get(n), where, n) for n in ("sOffset", "a", "b", "c", "d")])

    def end(tag: str) -> None:
        stack.pop()
        if tag == "road" and len(stack) == 1:
            ordered = sorted(enumerate(state["sections"]), key=lambda item: item[1][0])
            sections = tuple(
                LaneSection(s, {i: Lane(i, np.array(sorted(w, key=lambda r: r[0]), dtype=float).reshape(-1, 5), b,
                                        **state["lane_links"].get((n, i), {}))
                                for i, (w, b) in lanes.items()})
                for n, (s, lanes) in ordered
            )  # fmt: skip
            offset = np.array(sorted(state["offset"], key=lambda r: r[0]), dtype=float).reshape(-1, 5)
            roads[state["road"]] = RoadLanes(state["road"], offset, sections)

    parser = expat.ParserCreate()
    parser.buffer_text = True
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        with open(os.fspath(path), "rb") as handle:
            parser.ParseFile(handle)
    except expat.ExpatError as error:
        raise ValueError(f"{label}: not well-formed XML ({expat.ErrorString(error.code)}: line {error.lineno})") from None
    return Lanes(roads, links)


def lane_links(lanes: RoadLanes, end: str) -> list[tuple[int, int]]:
    """(lane, linked lane) for every lane at the road's ``end`` whose ``<link>`` names the lane
    it continues into there (its predecessor at the start, its successor at the end)."""
    if not lanes.sections:
        return []
    section = lanes.sections[0] if end == "start" else lanes.sections[-1]
    pairs = [(lane.id, lane.predecessor if end == "start" else lane.successor) for lane in section.lanes.values() if lane.id]
    return sorted((a, b) for a, b in pairs if b is not None and b != 0)


def lateral(lanes: RoadLanes, lane: int, s: float, end: str, where: str) -> tuple[float, float, float]:
    """The lane centre's lateral offset t from the reference line at road position ``s`` (at the
    road's ``end``: the first lane section at the start, the last at the end), and dt/ds, d²t/ds².

    Raises:
        ValueError: the road has no lane sections, no lane ``lane`` at that end, or that lane
            or one inside it is given by borders rather than widths.
    """
    if not lanes.sections:
        raise ValueError(f"{where}: road {lanes.road} has no lane sections")
    section = lanes.sections[0] if end == "start" else lanes.sections[-1]
    if lane == 0 or lane not in section.lanes:
        raise ValueError(f"{where}: road {lanes.road} has no lane {lane} at its {end} "
                         f"(lanes {sorted(i for i in section.lanes if i)})")  # fmt: skip
    offset = [float(records_at(lanes.offset, s, k)) for k in range(3)]
    sign = 1 if lane > 0 else -1
    ds = max(s - section.s, 0.0)
    total = [0.0, 0.0, 0.0]
    for i in range(sign, lane + sign, sign):  # inner lanes whole, the lane itself half
        found = section.lanes.get(i)
        if found is None:
            continue  # a missing inner lane has no width
        if not len(found.widths):
            if found.borders:
                raise ValueError(f"{where}: road {lanes.road}, lane {i} is given by <border>, which is not supported; give <width>")
            continue
        share = 0.5 if i == lane else 1.0
        for k in range(3):
            total[k] += share * float(records_at(found.widths, ds, k))
    return tuple(offset[k] + sign * total[k] for k in range(3))  # type: ignore[return-value]


def _curvature_rate(g: Geometry, t: float) -> float:
    """dκ/ds of a planView geometry at its parameter fraction ``t`` (0 or 1), in closed form."""
    p = g.params
    if g.kind in ("line", "arc"):
        return 0.0
    if g.kind == "spiral":
        return (p["curvEnd"] - p["curvStart"]) / g.length
    if g.kind == "paramPoly3":
        top = 1.0 if p.get("pRange", "normalized") == "normalized" else g.length
        u, v = [p[f"{n}U"] for n in "abcd"], [p[f"{n}V"] for n in "abcd"]
    else:  # poly3: u = p, v the cubic; u runs to where the arc length is the length
        points, _, _ = g.local([t])
        top = float(points[0, 0]) / t if t else 0.0
        u, v = [0.0, 1.0, 0.0, 0.0], [p[n] for n in "abcd"]
    q = t * top
    x1, y1 = u[1] + q * (2 * u[2] + 3 * u[3] * q), v[1] + q * (2 * v[2] + 3 * v[3] * q)
    x2, y2 = 2 * u[2] + 6 * u[3] * q, 2 * v[2] + 6 * v[3] * q
    x3, y3 = 6 * u[3], 6 * v[3]
    speed2 = x1 * x1 + y1 * y1
    speed = math.sqrt(speed2)
    cross = x1 * y2 - y1 * x2
    rate = (x1 * y3 - y1 * x3) / speed**3 - 3.0 * cross * (x1 * x2 + y1 * y2) / speed**5
    return rate / speed


def lane_frame(road: Road, lanes: RoadLanes, lane: int, end: str, where: str) -> Frame:
    """The centre of ``lane`` at the road's ``end`` (``"start"`` or ``"end"``), travelling along the
    road: (point, unit tangent, curvature vector) in 3-D, metres (see the module docstring).

    Raises:
        ValueError: see ``lateral``.
    """
    g = road.geometries[0] if end == "start" else road.geometries[-1]
    at = 0.0 if end == "start" else 1.0
    with np.errstate(all="ignore"):
        point, tangent, curvature = g.evaluate([at])
        rate = _curvature_rate(g, at)
    s = 0.0 if end == "start" else road.length
    c, tx, ty, k = point[0], float(tangent[0, 0]), float(tangent[0, 1]), float(curvature[0])
    t = lateral(lanes, lane, s, end, where)
    e = [float(road.elevation_at(s, d)) for d in range(3)]
    phi = [float(road.superelevation_at(s, d)) for d in range(3)]
    cos, sin = math.cos(phi[0]), math.sin(phi[0])
    h = (t[0] * cos, t[1] * cos - t[0] * sin * phi[1],
         t[2] * cos - 2 * t[1] * sin * phi[1] - t[0] * (cos * phi[1] ** 2 + sin * phi[2]))  # fmt: skip
    g_ = (t[0] * sin, t[1] * sin + t[0] * cos * phi[1],
          t[2] * sin + 2 * t[1] * cos * phi[1] + t[0] * (cos * phi[2] - sin * phi[1] ** 2))  # fmt: skip
    nx, ny = -ty, tx
    a1, b1 = 1.0 - k * h[0], h[1]  # P' = a1·T + b1·N + z1·k
    a2, b2 = -rate * h[0] - 2.0 * k * h[1], k * (1.0 - k * h[0]) + h[2]
    d1 = np.array([a1 * tx + b1 * nx, a1 * ty + b1 * ny, e[1] + g_[1]])
    d2 = np.array([a2 * tx + b2 * nx, a2 * ty + b2 * ny, e[2] + g_[2]])
    speed = float(np.linalg.norm(d1))
    u = d1 / speed
    kv = (d2 - float(d2 @ u) * u) / speed**2
    return (float(c[0] + h[0] * nx), float(c[1] + h[0] * ny), e[0] + g_[0], *u.tolist(), *kv.tolist())
