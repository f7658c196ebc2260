"""What ``spiral-cad g2`` did to a G-code program (``gcode_inplace``): each run of cutting moves, and the report."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["GcodeG2Report", "GcodeRun"]


@dataclass
class GcodeRun:
    """One run of cutting lines and what became of it.

    Attributes:
        first, last: its first and last line (1-based).
        moves: its moves.
        status: ``"G2"`` (rewritten, whole or in parts), ``"kept"`` (verbatim: see ``reason``) or
            ``"nothing to do"`` (one move, or every joint G2 already).
        reason: why it (or a part of it) was kept verbatim.
        refused: the joints ``make_g2`` refused, each left as it was (the run split there and each side
            made G2 on its own): the line ending at the joint, its point and ``make_g2``'s reason.
        deviation: the measured distance between the input's path and the output's (both ways; program unit).
        joints_changed: joints given a transition or rounded.
        splits: joints ``make_g2`` split at (left as the corners they were).
        lines_written: the lines written in its place.
        nurbs: it is a LinuxCNC NURBS block (``G5.2`` … ``G5.3``), not a run of moves.
    """

    first: int
    last: int
    moves: int
    status: str = "kept"
    reason: str = ""
    refused: list[str] = field(default_factory=list)
    deviation: float = 0.0
    joints_changed: int = 0
    splits: int = 0
    lines_written: int = 0
    nurbs: bool = False


@dataclass
class GcodeG2Report:
    """What ``gcode_g2`` did to a program.

    Attributes:
        source: the program's name.
        text: the output program.
        max_deviation: the bound (program unit).
        units: the program's unit.
        dialect: the output dialect.
        runs: every run of cutting lines, in order.
        notes: what else was kept verbatim and why (e.g. lines after parameters).
    """

    source: str
    text: str
    max_deviation: float
    units: str
    dialect: str
    runs: list[GcodeRun] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def deviation(self) -> float:
        """The largest measured deviation of a rewritten run (program unit)."""
        return max((r.deviation for r in self.runs if r.status == "G2"), default=0.0)

    @property
    def kept(self) -> list[GcodeRun]:
        """The runs kept verbatim for a reason (refused or not within the bound)."""
        return [r for r in self.runs if r.status == "kept"]

    @property
    def splits(self) -> int:
        """Joints left as corners where ``make_g2`` split a run."""
        return sum(r.splits for r in self.runs)

    @property
    def below_g2(self) -> list[GcodeRun]:
        """The runs left below G2 somewhere: kept verbatim for a reason, or split (``spiral-cad g2`` exits 1 on them without ``--allow-splits``)."""
        return [r for r in self.runs if r.status == "kept" or r.splits or r.refused]

    def lines(self) -> list[str]:
        """The short report: one line per run changed or kept, and the totals."""
        unit = self.units
        out = []
        for r in self.runs:
            where = f"lines {r.first}-{r.last}" if r.last != r.first else f"line {r.first}"
            if r.status == "G2" and r.nurbs:
                out.append(f"{self.source} {where}: NURBS block made G2 ({r.lines_written} lines), deviation {r.deviation:.3g} {unit}")
            elif r.status == "G2":
                split = f", {r.splits} split(s) left as corners" if r.splits else ""
                refused = f", {len(r.refused)} refused joint(s) left as they were" if r.refused else ""
                out.append(f"{self.source} {where}: {r.moves} moves made G2 ({r.lines_written} lines), deviation "
                           f"{r.deviation:.3g} {unit}, {r.joints_changed} joints changed{split}{refused}")  # fmt: skip
                out += [f"{self.source} {where}: joint at {joint}" for joint in r.refused]
                if r.reason:
                    out.append(f"{self.source} {where}: a part kept as it was: {r.reason}")
            elif r.status == "kept":
                out.append(f"{self.source} {where}: {r.moves} moves kept as they are: {r.reason}")
                out += [f"{self.source} {where}: joint at {joint}" for joint in r.refused[1:]]
        out += [f"{self.source}: {note}" for note in self.notes]
        made = sum(r.status == "G2" for r in self.runs)
        left = sum(len(r.refused) for r in self.runs if r.status == "G2")
        parts = sum(r.status == "G2" and bool(r.reason) for r in self.runs)
        also = (f", {left} joint(s) in them refused and left as they were" if left else "") + (
            f", a part of {parts} of them kept as it was" if parts else ""
        )
        out.append(f"{self.source}: {made} of {len(self.runs)} runs made G2 within {self.max_deviation:g} {unit}{also} "
                   f"(measured {self.deviation:.3g} {unit}), {len(self.kept)} kept for a reason, "
                   f"{sum(r.status == 'nothing to do' for r in self.runs)} G2 already, {self.splits} splits")  # fmt: skip
        return out
