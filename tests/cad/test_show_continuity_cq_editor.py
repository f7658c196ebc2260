"""``show_continuity(part, show_object=show_object)`` in CQ-editor itself: its main window on a virtual
X display (Xvfb), a script run by its own debugger (which injects its ``show_object``), its object tree
read and its 3-D view's own picture (``V3d_View.Dump``) read back."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("cadquery")
pytestmark = [pytest.mark.cad, pytest.mark.slow, pytest.mark.subprocess]

from spiral_cad.cad.faces import CLASS_COLOURS  # noqa: E402

# CQ-editor's main window: open the script, run it with the debugger's render (what its Render button
# does), then print the object tree's names and dump the view.
DRIVER = """
import json, sys, time
from PyQt5.QtWidgets import QApplication
app = QApplication(sys.argv)
from cq_editor.main_window import MainWindow
window = MainWindow(filename=sys.argv[1])
window.resize(1200, 900)
window.show()
def settle():
    for _ in range(20):
        app.processEvents()
        time.sleep(0.05)
settle()
window.components["debugger"].render()
settle()
root = window.components["object_tree"].CQ
names = [root.child(k).text(0) for k in range(root.childCount())]
window.components["viewer"]._get_view().Dump(sys.argv[2])
print(json.dumps(names))
"""

G1_PART = "part = cq.Workplane().box(60, 40, 10).edges('|Z').fillet(12)"
G2_PART = "import spiral_cad.cadquery\npart = cq.Workplane().continuousRect(60, 40, 12).extrude(10)"


@pytest.fixture(scope="module")
def cq_editor():
    if importlib.util.find_spec("cq_editor") is None:
        pytest.skip('CQ-editor is not installed (pip install "spiral_cad[test]")')
    if shutil.which("xvfb-run") is None:
        pytest.skip("Xvfb is not installed (Debian: apt-get install xvfb xauth): CQ-editor needs an X display")
    return "xvfb-run"


def _shown(xvfb_run: str, made: str, folder: Path) -> tuple[list[str], dict, np.ndarray]:
    from PIL import Image

    folder.mkdir()
    script, picture, report = folder / "part.py", folder / "view.png", folder / "report.json"
    script.write_text(
        f"import json\nimport cadquery as cq\nfrom spiral_cad.build123d import show_continuity\n{made}\n"
        "report = show_continuity(part, show_object=show_object)\n"
        f"open({str(report)!r}, 'w').write(json.dumps(sorted({{e.level for e in report.edges}})))\n",
        encoding="utf-8",
    )
    env = {**os.environ, "HOME": str(folder), "XDG_RUNTIME_DIR": str(folder)}  # its settings, not the user's
    run = subprocess.run([xvfb_run, "-a", "-s", "-screen 0 1280x1024x24", sys.executable, "-c", DRIVER, str(script), str(picture)],
                         capture_output=True, text=True, timeout=300, cwd=folder, env=env)  # fmt: skip
    assert run.returncode == 0, run.stderr[-3000:]
    assert report.is_file(), f"the script failed in CQ-editor: {run.stderr[-3000:]}"
    names = json.loads(run.stdout.strip().splitlines()[-1])
    return names, json.loads(report.read_text()), np.asarray(Image.open(picture).convert("RGB"), dtype=int)


def _pixels_of(picture: np.ndarray, colour: str, tolerance: int = 60) -> int:
    rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
    return int((np.abs(picture - rgb).sum(axis=2) < tolerance).sum())


def test_cq_editor_shows_g1_edges_orange_and_g2_ones_green_on_faces_coloured_by_curvature(cq_editor, tmp_path):
    g1_names, g1_levels, g1 = _shown(cq_editor, G1_PART, tmp_path / "g1")
    g2_names, g2_levels, g2 = _shown(cq_editor, G2_PART, tmp_path / "g2")
    assert g1_levels == ["G1", "sharp"] and g2_levels == ["G2", "sharp"]
    # every face and judged edge an object of its own in CQ-editor's tree, named with its numbers
    assert sum(n.startswith("face ") for n in g1_names) == 10 and sum(" G1: angle " in n for n in g1_names) == 8
    assert sum(" G2: angle " in n for n in g2_names) > 8 and not any(" G1: " in n for n in g2_names)
    # the edges drawn in their class's colour, and not in the other's
    assert _pixels_of(g1, CLASS_COLOURS["G1"]) > 20 and _pixels_of(g1, CLASS_COLOURS["G2"]) == 0
    assert _pixels_of(g2, CLASS_COLOURS["G2"]) > 20 and _pixels_of(g2, CLASS_COLOURS["G1"]) == 0
    # the convex fillets red (CQ-editor's own colour is gold), the flat faces near white
    for picture in (g1, g2):
        red = (picture[..., 0] > 120) & (picture[..., 1] < 80) & (picture[..., 2] < 90)
        assert red.mean() > 0.005
        light = (picture.max(axis=2) - picture.min(axis=2) < 12) & (picture.min(axis=2) > 190)
        assert light.mean() > 0.05


def test_show_object_must_be_a_function():
    import cadquery as cq

    from spiral_cad.build123d import show_continuity

    with pytest.raises(ValueError, match="show_object must be CQ-editor's show_object function; got str"):
        show_continuity(cq.Workplane().box(1, 1, 1), show_object="show_object")
