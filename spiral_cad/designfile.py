"""JSON design files: validation, building and writing every output.

A design file holds ``units`` and a list of ``designs``; each design has a
``name``, a ``type`` and the fields of that type (see ``FORMAT``). Any byte
sequence is either a valid design or a ``DesignError`` naming the field and
the value: the file must be a regular file of at most ``MAX_DESIGN_BYTES``
(checked before it is read), it is decoded, parsed and every field checked
before anything is built, and every design is built before anything is
written. Output is all or nothing (``spiral_cad.staging``): files are
written into a staging folder inside the output folder and moved into place
only when all of them were written and every destination was checked; a
failure or an interrupt (Ctrl-C, SIGTERM, SIGHUP) leaves the output folder
as it was.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import signal
import stat
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import partial
from importlib.util import find_spec
from pathlib import Path
from typing import Any

from .core.chain import Chain
from .core.errors import NoSolutionError
from .core.shapes import CORNER_SHAPES, DEFAULT_SHAPE, TRANSITION_SHAPES
from .core.spiral import BezierSpiral
from .core.units import UNITS
from .formats.names import MAX_TEXT_LENGTH, check_name
from .staging import Staging

FORMAT = """\
{
  "units": "m",                          required: mm, cm, m, km, in or ft (every length below)
  "designs": [
    {"name": "highway", "type": "alignment",
     "pis": [[x, y], ...],               ≥ 3 points of intersection, in travel order
     "radii": [r, ...],                  one positive radius per interior PI (or one number)
     "spiral_angles_deg": [θ | [θin, θout], ...]   or "spiral_lengths": [L | [Lin, Lout], ...]
                                         or neither, with "design_speed": the shortest spirals
                                         that meet every criterion
     "start_station": 0,                 optional chainage of the first PI
     "design_speed": V,                  optional: km/h (metric units) or mph (in, ft)
     "criteria": "road" | "rail",        default road; road keys: "max_jerk" (m/s³, 0.6),
                                         "superelevation_max" (0.08), "side_friction",
                                         "shift_min", "shift_max"; rail keys (mm, mm/s, mm/m):
                                         "cant_max", "cant_deficiency_max", "cant_rate_max",
                                         "cant_deficiency_rate_max", "cant_gradient_max",
                                         "gauge", "cant"
     "strict": false,                    true: a violated criterion is an error
     "spiral_shape": "near-linear",      default; or "walton-meek" (the 1996 spiral, 1.6–1.8× longer
                                         for the same jerk)
     "cross_section": {"driving_lanes": 1, "lane_width": 3.5, "shoulder_width": 2.5,
                       "rule": "RHT",    OpenDRIVE lanes (m)
                       "crossfall": 0.025, "depth": 0.5},   crown (m/m) and pavement (m) of the corridor
     "geo_reference": "+proj=utm ...",   OpenDRIVE geoReference (printable text, ≤ 10 000 characters)
     "profile": {                        optional vertical alignment: NAME_profile.csv, elevation in
                                         the .xodr, the 3-D centre line and corridor in NAME_3d.step
       "pvis": [[station, elevation], ...],   ≥ 2, stations are the alignment's chainages
                                         (start_station at its first PI); it must cover the alignment
       "curve_lengths": [L | [Lin, Lout], ...]  or "k_values": [K, ...] (length per % of grade
                                         change) or neither, with design_speed (road criteria): the
                                         shortest curves that meet the stopping sight distance
       "terrain": "rolling",             level | rolling | mountainous (the maximum grade)
       "max_grade": 0.05, "min_curve_length": L}},  optional overrides (fraction; length)
    {"name": "oval", "type": "circle_chain",
     "circles": [{"center": [x, y], "radius": r}, ...],    signed radius = travel sense (+ ccw)
     "spiral_shape": "walton-meek" | "near-linear"},        default walton-meek
    {"name": "robot", "type": "rounded_polyline",
     "points": [[x, y] | [x, y, z], ...],   a polyline in the plane or in space (≥ 3 points), or
     "gcode": "FILE.nc",                 the G0/G1 moves of a G-code program (a path relative to the
                                         design file; G20/G21 converted to "units"; README: the subset)
     "max_deviation": h,                 the largest distance between a corner point and the path,
     "max_curvature": k,                 and/or the curvature bound (alone: every corner peaks at k),
                                         or "curvature": k | "spiral_lengths": L | none (as large as
                                         fits); each a number or one per interior point
     "samples": {"step": s} | {"chord_tolerance": c},   optional NAME_samples.csv for a machine:
                                         s, x, y, z, tangent and curvature along the path
     "spiral_shape": "walton-meek" | "near-linear" | "g2cbs"},   default walton-meek
                                         ("method" is its former name)
    {"name": "t", "type": "transition", "case": "line_to_circle" | "circle_to_circle" |
     "line_to_line" | "circle_in_circle", ...that function's arguments by name...,
     "spiral_shape": "walton-meek" | "near-linear"}          default walton-meek
  ]
}
Names: 1–64 characters of A–Z, a–z, 0–9, - and _ (they name the output files; no two may
differ only in case). The file: UTF-8 JSON, a regular file of at most 10 MB; at most 20 000 PIs
per alignment and 2 000 PVIs per profile. A path in space
gets STEP, IGES, DXF, samples and the continuity report (SVG and the plots are plane outputs)."""

TRANSITION_ARGS = {
    "line_to_circle": ("point", "direction", "center", "radius"),
    "circle_to_circle": ("center0", "radius0", "center1", "radius1"),
    "line_to_line": ("p0", "corner", "p1", "curvature"),
    "circle_in_circle": ("center0", "radius0", "center1", "radius1"),
}
OPTIONAL = {"curvature"}
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}")
#: JSON integers longer than this are refused (they cannot be lengths in float64 anyway).
MAX_DIGITS = 308
#: Design files larger than this are refused before they are read.
MAX_DESIGN_BYTES = 10_000_000
#: PIs of one alignment and PVIs of one profile: a design's time and memory grow with them (about
#: 20 s and 1 GB for 10 000 PIs; a corridor about 0.2 GB per 1 000 PVIs), so a file cannot ask for 30 GB.
MAX_PIS = 20_000
MAX_PVIS = 2_000
#: The packages of the ``cad`` extra and what needs them.
CAD_EXTRA = {"OCP": "IGES, the 3-D STEP of roads and the continuity check", "ezdxf": "DXF", "matplotlib": "plots"}


class DesignError(ValueError):
    """A design file is malformed or infeasible; the message names the field and value."""


@dataclass
class Built:
    """One built design: its chain and the object that made it (for tables)."""

    name: str
    kind: str
    chain: Chain
    source: Any = None
    notes: dict[str, Any] = field(default_factory=dict)


# ------------------------------------------------------------ validation


def _number(value: Any, where: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DesignError(f"{where}: must be a finite number; got {value!r:.80}")
    try:
        number = float(value)
    except OverflowError:
        raise DesignError(f"{where}: must be a finite number; got an integer of {len(str(value))} digits") from None
    if not math.isfinite(number):
        raise DesignError(f"{where}: must be a finite number; got {value!r:.80}")
    if positive and not number > 0:
        raise DesignError(f"{where}: must be positive; got {value!r:.80}")
    return number


def _point(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise DesignError(f"{where}: must be a point [x, y]; got {value!r:.80}")
    return _number(value[0], f"{where}[0]"), _number(value[1], f"{where}[1]")


def _points(value: Any, where: str, minimum: int, maximum: int) -> list[tuple[float, float]]:
    if not isinstance(value, list) or len(value) < minimum:
        raise DesignError(f"{where}: must be a list of at least {minimum} points [x, y]; got {value!r:.80}")
    if len(value) > maximum:
        raise DesignError(f"{where}: {len(value):,} points; at most {maximum:,} per design (split a longer road into designs)")
    return [_point(p, f"{where}[{i}]") for i, p in enumerate(value)]


def _points_in_space(value: Any, where: str, minimum: int) -> list[tuple[float, ...]]:
    """At least ``minimum`` points, all [x, y] or all [x, y, z]."""
    if not isinstance(value, list) or len(value) < minimum:
        raise DesignError(f"{where}: must be a list of at least {minimum} points [x, y] or [x, y, z]; got {value!r:.80}")
    size = len(value[0]) if isinstance(value[0], list) else 0
    points = []
    for i, p in enumerate(value):
        if not isinstance(p, list) or len(p) not in (2, 3) or len(p) != size:
            raise DesignError(f"{where}[{i}]: must be a point like the first, [x, y] or [x, y, z]; got {p!r:.80}")
        points.append(tuple(_number(c, f"{where}[{i}][{j}]") for j, c in enumerate(p)))
    return points


def _numbers(value: Any, where: str) -> float | list[float]:
    """A positive number, or a list of them."""
    if isinstance(value, list):
        return [_number(v, f"{where}[{i}]", positive=True) for i, v in enumerate(value)]
    return _number(value, where, positive=True)


def _pairs(value: Any, where: str, count: int, convert: Callable[[Any, str], float]) -> list[tuple[float, float]]:
    """One number for all, or a list of numbers / [in, out] pairs, one per interior PI."""
    if not isinstance(value, list):
        v = convert(value, where)
        return [(v, v)] * count
    if len(value) != count:
        raise DesignError(f"{where}: needs one entry per interior PI ({count}); got {len(value)}")
    out = []
    for i, item in enumerate(value):
        if isinstance(item, list):
            if len(item) != 2:
                raise DesignError(f"{where}[{i}]: must be a number or [in, out]; got {item!r:.80}")
            out.append((convert(item[0], f"{where}[{i}][0]"), convert(item[1], f"{where}[{i}][1]")))
        else:
            v = convert(item, f"{where}[{i}]")
            out.append((v, v))
    return out


def _degrees(value: Any, where: str) -> float:
    v = _number(value, where)
    if not 0 < v < 90:
        raise DesignError(f"{where}: spiral angles are in degrees and must lie in (0, 90); got {value!r:.80}")
    return math.radians(v)


def _fields(design: dict, where: str, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> None:
    missing = [k for k in required if k not in design]
    if missing:
        raise DesignError(f"{where}: missing field(s) {', '.join(missing)}")
    unknown = sorted(set(design) - set(required) - set(optional) - {"name", "type"})
    if unknown:
        raise DesignError(f"{where}: unknown field(s) {', '.join(unknown)}")


def _choice(value: Any, where: str, choices) -> str:
    if not isinstance(value, str) or value not in choices:
        raise DesignError(f"{where}: must be one of {', '.join(choices)}; got {value!r:.80}")
    return value


def _json_integer(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise DesignError(f"an integer of {len(text.lstrip('-'))} digits is not a length or a count")
    return int(text)


def _json_constant(text: str) -> float:
    raise DesignError(f"{text} is not a number in JSON")


def _read(source: str | Path) -> bytes:
    """The bytes of the design file ``source``: a regular file of at most ``MAX_DESIGN_BYTES``.

    The file is opened without blocking and inspected before anything is
    read, so a FIFO, a device (/dev/zero), a folder or an enormous file is
    refused at once.
    """
    label = Path(source).name or str(source)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)
    try:
        descriptor = os.open(source, flags)
    except OSError as e:
        raise DesignError(f"cannot read design file {label}: {e.strerror}") from None
    except ValueError as e:  # e.g. a NUL character in the path
        raise DesignError(f"cannot read design file {label!r}: {e}") from None
    try:
        info = os.fstat(descriptor)
        if stat.S_ISDIR(info.st_mode):
            raise DesignError(f"design file {label} is a folder, not a file")
        if not stat.S_ISREG(info.st_mode):
            raise DesignError(f"design file {label} is not a regular file (a device, pipe or socket)")
        if info.st_size > MAX_DESIGN_BYTES:
            raise DesignError(f"design file {label} has {info.st_size} bytes; at most {MAX_DESIGN_BYTES} are read")
        with os.fdopen(descriptor, "rb", closefd=False) as handle:
            raw = handle.read(MAX_DESIGN_BYTES + 1)
    except OSError as e:
        raise DesignError(f"cannot read design file {label}: {e.strerror}") from None
    finally:
        os.close(descriptor)
    if len(raw) > MAX_DESIGN_BYTES:  # it grew after it was inspected
        raise DesignError(f"design file {label} has more than {MAX_DESIGN_BYTES} bytes")
    return raw


def _parse(source: str | Path) -> Any:
    """The JSON value in the file ``source``; any byte sequence either parses or raises DesignError."""
    label = Path(source).name
    raw = _read(source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise DesignError(f"{label}: not UTF-8 text (byte {e.start}: 0x{raw[e.start]:02x})") from None
    try:
        return json.loads(text, parse_int=_json_integer, parse_constant=_json_constant)
    except DesignError as e:
        raise DesignError(f"{label}: {e}") from None
    except json.JSONDecodeError as e:
        raise DesignError(f"{label}: malformed JSON at line {e.lineno}, column {e.colno}: {e.msg}") from None
    except RecursionError:
        raise DesignError(f"{label}: JSON nested too deeply") from None
    except ValueError as e:  # e.g. number conversions the json module refuses
        raise DesignError(f"{label}: {e}") from None


def load(source: str | Path | dict) -> tuple[str, list[dict]]:
    """Parse and check the top level of a design (a JSON file path or a dict): (units, designs)."""
    data = source if isinstance(source, dict) else _parse(source)
    if not isinstance(data, dict):
        raise DesignError(f"the design must be a JSON object with 'units' and 'designs'; got {type(data).__name__}")
    unknown = sorted(set(data) - {"units", "designs"})
    if unknown:
        raise DesignError(f"unknown top-level field(s) {', '.join(map(repr, unknown))}")
    if "units" not in data:
        raise DesignError(f"units: required, one of {', '.join(UNITS)}")
    units = _choice(data["units"], "units", UNITS)
    designs = data.get("designs")
    if not isinstance(designs, list) or not designs:
        raise DesignError("designs: must be a non-empty list of designs")
    names = set()
    for i, d in enumerate(designs):
        if not isinstance(d, dict):
            raise DesignError(f"designs[{i}]: must be an object; got {d!r:.80}")
        name = d.get("name")
        if not isinstance(name, str) or not NAME.fullmatch(name):
            raise DesignError(
                f"designs[{i}].name: must be 1–64 characters of A–Z, a–z, 0–9, - and _ (starting with a letter or "
                f"digit); got {name!r:.80}"
            )
        if name.casefold() in names:
            raise DesignError(f"designs[{i}].name: {name!r} is used twice (names may not differ only in case: they name files)")
        names.add(name.casefold())
        _choice(d.get("type"), f"designs[{i}].type", tuple(BUILDERS))
    return units, designs


# ------------------------------------------------------------- building


#: Design-file keys of the criteria, by kind (values as the criteria classes take them).
ROAD_KEYS = ("max_jerk", "superelevation_max", "side_friction", "shift_min", "shift_max")
RAIL_KEYS = ("cant_max", "cant_deficiency_max", "cant_rate_max", "cant_deficiency_rate_max", "cant_gradient_max", "gauge", "cant")
CROSS_SECTION_KEYS = {"driving_lanes": int, "lane_width": float, "shoulder_width": float, "rule": str, "crossfall": float,
                      "depth": float}  # fmt: skip
PROFILE_KEYS = ("pvis", "curve_lengths", "k_values", "terrain", "max_grade", "min_curve_length")


def _design_criteria(d: dict, where: str):
    """The RoadCriteria / RailCriteria of an alignment design, or None."""
    from .design import RailCriteria, RoadCriteria

    kind = _choice(d.get("criteria", "road"), f"{where}.criteria", ("road", "rail"))
    own, other = (ROAD_KEYS, RAIL_KEYS) if kind == "road" else (RAIL_KEYS, ROAD_KEYS)
    stray = [k for k in other if k in d]
    if stray:
        raise DesignError(f"{where}: {', '.join(stray)} belong(s) to {'rail' if kind == 'road' else 'road'} criteria, not {kind}")
    given = {k: _number(d[k], f"{where}.{k}") for k in own if k in d}
    if "design_speed" not in d:
        if given or "criteria" in d or "strict" in d:
            raise DesignError(f"{where}: design criteria need design_speed")
        return None
    speed = _number(d["design_speed"], f"{where}.design_speed", positive=True)
    try:
        return (RoadCriteria if kind == "road" else RailCriteria)(speed, **given)
    except ValueError as e:
        raise DesignError(f"{where}: {e}") from None


def _cross_section(d: dict, where: str):
    from .formats.opendrive import CrossSection

    value = d.get("cross_section", {})
    if not isinstance(value, dict) or set(value) - set(CROSS_SECTION_KEYS):
        raise DesignError(f"{where}.cross_section: must be an object with {', '.join(CROSS_SECTION_KEYS)}; got {value!r:.80}")
    fields = {}
    for key, kind in CROSS_SECTION_KEYS.items():
        if key in value:
            item = value[key]
            if kind is str:
                fields[key] = _choice(item, f"{where}.cross_section.{key}", ("RHT", "LHT"))
            elif kind is int:
                if isinstance(item, bool) or not isinstance(item, int) or not 1 <= item <= 10:
                    raise DesignError(f"{where}.cross_section.{key}: must be an integer from 1 to 10; got {item!r:.80}")
                fields[key] = item
            else:
                fields[key] = _number(item, f"{where}.cross_section.{key}")
    try:
        return CrossSection(**fields)
    except ValueError as e:
        raise DesignError(f"{where}.cross_section: {e}") from None


def _shape(d: dict, where: str, choices: tuple[str, ...], default: str = DEFAULT_SHAPE) -> str:
    """The design's ``spiral_shape`` (one of ``choices``), or ``default``."""
    return _choice(d.get("spiral_shape", default), f"{where}.spiral_shape", choices)


