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
* **the profile**: one element per segment of the ``IfcGradientCurve``, in the plane (distance along, height),
  evaluated the same way, its curvature that of the curve z(s) (the vertical segment's own number where it
  agrees: 0 on a constant gradient, z''/(1 + z'²)^1.5 at the ends of a parabolic arc, (sin θ1 − sin θ0)/L
  along a circular arc between gradient angles θ0 and θ1). A profile without its gradient curve is judged on
  the vertical segments' numbers alone (from ``StartDistAlong``, ``StartHeight`` and ``StartGradient`` to
  where its kind takes it, ``HorizontalLength`` further); a kind they do not measure (a vertical clothoid) has
  unmeasurable joints.

Zero-length segments (the one that ends every layout) are left out; the joint is across them. The
measures and tolerances are those of every checker (``spiral_cad.continuity.joints``): by default a gap of
the file's geometric precision (its representation context's ``Precision``, 1e-5 m where it states none)
or 1e-6 of the model's size (its largest piece's extent: a plan in map coordinates is not measured from a
profile at 0) if larger, an angle of twice that gap over the shortest segment, and a
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
        vertical = next((layout for layout in layouts if layout.is_a("IfcAlignmentVertical")), None)
        curves = _representation_curves(alignment)
        plan = curves.get("IfcCompositeCurve")  # the gradient curve's base curve, or its own
        if horizontal is None or plan is None:
            notes.append(f"alignment {name!r}: no horizontal layout with its IfcCompositeCurve: its plan is not judged")
        else:
            judged = _judged(plan, _horizontal_curvatures(layout_segments(horizontal)), metres, f"alignment {name!r}: plan", notes)
            if judged is not None:
                precisions.append(_precision(plan, model))
                pieces.append(("plan", judged[0], False, f"{name} plan"))
                lengths += judged[1]
        profile = curves.get("IfcGradientCurve")
        if vertical is not None and profile is not None:  # the profile as its curve runs, in (distance along, height)
            judged = _judged(profile, _vertical_curvatures(layout_segments(vertical)), metres, f"alignment {name!r}: profile", notes)
            if judged is not None:
                pieces.append(("profile", judged[0], False, f"{name} profile"))
                lengths += judged[1]
        elif vertical is not None:  # no curve drawn: the layout's own numbers
            frames, stated = _profile_frames(layout_segments(vertical), name, notes)
            if frames:
                pieces.append(("profile", frames, False, f"{name} profile"))
                lengths += stated
            else:
                notes.append(f"alignment {name!r}: its vertical layout holds no segment of length: no profile to judge")
    if not pieces:
        raise ValueError(f"{source}: no alignment with a plan or a profile to judge" + (f" ({'; '.join(notes)})" if notes else ""))
    # the model's size: its largest piece's (a plan in map coordinates and a profile from 0 are apart, not one model)
    size = max(_size(frames, source) for _, frames, *_ in pieces)
    stated_tolerances = []
    if gap_tol is None:
        precision = max(precisions, default=DEFAULT_PRECISION / metres)
        gap_tol = max(1e-7, precision, RELATIVE_GAP * size)
        stated_tolerances.append(f"gap {gap_tol:.3g} (the file's precision {precision:.3g}, or 1e-6 of its size)")
    if angle_tol is None:
        longest = max(lengths)
        real = [length for length in lengths if length > _SLIVER_SHARE * longest]
        angle_tol = max(1e-7, 2.0 * gap_tol / min(real))
        stated_tolerances.append(f"angle {angle_tol:.3g} rad")
    if curvature_tol is None:
        curvature_tol = 1e-6
    report = classify_pieces(pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, source=source,
                             element="segment", units=units)  # fmt: skip
    notes.insert(0, "the plan and the profile as ifcopenshell evaluates their curves' segments (a profile without its "
                    "IfcGradientCurve from its vertical segments' own numbers)")  # fmt: skip
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


