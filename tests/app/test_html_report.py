"""The continuity report as a web page (``spiral_cad.app.html_report``): what it holds, what it refuses, and
how it looks in a browser we did not write (headless Chromium, software WebGL)."""

from __future__ import annotations

import base64
import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from helpers import CHROMIUM_FLAGS, chromium, serve

bd = pytest.importorskip("build123d")
pytestmark = pytest.mark.cad

import spiral_cad as sc  # noqa: E402
from spiral_cad.app.html_report import COLOURS, write_html_report  # noqa: E402
from spiral_cad.build123d import ContinuousRectangle  # noqa: E402
from spiral_cad.cad.faces import check_faces  # noqa: E402


def _g1_part():
    return bd.fillet(bd.Box(60, 40, 10).edges().filter_by(bd.Axis.Z), 12)


def _g2_part():
    return bd.extrude(ContinuousRectangle(60, 40, 12), 10)


def _data(page: str) -> dict:
    found = re.search(r'<script type="application/json" id="spiral-data">(.*?)</script>', page, re.S)
    assert found is not None
    return json.loads(found.group(1).replace("<\\/", "</"))


def test_the_page_holds_every_edge_and_its_verdict_and_fetches_nothing(tmp_path):
    page_path = tmp_path / "g1.html"
    report = sc.check(_g1_part(), html=page_path)
    page = page_path.read_text(encoding="utf-8")
    data = _data(page)
    assert len(data["items"]) == len(report.edges)
    assert sorted(item["level"] for item in data["items"]) == sorted(e.level for e in report.edges)
    assert {item["level"] for item in data["items"]} == {"G1", "sharp"}
    # every judged edge is drawn as its own polyline; the G1 edge's passes through its worst point
    points = np.frombuffer(base64.b64decode(data["lines"]["points"]), dtype=np.float32).reshape(-1, 3)
    starts = data["lines"]["starts"]
    for k, item in enumerate(data["items"]):
        assert starts[item["line"] + 1] - starts[item["line"]] >= 2 and data["lines"]["items"][item["line"]] == k
    worst = next(e for e in report.edges if e.level == "G1")
    item = next(i for i in data["items"] if i["label"] == f"edge {worst.index}")
    line = points[starts[item["line"]] : starts[item["line"] + 1]]
    centre = np.array(tuple(_g1_part().bounding_box().center()))  # the page's points are relative to it
    assert np.linalg.norm(line - (np.array(worst.angle_at) - centre), axis=1).min() < 1e-3 * report.size
    assert "G1" in page and "edge" in page and report.describe() in page
    # self-contained: no address the browser would fetch
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//)""", page), "the page fetches something"
    assert "<script src" not in page


def test_refusals_name_the_value(tmp_path):
    part = _g1_part()
    judged = check_faces(part)
    with pytest.raises(ValueError, match=r"give a \.html file"):
        write_html_report(judged, part, tmp_path / "out.png")
    with pytest.raises(ValueError, match="no folder"):
        write_html_report(judged, part, tmp_path / "missing" / "out.html")
    with pytest.raises(ValueError, match="is a folder"):
        (tmp_path / "folder.html").mkdir()
        write_html_report(judged, part, tmp_path / "folder.html")
    with pytest.raises(ValueError, match="stripes"):
        write_html_report(judged, part, tmp_path / "out.html", stripes=0)
    with pytest.raises(ValueError, match="judged on its own numbers"):  # refused before the file is read
        sc.check(tmp_path / "road.xml", html=tmp_path / "road.html")
    with pytest.raises(ValueError, match=r"give a \.html file"):  # refused before the part is judged
        sc.check(tmp_path / "missing.step", html=tmp_path / "out.txt")
    assert [p.name for p in tmp_path.glob("*.html")] == ["folder.html"]


def test_check_writes_the_page_of_a_step_file(tmp_path, capsys):
    from spiral_cad.app.cli import main

    step = tmp_path / "g1.step"
    bd.export_step(_g1_part(), str(step))
    assert main(["check", str(step), "--html", str(tmp_path / "g1.html"), "--stripes", "30", "--quiet"]) == 0
    assert "web page written to" in capsys.readouterr().out
    data = _data((tmp_path / "g1.html").read_text(encoding="utf-8"))
    assert data["stripes"] == 30 and data["units"] == "mm"
    assert sum(item["level"] == "G1" for item in data["items"]) == 8
    assert main(["check", str(tmp_path / "road.xml"), "--html", str(tmp_path / "d.html")]) == 2
    assert "the page draws STEP/IGES parts and curves" in capsys.readouterr().err
    assert main(["check", str(step), "--pixels", "300", "--html", str(tmp_path / "p.html")]) == 2
    assert "--pixels: only with --zebra or --curvature-map" in capsys.readouterr().err