def _alignment(d: dict, where: str, units: str) -> Built:
    from .design import Alignment

    optional = ("spiral_angles_deg", "spiral_lengths", "start_station", "design_speed", "criteria", "strict",
                "cross_section", "geo_reference", "spiral_shape", "profile") + ROAD_KEYS + RAIL_KEYS  # fmt: skip
    _fields(d, where, ("pis", "radii"), optional)
    pis = _points(d["pis"], f"{where}.pis", 3, MAX_PIS)
    count = len(pis) - 2
    radii = d["radii"]
    if isinstance(radii, list):
        if len(radii) != count:
            raise DesignError(f"{where}.radii: needs one radius per interior PI ({count}); got {len(radii)}")
        radii = [_number(r, f"{where}.radii[{i}]", positive=True) for i, r in enumerate(radii)]
    else:
        radii = _number(radii, f"{where}.radii", positive=True)
    criteria = _design_criteria(d, where)
    if "spiral_angles_deg" in d and "spiral_lengths" in d:
        raise DesignError(f"{where}: give at most one of spiral_angles_deg and spiral_lengths")
    if criteria is None and "spiral_angles_deg" not in d and "spiral_lengths" not in d:
        raise DesignError(f"{where}: give spiral_angles_deg, spiral_lengths or design_speed (to choose the spirals)")
    kw = {}
    if "spiral_angles_deg" in d:
        kw["spiral_angles"] = _pairs(d["spiral_angles_deg"], f"{where}.spiral_angles_deg", count, _degrees)
    elif "spiral_lengths" in d:
        kw["spiral_lengths"] = _pairs(d["spiral_lengths"], f"{where}.spiral_lengths", count, lambda v, w: _number(v, w, positive=True))
    strict = d.get("strict", False)
    if not isinstance(strict, bool):
        raise DesignError(f"{where}.strict: must be true or false; got {strict!r:.80}")
    geo = d.get("geo_reference")
    if geo is not None:
        try:
            check_name(geo, f"{where}.geo_reference", limit=MAX_TEXT_LENGTH, multiline=True)
        except ValueError as e:
            raise DesignError(f"{e} (a PROJ string or WKT)") from None
    start = _number(d.get("start_station", 0.0), f"{where}.start_station")
    shape = _shape(d, where, TRANSITION_SHAPES, "near-linear")
    alignment = Alignment.from_pis(pis, radii, start_station=start, units=units, criteria=criteria, strict=strict, shape=shape, **kw)
    notes = {"cross_section": _cross_section(d, where), "geo_reference": geo}
    if "profile" in d:
        notes["profile"] = _profile(d["profile"], f"{where}.profile", alignment, strict)
    return Built(d["name"], "alignment", alignment.chain, alignment, notes)


