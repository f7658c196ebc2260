"""G0/G1/G2 at every joint of an IFC 4.3 file's alignments: the plan as its geometry runs, the profile on its
own numbers.

Each ``IfcAlignment`` gives up to two pieces:

* **the plan**: one element per segment of the horizontal ``IfcCompositeCurve`` (its representation), placed
  and run as ifcopenshell's geometry evaluates it (every parent curve IFC 4.3 allows: lines, circles,
  clothoids, the polynomial and trigonometric spirals), so a gap, a kink or a curvature jump between
  segments is what a reader of the geometry meets. The curvature at each end is the curve's: 0 on a line,
  1/radius on a circle, else the difference quotient of its heading (extrapolated); where the matching
  ``IfcAlignmentHorizontalSegment`` (``StartRadiusOfCurvature``, ``EndRadiusOfCurvature``; positive turns
  left) states a curvature that agrees with the quotient, the stated number is taken (exact), and where it
  does not, the curve's is judged and the notes name both. A layout whose segments do not match the curve's
  one for one (a Helmert curve drawn as two) gives no numbers; an alignment whose curve ifcopenshell cannot
  evaluate is named in the notes and not judged.
* **the profile**: one element per ``IfcAlignmentVerticalSegment``, in the plane (distance along, height),
  from its own numbers: it starts at ``StartDistAlong``, ``StartHeight`` with ``StartGradient`` and ends
  ``HorizontalLength`` further where its type takes it (a constant gradient, a parabolic arc from
  ``StartGradient`` to ``EndGradient``, a circular arc between them); its curvature is that of the curve
  z(s) there. Other types (a vertical clothoid) are not measured: their joints are "unmeasurable".

Zero-length segments (the one that ends every layout) are left out; the joint is across them. The
measures and tolerances are those of every checker (``spiral_cad.continuity.joints``): by default a gap of
the file's geometric precision (its representation context's ``Precision``, 1e-5 m where it states none)
or 1e-6 of the model's size if larger, an angle of twice that gap over the shortest segment, and a
relative curvature jump of 1e-6. Lengths are in the file's unit.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from typing import Any

import numpy as np

from ..continuity.joints import ContinuityReport, check_tolerances, classify_pieces, model_size
from .ifc import _representation_curves, layout_segments, open_alignment_model

__all__ = ["DEFAULT_PRECISION", "RELATIVE_GAP", "check_ifc"]

#: The geometric precision of a representation context that states none (IFC's default), in metres.
DEFAULT_PRECISION = 1e-5
#: The default gap tolerance's floor relative to the model's size (1 mm on a 1 km road).
RELATIVE_GAP = 1e-6
#: Segments shorter than this share of the longest are slivers: the angle tolerance is not taken from them.
_SLIVER_SHARE = 1e-3


def check_ifc(path: str | os.PathLike, *, gap_tol: float | None = None, angle_tol: float | None = None,
              curvature_tol: float | None = None) -> ContinuityReport:  # fmt: skip
    """Every joint of every alignment of the IFC 4.3 file ``path``: its plan and its profile (see the module).

    Args:
        path: the file.
        gap_tol: largest G0 gap (the file's unit); None: from the file's precision and size.
        angle_tol: largest G1 tangent angle (radians); None: from the gap and the segments' lengths.
        curvature_tol: largest G2 curvature jump, relative to ``max(|κa|, |κb|, 1/size)``; None: 1e-6.

    Returns:
        A ``ContinuityReport`` with a piece per plan and per profile (named after the alignment), its
        ``notes`` saying how the file was read and which tolerances were used.

    Raises:
        ValueError: not a readable IFC 4.3 file, no alignment with a plan or a profile to judge, or a bad
            tolerance.
    """
    check_tolerances(**{k: v for k, v in (("gap_tol", gap_tol), ("angle_tol", angle_tol), ("curvature_tol", curvature_tol))
                        if v is not None})  # fmt: skip
    source = os.path.basename(os.fspath(path))
    model, metres = open_alignment_model(path)
    units = _unit_name(metres)
    pieces: list[tuple] = []
    lengths: list[float] = []
    notes: list[str] = []
    precisions: list[float] = []
    alignments: list[Any] = list(model.by_type("IfcAlignment"))
    for number, alignment in enumerate(alignments, 1):
        name = alignment.Name or f"alignment {number}"
        layouts = [obj for rel in alignment.IsNestedBy for obj in rel.RelatedObjects]
        horizontal = next((layout for layout in layouts if layout.is_a("IfcAlignmentHorizontal")), None)
        curve = _representation_curves(alignment).get("IfcCompositeCurve")  # the gradient curve's base curve, or its own
        if horizontal is None or curve is None:
            notes.append(f"alignment {name!r}: no horizontal layout with its IfcCompositeCurve: its plan is not judged")
        else:
            try:
                frames, stated = _plan_frames(curve, layout_segments(horizontal), metres, name, notes)
                precisions.append(_precision(curve, model))
                pieces.append(("plan", frames, False, f"{name} plan"))
                lengths += stated
            except ValueError as error:
                notes.append(str(error))
        vertical = next((layout for layout in layouts if layout.is_a("IfcAlignmentVertical")), None)
        if vertical is not None:
            frames, stated = _profile_frames(layout_segments(vertical), name, notes)
            if frames:
                pieces.append(("profile", frames, False, f"{name} profile"))
                lengths += stated
    if not pieces:
        raise ValueError(f"{source}: no alignment with a plan or a profile to judge" + (f" ({'; '.join(notes)})" if notes else ""))
    points = np.array([frame[:3] for _, frames, *_ in pieces for pair in frames for frame in pair])
    size = model_size(points[np.isfinite(points).all(axis=1)], source)  # a segment not measured has no end point
    stated_tolerances = []
    if gap_tol is None:
        precision = max(precisions, default=DEFAULT_PRECISION / metres)
        gap_tol = max(1e-7, precision, RELATIVE_GAP * size)
        stated_tolerances.append(f"gap {gap_tol:.3g} (the file's precision {precision:.3g}, or 1e-6 of its size)")
    if angle_tol is None:
        real = [length for length in lengths if length > _SLIVER_SHARE * max(lengths)]
        angle_tol = max(1e-7, 2.0 * gap_tol / min(real))
        stated_tolerances.append(f"angle {angle_tol:.3g} rad")
    if curvature_tol is None:
        curvature_tol = 1e-6
    report = classify_pieces(pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, source=source,
                             element="segment", units=units)  # fmt: skip
    notes.insert(0, "the plan as ifcopenshell evaluates its curve's segments; the profile from its vertical segments' "
                    "own numbers")  # fmt: skip
    if stated_tolerances:
        notes.append(f"tolerances from the file: {', '.join(stated_tolerances)}; give them to judge otherwise")
    return replace(report, notes=tuple(notes))


def _unit_name(metres: float) -> str:
    """The unit of ``metres`` per unit, by name where it is one of ours (else ``"m×{metres}"``, never a wrong one)."""
    from ..core.units import MM_PER_UNIT

    for name, mm in MM_PER_UNIT.items():
        if math.isclose(mm / 1000.0, metres, rel_tol=1e-12):
            return name
    return f"{metres:g} m"


def _precision(curve: Any, model: Any) -> float:
    """The precision of the representation context ``curve`` is drawn in (a sub-context's parent's), in the file's unit."""
    for representation in model.get_inverse(curve):
        if representation.is_a("IfcShapeRepresentation"):
            context = representation.ContextOfItems
            while context.is_a("IfcGeometricRepresentationSubContext"):
                context = context.ParentContext
            if context.Precision:
                return float(context.Precision)
    return DEFAULT_PRECISION


#: Where the layout's curvature and the curve's (by differences) disagree by more than this share of the larger
#: (or of 1/size), the curve's is judged: ifcopenshell measures distance along a polynomial curve to ~1e-8, so its
#: difference quotients there hold ~1e-4; the layout's numbers, where they agree, are exact.
_DESIGN_AGREES = 1e-3


def _plan_frames(curve: Any, design: list[Any], metres: float, name: str, notes: list[str]) -> tuple[list, list[float]]:
    """Per non-zero segment of ``curve``, its (start, end) frames in the file's unit: position and tangent as
    ifcopenshell evaluates it, curvature as the curve has it (a line's 0, a circle's 1/radius exactly; other
    curves by differences, or the layout's number where it agrees with them).

    Raises:
        ValueError: a segment ifcopenshell cannot evaluate (an IFC 4 ``IfcCompositeCurveSegment``), named.
    """
    import ifcopenshell.geom
    import ifcopenshell.ifcopenshell_wrapper as wrapper

    settings = ifcopenshell.geom.settings()
    segments = list(curve.Segments)
    stated = [d if d is not None and d.is_a("IfcAlignmentHorizontalSegment") else None for d in design]
    if len(stated) != len(segments):  # a Helmert curve is two curve segments, say: the layout cannot be matched
        notes.append(f"alignment {name!r}: {len(stated)} horizontal segments for {len(segments)} curve segments: the plan's "
                     "curvatures are the curve's own, by differences")  # fmt: skip
        stated = [None] * len(segments)
    frames, lengths = [], []
    for k, segment in enumerate(segments):
        function = wrapper.map_shape(settings, segment)
        if function is None:
            raise ValueError(f"alignment {name!r}: plan segment {k} ({segment.is_a()}) is not a curve segment ifcopenshell "
                             "evaluates: the plan is not judged")  # fmt: skip
        length = float(function.length())
        if length == 0.0:
            continue
        evaluate = wrapper.function_item_evaluator(settings, function).evaluate
        parent = segment.ParentCurve.is_a() if segment.is_a("IfcCurveSegment") else ""
        ends = []
        for end, at in enumerate((0.0, length)):
            matrix = np.array(evaluate(at))
            point, tangent = matrix[:3, 3] / metres, matrix[:3, 0] / np.linalg.norm(matrix[:3, 0])
            measured = _turning(evaluate, at, length, end == 1) * metres  # 1/unit; positive turns left
            if parent == "IfcLine":
                curvature = 0.0
            elif parent == "IfcCircle":
                curvature = math.copysign(1.0 / float(segment.ParentCurve.Radius), measured)
            else:
                curvature = measured
            design_says = _stated_curvature(stated[k], end)
            floor = max(abs(curvature), metres / abs(length))  # 1/length: the segment's own scale of curvature
            if design_says is not None and abs(design_says - curvature) > _DESIGN_AGREES * max(floor, abs(design_says)):
                notes.append(f"alignment {name!r}: plan segment {k} {('starts', 'ends')[end]} with curvature {curvature:.6g}, not "
                             f"the {design_says:.6g} its layout states: the curve's is judged")  # fmt: skip
            elif design_says is not None and parent not in ("IfcLine", "IfcCircle"):
                curvature = design_says  # exact, where the curve's difference quotient agrees with it
            normal = np.array([-tangent[1], tangent[0], 0.0])
            ends.append((*point.tolist(), *tangent.tolist(), *(curvature * normal).tolist()))
        frames.append(tuple(ends))
        lengths.append(abs(length) / metres)
    return frames, lengths


def _stated_curvature(design: Any, end: int) -> float | None:
    """The curvature a horizontal layout segment states at its start (0) or end (1), in 1/its unit (None: none)."""
    if design is None:
        return None
    radius = design.StartRadiusOfCurvature if end == 0 else design.EndRadiusOfCurvature
    return None if radius is None else (0.0 if float(radius) == 0.0 else 1.0 / float(radius))


def _turning(evaluate: Any, at: float, length: float, backwards: bool) -> float:
    """The curvature (1/metre) at ``at`` of a segment of ``length`` evaluated by ifcopenshell: the one-sided
    three-point difference quotient of its heading over a thousandth of the segment, and over half that,
    extrapolated (Richardson: exact for headings of degree 3 in distance, a clothoid's and a Helmert curve's)."""

    def heading(t: float) -> float:
        matrix = np.array(evaluate(t))
        return math.atan2(matrix[1, 0], matrix[0, 0])

    def quotient(h: float) -> float:
        step = -h if backwards else h
        a, b, c = heading(at), heading(at + step), heading(at + 2 * step)
        turns = np.unwrap([a, b, c])
        return float(-3 * turns[0] + 4 * turns[1] - turns[2]) / (2 * step)

    h = 1e-3 * length
    return (4.0 * quotient(h / 2) - quotient(h)) / 3.0


def _profile_frames(design: list[Any], name: str, notes: list[str]) -> tuple[list, list[float]]:
    """Per non-zero vertical segment, its (start, end) frames in the plane (distance along, height)."""
    frames, lengths = [], []
    unmeasured = set()
    for segment in design:
        if segment is None or not segment.is_a("IfcAlignmentVerticalSegment"):
            notes.append(f"alignment {name!r}: its vertical layout nests a {getattr(segment, 'is_a', lambda: 'nothing')()}: left out")
            continue
        length = float(segment.HorizontalLength)
        if length == 0.0:
            continue
        s0, h0 = float(segment.StartDistAlong), float(segment.StartHeight)
        g0, g1 = float(segment.StartGradient), float(segment.EndGradient)
        kind = segment.PredefinedType
        if kind == "CONSTANTGRADIENT":
            rise, g1, bend = g0 * length, g0, (0.0, 0.0)
        elif kind == "PARABOLICARC":  # z'' = (g1 − g0) / L, constant
            second = (g1 - g0) / length
            rise, bend = 0.5 * (g0 + g1) * length, (second / (1 + g0 * g0) ** 1.5, second / (1 + g1 * g1) ** 1.5)
        elif kind == "CIRCULARARC" and g1 != g0:  # κ = (sin θ1 − sin θ0) / L along a circle from θ0 to θ1
            t0, t1 = math.atan(g0), math.atan(g1)
            k = (math.sin(t1) - math.sin(t0)) / length
            rise, bend = (math.cos(t0) - math.cos(t1)) / k, (k, k)
        else:
            unmeasured.add(str(kind))
            rise, bend = math.nan, (math.nan, math.nan)
        ends = []
        for point, gradient, kappa in (((s0, h0), g0, bend[0]), ((s0 + length, h0 + rise), g1, bend[1])):
            tangent = np.array([1.0, gradient, 0.0]) / math.hypot(1.0, gradient)
            ends.append((point[0], point[1], 0.0, *tangent.tolist(), *(kappa * np.array([-tangent[1], tangent[0], 0.0])).tolist()))
        frames.append(tuple(ends))
        lengths.append(length)
    if unmeasured:
        notes.append(f"alignment {name!r}: vertical {', '.join(sorted(unmeasured))} segments are not measured: their joints "
                     "are unmeasurable")  # fmt: skip
    return frames, lengths
