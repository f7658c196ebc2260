"""Errors and the per-row status codes shared by the scalar and batch solvers."""

from __future__ import annotations

from enum import IntEnum


class NoSolutionError(ValueError):
    """The input is well formed but no spiral transition of that kind exists.

    The message names the violated condition and its numbers.
    """


class JointError(ValueError):
    """A ``Chain`` joint that is not G2: ``joint`` is its index; ``part`` the index of the
    ``Chain.join`` part it belongs to (None for a ``Chain`` built from segments).

    Design tools catch it to name their PI, corner or circle (as a NoSolutionError:
    their parts are consistent by construction, so only float64 can break a joint).
    """

    def __init__(self, message: str, joint: int, part: int | None = None):
        super().__init__(message)
        self.joint = joint
        self.part = part


class Status(IntEnum):
    """Outcome of one solver row (``spiral_cad.core.batch`` results carry these)."""

    OK = 0
    NOT_FINITE = 1
    ZERO_DIRECTION = 2
    BAD_RADIUS = 3
    COINCIDENT = 4
    SIGN_MISMATCH = 5
    CIRCLE_MEETS_LINE = 6
    CIRCLES_ENCLOSED = 7
    CIRCLES_OVERLAP = 8
    CORNER_STRAIGHT = 9
    CORNER_REVERSAL = 10
    LEGS_TOO_SHORT = 11
    OUTSIDE_NESTED_BAND = 12
    EQUAL_RADII = 13
    UNVERIFIED = 14
    BAD_CURVATURE = 15
    BAD_ANGLE = 16
    OUTSIDE_SHAPE = 17


#: Codes that mean "malformed input" (plain ValueError); the rest are NoSolutionError.
MALFORMED = frozenset(
    {
        Status.NOT_FINITE,
        Status.ZERO_DIRECTION,
        Status.BAD_RADIUS,
        Status.COINCIDENT,
        Status.SIGN_MISMATCH,
        Status.BAD_CURVATURE,
        Status.BAD_ANGLE,
    }
)
