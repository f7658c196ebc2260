"""Helpers the test modules share (not tests): chains of every transition kind, independent end frames
of cubics (float64 and mpmath), a helix path, file readers we did not write (OCCT's IGES names, the
OpenDRIVE tools environment), and the check of plain-number CSV tables."""

from __future__ import annotations

import http.server
import io
import json
import math
import multiprocessing
import multiprocessing.context
import os
import re
import shutil
import subprocess
import threading
from dataclasses import dataclass
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
from scipy.spatial import cKDTree

import spiral_cad as sc
from spiral_cad import Arc, Chain, Circle, Line, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from spiral_cad.core.space import PlaneFrame

REPO = Path(__file__).resolve().parents[1]
mp.mp.dps = 40  # the independent end frames are taken at 40 digits


def arc_on(circle: Circle, point, sweep: float, before: bool = False) -> Arc:
    """Arc of ``circle`` (in its travel sense) ending at (``before``) or starting at ``point``."""
    angle = math.atan2(point[1] - circle.center[1], point[0] - circle.center[0])
    if before:
        angle -= math.copysign(sweep, circle.radius)
    return Arc(circle.center, circle.radius, angle, sweep)


def around(transition, sweep: float = 0.6) -> Chain:
    """The transition with a piece of its given lines/circles before and after."""
    t = transition
    if t.start_circle is not None:
        first = arc_on(t.start_circle, t.start, sweep, before=True)
    else:
        d = t.start_tangent
        first = Line(t.start - 3.0 * d, t.start)
    if t.end_circle is not None:
        last = arc_on(t.end_circle, t.end, sweep)
    else:
        d = t.end_tangent
        last = Line(t.end, t.end + 3.0 * d)
    return Chain([first, *t.spirals, last])


def curve_road(units: str = "mm") -> Chain:
    """A line, a spiral, an arc of radius 40 turning 1 rad, a spiral and a line (every segment kind)."""
    centre, radius, turn = np.array([100.0, 40.5]), 40.0, 1.0
    enter = line_to_circle((0, 0), (1, 0), tuple(centre), radius)
    total = turn + 2.0 * abs(enter.spirals[0].theta)
    out = np.array([math.cos(total), math.sin(total)])
    exit_point = centre + 40.5 * np.array([math.sin(total), -math.cos(total)])
    leave = line_to_circle(tuple(exit_point), tuple(-out), tuple(centre), radius).reversed()
    return Chain.join([enter, leave], start=(-50.0, 0.0), end=tuple(leave.end + 60.0 * out), units=units)


def transition_chains() -> dict[str, Chain]:
    """One chain per transition kind plus a mixed chain with full-size arcs."""
    nested_distance = (3.0 - 1.2) * 0.9935
    mixed = Chain.join(
        [
            line_to_circle((0, 0), (1, 0), (40, 25), 15.0),
            circle_to_circle((40, 25), 15.0, (85, 30), -12.0),
            circle_to_circle((85, 30), -12.0, (120, 10), -9.0),
        ],
        start=(-80, 0),
    )
    return {
        "line-circle": around(line_to_circle((0, 0), (1, 0), (6, 4), 2.5)),
        "circle-line": around(line_to_circle((0, 0), (1, 1), (2, 7), 3.0).reversed()),
        "C": around(circle_to_circle((0, 0), 2.0, (7, 1), 1.5)),
        "S": around(circle_to_circle((0, 0), 2.0, (8, -1), -1.5)),
        "line-line": around(line_to_line((-10, 0), (0, 0), (6, 8))),
        "nested": around(circle_in_circle((0, 0), 3.0, (nested_distance, 0.0), 1.2), sweep=2.0),
        "mixed": mixed,
    }


