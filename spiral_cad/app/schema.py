"""The design-file format as pydantic models: the one description of a design file.

A design file is a JSON object with ``units`` and a list of ``designs``; each
design is one of five kinds, told apart by its ``type`` (a discriminated
union), and a transition by its ``case``. The field descriptions below are
the reference: ``spiral-cad schema`` prints the JSON Schema made from them and
``schema_markdown`` renders the reference page (docs/reference/design-files.md).

Validation errors read as before the models existed: the JSON path of the
field, what it must be and the value given (``designs[0] (road).radii[1]:
must be positive; got -400``); ``error_message`` turns pydantic's errors into
that line. Checks that need a solver (does this curve fit?) are not here:
they belong to the builders of ``spiral_cad.app.designfile``.
"""

from __future__ import annotations

import json
import math
import re
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    ValidationError,
    model_validator,
)
from pydantic_core import ErrorDetails, PydanticCustomError

from ..core.units import UNITS
from ..io.names import MAX_TEXT_LENGTH, check_name

#: Design names: they name the output files.
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}")
#: PIs of one alignment and PVIs of one profile: a design's time and memory grow with them (about
#: 20 s and 1 GB for 10 000 PIs; a corridor about 0.2 GB per 1 000 PVIs), so a file cannot ask for 30 GB.
MAX_PIS = 20_000
MAX_PVIS = 2_000

#: The library's choices (UNITS, TRANSITION_SHAPES, CORNER_SHAPES; a test keeps them in step).
Units = Literal["mm", "cm", "m", "km", "in", "ft"]
TransitionShape = Literal["walton-meek", "near-linear"]
CornerShape = Literal["walton-meek", "near-linear", "g2cbs"]
Terrain = Literal["level", "rolling", "mountainous"]


# ------------------------------------------------------- field checks


def _error(message: str, *at: str | int, sep: str = ": ") -> PydanticCustomError:
    """A validation error whose message is shown as is, ``at`` the path below the failing field."""
    # the text goes in last, so no placeholder inside it (a value quoted as "{at}") is filled in
    return PydanticCustomError("design", "{message}", {"at": at, "sep": sep, "message": message})


def _shown(value: Any) -> str:
    return f"{value!r:.80}"


