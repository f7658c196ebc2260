"""LandXML 1.2 out: alignments as ``CoordGeom`` lines, curves and spirals, profiles as ``ProfAlign``.

Every plane chain (an ``Alignment``'s, or any other) becomes one
``<Alignment>`` whose ``<CoordGeom>`` holds its segments in travel order:

* ``Line`` → ``<Line>`` (``staStart``, ``length``, ``dir``, Start/End);
* ``Arc`` → ``<Curve crvType="arc">`` (``rot``, ``radius``, ``length``,
  ``dirStart``/``dirEnd``, Start/Center/End and, below a half turn, PI);
* ``BezierSpiral`` → ``<Spiral spiType="clothoid">``: LandXML has no Bézier
  spiral, so the nearest type is written — the clothoid with the same length
  and end radii (``radiusStart``/``radiusEnd``, ``INF`` where straight) — and
  its ``desc`` states the shape of our cubic and the largest offset between
  the cubic and that clothoid placed at the same start point and direction
  (measured with ``spiral_cad.core.clothoid`` at ``OFFSET_SAMPLES`` arc
  lengths); a ``<Feature name="spiral_cad">`` holds the cubic's control points
  (``Property label="controlPoints"``, northing easting four times), from
  which ``spiral_cad.io.read_landxml`` rebuilds the very cubic.

Coordinates are written northing before easting; directions in decimal
degrees counter-clockwise from east (what Civil 3D and Carlson write); every
number as the shortest decimal that reads back to the same double. Lengths
are in the chain's unit (``Metric`` for mm, cm, m, km; ``Imperial`` for ft,
in) or, with ``survey_feet``, converted to US survey feet. A ``Profile``
becomes ``<Profile><ProfAlign>``: the end PVIs as ``<PVI>``, every interior
PVI as ``<ParaCurve length>`` (``<UnsymParaCurve lengthIn lengthOut>`` when
asymmetric, ``<PVI>`` without a curve).

Needs no CAD kernel.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any
from xml.sax.saxutils import escape

import numpy as np
from numpy.typing import NDArray

from ..core.bezier import curvature, monotone_pieces, plain_spirals
from ..core.chain import Chain
from ..core.clothoid import clothoid_frames
from ..core.kinds import ARC, LINE, SPIRAL
from ..core.rows import NO_SHAPE
from ..core.segments import row_frames
from ..core.shapes import SHAPE_NAMES
from ..core.units import shared_unit, to_metres
from .staging import temporary_beside

__all__ = [
    "METRIC_UNITS",
    "OFFSET_SAMPLES",
    "segment_samples",
    "US_SURVEY_FOOT",
    "AlignmentToWrite",
    "landxml_text",
    "spiral_offsets",
    "write_landxml",
]

#: LandXML's linear unit names of our units (``Metric`` or ``Imperial``).
METRIC_UNITS = {"mm": "millimeter", "cm": "centimeter", "m": "meter", "km": "kilometer"}
IMPERIAL_UNITS = {"ft": "foot", "in": "inch"}
#: Metres per US survey foot (1200/3937).
US_SURVEY_FOOT = 1200.0 / 3937.0
#: Arc lengths per spiral at which the offset between our cubic and the clothoid is measured.
OFFSET_SAMPLES = 65
#: The prefix of the ``desc`` of every spiral written here (the reader recognises its own).
DESC_PREFIX = "spiral_cad cubic Bezier spiral"
#: The name of the ``Feature`` of each spiral written here that holds our cubic's control points (northing
#: easting, four times): ``read_landxml`` rebuilds the very cubic from it.
FEATURE = "spiral_cad"
#: |κ|·length below which a spiral's end counts as straight (radius ``INF``): rounding of the zero end.
STRAIGHT = 1e-9
NAMESPACE = "http://www.landxml.org/schema/LandXML-1.2"


@dataclass
class AlignmentToWrite:
    """One alignment to write.

    Attributes:
        chain: the plane chain (the alignment's centre line).
        name: the alignment's name.
        start_station: the chainage of the chain's start.
        profile: a ``spiral_cad.design.Profile`` on the same stations, or None.
    """

    chain: Chain
    name: str
    start_station: float = 0.0
    profile: Any = None


def _text(value: float) -> str:
    """The shortest round-trip decimal of a finite float; ``INF`` for an infinite one (a straight end)."""
    if math.isinf(value):
        return "INF"
    return repr(float(value) + 0.0)


#: A character XML 1.0 cannot hold (not even escaped): controls other than tab, newline and return,
#: lone surrogates, U+FFFE and U+FFFF.
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _check_name(text: str, what: str) -> None:
    """Refuse a name XML cannot hold, naming the character and where it is."""
    if not isinstance(text, str):
        raise ValueError(f"{what} must be text; got {type(text).__name__}")
    bad = _NOT_XML.search(text)
    if bad:
        raise ValueError(f"{what} {text!r}: the character U+{ord(bad.group()):04X} at position {bad.start()} cannot be "
                         "written in XML")  # fmt: skip


def _attribute(text: str) -> str:
    return '"' + escape(text, {'"': "&quot;", "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}) + '"'


def _ne(point: NDArray, scale: float) -> str:
    """A point as LandXML writes it: northing, then easting."""
    return f"{_text(point[1] * scale)} {_text(point[0] * scale)}"


def _direction(tangent: NDArray) -> float:
    """The direction of a tangent in decimal degrees, counter-clockwise from east, in [0, 360)."""
    degrees = math.degrees(math.atan2(tangent[1], tangent[0])) % 360.0
    return 0.0 if degrees >= 360.0 else degrees


def _meet(p: NDArray, t: NDArray, q: NDArray, u: NDArray) -> NDArray | None:
    """Where the line through p along t meets the line through q along u (None when parallel)."""
    cross = t[0] * u[1] - t[1] * u[0]
    if abs(cross) < 1e-12:
        return None
    d = q - p
    return p + t * ((d[0] * u[1] - d[1] * u[0]) / cross)


#: Spirals evaluated at once when sampling (bounds the memory of long alignments).
CHUNK = 1024
#: Gauss–Legendre nodes and weights on [0, 1] for the arc length of each sample interval of a cubic.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_U, _GL_HALF = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W


def _bezier_samples(cp: NDArray, u: NDArray) -> tuple[NDArray, NDArray]:
    """Points (m, k, 2) of cubic Bézier curves (m, 4, 2) at parameters ``u`` (k,) from 0, and their arc lengths (m, k)."""
    legs = np.diff(cp, axis=1)  # the derivative's control points / 3
    a, b = (1.0 - u)[None, :, None], u[None, :, None]
    points = a**3 * cp[:, None, 0] + 3 * a * a * b * cp[:, None, 1] + 3 * a * b * b * cp[:, None, 2] + b**3 * cp[:, None, 3]
    nodes = (u[:-1, None] + np.diff(u)[:, None] * _GL_U[None, :]).ravel()  # 8 Gauss–Legendre nodes per step
    a, b = (1.0 - nodes)[None, :, None], nodes[None, :, None]
    speed = 3.0 * np.hypot(*(a * a * legs[:, None, 0] + 2 * a * b * legs[:, None, 1] + b * b * legs[:, None, 2]).transpose(2, 0, 1))
    steps = (speed.reshape(len(cp), len(u) - 1, len(_GL_U)) @ _GL_HALF) * np.diff(u)
    return points, np.concatenate([np.zeros((len(cp), 1)), np.cumsum(steps, axis=1)], axis=1)


def segment_samples(chain: Chain, samples: int = OFFSET_SAMPLES) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Points of every segment of a plane chain at ``samples`` equal parameter steps, with their arc lengths.

    Returns (points (n, samples, 2), arc lengths from each segment's start (n, samples), end frames (n, 2, 9)).
    Lines and arcs are sampled in closed form, spirals as Bézier curves with the arc length of each step by
    8-point Gauss–Legendre quadrature (all segments at once, no inversion of arc length).
    """
    rows = chain.rows
    kind = np.array(rows.kind)
    frames, _, _ = row_frames(kind, np.array(rows.geometry), np.array(rows.params), rows.dim)
    u = np.linspace(0.0, 1.0, samples)
    s = chain.lengths[:, None] * u[None, :]
    k0 = frames[:, 0, 8]
    points, _, _ = clothoid_frames(s, k0[:, None], 0.0, x0=frames[:, 0, 0, None], y0=frames[:, 0, 1, None],
                                   hdg=np.arctan2(frames[:, 0, 4], frames[:, 0, 3])[:, None], length=chain.lengths[:, None])  # fmt: skip
    spiral = np.flatnonzero(kind == SPIRAL)
    for block in np.array_split(spiral, -(-len(spiral) // CHUNK)) if len(spiral) else ():  # bounded memory
        points[block], s[block] = _bezier_samples(rows.geometry[block, :, :2], u)
    return points, s, frames


def spiral_offsets(chain: Chain, samples: int = OFFSET_SAMPLES) -> NDArray[np.float64]:
    """Per segment the largest offset between it and the clothoid of the same length and end curvatures.

    The clothoid is placed at the segment's start point and direction (what a
    reader rebuilds from a LandXML ``Spiral``) and compared with the segment at
    ``samples`` points, each with the clothoid's point at the same arc length;
    lines and arcs give 0 (a clothoid of constant curvature is the arc itself).
    In the chain's unit.
    """
    points, s, frames = segment_samples(chain, samples)
    out = np.zeros(len(points))
    spiral = np.flatnonzero(np.asarray(chain.rows.kind) == SPIRAL)
    if not len(spiral):
        return out
    for block in np.array_split(spiral, -(-len(spiral) // CHUNK)):  # bounded memory: quadrature nodes per sample
        lengths = chain.lengths[block]
        k0, k1 = frames[block, 0, 8], frames[block, 1, 8]
        start = frames[block, 0]
        theirs, _, _ = clothoid_frames(s[block], k0[:, None], ((k1 - k0) / lengths)[:, None], x0=start[:, None, 0],
                                       y0=start[:, None, 1], hdg=np.arctan2(start[:, 4], start[:, 3])[:, None],
                                       length=lengths[:, None])  # fmt: skip
        out[block] = np.hypot(*(points[block] - theirs).transpose(2, 0, 1)).max(axis=1)
    return out


#: Parameters at which a refused cubic's curvature is quoted.
_CHECK = np.linspace(0.0, 1.0, 33)


def _check_spiral(cp: NDArray, index: int, unit: str, scale: float) -> None:
    """Refuse a cubic that no LandXML ``Spiral`` describes: its curvature changes sign (an S, an
    inflection) or does not grow or shrink monotonically in size between its ends.

    Raises:
        ValueError: naming the segment and its curvatures.
    """
    if len(monotone_pieces(cp)) == 1:  # the one test of "a spiral piece" (also splits G5 cubics)
        return
    k = curvature(cp, _CHECK)  # the numbers the message names
    size, tol = np.abs(k), 1e-9 * float(np.abs(k).max())
    if k.min() < -tol and k.max() > tol:
        why = f"its curvature changes sign ({k.min() / scale:.6g} to {k.max() / scale:.6g} 1/{unit}: an inflection)"
    else:
        why = (
            f"its curvature does not change monotonically ({k[0] / scale:.6g}, peak {size.max() / scale:.6g}, {k[-1] / scale:.6g} 1/{unit})"
        )
    raise ValueError(f"segment {index} (a cubic) is not a spiral: {why}, and a LandXML Spiral turns one way with its "
                     "curvature running monotonically between its end radii; split it where its curvature turns")  # fmt: skip


def _coord_geom(chain: Chain, start_station: float, scale: float, unit: str) -> list[str]:
    """The ``<CoordGeom>`` lines of one chain (lengths times ``scale``)."""
    if chain.dim != 2:
        raise ValueError("LandXML alignments are plane chains; this chain lies in space")
    rows = chain.rows
    kind = np.asarray(rows.kind)
    frames, _, _ = row_frames(kind, np.array(rows.geometry), np.array(rows.params), rows.dim)
    lengths, stations = chain.lengths, chain.stations[:-1] + start_station
    offsets = spiral_offsets(chain)
    plain = np.zeros(len(kind), dtype=bool)
    plain[kind == SPIRAL] = plain_spirals(np.asarray(rows.geometry)[kind == SPIRAL, :, :2])
    lines = ["      <CoordGeom>"]
    for i in range(len(kind)):
        p0, p1 = frames[i, 0, :2], frames[i, 1, :2]
        t0, t1 = frames[i, 0, 3:5], frames[i, 1, 3:5]
        k0, k1 = (0.0 if abs(k) * lengths[i] < STRAIGHT else float(k) for k in (frames[i, 0, 8], frames[i, 1, 8]))
        common = f'staStart="{_text(stations[i] * scale)}" length="{_text(lengths[i] * scale)}"'
        if kind[i] == LINE:
            lines += [f'        <Line {common} dir="{_text(_direction(t0))}">',
                      f"          <Start>{_ne(p0, scale)}</Start>", f"          <End>{_ne(p1, scale)}</End>", "        </Line>"]  # fmt: skip
            continue
        rot = "ccw" if (k0 + k1) > 0 else "cw"
        directions = f'dirStart="{_text(_direction(t0))}" dirEnd="{_text(_direction(t1))}"'
        pi = _meet(p0, t0, p1, t1)
        if kind[i] == ARC:
            radius, _, sweep = rows.params[i]
            center = rows.geometry[i, 0, :2]
            lines.append(f'        <Curve {common} rot="{rot}" crvType="arc" radius="{_text(abs(radius) * scale)}" {directions}>')
            lines += [f"          <Start>{_ne(p0, scale)}</Start>", f"          <Center>{_ne(center, scale)}</Center>",
                      f"          <End>{_ne(p1, scale)}</End>"]  # fmt: skip
            if pi is not None and abs(sweep) < math.pi:
                lines.append(f"          <PI>{_ne(pi, scale)}</PI>")
            lines.append("        </Curve>")
            continue
        if not plain[i]:
            _check_spiral(rows.geometry[i, :, :2], i, unit, scale)
        shape = SHAPE_NAMES[int(rows.shapes[i])] if int(rows.shapes[i]) != NO_SHAPE else "unstated"
        desc = (f"{DESC_PREFIX} (shape {shape}); written as the clothoid of the same length and end radii, "
                f"which lies within {offsets[i] * scale:.3g} {unit} of it")  # fmt: skip
        radii = [math.inf if k == 0.0 else 1.0 / abs(k) for k in (k0, k1)]
        lines.append(f'        <Spiral {common} radiusStart="{_text(radii[0] * scale)}" radiusEnd="{_text(radii[1] * scale)}" '
                     f'rot="{rot}" spiType="clothoid" {directions} desc={_attribute(desc)}>')  # fmt: skip
        pi = (p0 + p1) / 2 if pi is None else pi
        cp = " ".join(_ne(point, scale) for point in rows.geometry[i, :, :2])
        lines += [f"          <Start>{_ne(p0, scale)}</Start>", f"          <PI>{_ne(pi, scale)}</PI>",
                  f"          <End>{_ne(p1, scale)}</End>", f'          <Feature name="{FEATURE}">',
                  f'            <Property label="controlPoints" value="{cp}"/>', "          </Feature>", "        </Spiral>"]  # fmt: skip
    return lines + ["      </CoordGeom>"]


def _prof_align(profile: Any, name: str, scale: float) -> list[str]:
    """The ``<Profile>`` lines of a ``Profile``: end PVIs, interior PVIs with their vertical curves."""
    pvis = np.asarray(profile.pvis, dtype=float)
    curves = {c.index: c for c in profile.curves}
    lines = ["      <Profile>", f"        <ProfAlign name={_attribute(name)}>"]
    for k, (station, elevation) in enumerate(pvis):
        point = f"{_text(station * scale)} {_text(elevation * scale)}"
        curve = curves.get(k)
        if curve is None or curve.length == 0.0:
            lines.append(f"          <PVI>{point}</PVI>")
        elif curve.length_in == curve.length_out:
            lines.append(f'          <ParaCurve length="{_text(curve.length * scale)}">{point}</ParaCurve>')
        else:
            lines.append(f'          <UnsymParaCurve lengthIn="{_text(curve.length_in * scale)}" '
                         f'lengthOut="{_text(curve.length_out * scale)}">{point}</UnsymParaCurve>')  # fmt: skip
    return lines + ["        </ProfAlign>", "      </Profile>"]


def landxml_text(alignments: Sequence[AlignmentToWrite], units: str, name: str = "spiral_cad", *, survey_feet: bool = False,
                 application: str = "spiral_cad") -> str:  # fmt: skip
    """The LandXML 1.2 document of ``alignments`` (their chains in ``units``) as text; see the module docstring.

    Args:
        alignments: the alignments, written in order.
        units: the length unit of the chains (and profiles).
        name: the name of the ``<Alignments>`` collection.
        survey_feet: write lengths in US survey feet (converted from ``units``).
        application: the ``<Application>`` name.

    Raises:
        ValueError: a chain in space, a unit LandXML has no name for, or a name
            with a character XML cannot hold (naming it).
    """
    _check_name(name, "the collection name")
    _check_name(application, "the application name")
    for k, a in enumerate(alignments):
        _check_name(a.name, f"alignment {k + 1}'s name")
    if survey_feet:
        scale, system, linear = to_metres(units) / US_SURVEY_FOOT, "Imperial", "USSurveyFoot"
        unit = "US survey ft"
    elif units in METRIC_UNITS:
        scale, system, linear, unit = 1.0, "Metric", METRIC_UNITS[units], units
    elif units in IMPERIAL_UNITS:
        scale, system, linear, unit = 1.0, "Imperial", IMPERIAL_UNITS[units], units
    else:
        raise ValueError(f"LandXML has no length unit for {units!r}")
    area, volume = ("squareMeter", "cubicMeter") if system == "Metric" else ("squareFoot", "cubicFeet")
    now = datetime.now(UTC)
    lines = [
        '<?xml version="1.0" encoding="utf-8"?>',
        f'<LandXML xmlns="{NAMESPACE}" date="{now:%Y-%m-%d}" time="{now:%H:%M:%S}" version="1.2" language="English" readOnly="false">',
        "  <Units>",
        f'    <{system} areaUnit="{area}" linearUnit="{linear}" volumeUnit="{volume}" temperatureUnit="'
        f'{"celsius" if system == "Metric" else "fahrenheit"}" pressureUnit="{"milliBars" if system == "Metric" else "inchHG"}" '
        'angularUnit="decimal degrees" directionUnit="decimal degrees"/>',
        "  </Units>",
        f'  <Application name={_attribute(application)} manufacturer="spiral_cad" desc="directions counter-clockwise from east"/>',
        f"  <Alignments name={_attribute(name)}>",
    ]
    for a in alignments:
        total = a.chain.length * scale
        lines.append(f'    <Alignment name={_attribute(a.name)} length="{_text(total)}" staStart="{_text(a.start_station * scale)}">')
        lines += _coord_geom(a.chain, a.start_station, scale, unit)
        if a.profile is not None:
            lines += _prof_align(a.profile, a.name, scale)
        lines.append("    </Alignment>")
    lines += ["  </Alignments>", "</LandXML>\n"]
    return "\n".join(lines)


def _record(item: Any, name: str, profile: Any, place: int) -> AlignmentToWrite:
    """``item`` as an alignment to write: a record as it is, a chain or an alignment (its chain and start
    station) named ``name``; anything else refused naming its place."""
    if isinstance(item, AlignmentToWrite):
        return item
    if isinstance(item, Chain):
        return AlignmentToWrite(item, name, 0.0, profile)
    if isinstance(getattr(item, "chain", None), Chain) and hasattr(item, "start_station"):
        return AlignmentToWrite(item.chain, name, float(item.start_station), profile)
    raise ValueError(f"alignment {place + 1} must be a Chain, an Alignment or an AlignmentToWrite; got {type(item).__name__}")


def write_landxml(alignments: Sequence[AlignmentToWrite] | Any, path: str | os.PathLike, units: str | None = None, *,
                  name: str = "spiral_cad", survey_feet: bool = False, profile: Any = None) -> None:  # fmt: skip
    """Write alignments as one LandXML 1.2 file (UTF-8).

    Args:
        alignments: one plane ``Chain`` or ``spiral_cad.design.Alignment`` (with
            ``profile``, its vertical alignment), or a list of them or of
            ``AlignmentToWrite`` records (a chain or alignment in a list is named
            ``name`` and its place, ``"spiral_cad 2"``).
        path: the file to write.
        units: the chains' unit, only as a check: the chains are written in
            their own unit, which they must share (nothing is rescaled).
        name: the collection's name (and the alignment's, for a single one).
        survey_feet: write lengths in US survey feet.
        profile: the ``Profile`` of a single alignment.

    The file is written whole to a temporary file beside ``path`` and then
    renamed onto it: an existing file is replaced only by a complete one.

    Raises:
        ValueError: no alignment, something that is not one (naming its place
            and type), chains in different units or in another unit than
            ``units``, or see ``landxml_text`` (then nothing was written).
    """
    single = isinstance(alignments, Chain) or hasattr(alignments, "start_station")
    items = [alignments] if single else list(alignments) if isinstance(alignments, (list, tuple)) else None
    if not items:
        raise ValueError(f"write_landxml needs a Chain or an Alignment, or a non-empty list of them; got {type(alignments).__name__}")
    records = [_record(item, name if single else f"{name} {k + 1}", profile if single else None, k) for k, item in enumerate(items)]
    units = shared_unit((a.chain.units for a in records), units)
    data = landxml_text(records, units, name, survey_feet=survey_feet).encode("utf-8")
    target = os.fspath(path)
    temporary = temporary_beside(target, ".tmp")
    try:
        with open(temporary, "wb") as stream:
            stream.write(data)
        os.chmod(temporary, 0o666 & ~_umask())  # mkstemp makes it private: give it an ordinary file's mode
        os.replace(temporary, target)  # atomic on one file system: the old file or the whole new one
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def _umask() -> int:
    """The process's file-creation mask (read by setting it and back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