def curvature_vector(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """Curvature vector κN from first and second derivatives (independent of the parametrisation)."""
    speed2 = float(d1 @ d1)
    return (d2 - (d2 @ d1) / speed2 * d1) / speed2


def assert_plain_csv(path: Path) -> None:
    """Every header carries a unit in brackets, every cell is a plain number (never a numpy repr),
    except the documented text columns."""
    import csv

    from spiral_cad.design.tables import TEXT_COLUMNS

    with path.open(newline="", encoding="utf-8") as handle:
        head, *rows = list(csv.reader(handle))
    assert rows
    for k, column in enumerate(head):
        if column in TEXT_COLUMNS:
            continue
        assert re.fullmatch(r"\S+ \[[^\]]+\]", column), (path.name, column)
        for row in rows:
            assert re.fullmatch(r"-?\d+(\.\d+)?(e[-+]\d+)?", row[k]), (path.name, column, row[k])
            float(row[k])


def bezier_end(cp, at_end):
    """Point, unit tangent and κN of a cubic Bézier at u = 0 or 1 (travel order)."""
    cp = np.asarray(cp, dtype=float)
    if at_end:
        p, d1, d2 = cp[3], 3 * (cp[3] - cp[2]), 6 * (cp[3] - 2 * cp[2] + cp[1])
    else:
        p, d1, d2 = cp[0], 3 * (cp[1] - cp[0]), 6 * (cp[2] - 2 * cp[1] + cp[0])
    speed2 = d1 @ d1
    return p, d1 / math.sqrt(speed2), np.cross(np.cross(d1, d2), d1) / speed2**2


def helix(count=9, radius=40.0, rise=9.0, step=0.9):
    t = np.arange(count) * step
    return np.stack([radius * np.cos(t), radius * np.sin(t), rise * t], axis=1)


def corner_pair(before, corner, after, shrink=2.0):
    """The spiral pair rounding one corner, solved in the corner's plane and placed in space.

    The pair uses at most half of each leg (the Corollary 4.5 pair on the half legs, its
    curvature raised by ``shrink`` so straight pieces remain between corners).
    """
    frame = PlaneFrame.of_corner(before, corner, after)
    p0, p1 = frame.local([(before + corner) / 2, (corner + after) / 2])
    largest = sc.line_to_line(p0, (0.0, 0.0), p1)
    kappa = abs(largest.spirals[0].end_curvature) * shrink
    pair = sc.line_to_line(p0, (0.0, 0.0), p1, curvature=kappa)
    return [s.placed(frame) for s in pair.spirals], frame


def helix_chain():
    pts = helix()
    pairs = [corner_pair(*pts[i - 1 : i + 2]) for i in range(1, len(pts) - 1)]
    segments, previous = [], pts[0]
    for spirals, _ in pairs:
        segments += [Line(previous, spirals[0].start), *spirals]
        previous = spirals[1].end
    segments.append(Line(previous, pts[-1]))
    return Chain(segments, units="mm"), pairs, pts


def iges_names(path) -> tuple[str, list[str]]:
    """(the global section's sender product id, the names of the free shapes) as OCCT's IGES readers see them."""
    from OCP.IGESCAFControl import IGESCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    from spiral_cad.cad.console import captured_messages

    with captured_messages():
        document = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
        reader = IGESCAFControl_Reader()
        reader.SetNameMode(True)
        reader.ReadFile(str(path))
        reader.Transfer(document)
    sender = reader.WS().Model().GlobalSection().SendName().ToCString()
    labels = TDF_LabelSequence()
    XCAFDoc_DocumentTool.ShapeTool_s(document.Main()).GetFreeShapes(labels)
    names = []
    for i in range(1, labels.Length() + 1):
        attribute = TDataStd_Name()
        if labels.Value(i).FindAttribute(TDataStd_Name.GetID_s(), attribute):
            names.append(attribute.Get().ToExtString())
    return sender, names


def linuxcnc_rs274(program: Path | str, output: Path | str, **options) -> subprocess.CompletedProcess:
    """LinuxCNC's rs274 run on ``program`` (its canonical calls in ``output``) as a user runs it, but in a home of its
    own beside ``output``: rs274 empties ``$HOME/.tool.mmap``, so runs sharing a home break each other."""
    from spiral_cad.io import rs274

    home = Path(output).parent / "rs274_home"
    home.mkdir(exist_ok=True)
    options = {"capture_output": True, "text": True, "stdin": subprocess.DEVNULL, "timeout": 120} | options
    return subprocess.run([rs274.rs274_executable(), "-g", str(program), str(output)],
                          env={**os.environ, "HOME": str(home)}, **options)  # fmt: skip


def tools_python() -> str:
    """The python of the OpenDRIVE tools environment that `make test` builds (numpy < 2: not ours)."""
    path = os.environ.get("SPIRAL_CAD_XODR_TOOLS") or str(REPO / ".venv-tools" / "bin" / "python")
    if not Path(path).exists():
        pytest.skip("the OpenDRIVE tools environment is missing: run `make test`")
    return path


def independent_check(path: Path) -> dict:
    done = subprocess.run([tools_python(), str(REPO / "tests" / "tools" / "xodr_check.py"), str(path)],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout)


def end_frame(cp, at_end=True):
    """Point, unit tangent (travel sense), signed curvature and end-leg length of a cubic at u = 1 (or 0), in mpmath."""
    p = [[mp.mpf(float(v)) for v in row] for row in cp]
    if not at_end:
        p = p[::-1]
    d1 = [3 * (p[3][k] - p[2][k]) for k in range(2)]
    d2 = [6 * (p[3][k] - 2 * p[2][k] + p[1][k]) for k in range(2)]
    speed = mp.sqrt(d1[0] ** 2 + d1[1] ** 2)
    kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / speed**3
    tangent = [d1[0] / speed, d1[1] / speed]
    if not at_end:  # read backwards: the tangent and the curvature change sign
        tangent, kappa = [-tangent[0], -tangent[1]], -kappa
    return p[3], tangent, kappa, speed / 3


def assert_on_circle(cp, center, radius, at_end, tol=1e-9):
    """The spiral end (or start) joins the circle (centre, signed travel-sense radius) G2, by the
    documented measures: gap / L, tangent angle, curvature error × L, L = min(end leg, |radius|)."""
    point, tangent, kappa, leg = end_frame(cp, at_end)
    r = mp.mpf(float(radius))
    length = min(leg, abs(r))
    radial = [(point[0] - center[0]) / r, (point[1] - center[1]) / r]
    distance = mp.sqrt(radial[0] ** 2 + radial[1] ** 2)
    assert abs(distance - 1) * abs(r) / length <= tol
    assert abs(tangent[0] * radial[0] + tangent[1] * radial[1]) / distance <= tol
    assert radial[0] * tangent[1] - radial[1] * tangent[0] > 0  # travels in the circle's sense
    assert abs(kappa - 1 / r) * length <= tol


def assert_meet_g2(cp_a, cp_b, size, tol=1e-9):
    pa, ta, ka, _ = end_frame(cp_a, True)
    pb, tb, kb, _ = end_frame(cp_b, False)
    assert mp.sqrt((pa[0] - pb[0]) ** 2 + (pa[1] - pb[1]) ** 2) <= tol * size
    assert abs(ta[0] * tb[1] - ta[1] * tb[0]) <= tol and ta[0] * tb[0] + ta[1] * tb[1] > 0
    assert abs(ka - kb) * size <= tol * max(1, abs(ka) * size)


#: A fenced code block's opening line in Markdown.
FENCE = re.compile(r"^(?P<indent> *)```(?P<info>[^`]*)$")


@dataclass(frozen=True)
class Block:
    """A fenced ``python`` block of a Markdown page."""

    first_line: int  # 1-based line of the block's first code line
    code: str
    skip_reason: str | None


def python_blocks(text: str, marker: str, name: str = "page") -> list[Block]:
    """The fenced ``python`` blocks of a Markdown text, with the reason of the skip marker that precedes
    each, if any (``<!-- MARKER: skip (reason) -->``, ``marker`` being ``readme`` or ``docs``)."""
    skip = re.compile(rf"<!-- {marker}: skip \((?P<reason>[^()]+)\) -->")
    lines = text.splitlines()
    blocks, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if opening is None:
            i += 1
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j].strip() == "```"), None)
        assert end is not None, f"{name}:{i + 1}: a code block is never closed"
        if opening["info"].strip() == "python":
            before = next((line for line in reversed(lines[:i]) if line.strip()), "")
            found = skip.fullmatch(before.strip())
            indent = len(opening["indent"])
            code = "\n".join(line[indent:] for line in lines[i + 1 : end]) + "\n"
            blocks.append(Block(i + 2, code, found["reason"] if found else None))
        i = end + 1
    return blocks