def _profile(value: Any, where: str, alignment: Any, strict: bool):
    """The vertical alignment of an alignment design (its stations are the alignment's chainages)."""
    from .design import Profile, ProfileCriteria, RoadCriteria

    if not isinstance(value, dict):
        raise DesignError(f"{where}: must be an object with pvis and curve_lengths or k_values; got {value!r:.80}")
    _fields(value, where, ("pvis",), PROFILE_KEYS[1:])
    pvis = _points(value["pvis"], f"{where}.pvis", 2, MAX_PVIS)
    count = len(pvis) - 2
    if "curve_lengths" in value and "k_values" in value:
        raise DesignError(f"{where}: give at most one of curve_lengths and k_values")
    kw: dict[str, Any] = {}
    if "curve_lengths" in value:  # a number is a symmetric curve's whole length, a pair its halves
        lengths = value["curve_lengths"]
        if isinstance(lengths, list):
            pairs = _pairs(lengths, f"{where}.curve_lengths", count, lambda v, w: _number(v, w, positive=True))
            kw["curve_lengths"] = [pair if isinstance(item, list) else pair[0] for item, pair in zip(lengths, pairs)]
        else:
            kw["curve_lengths"] = _number(lengths, f"{where}.curve_lengths", positive=True)
    elif "k_values" in value:
        k = value["k_values"]
        items = k if isinstance(k, list) else [k] * count
        if len(items) != count:
            raise DesignError(f"{where}.k_values: needs one K per interior PVI ({count}); got {len(items)}")
        kw["k_values"] = [_number(v, f"{where}.k_values[{i}]", positive=True) for i, v in enumerate(items)]
    limits = {k: _number(value[k], f"{where}.{k}", positive=k == "max_grade") for k in ("max_grade", "min_curve_length") if k in value}
    terrain = value.get("terrain")
    if terrain is not None:
        from .design.profile import TERRAINS

        limits["terrain"] = _choice(terrain, f"{where}.terrain", TERRAINS)
    if isinstance(alignment.criteria, RoadCriteria):
        try:
            kw["criteria"] = ProfileCriteria(alignment.criteria.design_speed, **limits)
        except ValueError as e:
            raise DesignError(f"{where}: {e}") from None
    elif limits:
        raise DesignError(f"{where}: {', '.join(limits)} need road criteria (a design_speed with criteria \"road\")")
    if count and "curve_lengths" not in kw and "k_values" not in kw and "criteria" not in kw:
        raise DesignError(f"{where}: give curve_lengths or k_values (or a road design_speed to choose the curves)")
    try:
        return Profile.from_pvis(pvis, units=alignment.chain.units, strict=strict, alignment=alignment, **kw)
    except (NoSolutionError, ValueError) as e:
        raise DesignError(f"{where}: {e}") from None