def _number(value: Any, *at: str | int) -> float:
    """A finite JSON number (not a bool) as float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _error(f"must be a finite number; got {_shown(value)}", *at)
    try:
        number = float(value)
    except OverflowError:
        raise _error(f"must be a finite number; got an integer of {len(str(value))} digits", *at) from None
    if not math.isfinite(number):
        raise _error(f"must be a finite number; got {_shown(value)}", *at)
    return number


def _positive(value: Any, *at: str | int) -> float:
    number = _number(value, *at)
    if not number > 0:
        raise _error(f"must be positive; got {_shown(value)}", *at)
    return number


def _degrees(value: Any, *at: str | int) -> float:
    number = _number(value, *at)
    if not 0 < number < 90:
        raise _error(f"spiral angles are in degrees and must lie in (0, 90); got {_shown(value)}", *at)
    return number


def _point(value: Any, *at: str | int) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise _error(f"must be a point [x, y]; got {_shown(value)}", *at)
    return _number(value[0], *at, 0), _number(value[1], *at, 1)


def _points(minimum: int, maximum: int):
    def check(value: Any) -> list[tuple[float, float]]:
        if not isinstance(value, list) or len(value) < minimum:
            raise _error(f"must be a list of at least {minimum} points [x, y]; got {_shown(value)}")
        if len(value) > maximum:
            raise _error(f"{len(value):,} points; at most {maximum:,} per design (split a longer road into designs)")
        return [_point(p, i) for i, p in enumerate(value)]

    return check


def _points_in_space(value: Any) -> list[tuple[float, ...]]:
    """At least 3 points, all [x, y] or all [x, y, z]."""
    if not isinstance(value, list) or len(value) < 3:
        raise _error(f"must be a list of at least 3 points [x, y] or [x, y, z]; got {_shown(value)}")
    size = len(value[0]) if isinstance(value[0], list) else 0
    points = []
    for i, p in enumerate(value):
        if not isinstance(p, list) or len(p) not in (2, 3) or len(p) != size:
            raise _error(f"must be a point like the first, [x, y] or [x, y, z]; got {_shown(p)}", i)
        points.append(tuple(_number(c, i, j) for j, c in enumerate(p)))
    return points


def _one_or_many(convert):
    """A number, or a list of numbers (each checked by ``convert``)."""

    def check(value: Any) -> float | list[float]:
        if isinstance(value, list):
            return [convert(v, i) for i, v in enumerate(value)]
        return convert(value)

    return check


def _per_curve(convert):
    """A number for every curve, or a list of numbers / [in, out] pairs (counted by the design)."""

    def check(value: Any) -> float | list[float | tuple[float, float]]:
        if not isinstance(value, list):
            return convert(value)
        out: list[float | tuple[float, float]] = []
        for i, item in enumerate(value):
            if isinstance(item, list):
                if len(item) != 2:
                    raise _error(f"must be a number or [in, out]; got {_shown(item)}", i)
                out.append((convert(item[0], i, 0), convert(item[1], i, 1)))
            else:
                out.append(convert(item, i))
        return out

    return check


def _name(value: Any) -> str:
    if not isinstance(value, str) or not NAME.fullmatch(value):
        raise _error(f"must be 1–64 characters of A–Z, a–z, 0–9, - and _ (starting with a letter or digit); got {_shown(value)}")
    return value


def _text(value: Any) -> str:
    try:
        return check_name(value, "", limit=MAX_TEXT_LENGTH, multiline=True)
    except ValueError as e:
        raise _error(f"{str(e).strip()} (a PROJ string or WKT)", sep=" ") from None


def _gcode(value: Any) -> str:
    if not isinstance(value, str) or not value or "\0" in value:
        raise _error(f"must be the path of a G-code file; got {_shown(value)}")
    return value


def _lanes(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 10:
        raise _error(f"must be an integer from 1 to 10; got {_shown(value)}")
    return value


def _strict(value: Any) -> bool:
    if not isinstance(value, bool):
        raise _error(f"must be true or false; got {_shown(value)}")
    return value


PositiveSchema = Annotated[float, Field(gt=0)]
PairSchema = Annotated[list[PositiveSchema], Field(min_length=2, max_length=2)]
Number = Annotated[float, PlainValidator(_number, json_schema_input_type=float)]
Positive = Annotated[float, PlainValidator(_positive, json_schema_input_type=PositiveSchema)]
Point = Annotated[
    tuple[float, float],
    PlainValidator(_point, json_schema_input_type=Annotated[list[float], Field(min_length=2, max_length=2)]),
]
Name = Annotated[str, PlainValidator(_name, json_schema_input_type=Annotated[str, Field(pattern=f"^{NAME.pattern}$")])]
Flag = Annotated[bool, PlainValidator(_strict, json_schema_input_type=bool)]
PositiveOrList = Annotated[
    float | list[float],
    PlainValidator(_one_or_many(_positive), json_schema_input_type=PositiveSchema | list[PositiveSchema]),
]
PositivePerCurve = Annotated[
    float | list[float | tuple[float, float]],
    PlainValidator(_per_curve(_positive), json_schema_input_type=PositiveSchema | list[PositiveSchema | PairSchema]),
]
AngleSchema = Annotated[float, Field(gt=0, lt=90)]
AnglesPerCurve = Annotated[
    float | list[float | tuple[float, float]],
    PlainValidator(
        _per_curve(_degrees),
        json_schema_input_type=AngleSchema | list[AngleSchema | Annotated[list[AngleSchema], Field(min_length=2, max_length=2)]],
    ),
]


def _counted(value: float | list, count: int, what: str, field: str) -> None:
    """Refuse a list that does not hold one entry per interior PI/PVI (``count``)."""
    if isinstance(value, list) and len(value) != count:
        raise _error(f"needs {what} ({count}); got {len(value)}", field)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class GcodeOut(_Model):
    """NAME.ngc, the path as a G-code program: written for every rounded polyline, for other designs when given."""

    dialect: Literal["linuxcnc", "generic"] = Field(
        "linuxcnc", description="linuxcnc: spirals in XY as exact G5 cubics; generic (Grbl, Marlin): spirals as biarcs."
    )
    feed: Positive | None = Field(
        None,
        description="The F word, in the program's unit per minute (default: a path read from a G-code program keeps that "
        "program's F, else 1000 mm/min, 40 in/min).",
    )
    chord_tolerance: Positive | None = Field(None, description="Pieces in space as G1 chords within this (default 0.001 mm).")
    arc_tolerance: Positive | None = Field(None, description="Spirals as biarcs within this (default 0.001 mm).")

    def options(self) -> dict[str, Any]:
        """The keywords of ``write_gcode``."""
        return {k: v for k, v in self if v is not None}


# ------------------------------------------------------------ alignment


class CrossSection(_Model):
    """The road's lanes (OpenDRIVE) and the corridor's crown and pavement, in metres."""

    driving_lanes: Annotated[int, PlainValidator(_lanes, json_schema_input_type=Annotated[int, Field(ge=1, le=10)])] = Field(
        1, description="Driving lanes each side (1–10)."
    )
    lane_width: Number = Field(3.5, description="Lane width (m).")
    shoulder_width: Number = Field(2.5, description="Shoulder width (m).")
    rule: Literal["RHT", "LHT"] = Field("RHT", description="Right- or left-hand traffic.")
    crossfall: Number = Field(0.025, description="Crown crossfall of the corridor (m/m).")
    depth: Number = Field(0.5, description="Pavement depth of the corridor (m).")


class Profile(_Model):
    """The vertical alignment: NAME_profile.csv, elevation in the .xodr, the 3-D centre line and corridor
    in NAME_3d.step."""

    pvis: Annotated[
        list[tuple[float, float]],
        PlainValidator(_points(2, MAX_PVIS), json_schema_input_type=Annotated[list[Point], Field(min_length=2, max_length=MAX_PVIS)]),
    ] = Field(description="Points of vertical intersection [station, elevation] (≥ 2); stations are the alignment's "
              "chainages (start_station at its first PI) and must cover the alignment.")  # fmt: skip
    curve_lengths: PositivePerCurve | None = Field(
        None,
        description="Vertical curve lengths: one for all, or one per interior PVI, each a whole length or "
        "[in, out] halves. Or give k_values, or neither with a road design_speed: the shortest curves that meet "
        "the stopping sight distance.",
    )
    k_values: PositiveOrList | None = Field(None, description="K (length per % of grade change): one for all or one per interior PVI.")
    terrain: Terrain | None = Field(None, description="The terrain of the road criteria's maximum grade.")
    max_grade: Positive | None = Field(None, description="Maximum grade (a fraction), overriding the terrain's.")
    min_curve_length: Number | None = Field(None, description="Shortest vertical curve (a length).")

    @model_validator(mode="after")
    def _counts(self) -> Profile:
        if self.curve_lengths is not None and self.k_values is not None:
            raise _error("give at most one of curve_lengths and k_values")
        count = len(self.pvis) - 2
        if self.curve_lengths is not None:
            _counted(self.curve_lengths, count, "one entry per interior PI", "curve_lengths")
        if self.k_values is not None:
            _counted(self.k_values, count, "one K per interior PVI", "k_values")
        return self


#: Design-file keys of the criteria, by kind (values as the criteria classes take them).
ROAD_KEYS = ("max_jerk", "superelevation_max", "side_friction", "shift_min", "shift_max")
RAIL_KEYS = ("cant_max", "cant_deficiency_max", "cant_rate_max", "cant_deficiency_rate_max", "cant_gradient_max", "gauge", "cant")


class AlignmentDesign(_Model):
    """A road or railway alignment through points of intersection: spirals, circular curves and tangents
    (also the stationing CSV, OpenDRIVE and, with a profile, the road in 3-D)."""

    name: Name = Field(description="Names the output files: 1–64 of A–Z, a–z, 0–9, - and _; no two differ only in case.")
    type: Literal["alignment"]
    gcode_out: GcodeOut | None = Field(None, description="Also write NAME.ngc, the path as G-code.")
    pis: Annotated[
        list[tuple[float, float]],
        PlainValidator(_points(3, MAX_PIS), json_schema_input_type=Annotated[list[Point], Field(min_length=3, max_length=MAX_PIS)]),
    ] = Field(description="Points of intersection [x, y] in travel order (≥ 3).")
    radii: PositiveOrList = Field(description="One positive radius per interior PI, or one for all.")
    spiral_angles_deg: AnglesPerCurve | None = Field(
        None, description="Spiral angles in degrees: one for all, or one per interior PI, each θ or [θin, θout]."
    )
    spiral_lengths: PositivePerCurve | None = Field(
        None, description="Spiral lengths instead of angles: one for all, or one per interior PI, each L or [Lin, Lout]. "
        "Neither, with design_speed: the shortest spirals that meet every criterion.",
    )  # fmt: skip
    start_station: Number = Field(0.0, description="Chainage of the first PI.")
    design_speed: Positive | None = Field(None, description="km/h (metric units) or mph (in, ft); needed by criteria.")
    criteria: Literal["road", "rail"] | None = Field(None, description="Which design criteria (default road).")
    strict: Flag = Field(False, description="true: a violated criterion is an error.")
    spiral_shape: TransitionShape = Field("near-linear", description="near-linear, or walton-meek (the 1996 spiral, "
                                          "1.6–1.8× longer for the same jerk).")  # fmt: skip
    # ignore: without pydantic's mypy plugin, mypy misses Field's positional defaults and takes CrossSection() as incomplete
    cross_section: CrossSection = Field(default_factory=CrossSection, description="OpenDRIVE lanes and the corridor.")  # type: ignore[arg-type]
    geo_reference: (
        Annotated[str, PlainValidator(_text, json_schema_input_type=Annotated[str, Field(max_length=MAX_TEXT_LENGTH)])] | None
    ) = Field(None, description="OpenDRIVE geoReference: a PROJ string or WKT (printable text, ≤ 10 000 characters).")
    profile: Profile | None = Field(None, description="Optional vertical alignment.")
    max_jerk: Number | None = Field(None, description="Road: largest rate of change of lateral acceleration (m/s³, default 0.6).")
    superelevation_max: Number | None = Field(None, description="Road: largest superelevation (default 0.08).")
    side_friction: Number | None = Field(None, description="Road: side friction factor.")
    shift_min: Number | None = Field(None, description="Road: smallest shift of a circular curve.")
    shift_max: Number | None = Field(None, description="Road: largest shift of a circular curve.")
    cant_max: Number | None = Field(None, description="Rail: largest cant (mm).")
    cant_deficiency_max: Number | None = Field(None, description="Rail: largest cant deficiency (mm).")
    cant_rate_max: Number | None = Field(None, description="Rail: largest rate of change of cant (mm/s).")
    cant_deficiency_rate_max: Number | None = Field(None, description="Rail: largest rate of change of cant deficiency (mm/s).")
    cant_gradient_max: Number | None = Field(None, description="Rail: largest cant gradient (mm/m).")
    gauge: Number | None = Field(None, description="Rail: track gauge (mm).")
    cant: Number | None = Field(None, description="Rail: the applied cant (mm).")

    @model_validator(mode="after")
    def _consistent(self) -> AlignmentDesign:
        count = len(self.pis) - 2
        _counted(self.radii, count, "one radius per interior PI", "radii")
        kind = self.criteria or "road"
        stray = [k for k in (RAIL_KEYS if kind == "road" else ROAD_KEYS) if getattr(self, k) is not None]
        if stray:
            other = "rail" if kind == "road" else "road"
            raise _error(f"{', '.join(stray)} belong(s) to {other} criteria, not {kind}")
        if self.design_speed is None and (self.criteria_values() or self.criteria is not None or "strict" in self.model_fields_set):
            raise _error("design criteria need design_speed")
        if self.spiral_angles_deg is not None and self.spiral_lengths is not None:
            raise _error("give at most one of spiral_angles_deg and spiral_lengths")
        if self.design_speed is None and self.spiral_angles_deg is None and self.spiral_lengths is None:
            raise _error("give spiral_angles_deg, spiral_lengths or design_speed (to choose the spirals)")
        for key in ("spiral_angles_deg", "spiral_lengths"):
            if getattr(self, key) is not None:
                _counted(getattr(self, key), count, "one entry per interior PI", key)
        return self

    def criteria_values(self) -> dict[str, float]:
        """The criteria keys given (of road or rail criteria, whichever the design names)."""
        keys = RAIL_KEYS if self.criteria == "rail" else ROAD_KEYS
        return {k: getattr(self, k) for k in keys if getattr(self, k) is not None}


# --------------------------------------------------------- other kinds


class Circle(_Model):
    """One circle of a circle chain."""

    center: Point = Field(description="[x, y].")
    radius: Number = Field(description="Signed radius: its sign is the travel sense (+ counterclockwise); not 0.")

    @model_validator(mode="after")
    def _nonzero(self) -> Circle:
        if self.radius == 0:
            raise _error("must be non-zero (its sign is the travel sense); got 0", "radius")
        return self


class CircleChainDesign(_Model):
    """Circles joined in order by G2 spiral transitions."""

    name: Name = Field(description="Names the output files (see alignment).")
    type: Literal["circle_chain"]
    circles: list[Circle] = Field(min_length=2, description="At least 2 circles, in travel order.")
    spiral_shape: TransitionShape = Field("walton-meek", description="walton-meek or near-linear.")
    gcode_out: GcodeOut | None = Field(None, description="Also write NAME.ngc, the path as G-code.")


class Samples(_Model):
    """NAME_samples.csv for a machine: s, x, y, z, tangent and curvature along the path; one of the two keys."""

    step: Positive | None = Field(None, description="Samples at most this far apart along the path.")
    chord_tolerance: Positive | None = Field(
        None, description="Samples close enough that the path strays at most this far from their chords."
    )

    @model_validator(mode="after")
    def _one(self) -> Samples:
        if (self.step is None) == (self.chord_tolerance is None):
            raise _error('must be {"step": s} or {"chord_tolerance": c}; got both or neither')
        return self

    def options(self) -> dict[str, float]:
        """The keyword of ``export_samples``."""
        key = "step" if self.step is not None else "chord_tolerance"
        return {key: getattr(self, key)}


#: The per-corner options of a rounded polyline (``round_corners``'s keywords).
ROUNDING_KEYS = ("curvature", "max_curvature", "max_deviation", "spiral_lengths")


class RoundedPolylineDesign(_Model):
    """A polyline in the plane or in space, or a G-code program's straight moves (README: the subset), with
    every corner rounded G2. A path in space gets STEP, IGES, DXF, samples and the continuity report (SVG and
    the plots are plane outputs)."""

    name: Name = Field(description="Names the output files (see alignment).")
    type: Literal["rounded_polyline"]
    points: Annotated[
        list[tuple[float, ...]],
        PlainValidator(_points_in_space, json_schema_input_type=Annotated[
            list[Annotated[list[float], Field(min_length=2, max_length=3)]], Field(min_length=3)]),
    ] | None = Field(None, description="≥ 3 points, all [x, y] or all [x, y, z]. Give points or gcode.")  # fmt: skip
    gcode: Annotated[str, PlainValidator(_gcode, json_schema_input_type=Annotated[str, Field(min_length=1)])] | None = Field(
        None,
        description="A G-code program in the design file's folder (a relative path without '..'), named "
        "*.nc, .ngc, .gcode, .gc, .g, .tap, .cnc, .mpt or .mpf: its G0/G1 moves (G20/G21 converted to units).",
    )
    max_deviation: PositiveOrList | None = Field(None, description="The largest distance between a corner point and "
                                                 "the path: a number or one per interior point.")  # fmt: skip
    max_curvature: PositiveOrList | None = Field(None, description="The curvature bound (alone: every corner peaks at it).")
    curvature: PositiveOrList | None = Field(None, description="The peak curvature of every corner (instead of the bounds).")
    spiral_lengths: PositiveOrList | None = Field(None, description="The spiral length of every corner (instead of the "
                                                  "bounds); none of these: as large as fits.")  # fmt: skip
    samples: Samples | None = Field(None, description="Optional samples for a machine.")
    gcode_out: GcodeOut | None = Field(None, description="The options of NAME.ngc, the path as G-code (always written).")
    spiral_shape: CornerShape | None = Field(None, description="walton-meek (default), near-linear or g2cbs.")
    method: CornerShape | None = Field(None, description="The former name of spiral_shape.")

    @model_validator(mode="after")
    def _one_source(self) -> RoundedPolylineDesign:
        if (self.points is None) == (self.gcode is None):
            raise _error("give points or gcode (one of them)")
        if self.method is not None and self.spiral_shape is not None:
            raise _error("give spiral_shape or method (its former name), not both")
        return self

    @property
    def shape(self) -> str:
        """The spiral shape (walton-meek unless given)."""
        return self.spiral_shape or self.method or "walton-meek"

    def rounding(self) -> dict[str, Any]:
        """``round_corners``'s per-corner keywords that were given."""
        return {k: getattr(self, k) for k in ROUNDING_KEYS if getattr(self, k) is not None}