def _pages() -> multiprocessing.context.ForkServerContext:
    """Where pages run: processes forked from a server that imported spiral_cad, numpy and (where
    installed) build123d once and ran nothing else. Never forked from a test's process: once OCCT's
    thread pool has threads there (a boolean ran), a child forked from it that runs a boolean waits
    for threads it does not have, for ever."""
    global _PAGES
    if _PAGES is None:
        _PAGES = multiprocessing.get_context("forkserver")
        _PAGES.set_forkserver_preload(["numpy", "spiral_cad", "build123d"])  # one missing is skipped
    return _PAGES


_PAGES: multiprocessing.context.ForkServerContext | None = None


def _run_page(page: str, runnable: list[tuple[int, str]], cwd: str, argv: list[str] | None, err: str) -> None:
    """The page's own process: its blocks in one fresh ``__main__`` namespace; stderr into ``err``."""
    import sys

    status = 1
    try:
        os.chdir(cwd)
        sys.argv = argv or ["-c"]
        sys.path[0:0] = [str(Path(argv[0]).resolve().parent) if argv else cwd]  # as Python puts it first
        os.environ["MPLBACKEND"] = "Agg"
        if "matplotlib" in sys.modules:
            sys.modules["matplotlib"].use("Agg", force=True)
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
        os.dup2(os.open(err, os.O_WRONLY), 2)
        sys.stdout = io.TextIOWrapper(open(1, "wb", closefd=False), line_buffering=True)
        sys.stderr = io.TextIOWrapper(open(2, "wb", closefd=False), line_buffering=True)
        namespace = {"__name__": "__main__"}
        for first_line, code in runnable:
            exec(compile("\n" * (first_line - 1) + code, page, "exec"), namespace)
        status = 0
    except SystemExit as stop:  # as the interpreter would end
        status = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    except BaseException:  # noqa: BLE001 - the page's error, reported by the test
        import traceback

        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)