def _size(frames: list, source: str) -> float:
    """The diagonal of the box of a piece's segment ends (those measured)."""
    points = np.array([frame[:3] for pair in frames for frame in pair])
    return model_size(points[np.isfinite(points).all(axis=1)], source)


def _judged(curve: Any, stated: list[tuple[float | None, float | None]], metres: float, what: str,
            notes: list[str]) -> tuple[list, list[float]] | None:  # fmt: skip
    """``_curve_frames`` of ``curve``, or None with a note where there is nothing to judge."""
    try:
        frames, lengths = _curve_frames(curve, stated, metres, what, notes)
    except ValueError as error:
        notes.append(str(error))
        return None
    if not frames:
        notes.append(f"{what}: no segment of length: not judged")
        return None
    return frames, lengths


def _curve_frames(curve: Any, stated: list[tuple[float | None, float | None]], metres: float, what: str,
                  notes: list[str]) -> tuple[list, list[float]]:  # fmt: skip
    """Per segment of length of ``curve`` (a plan's composite curve, or a gradient curve in (distance along,
    height)), its (start, end) frames in the file's unit: position and tangent as ifcopenshell evaluates it,
    curvature as the curve has it (a line's 0, a circle's 1/radius exactly; other curves by differences, or the
    layout's number in ``stated`` where it agrees with them).

    Raises:
        ValueError: a segment ifcopenshell cannot evaluate (an IFC 4 ``IfcCompositeCurveSegment``), named.
    """
    import ifcopenshell.geom
    import ifcopenshell.ifcopenshell_wrapper as wrapper

    settings = ifcopenshell.geom.settings()
    segments = list(curve.Segments)
    if len(stated) != len(segments):  # a Helmert curve is two curve segments, say: the layout cannot be matched
        notes.append(f"{what}: {len(stated)} layout segments for {len(segments)} curve segments: its curvatures are the "
                     "curve's own, by differences")  # fmt: skip
        stated = [(None, None)] * len(segments)
    frames, lengths = [], []
    for k, segment in enumerate(segments):
        function = wrapper.map_shape(settings, segment)
        if function is None:
            raise ValueError(f"{what} segment {k} ({segment.is_a()}) is not a curve segment ifcopenshell evaluates: not judged")
        length = float(function.length())
        if length == 0.0:
            continue
        evaluate = wrapper.function_item_evaluator(settings, function).evaluate
        parent = segment.ParentCurve if segment.is_a("IfcCurveSegment") else None
        line = parent is not None and parent.is_a("IfcLine")
        radius = float(parent.Radius or 0.0) if parent is not None and parent.is_a("IfcCircle") else 0.0
        ends = []
        for end, at in enumerate((0.0, length)):
            matrix = np.array(evaluate(at))
            point, tangent = matrix[:3, 3] / metres, matrix[:3, 0] / np.linalg.norm(matrix[:3, 0])
            measured = _turning(evaluate, at, length, end == 1) * metres  # 1/unit; positive turns left
            exact = line or radius > 0.0
            curvature = (0.0 if line else math.copysign(1.0 / radius, measured)) if exact else measured
            says = stated[k][end]
            floor = max(abs(curvature), metres / abs(length))  # 1/length: the segment's own scale of curvature
            if says is not None and abs(says - curvature) > _DESIGN_AGREES * max(floor, abs(says)):
                notes.append(f"{what} segment {k} {('starts', 'ends')[end]} with curvature {curvature:.6g}, not the "
                             f"{says:.6g} its layout states: the curve's is judged")  # fmt: skip
            elif says is not None and not exact:
                curvature = says  # exact, where the curve's difference quotient agrees with it
            normal = np.array([-tangent[1], tangent[0], 0.0])
            ends.append((*point.tolist(), *tangent.tolist(), *(curvature * normal).tolist()))
        frames.append(tuple(ends))
        lengths.append(abs(length) / metres)
    return frames, lengths


