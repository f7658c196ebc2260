"""Messages for failed solver rows: each ``Status`` code explained with the row's inputs and numbers."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from . import _kernel_circles as KC
from .errors import MALFORMED, NoSolutionError, Status
from .shapes import SHAPE_CODES, shape_limits


def _g(value: float) -> str:
    return f"{value:.6g}"


def describe(case: str, status: int, measure: float, inputs: Mapping[str, Any]) -> str:
    """Human-readable reason for a failed row of solver ``case``.

    Args:
        case: solver name, e.g. ``"line_to_circle"``.
        status: a ``Status`` code other than ``OK``.
        measure: the feasibility number the kernel reported for the row.
        inputs: the row's inputs by argument name (shown in the message).
    """
    status = Status(status)
    shown = ", ".join(f"{k}={v!r}" if isinstance(v, str) else f"{k}={v}" for k, v in inputs.items())
    r0: Any = inputs.get("radius0")  # present (a number) for the circle cases that read it
    r1: Any = inputs.get("radius1")
    shape = inputs.get("shape", "walton-meek")
    if status is Status.NOT_FINITE:
        return f"{case}: every input must be finite; got {shown}"
    if status is Status.ZERO_DIRECTION:
        return f"{case}: direction must be a non-zero vector; got {inputs.get('direction')}"
    if status is Status.BAD_RADIUS:
        if case == "line_to_circle":
            return f"line_to_circle: radius must be positive (the turn side follows the centre); got {inputs.get('radius')}"
        return f"{case}: radii must be non-zero (the sign is the travel sense); got radius0={r0}, radius1={r1}"
    if status is Status.COINCIDENT:
        if case == "line_to_line":
            return f"line_to_line: p0 and p1 must differ from the corner; got {shown}"
        return f"{case}: the circle centres coincide at {inputs.get('center0')}"
    if status is Status.SIGN_MISMATCH:
        return f"{case}: nested circles are travelled in one sense, so the radii must share their sign; got radius0={r0}, radius1={r1}"
    if status is Status.BAD_CURVATURE:
        if case == "BezierSpiral":
            return (
                f"BezierSpiral: curvature must be non-zero with the sign of theta; got "
                f"theta = {inputs.get('theta')}, curvature = {inputs.get('curvature')}"
            )
        return f"{case}: curvature must be a positive finite number or None; got {inputs.get('curvature')}"
    if status is Status.CIRCLE_MEETS_LINE:
        return (
            "line_to_circle: the circle must lie clear of the line (radius r smaller than the "
            f"distance d from the line to the centre); here d/r = {measure:.5f}"
        )
    if status is Status.CIRCLES_ENCLOSED:
        return (
            "circle_to_circle (broken-back C): neither circle may enclose the other, "
            f"D > ||r1| - |r0||; here D/||r1| - |r0|| = {measure:.5f}"
        )
    if status is Status.CIRCLES_OVERLAP:
        return f"circle_to_circle (S): the circles must be disjoint, D > |r0| + |r1|; here D/(|r0| + |r1|) = {measure:.5f}"
    if status is Status.CORNER_STRAIGHT:
        return "line_to_line: p0, corner and p1 are collinear (θ = 0): there is no turn to make"
    if status is Status.CORNER_REVERSAL:
        return "line_to_line: the path folds back on itself at the corner (θ = π/2): no spiral pair exists"
    if status is Status.LEGS_TOO_SHORT:
        return (
            f"line_to_line: curvature {inputs.get('curvature')} puts the spiral starts {_g(measure)} "
            "times the shorter leg away from the corner; it must be ≤ 1 (raise the curvature, "
            "or pass curvature=None for the largest pair that fits)"
        )
    if status is Status.OUTSIDE_NESTED_BAND:
        big, small = sorted((abs(float(r0)), abs(float(r1))), reverse=True)
        q = small / big
        lower = float(KC.KERNELS.guarded().nested_band_lower(q, SHAPE_CODES[shape]))
        if not lower < 1.0:  # r1/r0 so small (or underflowing) that the band is empty in float64
            return (
                f"circle_in_circle: a single {shape} spiral needs r1/r0 well above 0; here r1/r0 = {q:.6g} "
                f"(radius0={r0}, radius1={r1}): no nested band is left"
            )
        shown = f"{lower:.5f}" if 1.0 - lower >= 1e-4 else f"1 − {1.0 - lower:.3g}"  # a narrow band: its width
        return (
            f"circle_in_circle: a single {shape} spiral exists only for "
            f"{shown} ≤ D/(r0 − r1) < 1 at r1/r0 = {q:.2f}{'' if q >= 0.01 else f' ({q:.3g})'}; here D/(r0 − r1) = {measure:.5f}"
        )
    if status is Status.OUTSIDE_SHAPE:
        return _outside_shape(case, shape, measure, inputs)
    if status is Status.EQUAL_RADII:
        return f"circle_in_circle: nested circles need different radii; got |radius0| = |radius1| = {abs(float(r0))}"
    if status is Status.UNVERIFIED:
        if not math.isfinite(measure):
            return (
                f"{case}: the solution does not fit in float64 (its control points overflow, underflow "
                f"or coincide); nothing is returned for {shown}"
            )
        return (
            f"{case}: the solution reproduces its contacts only to {measure:.2g} (relative; at most "
            f"1e-9 is returned): at these coordinates float64 cannot hold it (a transition tiny "
            f"against its coordinates, or one so close to θ = π/2 that its legs dwarf the radius); "
            f"nothing is returned for {shown}"
        )
    if status is Status.BAD_ANGLE:
        return f"{case}: |theta| must lie in (0, π/2); got theta = {inputs.get('theta')}"
    raise AssertionError(f"no description for status {status!r}")


def _outside_shape(case: str, shape: str, measure: float, inputs: Mapping[str, Any]) -> str:
    """Why a problem lies beyond what spirals of ``shape`` reach (its largest spiral angle)."""
    limits = shape_limits(shape)
    largest = f"{math.degrees(limits['theta']):g}°"
    advice = "; the walton-meek shape reaches it" if shape != "walton-meek" else ""
    if case == "BezierSpiral":
        return f"BezierSpiral: {shape} spirals turn by at most {largest}; got |theta| = {math.degrees(measure):.6g}°{advice}"
    if case == "line_to_line":
        return (
            f"line_to_line: {shape} spiral pairs round corners of at most {2 * math.degrees(limits['theta']):g}° "
            f"deflection (spiral angle {largest}); this corner deflects {2 * math.degrees(measure):.6g}°{advice}"
        )
    if case == "line_to_circle":
        return (
            f"line_to_circle: a {shape} spiral (at most {largest}) reaches circles only up to d/r < "
            f"{limits['line_circle']:.6g} (d the centre's distance from the line); here d/r = {measure:.6g}{advice}"
        )
    if case == "circle_to_circle":
        r0, r1 = abs(float(inputs["radius0"])), abs(float(inputs["radius1"]))
        if (float(inputs["radius0"]) > 0) != (float(inputs["radius1"]) > 0):
            return (
                f"circle_to_circle (S): a {shape} pair (at most {largest} each) needs D/(|r0| + |r1|) < "
                f"{limits['s_pair']:.6g}; here {measure:.6g}{advice}"
            )
        reach = math.hypot((r0 + r1) * limits["g2"], (r1 - r0) * limits["g1"])
        distance = measure * abs(r1 - r0) if r1 != r0 else math.dist(inputs["center0"], inputs["center1"])
        return (
            f"circle_to_circle (broken-back C): a {shape} pair (at most {largest} each) reaches centres only "
            f"up to D < {reach:.6g} apart for these radii; here D = {distance:.6g}{advice}"
        )
    return f"{case}: the {shape} shape has no spiral for {', '.join(f'{k}={v}' for k, v in inputs.items())}{advice}"


def error_for(case: str, status: int, measure: float, inputs: Mapping[str, Any]) -> ValueError:
    """The exception the scalar API raises for a failed row."""
    message = describe(case, status, measure, inputs)
    return ValueError(message) if Status(status) in MALFORMED else NoSolutionError(message)