#: Runs blocks as one Python session (one namespace), each compiled at its own line of the page.
def run_blocks(page: Path, blocks: list[Block], cwd: Path, timeout: float, argv: list[str] | None = None) -> None:
    """Run a page's blocks that are not marked skip, top to bottom in one fresh Python process in
    ``cwd`` with a fresh ``__main__`` namespace; fail the test with the process's stderr. With ``argv``
    the page is a script run as ``python *argv`` (its folder first on the path), else as ``python -c``.

    The process is forked from a server that imported spiral_cad, numpy and build123d once
    (``_pages``), so a page does not pay for importing them again (about 3 s a page); what it
    defines, changes or breaks stays in its own process."""
    import tempfile

    runnable = [(b.first_line, b.code) for b in blocks if b.skip_reason is None]
    with tempfile.NamedTemporaryFile() as err:
        process = _pages().Process(target=_run_page, args=(str(page), runnable, str(cwd), argv, err.name))
        process.start()
        process.join(timeout)
        if process.is_alive():
            process.kill()
            process.join()
            pytest.fail(f"{page}: still running after {timeout:g} s", pytrace=False)
        if process.exitcode != 0:
            err.seek(0)
            text = err.read().decode("utf-8", "replace")
            pytest.fail((text[-4000:] or f"{page}: exit status {process.exitcode}"), pytrace=False)


def unresolved(dotted: str) -> str | None:
    """Why a dotted name the prose gives (``spiral_cad.design.fillet_path``) does not import as written,
    or None: the longest importable module, then attributes."""
    import importlib

    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:split]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[split:]:
            if not hasattr(found, attribute):
                return f"{dotted}: {'.'.join(parts[:split])} has no {attribute}"
            found = getattr(found, attribute)
        return None
    return f"{dotted}: no such module"


#: LinuxCNC's own Python, with its interpreter library (`gcode`) and `rs274` package (Debian's linuxcnc-uspace).
LINUXCNC_PYTHON = "/usr/bin/python3"


