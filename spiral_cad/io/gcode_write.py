"""G-code out: a chain as a CNC program, exact wherever the dialect can say the curve.

Two dialects (``dialect=``):

* ``"linuxcnc"`` (RS274/NGC as LinuxCNC reads it): lines are ``G1``; arcs whose plane is
  a principal plane are ``G2``/``G3`` with ``I J`` (``G17``, XY), ``I K`` (``G18``, XZ) or
  ``J K`` (``G19``, YZ); spirals in the XY plane are ``G5`` cubic splines carrying the
  spiral's own control points (``I J``: start to first control point, ``P Q``: end to
  second control point), so the curve is the spiral itself, not an approximation;
  spirals in the XZ or YZ plane (``G5`` is XY only) are biarcs within ``arc_tolerance``;
  anything else in space (an arc or spiral in a plane that is not a principal one) is
  ``G1`` chords within ``chord_tolerance``.
* ``"generic"`` (Grbl, Marlin and other controllers without splines): the same, but every
  spiral is biarcs (two tangent circular arcs per piece, split until the measured distance
  from the spiral is within ``arc_tolerance``).

No arc is written with a radius below LinuxCNC's least radius (0.00005 in, 0.00127 mm; rs274
refuses it as a zero-radius arc): such a piece of a biarc is a straight move, measured and fitted
within ``arc_tolerance`` like every biarc, and such an arc of the chain is ``G1`` chords within
``chord_tolerance``.

The program states its unit with ``G21`` (mm) or ``G20`` (inch): a chain in mm or inches
is written as it is, one in cm, m or km is converted to mm, one in feet to inches (said in
the header). Every number is written with a fixed number of decimals (``decimals``; by
default 15 significant digits for the largest coordinate, between 6 and 15 decimals: the
doubles nearly to the last bit, far inside any tolerance; G-code has no exponent
notation), and arc centres and spline offsets are differences of the rounded
points, so a reader lands on the rounded control points exactly. The header (comments)
states the dialect, the unit, what each piece became and the tolerances with the distance
measured for every approximation. Approximations are fitted within their tolerance less
what printing may add (√3·10^-decimals), so the printed program is within the stated
tolerances; decimals too coarse for them are refused, as are tolerances float64 cannot
resolve at the chain's size. ``G64 P`` (LinuxCNC's blend tolerance) is never ``P0``, which
LinuxCNC reads as blending without a limit. Header comments stay within LinuxCNC's
255-character lines (a long name is cut).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core import bezier
from ..core.chain import Chain
from ..core.kinds import ARC, LINE, SPIRAL
from ..core.segments import Arc
from ..core.units import MM_PER_UNIT
from .samples import sample_path

__all__ = ["DIALECTS", "GcodeProgram", "gcode_program", "spiral_biarcs", "spirals_biarcs", "write_gcode"]

#: The dialects ``write_gcode`` writes.
DIALECTS = ("linuxcnc", "generic")
#: The program's unit for a chain's unit (G-code has only mm and inches).
PROGRAM_UNIT = {"mm": "mm", "cm": "mm", "m": "mm", "km": "mm", "in": "in", "ft": "in"}
UNIT_CODE = {"mm": "G21", "in": "G20"}
#: Significant digits of the largest coordinate by default (float64 holds 15 to 17), and the fewest and most decimals.
DIGITS = 15
MIN_DECIMALS, MAX_DECIMALS = 6, 15
#: Default feed (program unit per minute) and tolerances (in mm, converted to the chain's unit).
FEED = {"mm": 1000.0, "in": 40.0}
TOLERANCE_MM = 0.001
#: Coordinates beyond this (program units) are refused: a fixed-decimal number would be meaninglessly long.
MAX_COORDINATE = 1e9
#: Principal planes: (G code, first axis, second axis, normal axis); LinuxCNC's G18 is the ZX plane.
PLANES = (("G17", 0, 1, 2), ("G18", 2, 0, 1), ("G19", 1, 2, 0))
AXES = "XYZ"
CENTRE_WORDS = "IJK"
#: Points of each biarc piece where its distance from the spiral is measured.
BIARC_PROBES = 24
#: The most halvings of a spiral's parameter interval for biarcs.
MAX_DEPTH = 40
#: The most biarcs of one spiral (a tolerance far below the spiral's size is refused, not minutes of halving).
MAX_BIARCS = 1 << 14
#: Tolerances below this times the largest coordinate are refused: float64 (about 2.2e-16 relative)
#: cannot place points that finely, so the fit would halve without end.
MIN_RELATIVE_TOLERANCE = 1e-13
#: LinuxCNC's least arc radius (inches; 0.00127 mm in a G21 program): rs274 refuses an arc whose start or end
#: lies closer to its centre as a "zero-radius arc", so a smaller arc is written as a straight move.
LEAST_ARC_RADIUS_IN = 0.00005
#: LinuxCNC's longest line (characters); header comments are cut to fit.
MAX_LINE = 255
#: The most characters of the name shown in the header.
MAX_NAME = 120


@dataclass
class GcodeProgram:
    """A chain as G-code (``gcode_program``): the text and what it holds.

    Attributes:
        text: the program.
        units: its unit, ``"mm"`` (G21) or ``"in"`` (G20).
        counts: pieces of the chain by how they were written (``line``, ``arc``, ``G5``,
            ``biarcs``, ``chords``) and the moves written for them (``moves``).
        chord_error: the largest measured distance between a chorded piece and its chords
            (program unit; 0 when nothing was chorded).
        arc_error: the largest measured distance between a spiral and its biarcs (program unit).
        moves: the program's move lines alone (no header, no first ``F``, no ``M2``): what a rewrite
            in place puts into another program.
    """

    text: str
    units: str
    counts: dict[str, int] = field(default_factory=dict)
    chord_error: float = 0.0
    arc_error: float = 0.0
    moves: list[str] = field(default_factory=list)


def _positive(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < float(value) < math.inf:
        raise ValueError(f"{name} must be a positive finite number; got {value!r:.40}")
    return float(value)


class _Writer:
    """Lines of the program and the tool's printed position (rounded, program unit)."""

    def __init__(self, dim: int, decimals: int, factor: float):
        self.dim, self.decimals, self.factor = dim, decimals, factor
        self.lines: list[str] = []
        self.position: list[float] = [0.0, 0.0, 0.0]
        self.plane = "G17"

    def rounded(self, point: NDArray | list[float]) -> list[float]:
        """A chain point (its first ``dim`` coordinates) in the program's unit, rounded to the printed decimals."""
        factor, decimals = self.factor, self.decimals
        coordinates = point[: self.dim] if isinstance(point, list) else np.asarray(point, dtype=float)[: self.dim].tolist()
        values = [round(v * factor, decimals) for v in coordinates]
        for v in values:
            if not abs(v) <= MAX_COORDINATE:  # NaN fails too; infinity is beyond
                raise ValueError(f"the point {tuple(coordinates)} is beyond {MAX_COORDINATE:g} program units or not finite; "
                                 "G-code writes fixed decimals")  # fmt: skip
        return values + [self.position[2]] * (3 - self.dim)

    def number(self, value: float) -> str:
        text = f"{value:.{self.decimals}f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "", "-") else text

    def axes(self, point: list[float], skip: tuple[int, ...] = ()) -> str:
        return " ".join(f"{AXES[a]}{self.number(point[a])}" for a in range(self.dim) if a not in skip)

    def set_plane(self, plane: str) -> None:
        if plane != self.plane:
            self.lines.append(plane)
            self.plane = plane

    def line(self, point: list[float], code: str = "G1") -> None:
        self.lines.append(f"{code} {self.axes(point)}")
        self.position = point

    def arc(self, plane: tuple[str, int, int, int], centre: list[float], end: list[float], ccw: bool) -> None:
        """An arc about ``centre`` (rounded) to ``end`` (rounded) in ``plane``, counterclockwise about its normal axis."""
        name, first, second, _ = plane
        self.set_plane(name)
        offsets = " ".join(f"{CENTRE_WORDS[a]}{self.number(centre[a] - self.position[a])}" for a in sorted((first, second)))
        self.lines.append(f"{'G3' if ccw else 'G2'} {self.axes(end)} {offsets}")
        self.position = end