def _points_file(value: Any) -> str:
    if not isinstance(value, str) or not value or "\0" in value:
        raise _error(f"must be the path of a points file (.csv, .txt or .xyz); got {_shown(value)}")
    return value


class FitDesign(_Model):
    """Lines, arcs and spirals fitted G2 to measured or digitised points, every point within a tolerance
    (``spiral_cad.fit_points``); NAME_residuals.csv and NAME_fit.png report every point's distance. With a
    design_speed the fit is a road alignment (``Alignment.fit``: also the stationing CSV and OpenDRIVE); points
    with z are a road's plan and profile (``fit_survey``: also the profile CSV and the road in 3-D)."""

    name: Name = Field(description="Names the output files (see alignment).")
    type: Literal["fit"]
    points: Annotated[
        list[tuple[float, ...]],
        PlainValidator(_points_in_space, json_schema_input_type=Annotated[
            list[Annotated[list[float], Field(min_length=2, max_length=3)]], Field(min_length=3)]),
    ] | None = Field(None, description="≥ 3 points in order, all [x, y] or all [x, y, z]. Give points or points_file.")  # fmt: skip
    points_file: Annotated[str, PlainValidator(_points_file, json_schema_input_type=Annotated[str, Field(min_length=1)])] | None = Field(
        None,
        description="A points file in the design file's folder (a relative path without '..'): CSV or "
        "whitespace-separated columns x, y[, z], header optional (x/easting, y/northing, z/elevation in any order), "
        "# comments, '# units: m' or 'x [m]' stating its unit (converted to units).",
    )  # fmt: skip
    points_units: Units | None = Field(None, description="The unit of the points file's numbers when the file states none "
                                       "(default: the design file's units).")  # fmt: skip
    tolerance: Positive = Field(description="The largest distance from any point to the fitted path.")
    closed: Flag = Field(False, description="true: the path closes G2 through the first point.")
    spiral_shape: TransitionShape = Field("near-linear", description="near-linear, or walton-meek.")
    max_curvature: Positive | None = Field(None, description="A curvature bound for the fitted path (1/unit).")
    design_speed: Positive | None = Field(None, description="km/h (metric units) or mph (in, ft): fit a road alignment "
                                          "and report which curves meet the road criteria at this speed.")  # fmt: skip
    vertical_tolerance: Positive | None = Field(None, description="Points with z (a 3-D survey, fitted as a road: plan "
                                                "and profile): the largest |z − profile| (default: tolerance).")  # fmt: skip
    samples: Samples | None = Field(None, description="Optional samples for a machine.")
    gcode_out: GcodeOut | None = Field(None, description="Also write NAME.ngc, the path as G-code.")

    @model_validator(mode="after")
    def _one_source(self) -> FitDesign:
        if (self.points is None) == (self.points_file is None):
            raise _error("give points or points_file (one of them)")
        if self.points_units is not None and self.points_file is None:
            raise _error("points_units states the unit of a points_file; inline points are in the file's units")
        return self