def linuxcnc_preview(program: Path, units: str) -> list[tuple[str, int, np.ndarray]]:
    """The moves of ``program`` as LinuxCNC's interpreter library executes them (tests/tools/linuxcnc_preview.py):
    (kind, line, point) with G5 splines and arcs as points on the curves; skips where LinuxCNC is not installed."""
    probe = subprocess.run([LINUXCNC_PYTHON, "-c", "import gcode, rs274.interpret"], capture_output=True) if Path(
        LINUXCNC_PYTHON).exists() else None  # fmt: skip
    if probe is None or probe.returncode != 0:
        pytest.skip(
            "LinuxCNC's interpreter library (the `gcode` module of the Debian package linuxcnc-uspace, "
            "which `make test` installs where it can) is not installed for /usr/bin/python3"
        )
    done = subprocess.run([LINUXCNC_PYTHON, str(REPO / "tests" / "tools" / "linuxcnc_preview.py"), str(program), units],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return [(kind, line, np.array(point)) for kind, line, *point in json.loads(done.stdout)["moves"]]


def distance_to_chain(chain: Chain, points: np.ndarray, spacing: float) -> np.ndarray:
    """The distance of every point from ``chain`` (an independent measure: the nearest point of the
    polyline through the chain's points ``spacing`` apart along it, then the foot of the perpendicular
    on the chain from there, found by iterating the projection on the tangent)."""
    s = np.linspace(0.0, chain.length, max(2, math.ceil(chain.length / spacing) + 1))
    polyline = chain.point_at(s)
    points = np.asarray(points, dtype=float)[:, : polyline.shape[1]]
    a, d = polyline[:-1], np.diff(polyline, axis=0)
    length2 = np.einsum("ij,ij->i", d, d)
    # only segments with an end within (nearest vertex + longest segment) of a point can hold its nearest point
    tree = cKDTree(polyline)
    reach = tree.query(points)[0] + math.sqrt(float(length2.max()))
    near = tree.query_ball_point(points, reach)
    vertex = np.concatenate([np.asarray(v, dtype=int) for v in near])
    owner = np.repeat(np.arange(len(points)), [len(v) for v in near])
    segment, owner = np.clip(np.concatenate([vertex, vertex - 1]), 0, len(a) - 1), np.concatenate([owner, owner])
    offset = points[owner] - a[segment]
    t = np.clip(np.einsum("ij,ij->i", offset, d[segment]) / length2[segment], 0.0, 1.0)
    foot = offset - t[:, None] * d[segment]
    gaps = np.einsum("ij,ij->i", foot, foot)
    order = np.lexsort((gaps, owner))
    best = order[np.searchsorted(owner[order], np.arange(len(points)))]  # each point's least gap
    k = segment[best]
    nearest, station = np.sqrt(gaps[best]), s[k] + t[best] * (s[k + 1] - s[k])
    moving = np.arange(len(points))
    for _ in range(8):  # then the foot of the perpendicular on the chain itself: s ← s + (p − C(s))·T(s)
        at = station[moving]
        step = np.einsum("ij,ij->i", points[moving] - chain.point_at(at), chain.tangent_at(at))
        station[moving] = np.clip(at + step, 0.0, chain.length)
        moving = moving[np.abs(station[moving] - at) > 1e-13 * chain.length]  # settled ones stay
        if not len(moving):
            break
    out = np.minimum(nearest, np.linalg.norm(points - chain.point_at(station), axis=1))
    return out


def freecad_lib() -> str | None:
    """The directory holding FreeCAD's Python modules (FreeCAD.so, Import.so), if FreeCAD is installed
    (they are built for the system Python: run them with /usr/bin/python3 in a child process)."""
    candidates = [os.environ.get("SPIRAL_CAD_FREECAD_LIB", ""), "/usr/lib/freecad-python3/lib", "/usr/lib/freecad/lib",
                  "/usr/local/lib/freecad/lib"]  # fmt: skip
    return next((c for c in candidates if c and (Path(c) / "Import.so").exists()), None)


# --- a browser we did not write: headless Chromium, and a local server that logs every request ---------

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def chromium() -> str:
    """The headless browser's command, or the test is skipped saying how to install it."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if found := shutil.which(name):
            return found
    pytest.skip("headless Chromium is not installed (Debian: apt-get install chromium)")


class Server(http.server.ThreadingHTTPServer):
    """A local server of one folder: ``requests`` every path asked for, ``failed`` those not served."""

    requests: list[str]
    failed: list[str]


def serve(root: Path) -> Server:
    """Serve ``root`` on a free local port until ``shutdown()``."""

    class Handler(http.server.SimpleHTTPRequestHandler):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, directory=str(root), **kwargs)

        def log_request(self, code="-", size="-"):
            self.server.requests.append(self.path)
            if str(code) not in ("200", "304"):
                self.server.failed.append(f"{code} {self.path}")

        def log_message(self, *args):
            pass

    server = Server(("127.0.0.1", 0), Handler)
    server.requests, server.failed = [], []
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server
