"""Robot path smoothing: round a waypoint polyline G2 under a curvature bound.

Run: ``python examples/robot_path.py [OUT_DIR]`` (default ./out). Rounds the
same waypoints with the Walton–Meek spiral pair and with Yang & Sukkarieh's
G2CBS legs under κmax, checks the measured peak curvature of both against
the bound, and writes ``robot_path.png`` (plan with curvature comb and the
curvature profile) and ``robot_path.svg``.
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from spiral_cad.app.plots import plot_curvature, plot_plan
from spiral_cad.cad.export import export_svg
from spiral_cad.design import round_corners

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

waypoints = np.array([[0, 0], [2.0, 0.2], [2.6, 1.6], [4.2, 1.8], [4.6, 0.4], [6.2, 0.9], [6.0, 2.6]])
kappa_max = 4.0  # 1/m: a 0.25 m minimum turning radius

fig, axes = plt.subplots(2, 2, figsize=(12, 7), height_ratios=[3, 2])
for column, method in enumerate(("walton-meek", "g2cbs")):
    path = round_corners(waypoints, max_curvature=kappa_max, shape=method)
    s = np.linspace(0, path.chain.length, 20001)
    peak = np.abs(path.chain.curvature_at(s)).max()
    assert peak <= kappa_max * (1 + 1e-9), (method, peak)
    corner_distance = sum(c.distance for c in path.corners)
    print(
        f"{method:12} corners {len(path.corners)}  length {path.chain.length:.4f} m  "
        f"measured max |κ| {peak:.6f} ≤ κmax {kappa_max}  total corner distance {corner_distance:.4f} m"
    )
    plot_plan(path.chain, ax=axes[0, column])
    axes[0, column].plot(*waypoints.T, "k--", lw=0.8, marker="o", ms=3, label="waypoints")
    axes[0, column].set_title(f"{method}: κmax = {kappa_max} 1/m")
    plot_curvature(path.chain, ax=axes[1, column])
    axes[1, column].axhline(kappa_max, color="k", ls=":", lw=0.8)
    axes[1, column].axhline(-kappa_max, color="k", ls=":", lw=0.8)
    if method == "walton-meek":
        export_svg(path.chain, out / "robot_path.svg")
fig.tight_layout()
fig.savefig(out / "robot_path.png", dpi=110)
print(f"wrote {out / 'robot_path.png'} and {out / 'robot_path.svg'}")
