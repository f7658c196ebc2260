"""The designs a design file builds: one ``Built`` kind per design type, and ``DesignError``.

Apart from ``designfile`` (which loads, builds and writes them) so that the builders of other
inputs (G-code programs, lines and arcs made G2) make them without importing the loader.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..core.chain import Chain

__all__ = ["Built", "BuiltAlignment", "BuiltCircleChain", "BuiltFit", "BuiltLandXML", "BuiltRoadFit", "BuiltRounded",
           "BuiltTransition", "DesignError", "FitResiduals", "WARN_OFFSET", "program_feed"]  # fmt: skip


class DesignError(ValueError):
    """A design file is malformed or infeasible; the message names the field and value."""


@dataclass(kw_only=True)
class Built(ABC):
    """One built design: its chain and the object that made it (for tables).

    ``continuity`` and ``road_3d`` are filled in by ``write``: the checked
    continuity of the STEP file and the fit of a road's 3-D file.
    """

    name: str
    chain: Chain
    source: Any
    continuity: str | None = None
    road_3d: str | None = None
    gcode: dict[str, Any] | None = None  # write_gcode's options of NAME.ngc (None: no program)
    inputs: tuple[Path, ...] = ()  # files the design was read from: never written over
    program_feed: float | None = None  # the feed of the program a path was read from (chain's program unit per minute)
    segment_feeds: Any = None  # that program's feed per segment (the same unit; NaN: program_feed), or None

    @property
    @abstractmethod
    def kind(self) -> str:
        """What the design is, as the summary shows it."""


@dataclass(kw_only=True)
class BuiltAlignment(Built):
    """An alignment (``source``: the ``Alignment``), with its road's cross-section and its optional profile."""

    cross_section: Any
    geo_reference: str | None = None
    profile: Any = None

    @property
    def kind(self) -> str:
        return "alignment"


@dataclass(kw_only=True)
class BuiltCircleChain(Built):
    """A circle chain (``source``: the ``CircleChain``)."""

    @property
    def kind(self) -> str:
        return "circle_chain"


@dataclass(kw_only=True)
class BuiltRounded(Built):
    """A rounded polyline or toolpath (``source``: the ``RoundedPath``), with its optional samples."""

    samples: dict[str, float] | None = None
    notes: tuple[str, ...] = ()  # what the summary tells of how it was read (a G-code program split where it folds back)

    @property
    def kind(self) -> str:
        return "rounded_polyline"


@dataclass(frozen=True)
class FitResiduals:
    """Every fitted point's station on the path and its distance to it: NAME_residuals.csv and NAME_fit.png.

    ``vertical`` (a 3-D survey): each point's |z − profile elevation|; ``estimate``: the
    point-wise curvature the fit segmented (None when the fit does not give it).
    """

    points: Any
    stations: Any
    residuals: Any
    tolerance: float
    units: str
    estimate: Any = None
    vertical: Any = None

    def line(self) -> str:
        """The fit in one line: how many points, the worst residual and the tolerance."""
        text = (f"{len(self.points):,} points within {float(np.max(self.residuals)):.3g} {self.units} of the path "
                f"(tolerance {self.tolerance:g} {self.units})")  # fmt: skip
        if self.vertical is not None:
            text += f", within {float(np.max(self.vertical)):.3g} {self.units} of the profile"
        return text


@dataclass(kw_only=True)
class BuiltFit(Built):
    """A path fitted to points (``source``: the ``PointFit``), its ``fit`` residuals and optional samples."""

    fit: FitResiduals
    closed: bool = False
    samples: dict[str, float] | None = None

    @property
    def kind(self) -> str:
        return "fit (closed)" if self.closed else "fit"


@dataclass(kw_only=True)
class BuiltRoadFit(BuiltAlignment):
    """A road fitted to points (``source``: the ``Alignment``; with z also its profile), its ``fit`` residuals."""

    fit: FitResiduals

    @property
    def kind(self) -> str:
        return "fit (alignment)" if self.profile is None else "fit (alignment + profile)"


@dataclass(kw_only=True)
class BuiltTransition(Built):
    """One transition (``source``: the ``Transition``)."""

    @property
    def kind(self) -> str:
        return f"transition ({self.source.kind})"


#: The share of an element's length beyond which the build warns of the offset between the file's element and ours.
WARN_OFFSET = 1e-3


@dataclass(kw_only=True)
class BuiltLandXML(Built):
    """One G2 run of an alignment read from LandXML (``source``: its ``LandXMLAlignment``); ``renamed``
    says why its name has a suffix (another alignment's outputs already had the name), else empty."""

    run: int = 0
    renamed: str = ""

    def landxml_offset(self) -> str:
        """The alignment's largest offset from the file, a warning above ``WARN_OFFSET`` of its element's length."""
        a = self.source
        k = int(np.argmax(a.offsets))
        warn = a.offsets[k] > WARN_OFFSET * a.file_lengths[k]
        return f"{'warning: ' if warn else ''}largest offset from the file's alignment {a.name!r}: {a.worst}"

    @property
    def kind(self) -> str:
        return "LandXML alignment"


def program_feed(feeds: tuple[float, ...], program_units: str | None, units: str) -> float | None:
    """The feed of the rounded program of a G-code program with ``feeds`` (in its ``program_units`` per minute),
    in the unit per minute of the program written for a chain in ``units``: the one F of its feed moves, or the
    lowest of several (never faster than the program asked); None without one (a program read by rs274)."""
    from ..core.units import MM_PER_UNIT
    from ..io.gcode_write import PROGRAM_UNIT

    if not feeds or program_units is None:
        return None
    return min(feeds) * MM_PER_UNIT[program_units] / MM_PER_UNIT[PROGRAM_UNIT[units]]