class _Transition(_Model):
    name: Name = Field(description="Names the output files (see alignment).")
    type: Literal["transition"]
    gcode_out: GcodeOut | None = Field(None, description="Also write NAME.ngc, the path as G-code.")

    def arguments(self) -> dict[str, Any]:
        """The transition function's keyword arguments."""
        return {k: v for k, v in self if k not in ("name", "type", "case", "spiral_shape", "gcode_out") and v is not None}


class LineToCircle(_Transition):
    """``line_to_circle``: from a line into a circle."""

    case: Literal["line_to_circle"]
    point: Point = Field(description="A point of the line.")
    direction: Point = Field(description="The line's direction of travel.")
    center: Point = Field(description="The circle's centre.")
    radius: Number = Field(description="The circle's radius.")
    spiral_shape: TransitionShape = Field("walton-meek", description="walton-meek or near-linear.")


class CircleToCircle(_Transition):
    """``circle_to_circle``: a C (same sense) or S (opposite senses: signed radii) transition."""

    case: Literal["circle_to_circle"]
    center0: Point = Field(description="The first circle's centre.")
    radius0: Number = Field(description="The first circle's signed radius.")
    center1: Point = Field(description="The second circle's centre.")
    radius1: Number = Field(description="The second circle's signed radius.")
    spiral_shape: TransitionShape = Field("walton-meek", description="walton-meek or near-linear.")


