"""What rewriting a document G2 did: per path its measured deviation, joints changed, splits, or why it was kept.

``rewrite_dxf_g2``, ``rewrite_landxml_g2`` and ``rewrite_opendrive_g2`` return a :class:`DocumentReport`; ``lines()`` is the short
report a command prints (the last line is the verdict).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["DocumentReport", "PathReport"]


@dataclass(frozen=True)
class PathReport:
    """One path of a document and what was done to it.

    Attributes:
        name: the path's name (a drawing's ``path 3 (LINE 2A, layer OUTLINE)``, an alignment's name).
        joints: the path's joints (a closed path's closing joint counted).
        changed: the joints given a transition (or rounded) to make the path G2.
        deviation: the measured Hausdorff distance between the input and the G2 path (NaN when kept).
        splits: where the path was split (a reversal, a corner too sharp for the bound).
        kept: why the path was kept as it is ("" when it was made G2).
        pieces: how many pieces were written for it (lines, arcs, spirals).
        g2: whether the path as written is G2 at every joint (made so, or G2 already: a circle, a lone entity,
            clothoids between lines and arcs).
    """

    name: str
    joints: int
    changed: int = 0
    deviation: float = math.nan
    splits: int = 0
    kept: str = ""
    pieces: int = 0
    g2: bool = False

    @property
    def made(self) -> bool:
        """Whether the path was rewritten G2."""
        return not self.kept

    def line(self, units: str) -> str:
        """The path's line of the report."""
        if self.kept:
            return f"  {self.name}: kept as is ({self.kept})"
        split = f", split at {self.splits} joint(s)" if self.splits else ""
        return (f"  {self.name}: G2 within {self.deviation:.3g} {units}, {self.changed} of {self.joints} joint(s) changed, "
                f"{self.pieces} piece(s){split}")  # fmt: skip


@dataclass(frozen=True)
class DocumentReport:
    """What rewriting one document G2 did.

    Attributes:
        source: the input file's name.
        target: the output file's name.
        kind: ``"DXF drawing"``, ``"LandXML file"`` or ``"OpenDRIVE file"``.
        units: the unit of ``max_deviation`` and of the deviations (the document's own; ``"drawing units"``
            for a unitless drawing).
        max_deviation: the bound asked for, in ``units``.
        paths: one :class:`PathReport` per path, in the document's order.
        notes: what else the reader should know (entities kept, blocks exploded, a unitless drawing, …).
    """

    source: str
    target: str
    kind: str
    units: str
    max_deviation: float
    paths: tuple[PathReport, ...]
    notes: tuple[str, ...] = ()

    @property
    def worst(self) -> float:
        """The largest measured deviation of the paths made G2 (0 when none was)."""
        return max((p.deviation for p in self.paths if p.made), default=0.0)

    @property
    def kept(self) -> tuple[PathReport, ...]:
        """The paths kept as they were."""
        return tuple(p for p in self.paths if not p.made)

    @property
    def below_g2(self) -> tuple[PathReport, ...]:
        """The paths left below G2 somewhere: kept as they were although not G2, or split (a command exits non-zero on them)."""
        return tuple(p for p in self.paths if not p.g2 or p.splits)

    @property
    def splits(self) -> int:
        """How many joints split a path, over the document."""
        return sum(p.splits for p in self.paths)

    def lines(self) -> list[str]:
        """The short human report: a header, one line per path, the notes, and the verdict last."""
        made = len(self.paths) - len(self.kept)
        already = sum(p.g2 and not p.made for p in self.paths)
        out = [f"{self.source} → {self.target} ({self.kind}), max deviation {self.max_deviation:g} {self.units}:"]
        out += [p.line(self.units) for p in self.paths]
        out += [f"  note: {n}" for n in self.notes]
        changed = sum(p.changed for p in self.paths)
        splits = f", {self.splits} split(s)" if self.splits else ""
        out.append(f"{made} of {len(self.paths)} path(s) made G2 (worst {self.worst:.3g} {self.units}, {changed} joint(s) changed"
                   f"{splits}), {already} G2 already, {len(self.below_g2)} left below G2")  # fmt: skip
        return out
