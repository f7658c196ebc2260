"""Regenerate the pictures of the README and the documentation site in docs/images from the project's own outputs.

Run: ``make pictures`` (or ``.venv/bin/python docs/make_pictures.py``).
"""

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import cadquery as cq

ROOT = Path(__file__).resolve().parent.parent
IMAGES = ROOT / "docs" / "images"


def run(*args: str) -> None:
    subprocess.run([sys.executable, *args], check=True, cwd=ROOT, stdout=subprocess.DEVNULL)


def first_curve() -> None:
    """The picture of Getting started's first curve, made by the same calls as the page."""
    import spiral_cad as sc
    from spiral_cad.app.plots import plot_plan

    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = sc.line_to_circle((-20, 120), (1, 0), (100, 60), 50.0).reversed()
    chain = sc.Chain.join([enter, leave], start=(-20, 0), end=(-20, 120), units="mm")
    plot_plan(chain, comb=True).savefig(IMAGES / "first_curve.png")


def zebra_pictures() -> None:
    """Zebra stripes and mean curvature: a box with circular vertical fillets (G1) beside an extruded
    continuous rectangle (G2), the pictures of the Faces guide."""
    import build123d as bd
    from matplotlib.figure import Figure

    from spiral_cad.app.zebra import plot_curvature_map, plot_zebra
    from spiral_cad.build123d import ContinuousRectangle
    from spiral_cad.cad.mesh import face_mesh

    parts = {
        "circular fillets, r = 5: G1": face_mesh(bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 5)),
        "continuous rectangle, extruded: G2": face_mesh(bd.extrude(ContinuousRectangle(40, 20, 5), 8)),
    }
    for name, draw in (("zebra_boxes.png", plot_zebra), ("zebra_curvature.png", plot_curvature_map)):
        fig = Figure(figsize=(14, 4.2), dpi=110)
        for ax, (title, mesh) in zip(fig.subplots(1, 2), parts.items()):
            draw(mesh, ax=ax, title=title)
        fig.savefig(IMAGES / name, bbox_inches="tight")
    # every edge filleted: stripes cross the cylinder/sphere edges (G1) and kink there
    rounded = bd.fillet(bd.Box(40, 20, 16).edges(), 6)
    plot_zebra(rounded, view=(1.0, -1.3, 1.0), pixels=700).savefig(IMAGES / "zebra_corners.png", bbox_inches="tight")


def solids_pictures() -> None:
    """The G2 solids tutorial's picture: zebra stripes on a ContinuousBox beside build123d's box with
    circular fillets of the same radii (the stripes kink at every G1 edge, not at the G2 ones)."""
    import build123d as bd
    from matplotlib.figure import Figure

    from spiral_cad.app.zebra import plot_zebra
    from spiral_cad.build123d import ContinuousBox
    from spiral_cad.cad.mesh import face_mesh

    circular = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 6)
    circular = bd.fillet(circular.edges().filter_by(bd.Axis.Z, reverse=True), 1.5)
    parts = {
        "build123d Box + fillet (6, then 1.5): G1": face_mesh(circular),
        "ContinuousBox(40, 20, 8, 6, edge_radius=1.5): G2": face_mesh(ContinuousBox(40, 20, 8, 6, edge_radius=1.5)),
    }
    fig = Figure(figsize=(14, 4.6), dpi=110)
    for ax, (title, mesh) in zip(fig.subplots(1, 2), parts.items()):
        plot_zebra(mesh, ax=ax, title=title, view=(1.0, -0.9, 0.7))
    fig.savefig(IMAGES / "solids_zebra.png", bbox_inches="tight")


def gallery_pictures() -> None:
    """The solids tutorial's gallery: each 2.5-D part rounded by build123d's circular ``fillet`` (the
    stripes kink where the fillets meet the faces) beside ``g2_fillet`` of the same edges (they do not)."""
    from matplotlib.figure import Figure

    from spiral_cad.app.gallery import GALLERY, gallery_part
    from spiral_cad.app.zebra import plot_zebra

    fig = Figure(figsize=(12, 4.0 * len(GALLERY)), dpi=100)
    axes = fig.subplots(len(GALLERY), 2)
    for row, (name, (_, radius)) in zip(axes, GALLERY.items()):
        for ax, g2 in zip(row, (False, True)):
            title = f"{name.replace('_', ' ')}: {'g2_fillet' if g2 else 'build123d fillet'}, r = {radius:g}: {'G2' if g2 else 'G1'}"
            plot_zebra(gallery_part(name, g2=g2), ax=ax, title=title, view=(1.0, -1.1, 0.8), stripes=10, pixels=900)
    fig.savefig(IMAGES / "solids_gallery.png", bbox_inches="tight")


