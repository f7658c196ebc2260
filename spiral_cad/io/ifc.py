"""IFC 4.3 (ISO 16739-1:2024) alignments, written through ifcopenshell.

``write_ifc`` writes one ``IfcAlignment`` per alignment, aggregated to the
``IfcProject`` and referenced by the ``IfcSite`` (as ifcopenshell's alignment
API places them), with

* the horizontal layout: an ``IfcAlignmentHorizontal`` nesting one
  ``IfcAlignmentSegment`` per piece, whose ``IfcAlignmentHorizontalSegment``
  is ``LINE``, ``CIRCULARARC`` or ``CUBIC`` (our spirals), and the
  ``IfcCompositeCurve`` of ``IfcCurveSegment`` that represents it: lines on
  ``IfcLine``, arcs on ``IfcCircle`` (``SegmentLength`` negative for a right
  turn) and spirals on ``IfcPolynomialCurve`` (the mapping the concept
  templates and the validation rule ALB023 give for ``CUBIC``);
* with a profile, the vertical layout (``IfcAlignmentVertical``:
  ``CONSTANTGRADIENT`` and ``PARABOLICARC``) and the ``IfcGradientCurve`` over
  the composite curve: grades on ``IfcLine``, parabolas on
  ``IfcPolynomialCurve`` with ``CoefficientsX = (0, 1)``;
* the zero-length segment that ends every layout and every curve;
* the project's length unit from the design (``IfcSIUnit`` metre with its
  prefix, ``IfcConversionBasedUnit`` foot or inch), angles in radians.

**A spiral as a graph, so that stations agree.** ``SegmentStart`` and
``SegmentLength`` are ``IfcLengthMeasure``: lengths along the parent curve. Our
spiral is a cubic Bézier, a parametric cubic x(u), y(u) in its start frame; but
ifcopenshell (0.8, 0.9, like the concept template of ``CUBIC``, which takes
``CoefficientsX`` = (0, 1)) reads a length along an ``IfcPolynomialCurve`` as the
length of the graph of ``CoefficientsY``, ∫ √(1 + y'(t)²) dt, and only then evaluates
x(t): written as the parametric cubic, its station inside a spiral lands metres
away from ours (2–5 m on ordinary roads, 24 m in a hairpin) although its points lie
on the cubic. So each spiral is written as the graph y = p(x) of a polynomial in its
start frame (``CoefficientsX`` = (0, 1), ``graph_polynomials``): the parameter is x,
the graph's length is the arc length, and the schema's reading, the template's and
ifcopenshell's all put a distance along the segment at our station. p interpolates
the cubic at Chebyshev–Lobatto points, at the lowest degree (6 to 20) within
``GRAPH_TOLERANCE`` (1 nm) of it — degree 8 to 14 on road spirals; a spiral that no
degree follows within it (one turning more than about 40°) is written as its two halves
(each its own layout and curve segment), again if need be. ifcopenshell then puts every
distance along within 1.3 µm of our station and every segment end within 1 µm of ours
(its own trapezoidal graph length, relative tolerance 1.5e-8, is most of that).

Needs ifcopenshell (the ``cad`` extra). No CAD kernel.
"""

from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.chain import Chain
from ..core.kinds import ARC, LINE, SPIRAL
from ..core.units import length_unit, to_metres
from .names import check_name
from .opendrive import plan_records

__all__ = [
    "GRAPH_DEGREES", "GRAPH_TOLERANCE", "IFC_SCHEMA", "IfcAlignmentLayout", "LayoutSegment", "graph_polynomials",
    "ifc_file", "layout_segments", "open_alignment_model", "read_ifc_alignments", "write_ifc",
]  # fmt: skip

#: The schema written: IFC 4.3 ADD2 (ISO 16739-1:2024).
IFC_SCHEMA = "IFC4X3_ADD2"
#: The precision of the geometric context in metres: IFC's default of 1e-5 length units for a metre file,
#: and the same 10 µm in every unit (1e-5 mm would ask for more than ifcopenshell's evaluator holds: 1e-7 m).
CONTEXT_PRECISION = 1e-5
#: Our length units as IFC units: the prefix of the metre (None: none), or the conversion-based unit's name.
_SI_UNITS = {"mm": "MILLI", "cm": "CENTI", "m": None, "km": "KILO"}
_CONVERTED_UNITS = {"ft": "foot", "in": "inch"}


_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(32)
_NODES, _WEIGHTS = 0.5 * (_NODES + 1.0), 0.5 * _WEIGHTS  # on [0, 1]
#: The degrees tried, in turn, for a spiral's graph polynomial (above 20 the monomials lose more than they gain).
GRAPH_DEGREES = (6, 8, 10, 12, 14, 16, 18, 20)
#: The largest distance (m) between a spiral's graph polynomial and our cubic; a spiral no degree brings
#: within it (one turning more than about 40°) is written as its two halves, each its own segment.
GRAPH_TOLERANCE = 1e-9