def _circle_chain(d: dict, where: str, units: str) -> Built:
    from .design import circle_chain

    _fields(d, where, ("circles",), ("spiral_shape",))
    circles = d["circles"]
    if not isinstance(circles, list) or len(circles) < 2:
        raise DesignError(f"{where}.circles: must be a list of at least 2 circles; got {circles!r:.80}")
    parsed = []
    for i, c in enumerate(circles):
        w = f"{where}.circles[{i}]"
        if not isinstance(c, dict) or set(c) != {"center", "radius"}:
            raise DesignError(f'{w}: must be {{"center": [x, y], "radius": r}}; got {c!r:.80}')
        radius = _number(c["radius"], f"{w}.radius")
        if radius == 0:
            raise DesignError(f"{w}.radius: must be non-zero (its sign is the travel sense); got 0")
        parsed.append((_point(c["center"], f"{w}.center"), radius))
    result = circle_chain(parsed, units=units, shape=_shape(d, where, TRANSITION_SHAPES))
    return Built(d["name"], "circle_chain", result.chain, result)


#: The per-corner options of a rounded polyline (``round_corners``'s keywords).
ROUNDING_KEYS = ("curvature", "max_curvature", "max_deviation", "spiral_lengths")


def _rounded(d: dict, where: str, units: str) -> Built:
    from .design import round_corners

    _fields(d, where, (), ("points", "gcode", *ROUNDING_KEYS, "spiral_shape", "method", "samples"))
    if ("points" in d) == ("gcode" in d):
        raise DesignError(f"{where}: give points or gcode (one of them)")
    kw = {k: _numbers(d[k], f"{where}.{k}") for k in ROUNDING_KEYS if k in d}
    if "method" in d and "spiral_shape" in d:
        raise DesignError(f"{where}: give spiral_shape or method (its former name), not both")
    shape = _choice(d["method"], f"{where}.method", CORNER_SHAPES) if "method" in d else _shape(d, where, CORNER_SHAPES)
    samples = _samples(d["samples"], f"{where}.samples") if "samples" in d else None
    if "gcode" in d:
        from .formats.gcode import read_gcode, round_toolpath

        program = d["gcode"]
        if not isinstance(program, str) or not program or "\0" in program:
            raise DesignError(f"{where}.gcode: must be the path of a G-code file; got {program!r:.80}")
        result = round_toolpath(read_gcode(program).in_units(units), shape=shape, **kw)
    else:
        result = round_corners(_points_in_space(d["points"], f"{where}.points", 3), shape=shape, units=units, **kw)
    return Built(d["name"], "rounded_polyline", result.chain, result, {"samples": samples})