def _plane_of(points: NDArray, normal: NDArray | None, tolerance: float) -> tuple[str, int, int, int] | None:
    """The principal plane the piece lies in (its points within ``tolerance`` of one plane normal to an axis)."""
    return _plane_of_spread(np.ptp(points[:, :3], axis=0).tolist(), normal, tolerance)


def _planes_of(points: NDArray, tolerance: float) -> list[tuple[str, int, int, int] | None]:
    """``_plane_of`` of many pieces at once (points (m, k, 3)), without normals."""
    return [_plane_of_spread(spread, None, tolerance) for spread in np.ptp(points, axis=1).tolist()]


def _plane_of_spread(spread: list[float], normal: NDArray | None, tolerance: float) -> tuple[str, int, int, int] | None:
    """The first principal plane whose normal axis the points spread along by at most ``tolerance`` (and, given a
    normal, that it is)."""
    for plane in PLANES:
        axis = plane[3]
        if normal is not None and abs(abs(float(normal[axis])) - 1.0) > 1e-12:
            continue
        if spread[axis] <= tolerance:
            return plane
    return None


Piece = tuple[NDArray, NDArray | None, float]


def _equal_legs(p0: NDArray, p1: NDArray, t0: NDArray, t1: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """The biarc of equal legs between each ``p0`` (unit tangent ``t0``) and ``p1`` (``t1``): the leg length
    (not positive where none exists), the joint point and the unit tangent there, rows of arrays."""
    chord = p1 - p0
    a = 2.0 * (np.einsum("ij,ij->i", t0, t1) - 1.0)
    b = -2.0 * np.einsum("ij,ij->i", chord, t0 + t1)
    c = np.einsum("ij,ij->i", chord, chord)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = (-b - np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0))) / (2.0 * a)  # the positive root (a < 0 < c)
        leg = np.where(np.abs(a) < 1e-12, c / -b, root)
        q0, q1 = p0 + leg[:, None] * t0, p1 - leg[:, None] * t1
        middle = (q1 - q0) / np.linalg.norm(q1 - q0, axis=1, keepdims=True)
    return leg, (q0 + q1) / 2.0, middle