class CircleInCircle(_Transition):
    """``circle_in_circle``: from a circle to one inside it."""

    case: Literal["circle_in_circle"]
    center0: Point = Field(description="The outer circle's centre.")
    radius0: Number = Field(description="The outer circle's radius.")
    center1: Point = Field(description="The inner circle's centre.")
    radius1: Number = Field(description="The inner circle's radius.")
    spiral_shape: TransitionShape = Field("walton-meek", description="walton-meek or near-linear.")


class LineToLine(_Transition):
    """``line_to_line``: a corner p0 → corner → p1 rounded by two spirals."""

    case: Literal["line_to_line"]
    p0: Point = Field(description="A point of the first line.")
    corner: Point = Field(description="The corner.")
    p1: Point = Field(description="A point of the second line.")
    curvature: Number | None = Field(None, description="The peak curvature (default: as large as fits).")
    spiral_shape: CornerShape = Field("walton-meek", description="walton-meek, near-linear or g2cbs.")


def _g2_source(value: Any) -> str:
    if not isinstance(value, str) or not value or "\0" in value or not value.lower().endswith((".dxf", ".xml", ".xodr")):
        raise _error(f"must be the path of a .dxf, .xml (LandXML) or .xodr (OpenDRIVE) file; got {_shown(value)}")
    return value


