"""ASAM OpenDRIVE reading at array speed: planViews, elevation, superelevation, links and junctions.

``read_network`` parses a file in one pass of expat, gathering only what it
needs; converts and checks every numeric attribute over all elements at once
(a bad one is named by road, element and attribute); and evaluates the
start, middle and end of every geometry kind by kind, all at once — lines,
arcs, clothoid spirals (``spiral_cad.core.clothoid``: exact at every rate), ``paramPoly3`` in both
``pRange`` and the deprecated ``poly3`` (its parameter range by a batched
Gauss–Legendre Newton on its arc length). ``Geometry`` objects are made
only when a road's ``geometries`` are asked for. Public names:
``spiral_cad.io.opendrive``.

Needs no CAD kernel.
"""

from __future__ import annotations

import gc
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import cast
from xml.parsers import expat

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..continuity.joints import Frame
from ..core.chain import Chain
from ..core.clothoid import NONE, clothoid_frames, clothoid_method
from ..core.piecewise import piecewise_at
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral

#: Shape elements of a planView geometry and their numeric attributes.
_KINDS = {
    "line": (),
    "arc": ("curvature",),
    "spiral": ("curvStart", "curvEnd"),
    "paramPoly3": ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV"),
    "poly3": ("a", "b", "c", "d"),
}
#: Children of a geometry that are not its shape and are allowed.
_GEOMETRY_EXTRAS = ("userData", "include", "dataQuality")
#: Where a start, end and middle frame are evaluated, in that order.
_ENDS = np.array([0.0, 1.0, 0.5])
_END_NAMES = ("start", "end", "middle")


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

    def local(self, t: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
        """Points, unit tangents and signed curvature at ``t`` ∈ [0, 1] of the element's
        own parameter (arc length for lines, arcs and spirals; p for the polynomials),
        in the local frame at (x, y) with heading hdg."""
        t = np.asarray(t, dtype=float)
        values = np.array([[self.params[name] for name in _KINDS[self.kind]]]) if _KINDS[self.kind] else np.zeros((1, 0))
        top = _parameter_end(self.kind, values, np.array([self.length]), [self.params.get("pRange", "normalized")])
        with np.errstate(all="ignore"):
            points, tangents, curvature, _ = _local_frames(self.kind, values, np.array([self.length]), top, t.reshape(1, -1))
        return points.reshape(t.shape + (2,)), tangents.reshape(t.shape + (2,)), curvature.reshape(t.shape)

    def evaluate(self, t: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
        """World points, unit tangents and signed curvature at ``t`` ∈ [0, 1] (see ``local``)."""
        points, tangents, curvature = self.local(t)
        c, s = math.cos(self.hdg), math.sin(self.hdg)
        rotation = np.array([[c, s], [-s, c]])  # row vectors times this rotate by hdg
        return points @ rotation + (self.x, self.y), tangents @ rotation, curvature

    @cached_property
    def _start_end_middle(self) -> tuple[Frame, Frame, Frame]:
        """Start, end and middle frames (NaN where a tangent or curvature is not defined); the
        reader fills them in as it evaluates every geometry at once."""
        with np.errstate(all="ignore"):
            points, tangents, curvature = self.evaluate(_ENDS)
        return cast("tuple[Frame, Frame, Frame]", _frames(points, tangents, curvature))  # _ENDS: three parameters

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


def _frames(points: NDArray, tangents: NDArray, curvature: NDArray) -> tuple[Frame, ...]:
    """Joint-check frames (point, unit tangent, curvature vector κN; z = 0) from (m, 2), (m, 2), (m,) arrays."""
    return tuple(
        (p[0], p[1], 0.0, t[0], t[1], 0.0, -t[1] * k, t[0] * k, 0.0)
        for p, t, k in zip(points.tolist(), tangents.tolist(), curvature.tolist())
    )


def _parameter_end(kind: str, values: NDArray, length: NDArray, ranges: Sequence[str]) -> NDArray:
    """The largest parameter of each geometry: its length for lines, arcs and spirals; 1 or the
    length for paramPoly3 (normalized or arcLength); for poly3 the u whose arc length is the length."""
    if kind == "paramPoly3":
        return np.where(np.array(ranges) == "normalized", 1.0, length)
    if kind == "poly3":
        return _poly3_ends(values[:, 1:], length)
    return length


#: Composite Gauss–Legendre rule on [0, 1] (16 panels × 16 nodes) for poly3 arc lengths.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(16)
_QUAD_U = ((np.arange(16)[:, None] + 0.5 * (_NODES[None, :] + 1.0)) / 16).ravel()
_QUAD_W = np.tile(_WEIGHTS / 32.0, 16)


def _poly3_ends(bcd: NDArray, length: NDArray) -> NDArray:
    """For every poly3 v = a + b·u + c·u² + d·u³, the u where ∫₀ᵘ √(1 + v'²) reaches ``length``.

    Safeguarded Newton on all of them at once (the arc length is ≥ u, so the
    root lies in [0, length]), each step's integral by a batched composite
    Gauss–Legendre rule.
    """
    b, c, d = (bcd[:, k : k + 1] for k in range(3))

    def speed(u: NDArray) -> NDArray:
        return np.hypot(1.0, b + u * (2.0 * c + 3.0 * d * u))

    lo, hi = np.zeros(len(length)), length.astype(float).copy()
    u = length / np.hypot(1.0, bcd[:, 0])
    with np.errstate(all="ignore"):
        for _ in range(100):
            arc = (speed(u[:, None] * _QUAD_U) @ _QUAD_W) * u - length
            lo, hi = np.where(arc < 0.0, u, lo), np.where(arc < 0.0, hi, u)
            step = u - arc / speed(u[:, None])[:, 0]
            inside = (step > lo) & (step < hi)
            nxt = np.where(inside, step, 0.5 * (lo + hi))
            if np.all(np.abs(nxt - u) <= 1e-15 * np.maximum(length, 1e-300)):
                return nxt
            u = nxt
    return u


def _local_frames(kind: str, values: NDArray, length: NDArray, top: NDArray, t: NDArray):
    """Local points (n, m, 2), tangents, curvature (n, m) and headings (n, m) of n geometries of
    one ``kind`` at parameters ``t`` (n, m) or (1, m) ∈ [0, 1] (``top`` their largest parameter)."""
    p = t * top[:, None]
    if kind in ("line", "arc", "spiral"):
        zero = np.zeros((len(values), 1))
        k0 = zero if kind == "line" else values[:, :1]
        rate = zero if kind != "spiral" else (values[:, 1:2] - values[:, :1]) / length[:, None]
        return _clothoid(p, k0, rate, length[:, None])
    if kind == "paramPoly3":
        u, v = (values[:, 4 * k : 4 * k + 4] for k in range(2))
    else:
        u = np.broadcast_to(np.array([0.0, 1.0, 0.0, 0.0]), (len(values), 4))
        v = values
    return _parametric(u, v, p)


def _clothoid(s: NDArray, k0: NDArray, rate: NDArray, length: NDArray):
    """Local points, tangents, curvature and an evaluability flag (0, or NaN where the clothoid
    cannot be evaluated: its heading overflows or holds no angle) at arc lengths ``s`` (n, m) of curves of ``length``
    with κ = k0 + rate·s ((n, 1) each), by ``spiral_cad.core.clothoid`` (closed-form lines and arcs,
    quadrature or well-conditioned Fresnel integrals for clothoids, chosen per piece by its length)."""
    method = clothoid_method(length, k0, rate)
    points, heading, curvature = clothoid_frames(s, k0, rate, method=method)
    with np.errstate(all="ignore"):
        tangents = np.stack([np.cos(heading), np.sin(heading)], axis=-1)
    flag = np.broadcast_to(np.where(method == NONE, np.nan, 0.0), s.shape)
    return points, tangents, curvature, flag


def _parametric(u: NDArray, v: NDArray, p: NDArray):
    """Points, unit tangents, curvature and a zero flag (see ``_clothoid``) of the parametric
    cubics (u(p), v(p)), coefficients (n, 4) each, at parameters ``p`` (n, m)."""
    (x, x1, x2), (y, y1, y2) = _cubic(u, p), _cubic(v, p)
    with np.errstate(all="ignore"):  # speed 0 (bU = bV = 0): no tangent, NaN
        speed = np.hypot(x1, y1)
        tangents = np.stack([x1 / speed, y1 / speed], axis=-1)
        curvature = (x1 * y2 - y1 * x2) / speed**3
    return np.stack([x, y], axis=-1), tangents, curvature, np.zeros_like(p)


def _cubic(coefficients: NDArray, p: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """a + b·p + c·p² + d·p³ and its first two derivatives at ``p`` (n, m); coefficients (n, 4)."""
    a, b, c, d = (coefficients[:, k : k + 1] for k in range(4))
    with np.errstate(all="ignore"):
        return a + p * (b + p * (c + p * d)), b + p * (2.0 * c + 3.0 * d * p), 2.0 * c + 6.0 * d * p


@dataclass(frozen=True)
class Link:
    """A road's ``<predecessor>`` or ``<successor>``: a road (and which end of it) or a junction."""

    element_type: str
    element_id: str
    contact_point: str | None = None


@dataclass(frozen=True)
class Connection:
    """A junction's ``<connection>``: traffic from ``incoming`` enters ``connecting`` at its ``contact_point``
    (``connecting`` is the linked road of a direct junction)."""

    id: str
    incoming: str
    connecting: str
    contact_point: str


@dataclass(frozen=True)
class Junction:
    """A ``<junction>``: its id, type (``default``, ``direct``, ``virtual``) and connections."""

    id: str
    kind: str
    connections: tuple[Connection, ...]


@dataclass(frozen=True, eq=False)
class Plan:
    """A road's planView as arrays: what the reader checked and evaluated, all geometries at once.

    Attributes:
        kinds: the shape of every geometry.
        head: ``s``, ``x``, ``y``, ``hdg``, ``length`` arrays.
        shapes: per kind, (indices of its geometries, their shape attributes (m, k), pRange texts).
        frames: (n, 3, 9) start, end and middle frames of every geometry.
    """

    kinds: tuple[str, ...]
    head: dict[str, NDArray]
    shapes: dict[str, tuple[NDArray, NDArray, list[str]]]
    frames: NDArray


@dataclass(frozen=True, eq=False)
class Road:
    """One road as read from an OpenDRIVE file (metres, radians).

    Attributes:
        id, name, length: the road's attributes.
        plan: its planView as arrays (``geometries`` as objects, made when first asked for).
        junction: the junction it belongs to (``"-1"``: none).
        predecessor, successor: its links, if any.
        elevation: (m, 5) ``elevation`` records (s, a, b, c, d); empty: level at 0.
        superelevation: (m, 5) ``superelevation`` records (the roll angle); empty: none.
    """

    id: str
    name: str
    length: float
    plan: Plan = field(repr=False)
    junction: str = "-1"
    predecessor: Link | None = None
    successor: Link | None = None
    elevation: NDArray = field(default_factory=lambda: np.zeros((0, 5)), repr=False)
    superelevation: NDArray = field(default_factory=lambda: np.zeros((0, 5)), repr=False)

    @cached_property
    def geometries(self) -> tuple[Geometry, ...]:
        """The planView's geometries, in order."""
        plan = self.plan
        params: list[dict] = [{} for _ in plan.kinds]
        for kind, (rows, values, ranges) in plan.shapes.items():
            names = _KINDS[kind]
            for j, (i, row) in enumerate(zip(rows.tolist(), values.tolist())):
                params[i] = dict(zip(names, row))
                if kind == "paramPoly3":
                    params[i]["pRange"] = ranges[j]
        s, x, y, hdg, length = (plan.head[name].tolist() for name in ("s", "x", "y", "hdg", "length"))
        frames = plan.frames.tolist()
        geometries = []
        for i, kind in enumerate(plan.kinds):
            geometry = Geometry(self.id, i, s[i], x[i], y[i], hdg[i], length[i], kind, params[i])
            geometry.__dict__["_start_end_middle"] = tuple(map(tuple, frames[i]))  # the cached property, from the batch
            geometries.append(geometry)
        return tuple(geometries)

    @property
    def exact(self) -> bool:
        """True when the planView holds only lines, arcs and paramPoly3 (it can become a Chain)."""
        return all(kind in ("line", "arc", "paramPoly3") for kind in self.plan.kinds)

    def chain(self, tolerance: float = 1e-9) -> Chain:
        """The planView as a G2 ``Chain`` in metres.

        Raises:
            ValueError: clothoids or poly3 in the planView, or a joint that is
                not G2 (a Chain is G2 by construction; ``check_opendrive``
                reports such joints).
        """
        if not self.exact:
            kinds = sorted(set(self.plan.kinds) - {"line", "arc", "paramPoly3"})
            raise ValueError(f"road {self.id}: {', '.join(kinds)} geometries have no exact Chain form")
        segments = []
        for g in self.geometries:
            try:
                with np.errstate(all="ignore"):
                    segments.append(cast(Segment, g.segment()))  # the kinds checked above all have one
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

    def elevation_at(self, s: ArrayLike, derivative: int = 0) -> NDArray:
        """z (or dz/ds, d²z/ds²) at road positions ``s``: the cubic of the last record at or before s."""
        return records_at(self.elevation, s, derivative)

    def superelevation_at(self, s: ArrayLike, derivative: int = 0) -> NDArray:
        """The roll angle (or its derivatives in s) at road positions ``s`` (0 without records)."""
        return records_at(self.superelevation, s, derivative)


def records_at(records: NDArray, s: ArrayLike, derivative: int = 0) -> NDArray:
    """Piecewise cubic records (s, a, b, c, d) — or its ``derivative`` 1 or 2 — at ``s`` (0 without records)."""
    if not len(records):
        return np.zeros_like(np.asarray(s, dtype=float))
    return piecewise_at(records[:, 0], records[:, 1:], s, derivative)


@dataclass(frozen=True)
class Network:
    """Every road and junction of an OpenDRIVE file."""

    roads: tuple[Road, ...]
    junctions: tuple[Junction, ...] = ()


def _label(value: str) -> str:
    """A road id for messages: as written if short and printable, else quoted and cut."""
    return value if value.isprintable() and 0 < len(value) <= 64 else repr(value[:40]) + ("…" if len(value) > 40 else "")


def _real(text: str | None, name: str, where: str) -> float:
    """One attribute as a finite float, else ValueError naming it (the slow path of ``_reals``)."""
    if text is None:
        raise ValueError(f"{where}: missing attribute {name}")
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: {name} must be a number; got {text!r:.40}") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: {name} must be finite; got {text!r:.40}")
    return value


def _reals(texts: list, name: str, where) -> NDArray:
    """Attribute texts of many elements as finite floats in one pass; on a bad one the element
    is named (``where(i)``) by ``_real``."""
    try:
        values = np.array(list(map(float, texts)))
    except (TypeError, ValueError):  # a missing attribute (None) or text that is not a number
        values = None
    if values is None or not np.isfinite(values).all():
        for i, text in enumerate(texts):
            _real(text, name, where(i))
    assert values is not None  # _real raised on the text float() refused
    return values


class _Collector:
    """The parts of an OpenDRIVE document a reader needs, gathered in one pass of expat.

    Per road: the attributes of every planView geometry, of its shape element
    (and how many it has, and any other child), of every elevation and
    superelevation record and of its links; per junction its connections.
    The tests are ordered by how often each element occurs in a road network.
    """

    def __init__(self) -> None:
        self.stack: list[str] = []
        self.roads: list[dict] = []
        self.junctions: list[dict] = []
        self.road: dict = {}

    def start(self, tag: str, attributes: dict) -> None:
        stack = self.stack
        stack.append(tag)
        depth = len(stack)
        if depth == 5:
            if stack[3] == "geometry" and stack[2] == "planView" and stack[1] == "road":
                road = self.road
                if tag in _KINDS:
                    road["shapes"][-1] = (tag, attributes)
                    road["counts"][-1] += 1
                elif tag not in _GEOMETRY_EXTRAS:
                    road["others"].append((len(road["counts"]) - 1, tag))
        elif depth == 4:
            parent = stack[2]
            if stack[1] == "road":
                road = self.road
                if tag == "geometry" and parent == "planView":
                    road["geometries"].append(attributes)
                    road["shapes"].append(None)
                    road["counts"].append(0)
                elif tag == "superelevation" and parent == "lateralProfile":
                    road["superelevation"].append(attributes)
                elif tag == "elevation" and parent == "elevationProfile":
                    road["elevation"].append(attributes)
                elif parent == "link" and tag in ("predecessor", "successor"):
                    road["links"][tag] = attributes
        elif depth == 3:
            if stack[1] == "road":
                if tag == "planView":
                    self.road["planViews"] += 1
            elif stack[1] == "junction" and tag == "connection":
                self.junctions[-1]["connections"].append(attributes)
        elif depth == 2:
            if tag == "road":
                self.road = {"attributes": attributes, "geometries": [], "shapes": [], "counts": [], "others": [],
                             "planViews": 0, "elevation": [], "superelevation": [], "links": {}}  # fmt: skip
                self.roads.append(self.road)
            elif tag == "junction":
                self.junctions.append({"attributes": attributes, "connections": []})
        elif depth == 1 and tag != "OpenDRIVE":
            raise _WrongRoot(tag)

    def end(self, tag: str) -> None:
        self.stack.pop()


class _WrongRoot(Exception):
    """The document's root is not <OpenDRIVE> (raised inside expat's callback)."""


def read_network(path: str | os.PathLike) -> Network:
    """Every road (planView, elevation, superelevation, links) and junction of an OpenDRIVE file, in metres.

    The file is parsed in one pass and its numbers converted and checked per
    attribute over all elements at once; every geometry is evaluated at its
    start, middle and end (all geometries of a kind together), so a road
    whose points are not finite numbers (a line at 1e308, an arc of
    curvature 1e308) is refused here rather than measured as NaN.

    Raises:
        ValueError: unreadable or malformed XML, a root that is not
            ``OpenDRIVE``, a road without a planView, an unknown or missing
            geometry element, a number that is not finite, a non-positive
            length, geometries or profile records out of ``s`` order, a
            geometry that does not evaluate to finite points, or a link that
            is not a road or junction with a contact point — naming the road
            id and the element.
    """
    collecting = gc.isenabled()
    gc.disable()  # one dict per element and no cycles: collections would only rescan them (3x the parse)
    try:
        return _read_network(path)
    finally:
        if collecting:
            gc.enable()


def _read_network(path: str | os.PathLike) -> Network:
    label = os.path.basename(os.fspath(path))
    if not os.path.isfile(path):
        raise ValueError(f"cannot read {label}: " + ("not a regular file" if os.path.exists(path) else "no such file"))
    collector = _Collector()
    parser = expat.ParserCreate()
    parser.buffer_text = True
    parser.StartElementHandler = collector.start
    parser.EndElementHandler = collector.end
    try:
        with open(os.fspath(path), "rb") as handle:
            parser.ParseFile(handle)
    except expat.ExpatError as error:
        raise ValueError(f"{label}: not well-formed XML ({expat.ErrorString(error.code)}: line {error.lineno}, "
                         f"column {error.offset})") from None  # fmt: skip
    except _WrongRoot as root:
        raise ValueError(f"{label}: the root element is <{root.args[0]}>, not <OpenDRIVE>") from None
    except OSError as error:
        raise ValueError(f"cannot read {label}: {error.strerror}") from None
    if not collector.roads:
        raise ValueError(f"{label}: no <road> elements")
    roads = tuple(_road(label, number_, record) for number_, record in enumerate(collector.roads))
    seen: dict[str, int] = {}
    for number_, road in enumerate(roads):  # links name roads by id: two roads of one id make every link ambiguous
        if road.id in seen:
            raise ValueError(f"{label}: roads {seen[road.id]} and {number_} (in file order) both have id {road.id!r}; ids must be unique")
        seen[road.id] = number_
    junctions = tuple(_junction(label, record) for record in collector.junctions)
    return Network(roads, junctions)


def read_opendrive(path: str | os.PathLike) -> list[Road]:
    """Every road of an OpenDRIVE file (any revision), in metres (see ``read_network``)."""
    return list(read_network(path).roads)


def _road(label: str, number_: int, record: dict) -> Road:
    attributes = record["attributes"]
    road_id = _label(attributes.get("id", f"#{number_}"))
    if not record["planViews"]:
        raise ValueError(f"{label}: road {road_id} has no planView")
    if not record["geometries"]:
        raise ValueError(f"{label}: road {road_id}: the planView has no geometry")
    plan = _plan(road_id, record)
    steps = np.diff(plan.head["s"])
    if not (steps > 0.0).all():
        i = int(np.argmin(steps > 0.0)) + 1
        s = plan.head["s"]
        raise ValueError(f"{label}: road {road_id}, planView geometry {i}: s = {float(s[i])!r} is not after "
                         f"s = {float(s[i - 1])!r} of geometry {i - 1}")  # fmt: skip
    text = attributes.get("length")
    length = _real(text, "length", f"{label}: road {road_id}") if text else float(plan.head["length"].sum())
    if not length > 0.0:
        raise ValueError(f"{label}: road {road_id}: length must be positive; got {length!r}")
    links = {}
    for end, link in record["links"].items():
        kind = link.get("elementType", "road")
        if kind not in ("road", "junction"):
            raise ValueError(f"{label}: road {road_id} <{end}>: elementType must be road or junction; got {kind!r:.40}")
        contact = link.get("contactPoint")
        if kind == "road" and contact not in ("start", "end"):
            raise ValueError(f"{label}: road {road_id} <{end}>: a road link needs contactPoint start or end; got {contact!r:.40}")
        if "elementId" not in link:
            raise ValueError(f"{label}: road {road_id} <{end}>: missing attribute elementId")
        links[end] = Link(kind, link["elementId"], contact)
    return Road(
        road_id, attributes.get("name", ""), length, plan, attributes.get("junction", "-1"),
        links.get("predecessor"), links.get("successor"),
        _records(label, road_id, "elevation", record["elevation"]),
        _records(label, road_id, "superelevation", record["superelevation"]),
    )  # fmt: skip


def _records(label: str, road_id: str, tag: str, elements: list[dict]) -> NDArray:
    """(m, 5) records s, a, b, c, d of ``elevation`` or ``superelevation`` elements, in s order."""
    columns = [_reals([e.get(name) for e in elements], name, lambda i: f"{label}: road {road_id}, {tag} {i}") for name in "sabcd"]
    rows = np.column_stack(columns) if elements else np.zeros((0, 5))
    steps = np.diff(rows[:, 0])
    if len(rows) and rows[0, 0] < 0.0:
        raise ValueError(f"{label}: road {road_id}, {tag} 0: s must be ≥ 0; got {float(rows[0, 0])!r}")
    if (steps < 0.0).any():
        i = int(np.argmax(steps < 0.0)) + 1
        raise ValueError(
            f"{label}: road {road_id}, {tag} {i}: s = {float(rows[i, 0])!r} is before s = {float(rows[i - 1, 0])!r} of {tag} {i - 1}"
        )
    return rows


def _plan(road_id: str, record: dict) -> Plan:
    """The planView of one road: its numbers checked per attribute and its ends evaluated kind by kind."""
    where = lambda i: f"road {road_id}, planView geometry {i}"  # noqa: E731
    elements, shapes, counts = record["geometries"], record["shapes"], record["counts"]
    others = dict(record["others"][::-1])  # the first other child of each geometry
    bad = next((i for i, count in enumerate(counts) if count != 1 or i in others), None)
    if bad is not None:
        found = ([others[bad]] if bad in others else []) + ([shapes[bad][0]] * counts[bad] if shapes[bad] else [])
        raise ValueError(f"{where(bad)}: needs exactly one of {', '.join(_KINDS)}; found {', '.join(found) or 'none'}")
    head = {name: _reals([e.get(name) for e in elements], name, where) for name in ("s", "x", "y", "hdg", "length")}
    wrong = np.flatnonzero(~(head["length"] > 0.0))
    if len(wrong):
        raise ValueError(f"{where(wrong[0])}: length must be positive; got {float(head['length'][wrong[0]])!r}")
    wrong = np.flatnonzero(head["s"] < 0.0)
    if len(wrong):
        raise ValueError(f"{where(wrong[0])}: s must be ≥ 0; got {float(head['s'][wrong[0]])!r}")
    kinds = tuple(tag for tag, _ in shapes)
    frames = np.empty((len(kinds), 3, 9))
    by_kind = {}
    for kind in _KINDS:
        rows = np.array([i for i, k in enumerate(kinds) if k == kind], dtype=int)
        if not len(rows):
            continue
        attributes = [shapes[i][1] for i in rows.tolist()]
        columns = [_reals([a.get(name) for a in attributes], name, lambda j: f"{where(rows[j])} <{kind}>") for name in _KINDS[kind]]
        values = np.column_stack(columns) if columns else np.zeros((len(rows), 0))
        ranges = [a.get("pRange", "normalized") for a in attributes] if kind == "paramPoly3" else []
        for j, value in enumerate(ranges):
            if value not in ("normalized", "arcLength"):
                raise ValueError(f"{where(rows[j])} <paramPoly3>: pRange must be normalized or arcLength; got {value!r:.40}")
        own = {name: column[rows] for name, column in head.items()}
        evaluated, problems = _world_frames(kind, values, own, ranges or ["normalized"] * len(rows))
        if problems:
            j, problem = problems[0]
            numbers = ", ".join([f"{k}={float(own[k][j])!r}" for k in ("x", "y", "hdg", "length")]
                                + [f"{k}={v!r}" for k, v in zip(_KINDS[kind], values[j].tolist())])  # fmt: skip
            raise ValueError(f"{where(rows[j])} <{kind}>: " + (f"cannot be evaluated (its heading overflows or is too large to hold an angle; {numbers})"
                             if problem is None else f"{problem} ({numbers})"))  # fmt: skip
        frames[rows] = evaluated
        by_kind[kind] = (rows, values, ranges)
    return Plan(kinds, head, by_kind, frames)


def _world_frames(kind: str, values: NDArray, head: dict[str, NDArray], ranges: list[str]) -> tuple[NDArray, list]:
    """(m, 3, 9) start, end and middle frames of m geometries of one kind, and the problems: (j, None)
    where a clothoid cannot be evaluated or a poly3's end is not finite, (j, text) where a point is not finite."""
    length = head["length"]
    with np.errstate(all="ignore"):
        top = _parameter_end(kind, values, length, ranges)
        points, tangents, curvature, phase = _local_frames(kind, values, length, top, _ENDS[None, :])
        c, s = np.cos(head["hdg"])[:, None], np.sin(head["hdg"])[:, None]
        frames = np.zeros((len(values), 3, 9))
        frames[..., 0] = points[..., 0] * c - points[..., 1] * s + head["x"][:, None]
        frames[..., 1] = points[..., 0] * s + points[..., 1] * c + head["y"][:, None]
        frames[..., 3] = tangents[..., 0] * c - tangents[..., 1] * s
        frames[..., 4] = tangents[..., 0] * s + tangents[..., 1] * c
        frames[..., 6] = -frames[..., 4] * curvature  # the curvature vector κN
        frames[..., 7] = frames[..., 3] * curvature
    problems: list = []
    # casts: numpy's stubs type .all(axis=k) as a scalar or an array
    heading_bad = cast(NDArray, ~(np.isfinite(phase).all(axis=1) & np.isfinite(top)))
    point_bad = cast(NDArray, ~np.isfinite(frames[..., :2]).all(axis=2))
    for j in np.flatnonzero(heading_bad | point_bad.any(axis=1)).tolist():
        problems.append(
            (j, None) if heading_bad[j] else (j, f"its {_END_NAMES[int(np.argmax(point_bad[j]))]} point is not a finite number")
        )
    return frames, problems


def _junction(label: str, record: dict) -> Junction:
    attributes = record["attributes"]
    junction_id = _label(attributes.get("id", "?"))
    kind = attributes.get("type", "default")
    connections = []
    for i, c in enumerate(record["connections"]):
        where = f"{label}: junction {junction_id}, connection {c.get('id', i)}"
        road = c.get("linkedRoad", c.get("connectingRoad"))
        contact = c.get("contactPoint")
        if kind == "virtual" and None in (c.get("incomingRoad"), road, contact):
            continue  # a virtual junction's connection need not name its roads
        for name, value in (("incomingRoad", c.get("incomingRoad")), ("connectingRoad or linkedRoad", road)):
            if value is None:
                raise ValueError(f"{where}: missing attribute {name}")
        if contact not in ("start", "end"):
            raise ValueError(f"{where}: contactPoint must be start or end; got {contact!r:.40}")
        connections.append(Connection(c.get("id", str(i)), c["incomingRoad"], road, contact))
    return Junction(junction_id, kind, tuple(connections))
