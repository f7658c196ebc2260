"""Command line: ``spiral-cad demo``."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from . import circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from .transitions import Transition


def core_examples() -> list[tuple[str, Transition]]:
    """One solved instance of each of the five cases (the core demo's input)."""
    return [
        ("line → circle (Thm 4.1)", line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0)),
        ("circle → circle, C (Thm 4.2)", circle_to_circle((0, 0), 2.0, (5, 1), 1.0)),
        ("circle → circle, S (Thm 4.3)", circle_to_circle((0, 0), -2.0, (5, 1), 1.0)),
        ("line → line (Cor 4.5)", line_to_line((0, 0), (10, 0), (15, 8))),
        ("circle in circle (5th case)", circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4)),
    ]


def transition_table(rows: Sequence[tuple[str, Transition]]) -> str:
    """Table of θ, end curvatures and the worst join residuals per transition."""
    head = f"{'case':30} {'θ°':>9} {'κ start':>10} {'κ end':>10} {'gap/len':>9} {'angle':>9} {'Δκ·len':>9}"
    lines = [head, "-" * len(head)]
    for name, t in rows:
        joins = t.joins()
        size = t.length
        lines.append(
            f"{name:30} {math.degrees(t.theta):9.4f} {t.spirals[0].start_curvature:10.5f} "
            f"{t.spirals[-1].end_curvature:10.5f} {max(j.gap for j in joins) / size:9.1e} "
            f"{max(j.angle for j in joins):9.1e} {max(j.curvature_jump for j in joins) * size:9.1e}"
        )
    return "\n".join(lines)


def _demo(args: argparse.Namespace) -> int:
    print(transition_table(core_examples()))
    return 0


def _check(args: argparse.Namespace) -> int:
    from .continuity import main_check  # imports OCP, so only when used

    return main_check(args)


def _add_check(sub: argparse._SubParsersAction) -> None:
    check = sub.add_parser("check", help="report G0/G1/G2 continuity at every joint of a STEP/IGES file")
    check.add_argument("file", help="a .step/.stp or .igs/.iges file")
    check.add_argument("--require", choices=["G0", "G1", "G2"], help="exit 1 if any joint is below this level")
    check.add_argument("--gap-tol", type=float, default=1e-7, help="G0 gap, absolute model units (default 1e-7)")
    check.add_argument("--angle-tol", type=float, default=1e-7, help="G1 tangent angle, radians (default 1e-7)")
    check.add_argument("--curvature-tol", type=float, default=1e-6, help="G2 curvature jump, relative (default 1e-6)")
    check.set_defaults(run=_check)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="spiral-cad", description="Exact G2 cubic Bézier spiral transitions for CAD.")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="solve the built-in default design and write its outputs")
    demo.add_argument("--out", default="out", help="output folder (default: out)")
    demo.set_defaults(run=_demo)
    _add_check(sub)
    args = parser.parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