def _arcs_through(start: NDArray, tangent: NDArray, end: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """The circles leaving each ``start`` (m, 2) along ``tangent`` through ``end``: (centres, signed radii,
    positive counterclockwise, and whether the piece is a line: ``end`` on the tangent)."""
    chord = end - start
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
    across = np.einsum("ij,ij->i", chord, normal)
    along = np.einsum("ij,ij->i", chord, chord)
    line = np.abs(across) <= 1e-14 * along
    radius = np.where(line, 0.0, along / (2.0 * np.where(line, 1.0, across)))
    return start + radius[:, None] * normal, radius, line


def _distances(points: NDArray, start: NDArray, end: NDArray, centre: NDArray, radius: NDArray, line: NDArray) -> NDArray:
    """Distance of points (m, k, 2) from each piece: the arc from ``start`` to ``end`` about ``centre``
    (or the line, where ``line``)."""
    chord = (end - start)[:, None]
    length2 = np.maximum(np.einsum("ijk,ijk->ij", chord, chord), np.finfo(float).tiny)
    t = np.clip(np.einsum("ijk,ijk->ij", points - start[:, None], chord) / length2, 0.0, 1.0)
    to_line = np.linalg.norm(points - start[:, None] - t[..., None] * chord, axis=-1)
    sense = np.where(radius >= 0.0, 1.0, -1.0)[:, None]
    a0 = np.arctan2(start[:, 1] - centre[:, 1], start[:, 0] - centre[:, 0])[:, None]
    sweep = (sense * (np.arctan2(end[:, 1] - centre[:, 1], end[:, 0] - centre[:, 0])[:, None] - a0)) % (2 * math.pi)
    offset = points - centre[:, None]
    angle = (sense * (np.arctan2(offset[..., 1], offset[..., 0]) - a0)) % (2 * math.pi)
    on_circle = np.abs(np.linalg.norm(offset, axis=-1) - np.abs(radius)[:, None])
    to_ends = np.minimum(np.linalg.norm(points - start[:, None], axis=-1), np.linalg.norm(points - end[:, None], axis=-1))
    return np.where(line[:, None], to_line, np.where(angle <= sweep, on_circle, to_ends))


def spirals_biarcs(control_points: NDArray, tolerance: float, least_radius: float = 0.0) -> list[tuple[list[Piece], float]]:
    """Biarcs within ``tolerance`` of plane cubics (``control_points`` (n, 4, 2)): for each, the pieces
    [(end, centre or None for a line, signed radius)] in travel order and the largest measured distance.

    An arc of a biarc with radius below ``least_radius`` (a controller's least radius) is a line
    between its ends instead, measured as a line: the halving goes on until it is within ``tolerance`` too.

    A biarc is two tangent arcs between two points of the cubic with its tangents there, with equal
    legs to their joint (the construction LinuxCNC uses for G5). Each cubic's parameter interval is
    halved until every biarc is within ``tolerance`` of the cubic at ``BIARC_PROBES`` points between its
    ends; all cubics are fitted at once, a level of halvings at a time.

    Raises:
        ValueError: ``tolerance`` below what float64 resolves at the cubics' coordinates
            (``MIN_RELATIVE_TOLERANCE`` times the largest; the smallest usable one is named), more
            than ``MAX_BIARCS`` biarcs for one cubic, or no biarcs within ``tolerance`` after ``MAX_DEPTH`` halvings.
    """
    cps = np.asarray(control_points, dtype=float)
    if cps.size:
        _resolvable(tolerance, float(np.abs(cps).max()), "arc_tolerance", "")
    found: list[list[tuple[float, list[Piece]]]] = [[] for _ in range(len(cps))]
    worst = np.zeros(len(cps))
    owner, u0, u1 = np.arange(len(cps)), np.zeros(len(cps)), np.ones(len(cps))
    inside = np.linspace(0.0, 1.0, BIARC_PROBES + 2)[1:-1]
    fitted = np.zeros(len(cps), dtype=np.int64)  # biarcs found per cubic
    for _ in range(MAX_DEPTH + 1):
        if not len(owner):
            break
        needed = fitted + np.bincount(owner, minlength=len(cps))
        if needed.max() > MAX_BIARCS:
            most = int(np.argmax(needed))
            raise ValueError(f"arc_tolerance {tolerance:g}: spiral {most} would need more than {MAX_BIARCS:,} biarcs "
                             f"({int(fitted[most]):,} fitted, {int(needed[most] - fitted[most]):,} still to fit); "
                             "give a larger arc_tolerance")  # fmt: skip
        curves = cps[owner]
        ends = bezier.point(curves, np.stack([u0, u1], axis=1))
        tangents = bezier.tangent(curves, np.stack([u0, u1], axis=1))
        probes = bezier.point(curves, u0[:, None] + (u1 - u0)[:, None] * inside)
        p0, p1, t0, t1 = ends[:, 0], ends[:, 1], tangents[:, 0], tangents[:, 1]
        leg, joint, middle = _equal_legs(p0, p1, t0, t1)
        with np.errstate(divide="ignore", invalid="ignore"):
            first = _straight_if_below(_arcs_through(p0, t0, joint), least_radius)
            second = _straight_if_below(_arcs_through(joint, middle, p1), least_radius)
            error = np.minimum(_distances(probes, p0, joint, *first), _distances(probes, joint, p1, *second)).max(axis=1)
        good = (leg > 0.0) & np.isfinite(error) & (error <= tolerance)
        for k in np.flatnonzero(good):
            pieces: list[Piece] = [
                (joint[k], None if first[2][k] else first[0][k], float(first[1][k])),
                (p1[k], None if second[2][k] else second[0][k], float(second[1][k])),
            ]
            found[owner[k]].append((float(u0[k]), pieces))
            fitted[owner[k]] += 1
            worst[owner[k]] = max(worst[owner[k]], float(error[k]))
        bad = ~good
        half = (u0[bad] + u1[bad]) / 2.0
        owner = np.repeat(owner[bad], 2)
        u0, u1 = np.ravel(np.stack([u0[bad], half], axis=1)), np.ravel(np.stack([half, u1[bad]], axis=1))
    if len(owner):
        raise ValueError(f"arc_tolerance {tolerance:g}: no biarcs within it after {MAX_DEPTH} halvings of a spiral")
    return [([piece for _, pieces in sorted(own, key=lambda f: f[0]) for piece in pieces], float(w)) for own, w in zip(found, worst)]


def _straight_if_below(arcs: tuple[NDArray, NDArray, NDArray], least_radius: float) -> tuple[NDArray, NDArray, NDArray]:
    """``_arcs_through``'s pieces with those of radius below ``least_radius`` made lines."""
    centre, radius, line = arcs
    return centre, radius, line | (np.abs(radius) < least_radius)


def _resolvable(tolerance: float, extent: float, name: str, unit: str) -> None:
    """Refuse a tolerance float64 cannot resolve at coordinates up to ``extent`` (the smallest usable one named)."""
    smallest = MIN_RELATIVE_TOLERANCE * min(extent, MAX_COORDINATE)
    if tolerance < smallest:
        raise ValueError(f"{name} {tolerance:g}{unit} is below what float64 resolves at coordinates up to {extent:g}{unit}; "
                         f"the smallest usable is {smallest:.2g}{unit} ({MIN_RELATIVE_TOLERANCE:g} of the largest coordinate)")  # fmt: skip


def spiral_biarcs(control_points: NDArray, tolerance: float, least_radius: float = 0.0) -> tuple[list[Piece], float]:
    """Biarcs within ``tolerance`` of one plane cubic (4, 2): ``spirals_biarcs`` of one.

    Raises:
        ValueError: as ``spirals_biarcs``.
    """
    return spirals_biarcs(np.asarray(control_points, dtype=float)[None], tolerance, least_radius)[0]


def gcode_program(
    chain: Chain | Any,
    *,
    dialect: str = "linuxcnc",
    feed: float | None = None,
    units: str | None = None,
    chord_tolerance: float | None = None,
    arc_tolerance: float | None = None,
    plane_tolerance: float | None = None,
    rapid_to_start: bool = True,
    decimals: int | None = None,
    name: str | None = None,
    feeds: Any = None,
) -> GcodeProgram:
    """The G-code program of ``chain`` and what it holds (see the module docstring; ``write_gcode`` writes it).

    Args:
        chain: the path, in the plane (written without Z: the machine's Z is kept) or in space; or an
            object that holds one as ``chain`` (a ``RoundedPath``, ``CircleChain``, ``Alignment``).
        dialect: ``"linuxcnc"`` (G5 for spirals in XY) or ``"generic"`` (no G5: biarcs).
        feed: the F word, in the program's unit per minute (default 1000 mm/min, 40 in/min).
        units: the program's unit, ``"mm"`` (G21) or ``"in"`` (G20); default from the chain's
            (mm for mm, cm, m and km; inches for in and ft).
        chord_tolerance: the largest distance between a piece in space and its G1 chords, in the
            chain's unit (default 0.001 mm).
        arc_tolerance: the largest distance between a spiral and its biarcs, in the chain's unit
            (default 0.001 mm).
        plane_tolerance: how far (the chain's unit) a piece's points may spread across a principal
            plane and still be written in it (default: half the last printed decimal).
        rapid_to_start: begin with a ``G0`` to the chain's start.
        decimals: decimals of every number (default: 15 significant digits for the largest
            coordinate, at least 6 and at most 15 decimals).
        name: the path's name, for the header comment.
        feeds: one feed per segment of the chain (program unit per minute; NaN: ``feed``), as read
            from the program a path was rounded from: an ``F`` word is written where it changes.

    Raises:
        ValueError: not a chain, an unknown dialect or unit, a feed or tolerance that is not a
            positive finite number, decimals outside 1–15, coordinates beyond 1e9 program units;
            decimals too coarse for a tolerance (printed curves may stray √3·10^-decimals, which
            must be at most half of ``arc_tolerance`` and ``chord_tolerance``: the fewest decimals
            are named); a tolerance below what float64 resolves at the chain's coordinates
            (``MIN_RELATIVE_TOLERANCE`` of the largest); more than ``MAX_BIARCS`` biarcs of a spiral; a feed
            that would print as 0 or beyond 1e9.
    """
    if not isinstance(chain, Chain) and isinstance(getattr(chain, "chain", None), Chain):
        chain = chain.chain
    if not isinstance(chain, Chain):
        raise ValueError(f"chain must be a Chain (or hold one as .chain); got {type(chain).__name__}")
    if dialect not in DIALECTS:
        raise ValueError(f"dialect must be one of {', '.join(DIALECTS)}; got {dialect!r:.40}")
    program = PROGRAM_UNIT[chain.units] if units is None else units
    if program not in UNIT_CODE:
        raise ValueError(f"units must be 'mm' (G21) or 'in' (G20), the only units of G-code; got {units!r:.40}")
    factor = MM_PER_UNIT[chain.units] / MM_PER_UNIT[program]
    feed = FEED[program] if feed is None else _positive(feed, "feed")
    default = TOLERANCE_MM / MM_PER_UNIT[chain.units]
    chord = default if chord_tolerance is None else _positive(chord_tolerance, "chord_tolerance")
    arcs = default if arc_tolerance is None else _positive(arc_tolerance, "arc_tolerance")
    if decimals is None:  # DIGITS significant digits for the largest coordinate: the doubles, nearly to the bit
        extent = float(np.abs(chain.rows.geometry).max()) * factor
        decimals = min(MAX_DECIMALS, max(MIN_DECIMALS, DIGITS - max(0, math.ceil(math.log10(max(extent, 1.0))))))
    if isinstance(decimals, bool) or not isinstance(decimals, int) or not 1 <= decimals <= 15:
        raise ValueError(f"decimals must be a whole number from 1 to 15; got {decimals!r:.40}")
    # a printed point is within printing of the chain's (each coordinate rounded by half the last decimal);
    # an arc's centre and end both are, so its printed curve strays up to twice that
    printing = math.sqrt(3.0) * 10.0**-decimals
    extent_chain = float(np.abs(chain.rows.geometry).max(initial=0.0))
    for label, value in (("arc_tolerance", arcs), ("chord_tolerance", chord)):
        _resolvable(value, extent_chain, label, f" {chain.units}")
        if value * factor < 2.0 * printing:  # the approximation keeps at least half of the tolerance
            fewest = math.ceil(math.log10(2.0 * math.sqrt(3.0) / (value * factor)))
            raise ValueError(f"decimals {decimals} round the printed numbers by up to {0.5 * 10.0**-decimals:g} {program}: "
                             f"printed curves may stray {printing:.2g} {program}, more than half of {label} "
                             f"{value * factor:g} {program}; give decimals of at least {fewest}, or a larger {label}")  # fmt: skip
    per_segment = np.full(len(chain), feed) if feeds is None else np.array(feeds, dtype=float).ravel()
    if per_segment.shape != (len(chain),):
        raise ValueError(f"feeds must hold one feed per segment ({len(chain)}); got {per_segment.size}")
    per_segment = np.where(np.isnan(per_segment), feed, per_segment)
    for value in (feed, *np.unique(per_segment).tolist()):
        if not 0.5 * 10.0**-decimals <= value <= MAX_COORDINATE:
            raise ValueError(f"feed {value:g} {program}/min cannot be printed with {decimals} decimals: it must be from "
                             f"{0.5 * 10.0**-decimals:g} to {MAX_COORDINATE:g}")  # fmt: skip
    # rs274 measures an arc's radius from its printed centre and ends: a margin of their rounding on top
    least_radius = (LEAST_ARC_RADIUS_IN * (25.4 if program == "mm" else 1.0) + 2.0 * printing) / factor
    plane_tol = 0.5 * 10.0**-decimals / factor if plane_tolerance is None else _positive(plane_tolerance, "plane_tolerance")
    if name is not None and ("(" in name or ")" in name or not name.isprintable()):
        raise ValueError(f"name {name!r:.60} cannot stand in a G-code comment (no parentheses, printable)")

    out = _Writer(chain.dim, decimals, factor)
    counts = {"line": 0, "arc": 0, "G5": 0, "biarcs": 0, "chords": 0}
    chord_error = arc_error = 0.0
    rows = chain.rows
    body = out.lines
    if rapid_to_start:
        out.line(out.rounded(chain.start), "G0")
    else:
        out.position = out.rounded(chain.start)
    kinds = np.asarray(rows.kind)
    # the principal plane of every spiral, and the biarcs of those G5 cannot carry, fitted at once per plane
    spirals = np.flatnonzero(kinds == SPIRAL)
    planes = dict(zip(spirals.tolist(), _planes_of(rows.geometry[spirals, :, :3], plane_tol)))
    fits: dict[int, tuple[list[Piece], float]] = {}
    for plane_name, first, second, _ in PLANES:
        wanted = [i for i, plane in planes.items() if plane is not None and plane[0] == plane_name
                  and not (plane_name == "G17" and dialect == "linuxcnc")]  # fmt: skip
        if wanted:
            fitted = spirals_biarcs(rows.geometry[wanted][:, :, [first, second]], arcs - printing / factor, least_radius)
            fits.update(zip(wanted, fitted))
    in_force, feed_words = float(per_segment[0]) if len(chain) else feed, 0
    listed = rows.geometry.tolist()  # every row's points as floats at once (each is rounded to text one by one)
    for i, (kind, segment_feed) in enumerate(zip(kinds.tolist(), per_segment.tolist())):
        geometry = rows.geometry[i]
        if segment_feed != in_force:  # the program's own feed changes here
            in_force = segment_feed
            body.append(f"F{out.number(round(in_force, decimals))}")
            feed_words += 1
        if kind == LINE:
            out.line(out.rounded(listed[i][1]))
            counts["line"] += 1
            continue
        if kind == ARC:
            segment = chain[i]
            assert isinstance(segment, Arc)
            normal = segment.normal
            if chain.dim == 2:  # a plane arc lies in its plane (z = 0): its points need not be computed
                ends = np.zeros((1, 3))
            else:
                ends = np.stack([segment.point(u) for u in np.linspace(0.0, 1.0, 5)])
            plane = _plane_of(ends, normal, plane_tol)
            if plane is not None and abs(segment.radius) >= least_radius:  # a smaller arc: chords, below
                ccw = (segment.radius > 0.0) == (normal[plane[3]] > 0.0)
                centre = out.rounded(geometry[0])
                out.arc(plane, centre, out.rounded(segment.end), ccw)
                counts["arc"] += 1
                continue
        else:
            cp = geometry[:, :3]
            plane = planes[i]
            if plane is not None and i not in fits:  # G5: XY, LinuxCNC
                out.set_plane("G17")
                p = [out.rounded(point) for point in listed[i]]
                start = out.position
                words = (f"I{out.number(p[1][0] - start[0])} J{out.number(p[1][1] - start[1])} "
                         f"P{out.number(p[2][0] - p[3][0])} Q{out.number(p[2][1] - p[3][1])}")  # fmt: skip
                body.append(f"G5 {out.axes(p[3], skip=(2,))} {words}")
                out.position = [p[3][0], p[3][1], start[2]]  # G5 moves X and Y only
                counts["G5"] += 1
                continue
            if plane is not None:
                _, first, second, normal_axis = plane
                pieces, error = fits[i]
                arc_error = max(arc_error, error)
                level = float(cp[:, normal_axis].mean())
                for end, about, radius in pieces:
                    point = np.zeros(3)
                    point[first], point[second], point[normal_axis] = end[0], end[1], level
                    target = out.rounded(point)
                    if about is None:
                        out.line(target)
                    else:
                        middle = np.zeros(3)
                        middle[first], middle[second], middle[normal_axis] = about[0], about[1], level
                        out.arc(plane, out.rounded(middle), target, radius > 0.0)
                counts["biarcs"] += 1
                continue
        # a piece in a plane that is not a principal one, or an arc below the least radius: chords
        piece = Chain([chain[i]], units=chain.units)
        samples = sample_path(piece, chord_tolerance=chord - printing / factor)
        points = samples[:, 1:4]
        between = piece.point_at((samples[1:, 0] + samples[:-1, 0]) / 2.0)
        chord_error = max(chord_error, _chord_error(points[:, : chain.dim], between))
        for point in points[1:]:
            out.line(out.rounded(point))
        counts["chords"] += 1
    counts["moves"] = len(body) - feed_words

    unit_note = "" if factor == 1.0 else f", converted from the chain's {chain.units}, times {factor:g}"
    arcs_p, chord_p = arcs * factor, chord * factor
    shown = name or "path"
    if len(shown) > MAX_NAME:  # LinuxCNC refuses lines beyond MAX_LINE characters
        shown = shown[: MAX_NAME - 3] + "..."

    printed = f"printed numbers add up to {printing:.2g}"
    head = [
        f"(spiral_cad: {shown}, {len(chain)} pieces, length {chain.length * factor:.6f} {program}, dialect {dialect})",
        f"(unit: {program}, {UNIT_CODE[program]}{unit_note}; numbers rounded to {10.0**-decimals:g} {program})",
        f"(lines: {counts['line']} G1; arcs: {counts['arc']} G2/G3 exact; spirals: {counts['G5']} G5 exact cubic, "
        f"{counts['biarcs']} as biarcs)",
        f"(biarcs within arc tolerance {arcs_p:g} {program}, measured {arc_error * factor:.3g}; {printed})",
        f"(pieces in space as G1 chords: {counts['chords']}, within chord tolerance {chord_p:g} {program}, "
        f"measured {chord_error * factor:.3g}; {printed})",
        f"(arcs below LinuxCNC's least radius {LEAST_ARC_RADIUS_IN * (25.4 if program == 'mm' else 1.0):g} {program}: "
        "straight moves within the tolerances above)",
        "(a plane path keeps the machine's Z)" if chain.dim == 2 else "(a path in space: X Y Z)",
    ]
    if dialect == "linuxcnc":
        # the blend tolerance, never printed as P0 (LinuxCNC's planner reads P0 as blending without a limit)
        blend = max(round(min(arcs_p, chord_p), decimals), 10.0**-decimals)
        head += [f"{UNIT_CODE[program]} G90 G91.1 G94 G17 G40 G49", f"G64 P{out.number(blend)}"]
    else:
        head += [f"{UNIT_CODE[program]} G90 G94 G17"]
    head.append(f"F{out.number(round(float(per_segment[0]) if len(chain) else feed, decimals))}")
    head = [line if len(line) <= MAX_LINE else line[: MAX_LINE - 4] + "...)" for line in head]
    text = "\n".join(head + body + ["M2", ""])
    return GcodeProgram(text, program, counts, chord_error * factor, arc_error * factor, list(body))


def _chord_error(points: NDArray, between: NDArray) -> float:
    """The distance of each chord's middle-of-arc point from the chord (the chord's sagitta, measured)."""
    a, b = points[:-1], points[1:]
    chord = b - a
    t = np.clip(np.einsum("ij,ij->i", between - a, chord) / np.einsum("ij,ij->i", chord, chord), 0.0, 1.0)
    return float(np.linalg.norm(between - (a + t[:, None] * chord), axis=1).max(initial=0.0))


def write_gcode(
    chain: Chain | Any,
    path: str | os.PathLike | None = None,
    *,
    dialect: str = "linuxcnc",
    feed: float | None = None,
    units: str | None = None,
    chord_tolerance: float | None = None,
    arc_tolerance: float | None = None,
    plane_tolerance: float | None = None,
    rapid_to_start: bool = True,
    decimals: int | None = None,
    name: str | None = None,
    feeds: Any = None,
) -> str | Path:
    """Write a chain (or a rounded path, circle chain or alignment: its ``chain``) as a G-code program
    (see ``gcode_program`` for the options): the file's path, or the text when ``path`` is None.

    Raises:
        ValueError: as ``gcode_program``.
        OSError: the file could not be written.
    """
    program = gcode_program(chain, dialect=dialect, feed=feed, units=units, chord_tolerance=chord_tolerance,
                            arc_tolerance=arc_tolerance, plane_tolerance=plane_tolerance, rapid_to_start=rapid_to_start,
                            decimals=decimals, name=name, feeds=feeds)  # fmt: skip
    if path is None:
        return program.text
    target = Path(path)
    target.write_text(program.text, encoding="utf-8")
    return target
