"""Reproduce Fig. 6 of Walton & Meek (1996), extend it to the near-linear spiral, compare with a clothoid.

Run: ``python examples/fig6.py [OUT_DIR]`` (default ./out). Writes
``fig6.png`` (the 1996 family θ = 10°…80°, normalised as in the paper, beside
the near-linear family θ = 10°…50°) and ``bezier_vs_clothoid.png`` (curvature
against arc length and the curves of both spirals and a clothoid with the same
θ and end curvature), and prints for each θ and shape the spiral's length and
its peak-to-mean ratio of dκ/ds.
"""

import math
import sys
from pathlib import Path

from spiral_cad import BezierSpiral
from spiral_cad.app.plots import plot_fig6_shapes, plot_vs_clothoid
from spiral_cad.design import peak_curvature_rate

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

print(f"{'θ°':>4} {'shape':>12} {'length·c':>9} {'peak/mean dκ/ds':>16}")
for degrees in range(10, 90, 10):
    for shape in ("walton-meek", "near-linear"):
        if shape == "near-linear" and degrees > 50:
            continue  # the near-linear family ends at 50°
        spiral = BezierSpiral((0, 0), (1, 0), math.radians(degrees), 1.0, shape=shape)
        peak, _ = peak_curvature_rate(spiral.control_points)
        print(f"{degrees:4d} {shape:>12} {spiral.length:9.5f} {peak / (1.0 / spiral.length):16.4f}")

plot_fig6_shapes().savefig(out / "fig6.png", dpi=110)
plot_vs_clothoid(math.radians(8), 1.0, shapes=("walton-meek", "near-linear")).savefig(out / "bezier_vs_clothoid.png", dpi=110)
print(f"wrote {out / 'fig6.png'} and {out / 'bezier_vs_clothoid.png'}")