def _samples(value: Any, where: str) -> dict[str, float]:
    if not isinstance(value, dict) or len(value) != 1 or not set(value) <= {"step", "chord_tolerance"}:
        raise DesignError(f'{where}: must be {{"step": s}} or {{"chord_tolerance": c}}; got {value!r:.80}')
    ((key, number),) = value.items()
    return {key: _number(number, f"{where}.{key}", positive=True)}


def _transition(d: dict, where: str, units: str) -> Built:
    from .core import transitions

    case = _choice(d.get("case"), f"{where}.case", tuple(TRANSITION_ARGS))
    names = TRANSITION_ARGS[case]
    optional = tuple(n for n in names if n in OPTIONAL) + ("spiral_shape",)
    _fields(d, where, tuple(n for n in names if n not in OPTIONAL) + ("case",), optional)
    args = {}
    for n in names:
        if n in d:
            value = d[n]
            args[n] = _point(value, f"{where}.{n}") if isinstance(value, list) else _number(value, f"{where}.{n}")
    shapes = CORNER_SHAPES if case == "line_to_line" else TRANSITION_SHAPES
    t = getattr(transitions, case)(**args, shape=_shape(d, where, shapes))
    return Built(d["name"], f"transition ({t.kind})", Chain(t.spirals, units=units), t)