def make_g2_picture() -> None:
    """The make_g2 tutorial's picture: curvature against arc length round a build123d ``fillet()``ed
    rectangle (it jumps 0 → 1/r at every tangent joint) and round the same outline after ``make_g2``
    (continuous: a spiral at every joint, the arcs kept as arcs)."""
    import build123d as bd
    import numpy as np
    from matplotlib.figure import Figure

    from spiral_cad.cad.fillet import planar_frame, wire_path
    from spiral_cad.design import make_g2

    wire = bd.fillet(bd.Rectangle(40, 20).vertices(), 5).faces()[0].outer_wire()
    segments, closed = wire_path(wire.wrapped, planar_frame(wire.wrapped))
    result = make_g2(segments, 0.2, closed=closed)
    fig = Figure(figsize=(11, 6.2), dpi=100)
    ax_before, ax_after, ax_plan = fig.add_subplot(2, 2, 1), fig.add_subplot(2, 2, 3), fig.add_subplot(1, 2, 2)
    station, s_in, k_in = 0.0, [], []
    for segment in segments:  # the input is G1 only: its curvature, one segment at a time
        u = np.linspace(0.0, 1.0, 60)
        s_in += list(station + u * segment.length) + [np.nan]
        k_in += list(np.broadcast_to(segment.curvature(u), u.shape)) + [np.nan]
        station += segment.length
    ax_before.plot(s_in, k_in, color="tab:red")
    ax_before.set_title("fillet(Rectangle(40, 20), 5): κ jumps at 8 joints", fontsize=10)
    chain = result.chain
    s_out = np.linspace(0.0, chain.length, 4000)
    ax_after.plot(s_out, chain.curvature_at(s_out), color="tab:blue")
    ax_after.set_title(f"make_g2(…, 0.2): κ continuous; deviation {result.deviation:.3f} mm", fontsize=10)
    for ax in (ax_before, ax_after):
        ax.set_xlabel("arc length (mm)")
        ax.set_ylabel("curvature (1/mm)")
        ax.grid(alpha=0.3)
    points = np.vstack([s.point(np.linspace(0.0, 1.0, 40)) for s in segments])
    ax_plan.plot(points[:, 0], points[:, 1], color="tab:red", lw=2.5, alpha=0.5, label="input: lines and arcs (G1)")
    for segment in chain:
        p = segment.point(np.linspace(0.0, 1.0, 40))
        kind = type(segment).__name__
        color = {"Line": "black", "Arc": "tab:blue", "BezierSpiral": "tab:orange"}[kind]
        ax_plan.plot(p[:, 0], p[:, 1], color=color, lw=1.2)
    ax_plan.plot([], [], color="tab:blue", label="result: arcs (true circles, shifted 0.2 mm)")
    ax_plan.plot([], [], color="tab:orange", label="result: spirals")
    ax_plan.set_xlim(8, 21)
    ax_plan.set_ylim(-11, 2)
    ax_plan.set_aspect("equal")
    ax_plan.set_title("one corner, close up (mm)", fontsize=10)
    ax_plan.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(IMAGES / "make_g2_curvature.png")


def report_page_picture() -> None:
    """The Faces guide's picture of the web page ``check --html`` writes, as headless Chromium draws it
    (software WebGL): build123d's box with circular vertical fillets, its G1 edges orange."""
    import build123d as bd

    import spiral_cad as sc

    with tempfile.TemporaryDirectory() as tmp:
        page = Path(tmp) / "part.html"
        sc.check(bd.fillet(bd.Box(60, 40, 10).edges().filter_by(bd.Axis.Z), 12), html=page)
        subprocess.run(
            [shutil.which("chromium") or "chromium", "--headless", "--no-sandbox", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", f"--user-data-dir={tmp}/profile", "--virtual-time-budget=8000",
             "--window-size=1100,720", f"--screenshot={IMAGES / 'report_page.png'}", f"{page.as_uri()}#item=0"],
            check=True, capture_output=True,
        )  # fmt: skip


def main() -> None:
    IMAGES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        run("-m", "spiral_cad.app.cli", "demo", "--out", str(tmp / "demo"))
        run("examples/robot_path.py", str(tmp / "robot"))
        run("examples/robot_path_3d.py", str(tmp / "robot3d"))
        run("examples/build123d_road.py", str(tmp / "road"))
        run("examples/cadquery_plugin.py", str(tmp / "cq" / "tube.step"))
        run("examples/continuous_corners.py", str(tmp / "corners"))
        run("examples/fit_points.py", str(tmp / "fit"))
        picks = {
            "demo/highway_plan.png": "highway_plan.png",
            "demo/highway_curvature.png": "highway_curvature.png",
            "demo/circles_plan.png": "circles_plan.png",
            "demo/fig6.png": "fig6.png",
            "demo/bezier_vs_clothoid.png": "bezier_vs_clothoid.png",
            "robot/robot_path.png": "robot_path.png",
            "robot3d/robot_path_3d.png": "robot_path_3d.png",
            "road/road.svg": "road.svg",
            "corners/continuous_corners.png": "continuous_corners.png",
            "fit/survey_fit.png": "fit_survey.png",
        }
        for source, target in picks.items():
            shutil.copy(tmp / source, IMAGES / target)
        from spiral_cad.app.plots import plot_jerk_length

        plot_jerk_length(shapes=("walton-meek", "near-linear")).savefig(IMAGES / "jerk_length.png", dpi=100)
        tube = cq.importers.importStep(str(tmp / "cq" / "tube.step"))
        cq.exporters.export(tube, str(IMAGES / "cadquery_tube.svg"), opt={"projectionDir": (0.4, -1.0, 0.5), "showHidden": False})
        first_curve()
        zebra_pictures()
        solids_pictures()
        gallery_pictures()
        make_g2_picture()
        report_page_picture()
    for path in sorted(IMAGES.iterdir()):
        print(path.relative_to(ROOT))


if __name__ == "__main__":
    main()
