"""Continuous corners: a phone-like slab with G2 corners, against a circular fillet and a C2 blend.

Run: ``python examples/continuous_corners.py [OUT_DIR]`` (default ./out).

* ``slab.step``: a 70 × 145 × 8 mm slab whose outline is a ``ContinuousRectangle``
  (spiral → arc → spiral at every corner), extruded with build123d;
* ``continuous_corners.png``: one 90° corner rounded three ways with the same
  footprint (the corner's tangent points 10 mm from the vertex) — curvature
  against arc length, and the curvature combs;
* a printed table: max curvature, largest curvature jump, peak rate of change
  of curvature dκ/ds and whether the curvature rises and falls monotonically,
  for build123d's ``fillet_2d`` (circular), ``BlendCurve`` (C2 quintic, its
  tangent scale tuned for the lowest peak curvature) and ``g2_fillet`` with
  the 1996 spiral and with the near-linear spiral.
"""

import math
import sys
from pathlib import Path

import build123d as bd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.GCPnts import GCPnts_AbscissaPoint

from spiral_cad.build123d import ContinuousRectangle, curvature_comb, g2_fillet
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.export import export_step
from spiral_cad.design.fillets import corner_distance

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

# ---------------------------------------------------------------- the slab
outline = ContinuousRectangle(70, 145, radius=9.0, transition=0.6)
slab = bd.extrude(outline, 8)
assert slab.is_valid
top = slab.faces().sort_by(bd.Axis.Z)[-1]
report = check_continuity(top.outer_wire())
assert report.passes("G2"), report.format_table()
export_step(slab, out / "slab.step", name="slab")
print(f"slab: volume {slab.volume:.1f} mm³, outline {report.describe()}, every joint G2 → {out / 'slab.step'}")

# ------------------------------------------------------- one corner, three ways
FOOTPRINT, LEG, TRANSITION = 10.0, 25.0, 0.6
radius = FOOTPRINT / corner_distance(1.0, math.pi / 2, TRANSITION)
radius_nl = FOOTPRINT / corner_distance(1.0, math.pi / 2, TRANSITION, "near-linear")
corner = bd.Polyline((0, 0), (LEG, 0), (LEG, LEG))
vertex = [v for v in corner.vertices() if (bd.Vector(v) - bd.Vector(LEG, 0)).length < 1e-9]
first = bd.Edge.make_line((0, 0), (LEG - FOOTPRINT, 0))
second = bd.Edge.make_line((LEG, FOOTPRINT), (LEG, LEG))


def peak_curvature(edge: bd.Edge) -> float:
    curve = BRepAdaptor_Curve(edge.wrapped)
    u = np.linspace(curve.FirstParameter(), curve.LastParameter(), 400)
    return max(BRepLProp_CLProps(curve, t, 2, 1e-12).Curvature() for t in u)


# BlendCurve's default tangents (the lines' unit derivatives) make a near-chord with spikes at its
# ends; give it its best chance: the tangent scale with the lowest peak curvature.
tension = min(np.arange(1.0, 40.0, 0.5), key=lambda t: peak_curvature(bd.BlendCurve(first, second, tangent_scalars=(t, t))))
ways = {
    "build123d fillet_2d (circular)": corner.fillet_2d(FOOTPRINT, vertex),
    f"build123d BlendCurve C2 (quintic, tangent scale {tension:g})": bd.Wire(
        [first, bd.BlendCurve(first, second, tangent_scalars=(tension, tension)), second]
    ),
    f"spiral_cad g2_fillet (r = {radius:.2f}, transition {TRANSITION})": g2_fillet(corner, radius, transition=TRANSITION),
    f"spiral_cad g2_fillet near-linear (r = {radius_nl:.2f})": g2_fillet(corner, radius_nl, transition=TRANSITION, shape="near-linear"),
}


def profile(wire: bd.Wire, per_edge: int = 400):
    """Arc length and curvature magnitude along the wire, edge by edge (OCCT's own evaluation)."""
    s0, pieces = 0.0, []
    for edge in wire.order_edges():
        curve = BRepAdaptor_Curve(edge.wrapped)
        u = np.linspace(curve.FirstParameter(), curve.LastParameter(), per_edge)
        s = np.array([GCPnts_AbscissaPoint.Length_s(curve, u[0], t) for t in u])
        k = np.array([BRepLProp_CLProps(curve, t, 2, 1e-12).Curvature() for t in u])
        if edge.wrapped.Orientation().name.endswith("REVERSED"):
            k = k[::-1]
        pieces.append((s0 + s, k))
        s0 += s[-1]
    return pieces


rows = []
fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
for (name, wire), color in zip(ways.items(), ("tab:blue", "tab:green", "tab:red", "tab:purple")):
    pieces = profile(wire)
    kappa = np.concatenate([k for _, k in pieces])
    jump = max(abs(a[1][-1] - b[1][0]) for a, b in zip(pieces, pieces[1:]))
    rate = max(float(np.max(np.abs(np.diff(k) / np.diff(s)))) for s, k in pieces)  # within edges: jumps are not rates
    peak = int(np.argmax(kappa))
    monotone = bool(np.all(np.diff(kappa[: peak + 1]) >= -1e-9) and np.all(np.diff(kappa[peak:]) <= 1e-9))
    rows.append((name, kappa.max(), jump, rate, "yes" if monotone else "no", "yes" if jump < 1e-6 else "no"))
    for s, k in pieces:
        left.plot(s - LEG + FOOTPRINT, k, color=color, lw=1.8, label=name if s is pieces[0][0] else None)
    teeth = curvature_comb(wire, scale=40.0, per_edge=30)
    for edge in teeth.edges():
        a, b = edge.position_at(0), edge.position_at(1)
        right.plot([a.X, b.X], [a.Y, b.Y], color=color, lw=0.6, alpha=0.8)
    points = np.array([tuple(wire.position_at(t))[:2] for t in np.linspace(0, 1, 400)])
    right.plot(*points.T, color=color, lw=2.0)
left.set_xlim(-3, 2 * FOOTPRINT + 3)
left.set_ylim(-0.01, 0.2)
left.set_xlabel("arc length from the first tangent point (mm)")
left.set_ylabel("curvature |κ| (1/mm)")
left.set_title(f"One 90° corner, tangent points {FOOTPRINT:g} mm from the vertex")
left.legend(loc="upper right", fontsize="small")
left.grid(True, alpha=0.3)
right.set_aspect("equal")
right.set_xlim(LEG - FOOTPRINT - 8, LEG + 8)
right.set_ylim(-8, FOOTPRINT + 8)
right.set_title("Curvature combs (a jump is a step in the comb)")
right.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(out / "continuous_corners.png", dpi=100)

header = f"{'corner':66} {'max κ (1/mm)':>12} {'κ jump':>9} {'max dκ/ds (1/mm²)':>18} {'monotone':>9} {'G2':>4}"
print(header)
print("-" * len(header))
for name, peak, jump, rate, monotone, g2 in rows:
    print(f"{name:66} {peak:12.5f} {jump:9.5f} {rate:18.5f} {monotone:>9} {g2:>4}")
print(f"wrote {out / 'continuous_corners.png'}")