def _horizontal_curvatures(design: list[Any]) -> list[tuple[float | None, float | None]]:
    """The curvatures (1/unit) a horizontal layout states at the start and end of each segment (None: not stated)."""

    def of(radius: Any) -> float | None:
        return None if radius is None else (0.0 if float(radius) == 0.0 else 1.0 / float(radius))

    return [(of(d.StartRadiusOfCurvature), of(d.EndRadiusOfCurvature)) if d is not None and d.is_a("IfcAlignmentHorizontalSegment")
            else (None, None) for d in design]  # fmt: skip


def _vertical_curvatures(design: list[Any]) -> list[tuple[float | None, float | None]]:
    """The curvatures (1/unit) of the profile z(s) at the start and end of each vertical segment, from its numbers
    (None where they do not say: another kind of segment, a number missing)."""
    return [_vertical_bend(d) if d is not None and d.is_a("IfcAlignmentVerticalSegment") else (None, None) for d in design]


def _vertical_bend(segment: Any) -> tuple[float | None, float | None]:
    """The end curvatures of one vertical segment of the profile z(s): 0 on a constant gradient, z''/(1+z'²)^1.5 on
    a parabola, (sin θ1 − sin θ0)/L on a circular arc (θ the gradients' angles); None where not known."""
    try:
        length, g0 = float(segment.HorizontalLength), float(segment.StartGradient)
        g1 = float(segment.EndGradient) if segment.EndGradient is not None else g0
    except (TypeError, ValueError):
        return None, None
    kind = segment.PredefinedType
    if kind == "CONSTANTGRADIENT":
        return 0.0, 0.0
    if length == 0.0:
        return None, None
    if kind == "PARABOLICARC":
        second = (g1 - g0) / length
        return second / (1 + g0 * g0) ** 1.5, second / (1 + g1 * g1) ** 1.5
    if kind == "CIRCULARARC" and g1 != g0:
        bend = (math.sin(math.atan(g1)) - math.sin(math.atan(g0))) / length
        return bend, bend
    return None, None


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
    """Per non-zero vertical segment, its (start, end) frames in the plane (distance along, height), from its
    numbers alone (an alignment whose profile has no ``IfcGradientCurve``)."""
    frames, lengths = [], []
    unmeasured = set()
    for segment in design:
        if segment is None or not segment.is_a("IfcAlignmentVerticalSegment"):
            notes.append(f"alignment {name!r}: its vertical layout nests a {getattr(segment, 'is_a', lambda: 'nothing')()}: left out")
            continue
        try:
            length, s0, h0 = float(segment.HorizontalLength), float(segment.StartDistAlong), float(segment.StartHeight)
            g0 = float(segment.StartGradient)
            g1 = float(segment.EndGradient) if segment.EndGradient is not None else g0
        except (TypeError, ValueError):
            notes.append(f"alignment {name!r}: a vertical segment without its numbers (#{segment.id()}): left out")
            continue
        if length == 0.0:
            continue
        kind = segment.PredefinedType
        bend = _vertical_bend(segment)
        if kind == "CONSTANTGRADIENT":
            rise, g1 = g0 * length, g0
        elif kind == "PARABOLICARC":
            rise = 0.5 * (g0 + g1) * length
        elif kind == "CIRCULARARC" and bend[0]:
            t0, t1 = math.atan(g0), math.atan(g1)
            rise = (math.cos(t0) - math.cos(t1)) / bend[0]
        else:
            unmeasured.add(str(kind))
            rise = math.nan
        ends = []
        for point, gradient, kappa in (((s0, h0), g0, bend[0]), ((s0 + length, h0 + rise), g1, bend[1])):
            tangent = np.array([1.0, gradient, 0.0]) / math.hypot(1.0, gradient)
            kappa = math.nan if kappa is None else kappa
            ends.append((point[0], point[1], 0.0, *tangent.tolist(), *(kappa * np.array([-tangent[1], tangent[0], 0.0])).tolist()))
        frames.append(tuple(ends))
        lengths.append(length)
    if unmeasured:
        notes.append(f"alignment {name!r}: vertical {', '.join(sorted(unmeasured))} segments are not measured: their joints "
                     "are unmeasurable")  # fmt: skip
    return frames, lengths
