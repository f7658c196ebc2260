"""Checking OpenDRIVE maps road by road and link by link.

Every road's planView joints (G0/G1/G2, the measures of every checker in
``spiral_cad.continuity.joints``), its ``elevation`` and ``superelevation`` in s
(C0/C1/C2), and every link between road ends (road links, junction
connections) measured as a joint — through a junction lane centre to lane
centre, what a driver follows (``spiral_cad.io.opendrive_lanes``).
Public names: ``spiral_cad.io.opendrive``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..continuity.joints import (
    Continuity,
    ContinuityReport,
    Frame,
    JointReport,
    check_tolerances,
    classify_joint,
    classify_pieces,
    flip,
    model_size,
)
from ..core.piecewise import polynomial
from .opendrive_lanes import lane_frame, lane_links, read_lanes
from .opendrive_read import Network, Road, _label, read_network

#: Continuity levels of a profile in s (elevation, superelevation).
PROFILE_LEVELS = ("unmeasurable", "none", "C0", "C1", "C2")


@dataclass(frozen=True)
class ProfileReport:
    """Continuity in s of one road's ``elevation`` or ``superelevation`` records.

    Attributes:
        road: the road's id.
        kind: ``"elevation"`` or ``"superelevation"``.
        records: how many records the road has.
        level: the worst boundary's level: ``C2`` (value, slope and second
            derivative continuous), ``C1``, ``C0``, ``none`` or ``unmeasurable``.
        worst: (s, value jump, slope jump, second-derivative jump) at the worst boundary, if any.
    """

    road: str
    kind: str
    records: int
    level: str
    worst: tuple[float, float, float, float] | None = None

    def describe(self) -> str:
        if self.worst is None:
            return f"{self.kind} {self.level} ({self.records} record{'s' if self.records != 1 else ''})"
        s, j0, j1, j2 = self.worst
        return f"{self.kind} {self.level} ({self.records} records; worst at s = {s:.6g}: jumps {j0:.2g}, {j1:.2g}, {j2:.2g})"


@dataclass(frozen=True)
class LinkReport:
    """One link between two road ends (a road link or a junction connection), measured as a joint.

    Attributes:
        name: ``"road 1 end → road 2 start"``, or ``"road 1 end lane -1 → road 2 start lane -1"``
            for a lane link.
        via: ``"road link"``, ``"junction J"`` or ``"direct junction J"``.
        joint: gap, angle and curvature jump from the first road's end, travelling out of it,
            into the second (a gap across the road of a direct junction is not counted: see ``offset``).
        offset: a direct junction's lateral offset of the reference lines (lanes), metres.
        lanes: (lane of the first road, lane of the second) when the link joins lane centres
            (a junction connection's ``laneLink``, or a lane's ``<link>`` at a junction road's end),
            else None (the reference lines).
    """

    name: str
    via: str
    joint: JointReport
    offset: float = 0.0
    lanes: tuple[int, int] | None = None


@dataclass(frozen=True)
class OpenDriveReport(ContinuityReport):
    """``check_opendrive``'s report: every road's planView (its pieces), its elevation and
    superelevation in s, and every link between roads, with the number of junctions."""

    profiles: tuple[ProfileReport, ...] = ()
    links: tuple[LinkReport, ...] = ()
    junctions: int = 0

    @property
    def link_level(self) -> Continuity:
        """The worst link (G2 without links)."""
        return min((link.joint.level for link in self.links), default=Continuity.G2)

    @property
    def profile_level(self) -> str:
        """The worst elevation or superelevation level (C2 without records)."""
        return min((p.level for p in self.profiles), key=PROFILE_LEVELS.index, default="C2")

    def passes(self, required: str | int | Continuity, pieces: int | None = None) -> bool:
        """Every road's planView reaches ``required`` (and, if given, the file holds ``pieces`` roads)."""
        return (pieces is None or self.pieces == pieces) and self.min_level >= Continuity.parse(required)

    def describe(self) -> str:
        """``"5 roads (…), 4 links, 1 junction"``: the roads as the checker counts pieces, then links and junctions."""
        parts = [super().describe()]
        if self.links:
            parts.append(f"{len(self.links)} link{'s' if len(self.links) != 1 else ''}")
        if self.junctions:
            parts.append(f"{self.junctions} junction{'s' if self.junctions != 1 else ''}")
        return ", ".join(parts)

    def format_table(self) -> str:
        out = [super().format_table()]
        if self.profiles:
            out.append("elevation and superelevation in s (per road):")
            out += [f"  road {p.road}: {p.describe()}" for p in self.profiles]
        if self.links:
            unit = f" {self.units}" if self.units else ""
            out.append(f"links: {len(self.links)}, worst {self.link_level}")
            out.append(f"  {'link':46} {'gap':>10} {'angle rad':>10} {'|Δκ|':>10} {'Δκ rel':>9} level")
            for link in self.links:
                j = link.joint
                note = (f"  ({link.via}; reference lines offset {link.offset:.6g}{unit} by lanes)" if link.offset
                        else f"  ({link.via}; lane centres)" if link.lanes else f"  ({link.via})")  # fmt: skip
                out.append(f"  {link.name:46} {j.gap:10.3e} {j.angle:10.3e} {j.curvature_jump:10.3e} "
                           f"{j.relative_curvature_jump:9.2e} {j.level}{note}")  # fmt: skip
        return "\n".join(out)


def check_opendrive(
    path: str | os.PathLike, *, gap_tol: float = 1e-7, angle_tol: float = 1e-7, curvature_tol: float = 1e-6
) -> OpenDriveReport:
    """Every road's planView joints (G0/G1/G2), its elevation and superelevation in s (C0/C1/C2)
    and every link between roads (G0/G1/G2), in metres.

    Each road is one piece; the measures and tolerances are those of the
    STEP/IGES checker (``spiral_cad.continuity.joints``). A profile boundary is
    C0 when the value jumps by at most ``gap_tol`` (elevation, m) or
    ``angle_tol`` (roll angle, rad), C1 when the slope jumps by at most
    ``angle_tol`` too, C2 when the second derivative jumps by at most
    ``curvature_tol`` relative to max(|f''|, 1/size) (1/size² for the roll).
    A link joins two road ends: a road's ``successor``/``predecessor`` with
    its ``contactPoint`` (an end-to-end link reverses the second road) or a
    junction's connection from its incoming road — at the end that road
    names the junction at; if both, the end the connecting road's own link
    names, else the nearer — into the connecting road at its ``contactPoint``
    (declared links are counted once). It is measured like a joint,
    travelling out of the first road into the second.

    In a junction the reference lines are meant to be apart (``laneOffset``,
    lanes on one side only), so a connection with ``laneLink`` elements is
    judged per lane link, and a road link to or from a road of a junction
    per lane ``<link>``: the lane centres (reference line + laneOffset +
    inner widths + half the lane's, in the first lane section at a road's
    start and the last at its end, raised by elevation and tilted by
    superelevation) in 3-D, their tangents and their curvature vectors in
    closed form (see ``opendrive_lanes``). Other road links, and
    connections without lane links, join the reference lines; at a direct
    junction without lane links the reference lines may be offset across
    the road, which is reported as such rather than as a gap.

    Raises:
        ValueError: an unreadable file (see ``read_network``), a link to a
            road or junction that is not in the file, a lane link to a lane
            the road does not have at that end (or given by ``<border>``), a
            road in a lane-linked connection without ``<lanes>``, or a bad tolerance.
    """
    check_tolerances(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol)
    network = read_network(path)
    source = os.path.basename(os.fspath(path))
    roads = network.roads
    pieces = [("road", [(tuple(f[0]), tuple(f[1])) for f in road.plan.frames.tolist()], False, road.id) for road in roads]
    size = model_size(np.vstack([road.plan.frames[:, :, :3].reshape(-1, 3) for road in roads]).tolist(), source)
    planview = classify_pieces(pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol,
                               source=source, element="geometry", units="m")  # fmt: skip
    floor = 1.0 / size if size > 0.0 else 0.0
    profiles = []
    for road in roads:
        for kind, records, tolerance, rate_floor in (("elevation", road.elevation, gap_tol, floor),
                                                     ("superelevation", road.superelevation, angle_tol, floor * floor)):  # fmt: skip
            if len(records):
                profiles.append(_profile_report(road.id, kind, records, tolerance, angle_tol, curvature_tol, rate_floor))
    links = _links(source, path, network, gap_tol, angle_tol, curvature_tol, floor)
    return OpenDriveReport(**{f.name: getattr(planview, f.name) for f in fields(planview)}, profiles=tuple(profiles),
                           links=tuple(links), junctions=len(network.junctions))  # fmt: skip


def _profile_report(road: str, kind: str, records: NDArray, value_tol: float, slope_tol: float, relative_tol: float,
                    floor: float) -> ProfileReport:  # fmt: skip
    """The C-level of piecewise cubic records at each boundary: value, slope and second derivative of the
    record before against the one starting there."""
    if len(records) < 2:
        return ProfileReport(road, kind, len(records), "C2")
    s = records[1:, 0]
    with np.errstate(all="ignore"):
        x = s - records[:-1, 0]
        before = [polynomial(records[:-1, 1:], x, k) for k in range(3)]  # each piece at the start of the next
        after = [polynomial(records[1:, 1:], np.zeros_like(x), k) for k in range(3)]
        jumps = np.abs(np.stack(before) - np.stack(after))
        scale = np.maximum(np.maximum(np.abs(before[2]), np.abs(after[2])), floor)
        relative = jumps[2] / scale
    levels = np.where(
        ~np.isfinite(jumps).all(axis=0), 0,
        np.where(~(jumps[0] <= value_tol), 1, np.where(~(jumps[1] <= slope_tol), 2, np.where(~(relative <= relative_tol), 3, 4))),
    )  # fmt: skip
    worst = int(np.argmin(levels))
    return ProfileReport(road, kind, len(records), PROFILE_LEVELS[int(levels[worst])],
                         cast("tuple[float, float, float, float]", (float(s[worst]), *(float(v) for v in jumps[:, worst]))))  # fmt: skip


def _links(source: str, path: str | os.PathLike, network: Network, gap_tol: float, angle_tol: float, curvature_tol: float,
           floor: float) -> list[LinkReport]:  # fmt: skip
    """Every declared link between two road ends, once, measured as a joint: junction connections
    lane by lane where they give lane links, road links (and connections without lane links)
    between the reference lines."""
    roads = {road.id: road for road in network.roads}
    junctions = {junction.id: junction for junction in network.junctions}
    lanes = read_lanes(path) if any(j.connections for j in network.junctions) else None
    in_junctions = {r.id for r in network.roads if r.junction not in ("-1", "")}
    seen: set = set()
    found: list[LinkReport] = []

    def road(name: str, where: str) -> Road:
        if _label(name) not in roads:
            raise ValueError(f"{source}: {where} links to road {_label(name)}, which is not in the file")
        return roads[_label(name)]

    def end_frame(r: Road, end: str) -> Frame:
        return tuple(r.plan.frames[0, 0].tolist()) if end == "start" else tuple(r.plan.frames[-1, 1].tolist())

    def add(a: Road, a_end: str, b: Road, b_end: str, via: str, direct: bool = False) -> None:
        key = frozenset({(a.id, a_end), (b.id, b_end)})
        if key in seen:
            return
        seen.add(key)
        out = end_frame(a, a_end) if a_end == "end" else flip(end_frame(a, a_end))
        into = end_frame(b, b_end) if b_end == "start" else flip(end_frame(b, b_end))
        offset = 0.0
        if direct:  # the reference lines may be offset across the road by lanes: only the gap along it counts
            dx, dy = into[0] - out[0], into[1] - out[1]
            offset = -dx * out[4] + dy * out[3]
            into = (into[0] + offset * out[4], into[1] - offset * out[3], *into[2:])
        joint = classify_joint(len(found), out, into, gap_tol, angle_tol, curvature_tol, floor)
        found.append(LinkReport(f"road {a.id} {a_end} → road {b.id} {b_end}", via, joint, offset))

    def add_lanes(a: Road, a_end: str, b: Road, b_end: str, via: str, pairs: tuple[tuple[int, int], ...], where: str) -> None:
        """One link per lane link: the centre of the incoming road's lane into the connecting road's."""
        assert lanes is not None
        for road_ in (a, b):
            if road_.id not in lanes.roads:
                raise ValueError(f"{source}: {where}: road {road_.id} has no <lanes>")
        for lane_a, lane_b in pairs:
            key = frozenset({(a.id, a_end, lane_a), (b.id, b_end, lane_b)})
            if key in seen:
                continue
            seen.add(key)
            out = lane_frame(a, lanes.roads[a.id], lane_a, a_end, f"{source}: {where}")
            into = lane_frame(b, lanes.roads[b.id], lane_b, b_end, f"{source}: {where}")
            out = out if a_end == "end" else flip(out)
            into = into if b_end == "start" else flip(into)
            joint = classify_joint(len(found), out, into, gap_tol, angle_tol, curvature_tol, floor)
            found.append(LinkReport(f"road {a.id} {a_end} lane {lane_a} → road {b.id} {b_end} lane {lane_b}", via, joint,
                                    lanes=(lane_a, lane_b)))  # fmt: skip

    def incoming_end(incoming: Road, target: Road, contact: str, junction: str, where: str) -> str:
        """The end of the incoming road in the junction: the one it names the junction at; if both,
        the one the connecting road's own link names, else the one nearer the connecting road's end."""
        ends = [end for end, link in (("start", incoming.predecessor), ("end", incoming.successor))
                if link is not None and link.element_type == "junction" and _label(link.element_id) == junction]  # fmt: skip
        if not ends:
            raise ValueError(f"{source}: {where}: its incoming road {incoming.id} names the junction as neither "
                             "predecessor nor successor")  # fmt: skip
        if len(ends) == 1:
            return ends[0]
        back = target.predecessor if contact == "start" else target.successor
        if back is not None and back.element_type == "road" and _label(back.element_id) == incoming.id and back.contact_point:
            return back.contact_point
        there = np.array(end_frame(target, contact)[:3])
        return min(ends, key=lambda end: float(np.linalg.norm(np.array(end_frame(incoming, end)[:3]) - there)))

    for r in network.roads:
        for link in (r.predecessor, r.successor):
            if link is not None and link.element_type == "junction" and _label(link.element_id) not in junctions:
                raise ValueError(f"{source}: road {r.id} links to junction {_label(link.element_id)}, which is not in the file")
    # junction connections first: they name the traffic's way, from the incoming road into the connecting one
    for junction in network.junctions:
        direct = junction.kind == "direct"
        via = f"{'direct junction' if direct else 'junction'} {junction.id}"
        for connection in junction.connections:
            where = f"junction {junction.id}, connection {connection.id}"
            incoming = road(connection.incoming, where)
            target = road(connection.connecting, where)
            end = incoming_end(incoming, target, connection.contact_point, junction.id, where)
            pairs = lanes.links.get((junction.id, connection.id), ()) if lanes is not None else ()
            if pairs:
                add_lanes(incoming, end, target, connection.contact_point, via, pairs, where)
                seen.add(frozenset({(incoming.id, end), (target.id, connection.contact_point)}))  # judged by its lanes
            else:
                add(incoming, end, target, connection.contact_point, via, direct)
    for r in network.roads:
        for end, link in (("start", r.predecessor), ("end", r.successor)):
            if link is None or link.element_type != "road":
                continue
            where = f"road {r.id} <{'predecessor' if end == 'start' else 'successor'}>"
            other = road(link.element_id, where)
            contact = link.contact_point or ""  # read_network refuses a road link without start or end
            # inside a junction the reference lines are meant to be apart: follow the lanes' own links
            # (this road's at this end, else the other road's, if its link there names this road's end)
            lane_pairs: list[tuple[int, int]] = []
            if lanes is not None and (r.id in in_junctions or other.id in in_junctions):
                lane_pairs = lane_links(lanes.roads[r.id], end) if r.id in lanes.roads else []
                back = other.predecessor if contact == "start" else other.successor
                if (
                    not lane_pairs
                    and other.id in lanes.roads
                    and back is not None
                    and back.element_type == "road"
                    and _label(back.element_id) == r.id
                    and back.contact_point == end
                ):
                    lane_pairs = [(b, a) for a, b in lane_links(lanes.roads[other.id], contact)]
            if lane_pairs:
                if frozenset({(r.id, end), (other.id, contact)}) in seen:
                    continue
                add_lanes(r, end, other, contact, "road link", tuple(lane_pairs), where)
                seen.add(frozenset({(r.id, end), (other.id, contact)}))
            else:
                add(r, end, other, contact, "road link")
    return found
