"""Reproduce Fig. 6 of Walton & Meek (1996) and compare with a clothoid.

Run: ``python examples/fig6.py [OUT_DIR]`` (default ./out). Writes
``fig6.png`` (the spiral family θ = 10°…80°, normalised as in the paper) and
``bezier_vs_clothoid.png`` (curvature against arc length and the curves of a
Bézier spiral and a clothoid with the same θ and end curvature), and prints
for each θ the spiral's length and its peak-to-mean ratio of dκ/ds.
"""

import math
import sys
from pathlib import Path

from spiral_cad import BezierSpiral
from spiral_cad.design import peak_curvature_rate
from spiral_cad.plots import plot_fig6, plot_vs_clothoid

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

print(f"{'θ°':>4} {'length·c':>9} {'peak/mean dκ/ds':>16}")
for degrees in range(10, 90, 10):
    spiral = BezierSpiral((0, 0), (1, 0), math.radians(degrees), 1.0)
    peak, _ = peak_curvature_rate(spiral.control_points)
    print(f"{degrees:4d} {spiral.length:9.5f} {peak / (1.0 / spiral.length):16.4f}")

plot_fig6().savefig(out / "fig6.png", dpi=110)
plot_vs_clothoid(math.radians(30), 1.0).savefig(out / "bezier_vs_clothoid.png", dpi=110)
print(f"wrote {out / 'fig6.png'} and {out / 'bezier_vs_clothoid.png'}")