class G2PathDesign(_Model):
    """The lines and arcs of a DXF drawing, a LandXML alignment or an OpenDRIVE road made G2 within max_deviation
    (``spiral_cad.design.make_g2``), arcs kept true arcs: one design per G2 path (NAME_1, NAME_2, … when there are several)."""

    name: Name = Field(description="Names the output files (see alignment).")
    type: Literal["g2_path"]
    source: Annotated[str, PlainValidator(_g2_source, json_schema_input_type=Annotated[str, Field(min_length=1)])] = Field(
        description="A .dxf, LandXML .xml or OpenDRIVE .xodr file in the design file's folder (relative, without '..'); "
        "a LandXML or OpenDRIVE file's unit must be the design file's.")  # fmt: skip
    max_deviation: Positive = Field(description="The largest distance between the file's path and the G2 path.")
    source_units: Units | None = Field(None, description="DXF: the unit of a unitless drawing (default: refused).")
    spiral_shape: TransitionShape = Field("near-linear", description="near-linear (default) or walton-meek.")
    gcode_out: GcodeOut | None = Field(None, description="Also write NAME.ngc, the path as G-code.")


TransitionDesign = Annotated[LineToCircle | CircleToCircle | LineToLine | CircleInCircle, Field(discriminator="case")]
Design = Annotated[AlignmentDesign | CircleChainDesign | RoundedPolylineDesign | TransitionDesign | FitDesign | G2PathDesign,
                   Field(discriminator="type")]  # fmt: skip
TYPES = ("alignment", "circle_chain", "rounded_polyline", "transition", "fit", "g2_path")
CASES = ("line_to_circle", "circle_to_circle", "line_to_line", "circle_in_circle")