BUILDERS: dict[str, Callable[[dict, str, str], Built]] = {
    "alignment": _alignment,
    "circle_chain": _circle_chain,
    "rounded_polyline": _rounded,
    "transition": _transition,
}


def build(source: str | Path | dict) -> tuple[str, list[Built]]:
    """Validate and build every design of ``source``: (units, built designs).

    Raises:
        DesignError: the first malformed field or infeasible design, named as
            ``designs[i] (name)``.
    """
    units, designs = load(source)
    if not isinstance(source, dict):  # a G-code program is found next to its design file
        base = Path(source).parent
        designs = [dict(d, gcode=str(base / d["gcode"])) if isinstance(d.get("gcode"), str) and d["gcode"] and "\0" not in d["gcode"]
                   else d for d in designs]  # fmt: skip
    built = []
    for i, d in enumerate(designs):
        where = f"designs[{i}] ({d['name']})"
        try:
            built.append(BUILDERS[d["type"]](d, where, units))
        except DesignError:
            raise
        except (NoSolutionError, ValueError) as e:
            raise DesignError(f"{where}: {e}") from None
    return units, built


# -------------------------------------------------------------- writing


def missing_cad_extra() -> list[str]:
    """The packages of the ``cad`` extra that are not installed."""
    return [name for name in CAD_EXTRA if find_spec(name) is None]