def test_names_links_and_tiny_parts_cannot_break_the_page(tmp_path):
    """What a hostile tester found: a name holding "<!--<script>" kept the viewer from running; a link named as
    the page wrote over the checked file; a part of 1e-4 mm could not be meshed; a helix was drawn as a line."""
    part = _g1_part()
    sc.check(part, html=tmp_path / "named.html", label="b<!--<script>x</script>")
    page = (tmp_path / "named.html").read_text(encoding="utf-8")
    assert page.count("</script>") == 2 and "<!--" not in page.split('id="spiral-data">')[1]
    assert _data(page)["title"] == "b<!--<script>x</script>"
    step = tmp_path / "victim.step"
    bd.export_step(part, str(step))
    before = step.read_bytes()
    (tmp_path / "link.html").symlink_to(step)
    with pytest.raises(ValueError, match="is the file being checked"):
        sc.check(step, html=tmp_path / "link.html")
    assert step.read_bytes() == before
    with pytest.raises(ValueError, match="judged on its own numbers"):  # a LandXML file by format=, before it is read
        sc.check(tmp_path / "road.txt", format="landxml", html=tmp_path / "road.html")
    tiny = bd.fillet(bd.Box(1e-4, 1e-4, 1e-4).edges().filter_by(bd.Axis.Z), 2e-5)
    assert sc.check(tiny, html=tmp_path / "tiny.html").faces == 10
    coil = bd.Wire(bd.Helix(10, 40, 5).edges())
    sc.check(coil, html=tmp_path / "coil.html")
    data = _data((tmp_path / "coil.html").read_text(encoding="utf-8"))
    points = np.frombuffer(base64.b64decode(data["lines"]["points"]), dtype=np.float32).reshape(-1, 3)
    helix = points[: data["lines"]["starts"][1]]
    assert np.ptp(helix[:, 0]) > 9.9 and np.ptp(helix[:, 1]) > 9.9  # its turns, not the chord between its ends


def test_a_long_program_keeps_its_page_small(tmp_path, monkeypatch):
    """Beyond ``LISTED`` G2 joints only those below G2 are points to click, and the comb has at most
    ``COMB_TEETH`` teeth: LinuxCNC's 169 000-line stellabee1.ngc had made a 298 MB page."""
    import spiral_cad.app.html_report as page_module

    monkeypatch.setattr(page_module, "LISTED", 40)
    monkeypatch.setattr(page_module, "COMB_TEETH", 300)
    arcs = [f"G3 X{10 * np.cos(a):.6f} Y{10 * np.sin(a):.6f} I{-10 * np.cos(b):.6f} J{-10 * np.sin(b):.6f}"
            for b, a in zip(np.linspace(0, np.pi, 121)[:-1], np.linspace(0, np.pi, 121)[1:])]  # fmt: skip
    program = tmp_path / "arcs.ngc"
    program.write_text("G21 G17 G90\nG0 X10 Y0 Z0\nG1 Z-1 F100\n" + "\n".join(arcs) + "\nG1 X-20 Y-5\nG0 Z5\nM2\n", encoding="ascii")
    report = sc.check(program, html=tmp_path / "arcs.html", angle_tol=1e-4, curvature_tol=1e-3)  # what 6 decimals resolve
    joints = [j for w in report.wires for j in w.joints]
    below = [j for j in joints if str(j.level) != "G2"]
    assert len(joints) > 100 and 1 <= len(below) < 40
    text = (tmp_path / "arcs.html").read_text(encoding="utf-8")
    data = _data(text)
    assert len(data["items"]) == 40 and {"G2"} < {i["level"] for i in data["items"]}
    assert f"{len(joints) - 40} of its G2 joints are not drawn as points" in text
    comb = [k for k, kind in enumerate(data["lines"]["kinds"]) if kind == "comb"]
    assert 0 < len(comb) <= 2 * 300 + 2 * len(joints)  # teeth (2 a joint-spaced edge at least) and envelopes


def test_a_drawings_page_holds_every_joint_where_it_is(tmp_path):
    drawing = Path(__file__).resolve().parents[2] / "examples" / "plate.dxf"
    report = sc.check(drawing, html=tmp_path / "plate.html")
    data = _data((tmp_path / "plate.html").read_text(encoding="utf-8"))
    joints = [j for w in report.wires for j in w.joints]
    assert len(data["items"]) == len(joints) > 0
    assert sorted(i["level"] for i in data["items"]) == sorted(str(j.level) for j in joints)
    assert data["mesh"] is None and data["view"] == [0.0, 0.0, 1.0]  # a drawing, seen from above
    assert set(data["lines"]["kinds"]) == {"curve", "comb"}
    # each joint's marker lies on the drawing's curves (the page's points are relative to the drawing's centre)
    points = np.frombuffer(base64.b64decode(data["lines"]["points"]), dtype=np.float32).reshape(-1, 3)
    curves = points[: data["lines"]["starts"][data["lines"]["kinds"].index("comb")]]
    markers = np.frombuffer(base64.b64decode(data["markers"]["points"]), dtype=np.float32).reshape(-1, 3)
    assert len(markers) == len(joints)
    for marker in markers:
        assert np.linalg.norm(curves - marker, axis=1).min() < 1e-3 * report.size
    edge = sc.check(bd.Box(10, 10, 10).edges()[0], html=tmp_path / "edge.html")  # one curve, no joint: a page all the same
    assert _data((tmp_path / "edge.html").read_text(encoding="utf-8"))["items"] == [] and edge.pieces == 1