class DesignFile(_Model):
    """A spiral-cad design file: UTF-8 JSON, a regular file of at most 10 MB. ``spiral-cad build FILE``
    writes every design's STEP, SVG (plane paths), IGES, DXF, plots and continuity report."""

    model_config = ConfigDict(extra="forbid", title="spiral-cad design file",
                              json_schema_extra={"$schema": "https://json-schema.org/draft/2020-12/schema"})  # fmt: skip

    schema_uri: str | None = Field(None, alias="$schema", description="The schema's address; accepted and ignored.")
    units: Units = Field(description="The unit of every length in the file (required).")
    designs: list[Design] = Field(min_length=1, description="The designs; each is built and written under its name.")

    @model_validator(mode="after")
    def _unique_names(self) -> DesignFile:
        seen: set[str] = set()
        for i, d in enumerate(self.designs):
            if d.name.casefold() in seen:
                raise _error(f"{d.name!r} is used twice (names may not differ only in case: they name files)", "designs", i, "name")
            seen.add(d.name.casefold())
        return self


# ------------------------------------------------------------- errors


def _where(loc: tuple, data: Any) -> str:
    """``loc`` as a JSON path, with the union tags dropped and a design named after its index."""
    parts = list(loc)
    label = ""
    if len(parts) >= 2 and parts[0] == "designs" and isinstance(parts[1], int):
        i = parts[1]
        parts = parts[2:]
        if parts and parts[0] in TYPES:
            tag = parts.pop(0)
            if tag == "transition" and parts and parts[0] in CASES:
                parts.pop(0)
        name = _at(data, ("designs", i, "name"))
        named = isinstance(name, str) and NAME.fullmatch(name) and not (parts and parts[0] in ("name", "type"))
        label = f"designs[{i}] ({name})" if named else f"designs[{i}]"
    for part in parts:
        label += f"[{part}]" if isinstance(part, int) else f".{part}" if label else str(part)
    return label


def _at(data: Any, loc: tuple) -> Any:
    for key in loc:
        try:
            data = data[key]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def _choices(expected: str) -> str:
    return ", ".join(re.findall(r"'([^']*)'", expected))


def _line(error: ErrorDetails, data: Any, errors: list[ErrorDetails]) -> str:
    """One error as ``path: message``."""
    kind, loc, value, ctx = error["type"], tuple(error["loc"]), error.get("input"), error.get("ctx") or {}
    if kind == "design":
        where = _where(loc + tuple(ctx.get("at", ())), data)
        return f"{where}{ctx.get('sep', ': ') if where else ''}{error['msg']}"
    if kind in ("missing", "extra_forbidden"):
        parent = loc[:-1]
        names = [e["loc"][-1] for e in errors if e["type"] == kind and tuple(e["loc"][:-1]) == parent]
        if kind == "missing" and not parent:
            return f"{names[0]}: required" + (f", one of {', '.join(UNITS)}" if names[0] == "units" else "")
        if kind == "extra_forbidden" and not parent:
            return f"unknown top-level field(s) {', '.join(map(repr, names))}"
        what = "missing field(s)" if kind == "missing" else "unknown field(s)"
        return f"{_where(parent, data)}: {what} {', '.join(map(str, names))}"
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        key = ctx.get("discriminator", "'type'").strip("'")
        where = _where(loc + (key,), data)
        choices = TYPES if key == "type" else CASES
        if kind == "union_tag_not_found":
            return f"{where}: required, one of {', '.join(choices)}"
        return f"{where}: must be one of {', '.join(choices)}; got {_shown(_at(value, (key,)))}"
    where = _where(loc, data)
    messages = {
        "literal_error": lambda: f"must be one of {_choices(ctx.get('expected', ''))}; got {_shown(value)}",
        "model_type": lambda: f"must be an object; got {_shown(value)}",
        "model_attributes_type": lambda: f"must be an object; got {_shown(value)}",
        "dict_type": lambda: f"must be an object; got {_shown(value)}",
        "list_type": lambda: f"must be a list; got {_shown(value)}",
        "string_type": lambda: f"must be a string; got {_shown(value)}",
        "too_short": lambda: f"must hold at least {ctx.get('min_length')} item(s); got {ctx.get('actual_length')}",
        "too_long": lambda: f"holds {ctx.get('actual_length')} items; at most {ctx.get('max_length')}",
    }
    message = messages.get(kind, lambda: f"{error['msg']}; got {_shown(value)}")()
    return f"{where}: {message}" if where else message


def error_message(error: ValidationError, data: Any) -> str:
    """The first problem of ``error`` (pydantic's, validating ``data``) as ``path: message``,
    naming how many more there are."""
    errors = error.errors(include_url=False)
    first = _line(errors[0], data, errors)
    grouped = errors[0]["type"] in ("missing", "extra_forbidden")
    rest = [e for e in errors[1:] if not (grouped and e["type"] == errors[0]["type"]
                                          and e["loc"][:-1] == errors[0]["loc"][:-1])]  # fmt: skip
    return first + (f" (and {len(rest)} more problem{'s' * (len(rest) > 1)})" if rest else "")