@dataclass
class Written:
    """What ``write`` produced: the files, and what it could not write without the CAD extra."""

    files: list[Path]
    skipped: list[str]


def write(
    built: list[Built],
    out: str | Path,
    units: str,
    progress: Callable[[str], None] = print,
    plots: bool = True,
    extra: Callable[[Path], None] | None = None,
) -> Written:
    """Write every output of every design into ``out``, all or nothing (see the module docstring).

    Per design: STEP and SVG (always), the stationing CSV of alignments, and
    with the ``cad`` extra IGES, DXF, the plan and curvature plots (unless
    ``plots`` is False) and the continuity report of the STEP file as OCCT
    reads it. Without the extra those are skipped and named in
    ``Written.skipped``. ``extra``, if given, writes more files into the
    folder it is passed (the staging folder); they are committed with the rest.

    Raises:
        ValueError: ``out`` is a file, cannot be created or written, or a
            file in it cannot be replaced (a folder, read-only); nothing in
            ``out`` was changed.
        OSError: writing or moving a file failed; nothing in ``out`` was changed.
        KeyboardInterrupt: Ctrl-C, SIGTERM or SIGHUP; nothing in ``out`` was changed.
    """
    missing = missing_cad_extra()
    with Staging(out) as staging, _interrupts_raise():
        for b in built:
            started = time.perf_counter()
            names = _write_design(b, staging.folder, units, missing, plots)
            progress(
                f"  {b.name}: {b.kind}, {len(b.chain)} segments, length {b.chain.length:.6g} {units} "
                f"→ {', '.join(names)} ({time.perf_counter() - started:.1f} s)"
            )
        if extra is not None:
            before = set(staging.files())
            extra(staging.folder)
            added = [p.name for p in staging.files() if p not in before]
            if added:
                progress(f"  also → {', '.join(added)}")
        written = staging.commit()
    skipped = [f"{CAD_EXTRA[name]} (needs {name})" for name in missing if plots or name != "matplotlib"]
    return Written(written, skipped)


def _write_design(b: Built, stage: Path, units: str, missing: list[str], plots: bool) -> list[str]:
    """Write one design's files into ``stage``; returns what follows the name of each file written.

    The STEP file goes first; then two child processes work beside this one:
    OCCT reads the STEP for the continuity report, and the DXF is written
    (ezdxf's objects are the slowest of the files), while the rest are written here.
    """
    from .cad.sandbox import Isolated
    from .export import export_dxf, export_step

    step = stage / f"{b.name}.step"
    export_step(b.chain, step, name=b.name)
    with contextlib.ExitStack() as children:
        continuity = None
        if "OCP" not in missing:
            from .cad.continuity import checking

            continuity = children.enter_context(checking(step))  # as `spiral-cad check` reads it: the same numbers
        dxf = None
        if "ezdxf" not in missing:
            dxf = children.enter_context(Isolated(partial(export_dxf, name=b.name), b.chain, stage / f"{b.name}.dxf",
                                                  what="the DXF writer", subject=f"{b.name}.dxf"))  # fmt: skip
        names = ["step"] + _write_others(b, stage, units, missing, plots)
        if dxf is not None:
            dxf.result()
            names.append("dxf")
        if continuity is None:
            return names
        report = continuity()
    b.notes["continuity"] = f"{report.min_level} ({report.describe()})"
    (stage / f"{b.name}_continuity.txt").write_text(report.format_table() + "\n", encoding="utf-8")
    return names + ["continuity.txt"]


def _write_others(b: Built, stage: Path, units: str, missing: list[str], plots: bool) -> list[str]:
    """Every file of a design but its STEP, DXF and continuity report."""
    from .export import export_svg

    names = []
    if b.chain.dim == 2:  # SVG is a plane output (the plots draw a path in space as its plan)
        export_svg(b.chain, stage / f"{b.name}.svg", name=b.name)
        names.append("svg")
    if b.notes.get("samples"):
        from .export import export_samples

        export_samples(b.chain, stage / f"{b.name}_samples.csv", **b.notes["samples"])
        names.append("samples.csv")
    if b.kind == "alignment":
        from .export import export_opendrive

        profile = b.notes.get("profile")
        b.source.to_csv(stage / f"{b.name}_stations.csv")
        export_opendrive(b.source, stage / f"{b.name}.xodr", name=b.name, cross_section=b.notes["cross_section"],
                         geo_reference=b.notes["geo_reference"], profile=profile)  # fmt: skip
        names += ["stations.csv", "xodr"]
        if b.source.checks:
            b.source.criteria_to_csv(stage / f"{b.name}_criteria.csv")
            names.append("criteria.csv")
        if profile is not None:
            profile.to_csv(stage / f"{b.name}_profile.csv")
            names.append("profile.csv")
            if "OCP" not in missing:
                names += _road_3d(b, profile, stage, units)
    if "OCP" not in missing:
        from .export import export_iges

        export_iges(b.chain, stage / f"{b.name}.igs", name=b.name)
        names.append("igs")
    if plots and "matplotlib" not in missing:
        names += _plots(b, stage)
    return names


