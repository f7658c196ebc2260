"""``show_continuity`` against a viewer we did not write: OCP CAD Viewer's standalone server
(``python -m ocp_viewer``) with headless Chromium as its browser, the picture it draws read back."""

from __future__ import annotations

import importlib.util
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import CHROMIUM_FLAGS, chromium

bd = pytest.importorskip("build123d")
pytest.importorskip("ocp_vscode", reason='OCP CAD Viewer\'s client is not installed (pip install "spiral_cad[viewer]")')
# the viewer's own advice for a user who kept the camera (its default), not a fault of what is shown
pytestmark = [
    pytest.mark.cad,
    pytest.mark.slow,
    pytest.mark.subprocess,
    pytest.mark.filterwarnings("ignore::ocp_viewer_core.utils.CameraKeepWarning"),
]

from spiral_cad.build123d import ContinuousRectangle, show_continuity  # noqa: E402
from spiral_cad.cad.faces import CLASS_COLOURS  # noqa: E402


@pytest.fixture(scope="module")
def viewer(tmp_path_factory):
    """A standalone OCP CAD Viewer on a free port, with a headless Chromium showing it."""
    for needed in ("ocp_vscode", "ocp_viewer"):
        if importlib.util.find_spec(needed) is None:
            pytest.skip(f'{needed} is not installed (pip install "spiral_cad[viewer,test]")')
    browser_command = chromium()
    folder = tmp_path_factory.mktemp("viewer")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    log = folder / "server.log"
    env = {**os.environ, "HOME": str(folder)}  # its settings file, not the user's
    with log.open("w") as output:
        server = subprocess.Popen(
            [sys.executable, "-m", "ocp_viewer", "--port", str(port)], stdout=output, stderr=subprocess.STDOUT, env=env
        )
        browser = None
        try:
            _wait(lambda: _listening(port), "the viewer's server to listen")
            browser = subprocess.Popen([browser_command, *CHROMIUM_FLAGS, "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                                        f"--user-data-dir={folder / 'profile'}", "--window-size=1200,800", f"http://127.0.0.1:{port}/viewer"],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
            _wait(lambda: "registered" in log.read_text(), "the browser to join the viewer")
            yield port, folder
        finally:
            for process in (browser, server):
                if process is not None:
                    process.terminate()
                    process.wait(timeout=30)


def _listening(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), 0.2).close()
        return True
    except OSError:
        return False


def _wait(ready, what: str, seconds: float = 60.0) -> None:
    end = time.monotonic() + seconds
    while not ready():
        if time.monotonic() > end:
            raise AssertionError(f"waited {seconds:.0f} s for {what}")
        time.sleep(0.2)


def _shown(part, port: int, path: Path) -> np.ndarray:
    from ocp_vscode import save_screenshot
    from PIL import Image

    report = show_continuity(part, port=port)
    time.sleep(1.0)  # the browser draws the model it was sent
    save_screenshot(str(path), port=port)
    _wait(path.is_file, "the viewer's screenshot")
    time.sleep(0.5)  # written whole
    drawn = Image.open(path).convert("RGBA")  # the background is transparent: seen on white
    return report, np.asarray(Image.alpha_composite(Image.new("RGBA", drawn.size, "white"), drawn).convert("RGB"), dtype=int)


def _pixels_of(picture: np.ndarray, colour: str, tolerance: int = 60) -> int:
    rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
    return int((np.abs(picture - rgb).sum(axis=2) < tolerance).sum())


def test_the_viewer_draws_g1_edges_orange_and_g2_ones_green_on_faces_coloured_by_curvature(viewer):
    port, folder = viewer
    g1_report, g1 = _shown(bd.fillet(bd.Box(60, 40, 10).edges().filter_by(bd.Axis.Z), 12), port, folder / "g1.png")
    g2_report, g2 = _shown(bd.extrude(ContinuousRectangle(60, 40, 12), 10), port, folder / "g2.png")
    assert {e.level for e in g1_report.edges} == {"G1", "sharp"} and {e.level for e in g2_report.edges} == {"G2", "sharp"}
    # the edges in their class's colour, and not in the other's
    assert _pixels_of(g1, CLASS_COLOURS["G1"]) > 20 and _pixels_of(g1, CLASS_COLOURS["G2"]) == 0
    assert _pixels_of(g2, CLASS_COLOURS["G2"]) > 20 and _pixels_of(g2, CLASS_COLOURS["G1"]) == 0
    # the convex fillets red, the flat faces near white
    for picture in (g1, g2):
        red = (picture[..., 0] > 150) & (picture[..., 1] < 90) & (picture[..., 2] < 110)
        assert red.mean() > 0.005
        grey = (picture.max(axis=2) - picture.min(axis=2) < 12) & (picture.min(axis=2) > 150)  # flat faces and background
        assert grey.mean() > 0.5