def validate(data: Any) -> DesignFile:
    """``data`` (a parsed design file) as a DesignFile.

    Raises:
        ValueError: the first malformed field, named by its JSON path (see ``error_message``).
    """
    if not isinstance(data, dict):
        raise ValueError(f"the design must be a JSON object with 'units' and 'designs'; got {type(data).__name__}")
    try:
        return DesignFile.model_validate(data)
    except ValidationError as e:
        raise ValueError(error_message(e, data)) from None


# ---------------------------------------------------- schema and docs


def json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of design files."""
    return DesignFile.model_json_schema(by_alias=True)


def schema_text() -> str:
    """The JSON Schema as indented JSON (what ``spiral-cad schema`` prints)."""
    return json.dumps(json_schema(), indent=2, ensure_ascii=False)


def _type(node: dict[str, Any]) -> str:
    """A schema node in a few words for a table cell."""
    if "$ref" in node:
        name = node["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{name.lower()})"
    if "anyOf" in node:
        kinds = [_type(n) for n in node["anyOf"] if n.get("type") != "null"]
        return " or ".join(kinds)
    if "oneOf" in node:
        return " or ".join(_type(n) for n in node["oneOf"])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        return " or ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    kind = node.get("type", "any")
    limits = []
    for key, sign in (("exclusiveMinimum", ">"), ("minimum", "≥"), ("exclusiveMaximum", "<"), ("maximum", "≤")):
        if key in node:
            limits.append(f"{sign} {node[key]:g}")
    if kind == "array":
        inner = _type(node.get("items", {})) if "items" in node else "any"
        if "prefixItems" in node:
            inner = ", ".join(_type(n) for n in node["prefixItems"])
        size = (node.get("minItems"), node.get("maxItems"))
        count = ("" if size == (None, None) else f"{size[0]}" if size[0] == size[1]
                 else f"{size[0] or 0}–{size[1]}" if size[1] is not None else f"≥ {size[0]}")  # fmt: skip
        inner = f"({inner})" if " or " in inner else inner
        return f"list{f' ({count})' if count else ''} of {inner}"
    if kind == "string" and "pattern" in node:
        limits.append(f"matching `{node['pattern']}`")
    if kind == "string" and "maxLength" in node:
        limits.append(f"≤ {node['maxLength']:,} characters")
    return kind + (f" ({', '.join(limits)})" if limits else "")


def _section(title: str, node: dict[str, Any]) -> list[str]:
    lines = [f"## {title}", "", node.get("description", "").replace("\n", " "), ""]
    if "oneOf" in node:  # a union: its members
        mapping = node.get("discriminator", {}).get("mapping", {})
        lines += [f"One of, by `{node['discriminator']['propertyName']}`:", ""]
        for tag, ref in mapping.items():
            if isinstance(ref, dict):  # a nested union (transitions by case)
                inner = ref.get("discriminator", {})
                cases = ", ".join(f"`{case}` {_type({'$ref': r})}" for case, r in inner.get("mapping", {}).items())
                lines.append(f"- `{tag}`: by `{inner.get('propertyName')}`: {cases}")
            else:
                lines.append(f"- `{tag}`: {_type({'$ref': ref})}")
        return lines + [""]
    required = set(node.get("required", ()))
    lines += ["| field | type | required / default | description |", "|---|---|---|---|"]
    for key, field in node.get("properties", {}).items():
        default = field.get("default")
        need = "required" if key in required else "optional" if default is None else f"default `{json.dumps(default)}`"
        text = field.get("description", "").replace("|", "\\|").replace("\n", " ")
        lines.append(f"| `{key}` | {_type(field)} | {need} | {text} |")
    return lines + [""]


def schema_markdown() -> str:
    """The reference page of design files (docs/reference/design-files.md), rendered from the JSON Schema."""
    schema = json_schema()
    lines = [
        "# Design files",
        "",
        "<!-- Generated by spiral_cad.app.schema.schema_markdown() from the JSON Schema; do not edit. -->",
        "",
        (
            "`spiral-cad build FILE.json` builds a design file; `spiral-cad schema` prints its JSON Schema "
            '(draft 2020-12), which a file may name in `"$schema"`. Every length is in the file\'s `units`.'
        ),
        "An error names the JSON path and the value, e.g. `designs[0] (highway).radii[1]: must be positive; got -400`.",
        "",
    ]
    lines += _section("DesignFile", schema)
    kinds = {"description": "Each design is told apart by its `type` (a transition also by its `case`).",
             **schema["properties"]["designs"]["items"]}  # fmt: skip
    lines += _section("Design", kinds)
    for name, node in schema.get("$defs", {}).items():
        lines += _section(name, node)
    return "\n".join(lines).rstrip() + "\n"