def _shot(url: str, out: Path, tmp_path: Path) -> str:
    """A screenshot of ``url`` (software WebGL) and the console lines the page logged."""
    done = subprocess.run(
        [chromium(), *CHROMIUM_FLAGS, "--use-angle=swiftshader", "--enable-unsafe-swiftshader", f"--user-data-dir={tmp_path / 'profile'}",
         "--enable-logging=stderr", "--v=0", "--virtual-time-budget=8000", "--window-size=1000,800", f"--screenshot={out}", url],
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert done.returncode == 0 and out.is_file(), done.stderr[-3000:]
    return "\n".join(line for line in done.stderr.splitlines() if "CONSOLE" in line)


def _dom(url: str, tmp_path: Path) -> str:
    done = subprocess.run(
        [chromium(), *CHROMIUM_FLAGS, "--use-angle=swiftshader", "--enable-unsafe-swiftshader", f"--user-data-dir={tmp_path / 'profile'}",
         "--virtual-time-budget=8000", "--dump-dom", url],
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


def _pixels(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=float)


@pytest.mark.slow
@pytest.mark.subprocess
def test_the_page_draws_in_a_browser_and_an_edge_click_shows_its_numbers(tmp_path):
    """Headless Chromium with software WebGL: no console error, nothing requested but the page, a picture
    of the part (not blank) that differs between the zebra and the curvature modes, and the G1 edge that
    the address names shown with its numbers."""
    report = sc.check(_g1_part(), html=tmp_path / "g1.html")
    g1 = next(e for e in report.edges if e.level == "G1")
    drawing = sc.check(Path(__file__).resolve().parents[2] / "examples" / "plate.dxf", html=tmp_path / "plate.html")
    server = serve(tmp_path)
    try:
        root = f"http://127.0.0.1:{server.server_address[1]}"
        consoles = [_shot(f"{root}/g1.html#mode={mode}", tmp_path / f"{mode}.png", tmp_path) for mode in ("zebra", "curvature")]
        consoles.append(_shot(f"{root}/plate.html", tmp_path / "plate.png", tmp_path))
        dom = _dom(f"{root}/g1.html#edge={g1.index}", tmp_path)
        consoles.append(_shot(f"{root}/g1.html#item=%&edge=%E0%A4%A", tmp_path / "bad.png", tmp_path))  # a malformed hash
        drawing_dom = _dom(f"{root}/plate.html#item=0", tmp_path)
    finally:
        server.shutdown()
    for console in consoles:
        assert not re.search(r"error|uncaught|warning", console, re.I), console
    assert server.failed == [] and set(server.requests) == {"/g1.html", "/plate.html"}, server.requests
    assert _pixels(tmp_path / "plate.png")[200:700, 50:650].std() > 10.0  # the drawing's curves and comb
    worst = min((j for w in drawing.wires for j in w.joints), key=lambda j: (int(j.level), -j.relative_curvature_jump))
    assert f": {worst.level}</h2>" in drawing_dom and "angle between the tangents" in drawing_dom
    zebra, curvature = (_pixels(tmp_path / f"{mode}.png") for mode in ("zebra", "curvature"))
    canvas = (slice(200, 700), slice(50, 650))  # the drawing area, left of the panel
    for picture in (zebra, curvature):
        assert picture[canvas].std() > 20.0  # the part is drawn, not a blank canvas
    assert np.abs(zebra[canvas] - curvature[canvas]).mean() > 10.0
    # zebra: black and white bands; curvature: the fillets red (convex)
    assert (zebra[canvas].max(axis=2) < 40).mean() > 0.02
    red = (curvature[..., 0] > 140) & (curvature[..., 1] < 60) & (curvature[..., 2] < 80)
    assert red[canvas].mean() > 0.01
    assert 'data-ready="yes"' in dom
    panel = re.search(r'<div id="item">(.*?)</div>', dom, re.S)
    assert panel is not None and f"edge {g1.index}: G1" in panel.group(1)
    assert "angle between the normals" in panel.group(1) and f"{g1.jump:.3g}" in panel.group(1)
    assert COLOURS["G1"] in dom