def _road_3d(b: Built, profile: Any, stage: Path, units: str) -> list[str]:
    """NAME_3d.step: the corridor solid and the 3-D centre line, their measured fit in the file's description."""
    from build123d import Compound

    from .cad.corridor import centerline_wire, corridor
    from .export import originating_system
    from .formats.step_occ import write_shape_step

    road = corridor(b.source, profile, b.notes["cross_section"])
    line = road.centerline
    fit = (
        f"{b.name} in 3-D: corridor solid and centre line (plan exact; z within {line.deviation:.3g} {units} of the "
        f"profile, tolerance {line.tolerance:.3g} {units}; corridor edges within {road.roadway.deviation:.3g} {units}); "
        f"centre line one wire, {line.continuity()}"
    )
    write_shape_step(Compound([road.solid, centerline_wire(line)]), stage / f"{b.name}_3d.step", b.name, units,
                     originating_system(), description=fit)  # fmt: skip
    b.notes["3d"] = f"{line.describe()}; {road.describe()}"
    return ["3d.step"]


def _plots(b: Built, stage: Path) -> list[str]:
    from .plots import plot_curvature, plot_plan

    names = []
    for suffix, plot in (("plan", plot_plan), ("curvature", plot_curvature)):
        fig = plot(b.chain)
        fig.suptitle(f"{b.name} — {b.kind}")
        fig.savefig(stage / f"{b.name}_{suffix}.png", dpi=110)
        names.append(f"{suffix}.png")
    return names


@contextmanager
def _interrupts_raise() -> Iterator[None]:
    """Turn SIGTERM and SIGHUP into KeyboardInterrupt while files are written, so cleanup runs
    (also when a library turned the interrupt into another exception: OCP's "ImportError:
    initialization failed" during a long import)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []

    def interrupt(signum, frame):
        received.append(signum)
        raise KeyboardInterrupt

    names = [s for s in ("SIGTERM", "SIGHUP") if hasattr(signal, s)]
    previous = {name: signal.signal(getattr(signal, name), interrupt) for name in names}
    try:
        yield
    except Exception:
        if received:
            raise KeyboardInterrupt from None
        raise
    finally:
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)


def criteria_tables(built: list[Built]) -> str:
    """The criteria table of every alignment designed with criteria and the table of every profile,
    with their violations."""
    parts = []
    for b in built:
        if b.kind == "alignment" and b.source.checks:
            broken = sum(1 for c in b.source.checks if not c.ok)
            verdict = "every curve meets the criteria" if not broken else f"{broken} curve(s) violate the criteria"
            parts.append(f"{b.name}: {b.source.criteria_table()}\n{b.name}: {verdict}")
        profile = b.notes.get("profile")
        if profile is not None:
            broken = sum(1 for c in profile.checks if not c.ok)
            verdict = "" if not profile.checks else (f"\n{b.name}: every PVI meets the profile criteria" if not broken
                                                     else f"\n{b.name}: {broken} PVI(s) violate the profile criteria")  # fmt: skip
            parts.append(f"{b.name} profile: {profile.table(6)}{verdict}")
    return "\n\n".join(parts)


def summary(built: list[Built], units: str) -> str:
    """One line per design: kind, spiral shape, segments, length, peak |κ| and the checked continuity."""
    head = (
        f"{'design':14} {'kind':30} {'spiral shape':13} {'segments':>8} {'length ' + units:>12} {'max |κ|':>10}  "
        "continuity (of the STEP file)"
    )
    lines = [head, "-" * len(head)]
    for b in built:
        peak = max(max(abs(seg.start_curvature), abs(seg.end_curvature)) for seg in b.chain)  # spirals are monotone
        shapes = sorted({seg.shape or "not stated" for seg in b.chain if isinstance(seg, BezierSpiral)}) or ["-"]
        lines.append(
            f"{b.name:14} {b.kind:30} {'+'.join(shapes):13} {len(b.chain):8d} {b.chain.length:12.3f} {peak:10.5f}  "
            f"{b.notes.get('continuity', '-')}"
        )
    lines += [f"{b.name}: {b.notes['3d']}" for b in built if "3d" in b.notes]
    return "\n".join(lines)