def _local_spirals(poly: NDArray, u: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Our spirals (``poly``: bU, cU, dU, cV, dV in their start frames) at parameters ``u`` (N, M): x, y, dx/du."""
    bu, cu, du, cv, dv = (c[:, None] for c in poly.T)
    return ((du * u + cu) * u + bu) * u, (dv * u + cv) * u * u, (3.0 * du * u + 2.0 * cu) * u + bu


@functools.cache
def _chebyshev_powers(degree: int) -> NDArray:
    """(degree + 1, degree + 1): row k the power coefficients in s of T_k(2s − 1), the Chebyshev polynomials on [0, 1]."""
    out = np.zeros((degree + 1, degree + 1))
    for k in range(degree + 1):
        power = np.polynomial.Chebyshev.basis(k, domain=[0.0, 1.0]).convert(kind=np.polynomial.Polynomial).coef
        out[k, : len(power)] = power
    return out


def _horner(coefficients: NDArray, x: NDArray) -> NDArray:
    out = np.zeros_like(x)
    for k in range(coefficients.shape[1] - 1, -1, -1):
        out = out * x + coefficients[:, k : k + 1]
    return out


def graph_polynomials(poly: NDArray, tolerance: float) -> tuple[NDArray, NDArray]:
    """Each spiral as the graph of a polynomial y = p(x) in its start frame (p(0) = p'(0) = 0 exactly).

    ifcopenshell (0.8, 0.9) reads a distance d along an ``IfcPolynomialCurve`` segment as the x where
    ∫₀ˣ √(1 + y'(x)²) dx = d — the length of the graph of ``CoefficientsY`` — and then evaluates both
    polynomials there: the arc length only where ``CoefficientsX`` = (0, 1). Written as a graph, every
    reading of a distance along the segment (the schema's arc length, the concept template's y(x),
    ifcopenshell's) lands on the same point, at our station. p = x²·q, q interpolating y/x² at the
    Chebyshev–Lobatto points of x (both ends exactly), at the first degree of ``GRAPH_DEGREES`` that keeps
    p within ``tolerance`` of the cubic (checked at 129 points of the cubic).

    Args:
        poly: (N, 5) the spirals' bU, cU, dU, cV, dV in their start frames (turning less than 90°).
        tolerance: the largest distance accepted, in the spirals' unit.

    Returns:
        (coefficients (N, 21) of p in powers of x, zeros above its degree; the largest vertical distance from
        the cubic (N,), above ``tolerance`` where no degree reaches it).
    """
    poly = np.asarray(poly, dtype=float)
    count = len(poly)
    width = poly[:, 0] + poly[:, 1] + poly[:, 2]  # x at u = 1
    coefficients = np.zeros((count, GRAPH_DEGREES[-1] + 1))
    error = np.full(count, np.inf)
    exact_x, exact_y, _ = _local_spirals(poly, np.broadcast_to(np.linspace(0.0, 1.0, 129), (count, 129)))
    todo = np.arange(count)
    for degree in GRAPH_DEGREES:
        if not len(todo):
            break
        nodes = 0.5 * (1.0 - np.cos(np.pi * np.arange(degree - 1) / (degree - 2)))
        target = nodes * width[todo, None]
        u = np.broadcast_to(nodes, target.shape).copy()
        for _ in range(40):  # Newton on x(u) = target: x increases along a spiral turning less than 90°
            x, _, dx = _local_spirals(poly[todo], u)
            step = (x - target) / dx
            u -= step
            if np.abs(step).max() <= 1e-15:
                break
        x, y, _ = _local_spirals(poly[todo], u)
        # p = x²·q: the start and its direction exactly (a reader turns the curve to its start tangent), q at
        # the Lobatto points, at x = 0 its limit cV/bU²
        quotient = np.where(nodes > 0.0, y / np.where(nodes > 0.0, x * x, 1.0), (poly[todo, 3] / poly[todo, 0] ** 2)[:, None])
        cheb = np.linalg.solve(np.polynomial.chebyshev.chebvander(2.0 * nodes - 1.0, degree - 2), quotient.T).T
        found = np.zeros((len(todo), degree + 1))
        found[:, 2:] = (cheb @ _chebyshev_powers(degree - 2)) / width[todo, None] ** np.arange(degree - 1)
        off = np.abs(_horner(found, exact_x[todo]) - exact_y[todo]).max(axis=1)
        better = off < error[todo]
        coefficients[todo[better]] = 0.0
        coefficients[todo[better], : degree + 1] = found[better]
        error[todo[better]] = off[better]
        todo = todo[error[todo] > tolerance]
    return coefficients, error


def _new_file(units: str, application: str, project_name: str) -> tuple[Any, Any, Any, Any]:
    """An IFC 4.3 file with its project, units, site and the Model/Axis context: (file, project, site, axis context)."""
    import ifcopenshell
    import ifcopenshell.api.aggregate
    import ifcopenshell.api.context
    import ifcopenshell.api.root
    import ifcopenshell.api.unit

    model = ifcopenshell.file(schema=IFC_SCHEMA)  # type: ignore[arg-type]  # its stubs list IFC4X3, not the ADD2 release it supports
    project = ifcopenshell.api.root.create_entity(model, ifc_class="IfcProject", name=project_name)
    if units in _CONVERTED_UNITS:
        length = ifcopenshell.api.unit.add_conversion_based_unit(model, name=_CONVERTED_UNITS[units])
    else:
        length = ifcopenshell.api.unit.add_si_unit(model, unit_type="LENGTHUNIT", prefix=_SI_UNITS[units])
    angle = ifcopenshell.api.unit.add_si_unit(model, unit_type="PLANEANGLEUNIT")
    ifcopenshell.api.unit.assign_unit(model, units=[length, angle])
    body = ifcopenshell.api.context.add_context(model, context_type="Model")
    body.Precision = CONTEXT_PRECISION / to_metres(units)
    axis = ifcopenshell.api.context.add_context(
        model, context_type="Model", context_identifier="Axis", target_view="MODEL_VIEW", parent=body
    )
    site = ifcopenshell.api.root.create_entity(model, ifc_class="IfcSite", name="Site")
    ifcopenshell.api.aggregate.assign_object(model, products=[site], relating_object=project)
    header = model.header.file_name
    header.originating_system = application
    header.preprocessor_version = f"IfcOpenShell {ifcopenshell.version}"
    return model, project, site, axis


#: The 64 characters of IFC's compressed GUIDs, in order.
_GUID_CHARS = np.frombuffer(b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_$", dtype=np.uint8)


def _guids(count: int) -> list[str]:
    """``count`` new IFC GlobalIds: random (version 4) UUIDs in IFC's 22-character compression (the 128 bits
    as 2 + 21 × 6 bits, most significant first), made at once."""
    raw = np.frombuffer(os.urandom(16 * count), dtype=np.uint8).reshape(count, 16).copy()
    raw[:, 6] = (raw[:, 6] & 0x0F) | 0x40  # version 4
    raw[:, 8] = (raw[:, 8] & 0x3F) | 0x80  # the RFC 4122 variant
    bits = np.concatenate([np.zeros((count, 4), dtype=np.uint8), np.unpackbits(raw, axis=1)], axis=1).reshape(count, 22, 6)
    digits = (bits * np.array([32, 16, 8, 4, 2, 1], dtype=np.uint8)).sum(axis=2)
    return [g.decode() for g in np.ascontiguousarray(_GUID_CHARS[digits]).view("S22")[:, 0]]


def _real(value: float) -> str:
    """A REAL of ISO 10303-21: the shortest repr that reads back exactly, with the point its grammar needs."""
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        return f"{mantissa if '.' in mantissa else mantissa + '.'}E{exponent}"
    return text


def _reals(values: Sequence[float]) -> str:
    return "(" + ",".join(_real(v) for v in values) + ")"


def _string(text: str) -> str:
    """A STRING of ISO 10303-21: apostrophes and backslashes doubled, other than printable ASCII as \\X2\\ (UTF-16) or \\X4\\."""
    out = []
    for char in text:
        code = ord(char)
        if char in "'\\":
            out.append(char * 2)
        elif 32 <= code < 127:
            out.append(char)
        elif code <= 0xFFFF:
            out.append(f"\\X2\\{code:04X}\\X0\\")
        else:
            out.append(f"\\X4\\{code:08X}\\X0\\")
    return f"'{''.join(out)}'"


class _Step:
    """The entities of the alignments as lines of the STEP file's DATA section, numbered from ``first`` on:
    written as text, one line per entity, rather than one ifcopenshell call per attribute (a 10 000-PI road
    holds 0.4 M entities). A few shared placements and directions, the rest per segment."""

    def __init__(self, first: int):
        self.lines: list[str] = []
        self.next = first
        self.spare: list[str] = []
        self.origin = self.add(f"IFCAXIS2PLACEMENT2D({self.point(0.0, 0.0)},{self.direction(1.0, 0.0)})")
        self.circles: dict[float, str] = {}
        vector = self.add(f"IFCVECTOR({self.direction(1.0, 0.0)},1.)")
        self.unit_line = self.add(f"IFCLINE({self.point(0.0, 0.0)},{vector})")

    def add(self, entity: str) -> str:
        """Append ``entity`` (its type and attributes, e.g. ``IFCLINE(#1,#2)``); its reference ``#n``."""
        ref = f"#{self.next}"
        self.lines.append(f"{ref}={entity};")
        self.next += 1
        return ref

    def guid(self) -> str:
        if not self.spare:
            self.spare = _guids(4096)
        return self.spare.pop()

    def point(self, *coordinates: float) -> str:
        return self.add(f"IFCCARTESIANPOINT({_reals(coordinates)})")

    def direction(self, *ratios: float) -> str:
        return self.add(f"IFCDIRECTION({_reals(ratios)})")

    def placement(self, point: str, dx: float, dy: float) -> str:
        """A 2-D placement at ``point`` (shared with the layout segment's start)."""
        return self.add(f"IFCAXIS2PLACEMENT2D({point},{self.direction(dx, dy)})")

    def circle(self, radius: float) -> str:
        """The parent circle of radius ``radius`` at the origin (one per radius: the arcs of a road share few)."""
        if radius not in self.circles:
            self.circles[radius] = self.add(f"IFCCIRCLE({self.origin},{_real(radius)})")
        return self.circles[radius]

    def segment(self, placement: str, length: float, parent: str, transition: str) -> str:
        return self.add(f"IFCCURVESEGMENT(.{transition}.,{placement},IFCLENGTHMEASURE(0.),IFCLENGTHMEASURE({_real(length)}),{parent})")

    def nest(self, parent: str, children: list[str]) -> None:
        self.add(f"IFCRELNESTS('{self.guid()}',$,$,$,{parent},({','.join(children)}))")

    def layout_segment(self, parameters: str) -> str:
        return self.add(f"IFCALIGNMENTSEGMENT('{self.guid()}',$,$,$,$,$,$,{parameters})")


def _horizontal(w: _Step, chain: Any, scale: float, tolerance: float) -> tuple[list[str], list[str], NDArray]:
    """The horizontal layout segments and curve segments of ``chain`` (lengths × ``scale``), each list
    ending with its zero-length segment; and the stations (in the file's unit) of the segment starts.
    ``tolerance``: ``GRAPH_TOLERANCE`` in the file's unit."""
    from ..core.segments import row_frames

    for _ in range(6):  # a spiral no graph polynomial follows closely enough is written as its two halves
        plan = plan_records(chain, scale)
        spiral = plan["kind"] == SPIRAL
        graphs = np.zeros((len(spiral), GRAPH_DEGREES[-1] + 1))
        error = np.zeros(len(spiral))
        if spiral.any():
            graphs[spiral], error[spiral] = graph_polynomials(plan["poly"][spiral], tolerance)
        if not (error > tolerance).any():
            break
        chain = _halved(chain, np.flatnonzero(error > tolerance))
    else:
        k = int(np.argmax(error))
        raise ValueError(f"segment {k}: no polynomial graph of its spiral lies within {tolerance:.3g} of it ({error[k]:.3g} at best)")
    rows = chain.rows
    frames, _, _ = row_frames(np.array(rows.kind), np.array(rows.geometry), np.array(rows.params), rows.dim)
    kind, x, y, hdg, length = (plan[k] for k in ("kind", "x", "y", "hdg", "length"))
    kappa = frames[:, :, 8] / scale  # signed curvature at both ends, in the file's unit
    # a spiral's straight end has |κ|·L at rounding level, not 0: IFC says 0 for a straight end
    kappa[np.abs(kappa) * length[:, None] <= 1e-9] = 0.0
    with np.errstate(divide="ignore"):
        radius = np.where(kappa != 0.0, 1.0 / np.where(kappa != 0.0, kappa, 1.0), 0.0)  # positive turns left
    layout, curve = [], []
    types = {LINE: "LINE", ARC: "CIRCULARARC", SPIRAL: "CUBIC"}
    for k in range(len(kind)):
        code, start, heading, size = int(kind[k]), (float(x[k]), float(y[k])), float(hdg[k]), float(length[k])
        r0, r1 = (0.0, 0.0) if code == LINE else (float(radius[k, 0]), float(radius[k, 1]))
        point = w.point(*start)
        parameters = w.add(
            f"IFCALIGNMENTHORIZONTALSEGMENT($,$,{point},{_real(heading)},{_real(r0)},{_real(r1)},{_real(size)},$,.{types[code]}.)"
        )
        layout.append(w.layout_segment(parameters))
        if code == LINE:
            parent, signed = w.unit_line, size
        elif code == ARC:
            parent = w.circle(abs(r0))
            signed = math.copysign(size, r0)
        else:  # the graph y = p(x) in the spiral's start frame (graph_polynomials)
            last = max(int(np.flatnonzero(graphs[k])[-1]) if graphs[k].any() else 0, 2)
            parent = w.add(f"IFCPOLYNOMIALCURVE({w.origin},(0.,1.),{_reals(graphs[k, : last + 1].tolist())},$)")
            signed = size
        place = w.placement(point, math.cos(heading), math.sin(heading))
        curve.append(w.segment(place, signed, parent, "CONTSAMEGRADIENTSAMECURVATURE"))
    # the zero-length end segment: at the chain's end, in its end direction and curvature
    end, tangent = frames[-1, 1, :2] * scale, frames[-1, 1, 3:5]
    heading = math.atan2(float(tangent[1]), float(tangent[0]))
    point = w.point(*end.tolist())
    parameters = w.add(f"IFCALIGNMENTHORIZONTALSEGMENT($,$,{point},{_real(heading)},0.,0.,0.,$,.LINE.)")
    layout.append(w.layout_segment(parameters))
    curve.append(w.segment(w.placement(point, float(tangent[0]), float(tangent[1])), 0.0, w.unit_line, "DISCONTINUOUS"))
    stations = np.concatenate([[0.0], np.cumsum(length)])
    return layout, curve, stations


def _halved(chain: Any, spirals: NDArray) -> Any:
    """``chain`` with the segments ``spirals`` (indices of spirals) each split into its two halves of arc length."""
    segments = list(chain.segments)
    for k in sorted(spirals.tolist(), reverse=True):
        spiral = segments[k]
        middle = float(spiral.parameter_at(0.5 * spiral.length))
        segments[k : k + 1] = [spiral.piece(0.0, middle), spiral.piece(middle, 1.0)]
    return Chain(segments, tolerance=chain.tolerance, units=chain.units)


def _parabola_length(grade: NDArray, rate: NDArray, run: NDArray) -> NDArray:
    """Arc length of z = g·d + c·d² over d ∈ [0, run] in the (distance, height) plane (32-node Gauss–Legendre)."""
    slope = grade[:, None] + 2.0 * rate[:, None] * (run[:, None] * _NODES)
    return np.sqrt(1.0 + slope * slope) @ _WEIGHTS * run


def _vertical(w: _Step, profile: Any, start: float, end: float, scale: float) -> tuple[list[str], list[str]]:
    """The vertical layout and gradient curve segments of ``profile`` from station ``start`` to ``end``
    (distance along from 0 at ``start``), each list ending with its zero-length segment."""
    records = profile.records(start, end)
    s, a, b, c = records.T
    run = np.diff(np.append(s, end - start))
    s, a, run, c = s * scale, a * scale, run * scale, c / scale
    end_grade = b + 2.0 * c * run
    parabola = c != 0.0
    along = np.where(parabola, _parabola_length(b, c, run), run * np.sqrt(1.0 + b * b))
    layout, curve = [], []
    for k in range(len(s)):
        start_k, height, grade, size = float(s[k]), float(a[k]), float(b[k]), float(run[k])
        numbers = f"{_real(start_k)},{_real(size)},{_real(height)},{_real(grade)}"
        if parabola[k]:
            rate = float(c[k])
            parameters = w.add(
                f"IFCALIGNMENTVERTICALSEGMENT($,$,{numbers},{_real(float(end_grade[k]))},{_real(1.0 / (2.0 * rate))},.PARABOLICARC.)"
            )
            parent = w.add(f"IFCPOLYNOMIALCURVE({w.origin},(0.,1.),{_reals((0.0, grade, rate))},$)")
        else:
            parameters = w.add(f"IFCALIGNMENTVERTICALSEGMENT($,$,{numbers},{_real(grade)},$,.CONSTANTGRADIENT.)")
            parent = w.unit_line
        layout.append(w.layout_segment(parameters))
        norm = math.hypot(1.0, grade)
        curve.append(
            w.segment(w.placement(w.point(start_k, height), 1.0 / norm, grade / norm), float(along[k]), parent, "CONTSAMEGRADIENT")
        )
    last = len(s) - 1
    finish = float(s[last] + run[last])
    height = float(a[last] + b[last] * run[last] + c[last] * run[last] ** 2)
    grade = float(end_grade[last])
    parameters = w.add(
        f"IFCALIGNMENTVERTICALSEGMENT($,$,{_real(finish)},0.,{_real(height)},{_real(grade)},{_real(grade)},$,.CONSTANTGRADIENT.)"
    )
    layout.append(w.layout_segment(parameters))
    norm = math.hypot(1.0, grade)
    curve.append(w.segment(w.placement(w.point(finish, height), 1.0 / norm, grade / norm), 0.0, w.unit_line, "DISCONTINUOUS"))
    return layout, curve


def _stationing(w: _Step, alignment: str, basis: str, chain: Any, station: float, scale: float) -> None:
    """The design's start station: an ``IfcReferent`` (STATION) at distance 0 on the basis curve with
    ``Pset_Stationing.Station``, nested in the alignment — what ``ifcopenshell.api.alignment.add_stationing_referent``
    makes, with the fallback position taken from the chain (that call evaluates the whole curve)."""
    x, y = (chain.start[:2] * scale).tolist()
    tx, ty = chain.tangent_at(0.0)[:2].tolist()
    fallback = w.add(f"IFCAXIS2PLACEMENT3D({w.point(x, y, 0.0)},{w.direction(0.0, 0.0, 1.0)},{w.direction(tx, ty, 0.0)})")
    location = w.add(f"IFCPOINTBYDISTANCEEXPRESSION(IFCLENGTHMEASURE(0.),$,$,$,{basis})")
    placement = w.add(f"IFCLINEARPLACEMENT($,{w.add(f'IFCAXIS2PLACEMENTLINEAR({location},$,$)')},{fallback})")
    referent = w.add(f"IFCREFERENT('{w.guid()}',$,{_string(f'{station:g}')},$,$,{placement},$,.STATION.)")
    value = w.add(f"IFCPROPERTYSINGLEVALUE('Station',$,IFCLENGTHMEASURE({_real(station)}),$)")
    pset = w.add(f"IFCPROPERTYSET('{w.guid()}',$,'Pset_Stationing',$,({value}))")
    w.add(f"IFCRELDEFINESBYPROPERTIES('{w.guid()}',$,$,$,({referent}),{pset})")
    w.nest(alignment, [referent])


def ifc_file(
    alignments: Any,
    *,
    units: str | None = None,
    profile: Any = None,
    names: Sequence[str] | None = None,
    project: str = "spiral_cad",
    application: str = "spiral_cad",
) -> Any:
    """The IFC 4.3 model of ``alignments`` as an ``ifcopenshell.file`` (``write_ifc`` writes the same text).

    Args and Raises: as ``write_ifc``; ``names`` are the ``IfcAlignment`` names
    (default ``alignment 1``, …), ``project`` the ``IfcProject`` name.
    """
    import ifcopenshell

    text = _ifc_text(alignments, units=units, profile=profile, names=names, project=project, application=application)
    return ifcopenshell.file.from_string(text)


@dataclass(frozen=True)
class _Stationed:
    """A chain written as an alignment: what ``_ifc_text`` reads of an ``Alignment``."""

    chain: Chain
    start_station: float
    end_station: float


def _ifc_text(alignments: Any, *, units: str | None, profile: Any, names: Sequence[str] | None, project: str, application: str,
              file_name: str = "") -> str:  # fmt: skip
    """The STEP text of ``ifc_file``: the project, units, contexts and site made by ifcopenshell's API, the
    alignments' entities appended as text (``_Step``)."""
    from ..design.alignment import Alignment

    given = (
        [alignments] if isinstance(alignments, (Alignment, Chain)) else list(alignments) if isinstance(alignments, (list, tuple)) else []
    )
    if not given or not all(isinstance(a, (Alignment, Chain)) for a in given):
        raise ValueError(f"alignments must be an Alignment or a plane Chain, or a non-empty list of them; got {type(alignments).__name__}")
    items: list[Alignment | _Stationed] = [_Stationed(a, 0.0, a.length) if isinstance(a, Chain) else a for a in given]
    profiles = list(profile) if isinstance(profile, (list, tuple)) else [profile] * len(items)
    if len(profiles) != len(items):
        raise ValueError(f"profile: give one profile (or None) per alignment ({len(items)}); got {len(profiles)}")
    own = {a.chain.units for a in items}
    if len(own) != 1:
        raise ValueError(f"the alignments must share one length unit; got {', '.join(sorted(own))}")
    design_units = own.pop()
    units = design_units if units is None else length_unit(units)
    scale = to_metres(design_units) / to_metres(units)
    names = [f"alignment {k}" for k in range(1, len(items) + 1)] if names is None else list(names)
    if len(names) != len(items):
        raise ValueError(f"names: give one name per alignment ({len(items)}); got {len(names)}")
    names = [check_name(n, f"names[{k}]") for k, n in enumerate(names)]  # IfcLabel: at most 255 characters
    project = check_name(project, "project")
    for k, p in enumerate(profiles):
        if p is not None and p.units != design_units:
            raise ValueError(f"profile {k}: in {p.units}, its alignment in {design_units}")
    for name, alignment in zip(names, items):
        if alignment.chain.dim != 2:
            raise ValueError(f"{name}: an IFC horizontal layout is plane; this chain lies in space")

    model, proj, site, axis = _new_file(units, application, project)
    model.header.file_name.time_stamp = time.strftime("%Y-%m-%dT%H:%M:%S")
    model.header.file_name.name = file_name
    w = _Step(max(entity.id() for entity in model) + 1)
    context = f"#{axis.id()}"
    made = []
    for alignment, p, name in zip(items, profiles, names):
        chain = alignment.chain
        horizontal = w.add(f"IFCALIGNMENTHORIZONTAL('{w.guid()}',$,$,$,$,$,$)")
        layouts = [horizontal]
        h_layout, h_curve, _ = _horizontal(w, chain, scale, GRAPH_TOLERANCE / to_metres(units))
        w.nest(horizontal, h_layout)
        plan = w.add(f"IFCCOMPOSITECURVE(({','.join(h_curve)}),.F.)")
        if p is None:
            reps = [w.add(f"IFCSHAPEREPRESENTATION({context},'Axis','Curve2D',({plan}))")]
        else:
            vertical = w.add(f"IFCALIGNMENTVERTICAL('{w.guid()}',$,$,$,$,$,$)")
            layouts.append(vertical)
            v_layout, v_curve = _vertical(w, p, alignment.start_station, alignment.end_station, scale)
            w.nest(vertical, v_layout)
            gradient = w.add(f"IFCGRADIENTCURVE(({','.join(v_curve)}),.F.,{plan},$)")
            reps = [w.add(f"IFCSHAPEREPRESENTATION({context},'FootPrint','Curve2D',({plan}))"),
                    w.add(f"IFCSHAPEREPRESENTATION({context},'Axis','Curve3D',({gradient}))")]  # fmt: skip
        representation = w.add(f"IFCPRODUCTDEFINITIONSHAPE($,$,({','.join(reps)}))")
        local = w.add(f"IFCLOCALPLACEMENT($,{w.origin})")
        entity = w.add(f"IFCALIGNMENT('{w.guid()}',$,{_string(name)},$,$,{local},{representation},$)")
        w.nest(entity, layouts)
        _stationing(w, entity, plan, chain, alignment.start_station * scale, scale)
        made.append(entity)
    # the relationships ifcopenshell's alignment API makes (aggregated to the project, referenced by the site)
    w.add(f"IFCRELAGGREGATES('{w.guid()}',$,$,$,#{proj.id()},({','.join(made)}))")
    w.add(f"IFCRELREFERENCEDINSPATIALSTRUCTURE('{w.guid()}',$,$,$,({','.join(made)}),#{site.id()})")
    head, tail = model.to_string().rsplit("ENDSEC;", 1)
    return head + "\n".join(w.lines) + "\nENDSEC;" + tail


def write_ifc(
    alignments: Any,
    path: str | os.PathLike,
    *,
    units: str | None = None,
    profile: Any = None,
    names: Sequence[str] | None = None,
    project: str = "spiral_cad",
    application: str = "spiral_cad",
) -> Path:
    """Write IFC 4.3 alignments (see the module docstring for the mapping).

    Args:
        alignments: an ``Alignment`` or a plane ``Chain`` (stations from 0), or a list of them (one unit).
        path: the .ifc file to write (STEP physical file, ISO 10303-21).
        units: the file's length unit (default: the alignments'); mm, cm,
            m and km are SI units, ft and in conversion-based units.
        profile: the ``Profile`` of an alignment, or one per alignment (None
            for none): adds the vertical layout and the ``IfcGradientCurve``.
        names: the alignments' names.
        project: the ``IfcProject``'s name.
        application: the application named in the file's owner history.

    Returns:
        The path written.

    Raises:
        ValueError: no alignments, alignments in different units, an
            unknown unit, profiles that do not match the alignments, or a
            chain in space.
    """
    path = Path(os.fspath(path))
    text = _ifc_text(alignments, units=units, profile=profile, names=names, project=project, application=application,
                     file_name=path.name)  # fmt: skip
    path.write_text(text, encoding="ascii")
    return path


# ------------------------------------------------------------------ reading


@dataclass(frozen=True)
class LayoutSegment:
    """One segment of an IFC alignment layout, in the file's length unit (angles in radians).

    Attributes:
        type: the ``PredefinedType`` (``LINE``, ``CIRCULARARC``, ``CUBIC``, ``CONSTANTGRADIENT``, …).
        length: ``SegmentLength`` (horizontal) or ``HorizontalLength`` (vertical).
        start: the start point (horizontal) or (distance along, height) (vertical).
        direction: the start direction (horizontal) or the start gradient (vertical).
        radii: start and end radius of curvature (horizontal; 0 straight, positive turns left);
            (radius, end gradient) for a vertical segment.
        curve: the entity type of the matching ``IfcCurveSegment.ParentCurve`` in the
            representation, or None when the alignment has no representation.
    """

    type: str
    length: float
    start: tuple[float, float]
    direction: float
    radii: tuple[float, float]
    curve: str | None


@dataclass(frozen=True)
class IfcAlignmentLayout:
    """An ``IfcAlignment`` as read: its name, length unit (metres per unit), layouts and start station
    (its stationing referent's, 0 without one)."""

    name: str
    metres_per_unit: float
    horizontal: tuple[LayoutSegment, ...]
    vertical: tuple[LayoutSegment, ...]
    start_station: float = 0.0


def layout_segments(layout: Any) -> list[Any]:
    """The ``IfcAlignmentSegment`` design parameters nested in ``layout``, in nesting order."""
    out = []
    for rel in layout.IsNestedBy:
        out += [s.DesignParameters for s in rel.RelatedObjects if s.is_a("IfcAlignmentSegment")]
    return out


def _cut_short(path: str) -> bool:
    """Whether the IFC text file at ``path`` lacks the ``END-ISO-10303-21;`` that ends every whole one (a zipped
    or XML file is not judged)."""
    try:
        with open(path, "rb") as file:
            if not file.read(16).lstrip().startswith(b"ISO-10303-21"):
                return False
            file.seek(max(0, os.fstat(file.fileno()).st_size - 4096))
            return b"END-ISO-10303-21" not in file.read()
    except OSError:
        return False


def open_alignment_model(source: Any) -> tuple[Any, float]:
    """An IFC 4.3 model (read from a path, or an ``ifcopenshell.file`` as given) and its length unit in metres.

    Raises:
        ValueError: the file cannot be read or is not IFC 4.3 (named).
    """
    import ifcopenshell
    import ifcopenshell.util.unit

    model = source
    name = "the model" if isinstance(source, ifcopenshell.file) else os.path.basename(os.fspath(source)) or os.fspath(source)
    if not isinstance(source, ifcopenshell.file):
        try:
            model = ifcopenshell.open(os.fspath(source))
        except (OSError, RuntimeError, ifcopenshell.Error) as error:
            raise ValueError(f"{name}: not a readable IFC file ({error})") from None
        if _cut_short(os.fspath(source)):
            raise ValueError(f"{name}: the file ends before END-ISO-10303-21; (cut short): what it held is not all there")
    if not model.schema.startswith("IFC4X3"):
        raise ValueError(f"{name}: alignments are IFC 4.3; this file is {model.schema}")
    return model, float(ifcopenshell.util.unit.calculate_unit_scale(model, "LENGTHUNIT"))


def read_ifc_alignments(source: Any) -> list[IfcAlignmentLayout]:
    """Every ``IfcAlignment`` of an IFC 4.3 file (a path or an ``ifcopenshell.file``) with its horizontal
    and vertical layouts, each segment beside the type of its representation's parent curve.

    Raises:
        ValueError: the file cannot be read or is not IFC 4.3.
    """
    import ifcopenshell
    import ifcopenshell.api.alignment
    import ifcopenshell.util.unit

    model, scale = open_alignment_model(source)
    result = []
    for alignment in model.by_type("IfcAlignment"):
        layouts = [obj for rel in alignment.IsNestedBy for obj in rel.RelatedObjects]
        curves = _representation_curves(alignment)
        horizontal: list[LayoutSegment] = []
        vertical: list[LayoutSegment] = []
        for layout in layouts:
            if layout.is_a("IfcAlignmentHorizontal"):
                parents = _parent_types(curves.get("IfcCompositeCurve"))
                for k, p in enumerate(layout_segments(layout)):
                    start = tuple(float(v) for v in p.StartPoint.Coordinates[:2])
                    horizontal.append(LayoutSegment(p.PredefinedType, float(p.SegmentLength), start,  # type: ignore[arg-type]
                                                    float(p.StartDirection),
                                                    (float(p.StartRadiusOfCurvature), float(p.EndRadiusOfCurvature)),
                                                    parents[k] if k < len(parents) else None))  # fmt: skip
            elif layout.is_a("IfcAlignmentVertical"):
                parents = _parent_types(curves.get("IfcGradientCurve"))
                for k, p in enumerate(layout_segments(layout)):
                    radius = float(p.RadiusOfCurvature) if p.RadiusOfCurvature is not None else 0.0
                    vertical.append(LayoutSegment(p.PredefinedType, float(p.HorizontalLength),
                                                  (float(p.StartDistAlong), float(p.StartHeight)), float(p.StartGradient),
                                                  (radius, float(p.EndGradient)), parents[k] if k < len(parents) else None))  # fmt: skip
        station = ifcopenshell.api.alignment.get_alignment_start_station(model, alignment)  # None: a referent without one
        result.append(IfcAlignmentLayout(alignment.Name or "", scale, tuple(horizontal), tuple(vertical), float(station or 0.0)))
    return result


def _representation_curves(alignment: Any) -> dict[str, Any]:
    """The alignment's representation curves by exact type (the gradient curve's base curve included)."""
    found: dict[str, Any] = {}
    shape = alignment.Representation
    for rep in shape.Representations if shape is not None else ():
        for item in rep.Items:
            while item is not None:
                found.setdefault(item.is_a(), item)
                item = getattr(item, "BaseCurve", None)
    return found


def _parent_types(curve: Any) -> list[str]:
    return [] if curve is None else [s.ParentCurve.is_a() for s in curve.Segments]
