"""A judge of programs made G2 in place, by LinuxCNC's own interpreter ``rs274`` (shares no code with spiral_cad).

``judge(input_text, output_text, bound)`` runs both programs through ``rs274 -g`` and compares what a
machine would do: the rapid moves (same, in the same order, as rs274 prints them), the tool, spindle,
coolant, dwell, stop and probe calls (same, in order), the feed rates of the feed moves (the output's
among the input's), and the cutting path (every feed move, sampled): every sample of each within
``bound`` of the other's path (plus the sampling step and rs274's printing, ``PRINTED``). rs274 prints no control points for a ``G5``
cubic (``NURBS_FEED(4, ...)``), so a ``G5`` is sampled from the program's own words (each line is given
its line number as N word, which rs274 prints with each call; absolute ``G90`` and ``G17`` assumed).
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

CALL = re.compile(r"\s*\d+\s+N([0-9]*)\.*\s*([A-Z_0-9]+)\((.*)\)\s*$")
WORD = re.compile(r"([A-Za-z])\s*([+-]?\s*(?:\d+\.?\d*|\.\d+))")
#: The calls a machinist checks: they must be the same, in the same order.
MACHINE = {"CHANGE_TOOL", "SELECT_TOOL", "CHANGE_TOOL_NUMBER", "START_SPINDLE_CLOCKWISE", "START_SPINDLE_COUNTERCLOCKWISE",
           "STOP_SPINDLE_TURNING", "SET_SPINDLE_SPEED", "FLOOD_ON", "FLOOD_OFF", "MIST_ON", "MIST_OFF", "DWELL",
           "PROGRAM_STOP", "OPTIONAL_PROGRAM_STOP", "PROGRAM_END", "PALLET_SHUTTLE", "STRAIGHT_PROBE", "USE_TOOL_LENGTH_OFFSET",
           "SET_G5X_OFFSET", "SET_G92_OFFSET", "MESSAGE", "USE_LENGTH_UNITS", "RIGID_TAP"}  # fmt: skip
#: What rs274's printing (4 decimals in the program's unit: 0.1 µm in mm, 2.5 µm in inch) may put between two points
#: of the same place, one printed from each program: each rounded by half a unit in up to 3 coordinates.
PRINTED = 2.0 * math.sqrt(3.0) * 0.5e-4
#: Runs of rs274 at most when it dies by a signal saying nothing (as spiral_cad.io.rs274 does).
SIGNAL_RUNS = 5
PLANE_AXES = {"CANON_PLANE_XY": (0, 1, 2), "CANON_PLANE_XZ": (2, 0, 1), "CANON_PLANE_YZ": (1, 2, 0)}


def available() -> bool:
    return shutil.which("rs274") is not None


@dataclass
class Run:
    """What rs274 did with a program."""

    rapids: list[str] = field(default_factory=list)
    calls: list[str] = field(default_factory=list)
    feeds: set[float] = field(default_factory=set)
    samples: list[np.ndarray] = field(default_factory=list)  # (k, 3) points of each feed move, start included
    feed_moves: int = 0


#: A line's own N word.
LABEL = re.compile(r"^[Nn]\s*\d+\s*")


def numbered(text: str) -> tuple[str, list[str]]:
    lines = text.replace("\r\n", "\n").split("\n")
    out = []
    for k, line in enumerate(lines, 1):
        head = line.lstrip(" \t/")
        if not head or head[0] in "%Oo":
            out.append(line)
        else:  # a line's own N word (a label the interpreter ignores) is replaced: rs274 prints the N number
            slash = line[: len(line) - len(head)]
            out.append(f"{slash}N{k} {LABEL.sub('', head)}")
    return "\n".join(out), lines


def run(text: str, step: float, folder: str | None = None) -> Run:
    """rs274's calls of ``text`` read back; feed moves sampled at most ``step`` apart.

    Raises:
        RuntimeError: rs274 refused the program (its message).
    """
    program, lines = numbered(text)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "p.ngc")
        with open(path, "w") as f:
            f.write(program)
        for _ in range(SIGNAL_RUNS):  # LinuxCNC's rs274 now and then dies by a signal saying nothing: run it again
            done = subprocess.run(["rs274", "-g", path, os.path.join(tmp, "out")], cwd=folder or tmp, capture_output=True, text=True,
                                  stdin=subprocess.DEVNULL, timeout=600)  # fmt: skip
            # (a parameter file it cannot update is said on stderr, and is no refusal of the program)
            said = [m for m in done.stderr.splitlines() if m.strip() and m.strip() != "executing" and "variable file" not in m]
            if not (done.returncode < 0 and not said):
                break
        if done.returncode or said:
            raise RuntimeError(f"rs274 refused it: {' / '.join(said[:2]) or f'exit status {done.returncode}'}")
        with open(os.path.join(tmp, "out")) as f:
            calls = f.read().splitlines()
    result = Run()
    position = np.zeros(3)
    plane = PLANE_AXES["CANON_PLANE_XY"]
    feed = math.nan
    written: dict[str, float] = {}  # the X, Y, Z words last written on a move's line (G90 assumed), to the digit
    for raw in calls:
        m = CALL.match(raw)
        if not m:
            continue
        number, name, args = m.group(1), m.group(2), m.group(3)
        before = dict(written)
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED") and number:
            code = re.sub(r"\([^)]*\)|;.*", "", lines[int(number) - 1])
            written.update({k.upper(): float(x.replace(" ", "")) for k, x in WORD.findall(code) if k.upper() in "XYZ"})
        if name == "STRAIGHT_TRAVERSE":
            result.rapids.append(args)
            position = np.array([float(v) for v in args.split(",")[:3]])
        elif name == "STRAIGHT_FEED":
            end = np.array([float(v) for v in args.split(",")[:3]])
            if not np.array_equal(end, position):
                n = max(1, math.ceil(np.linalg.norm(end - position) / step))
                result.samples.append(position + np.linspace(0, 1, n + 1)[:, None] * (end - position))
                result.feeds.add(feed)
                result.feed_moves += 1
            position = end
        elif name == "ARC_FEED":
            v = [float(x) for x in args.split(",")]
            first, second, normal = plane
            end = np.zeros(3)
            end[first], end[second], end[normal] = v[0], v[1], v[5]
            cx, cy, rotation = v[2], v[3], int(v[4])
            a0 = math.atan2(position[second] - cy, position[first] - cx)
            a1 = math.atan2(end[second] - cy, end[first] - cx)
            sweep = a1 - a0
            names = "XYZ"[first] + "XYZ"[second]
            if (abs(rotation) == 1 and np.abs(end[[first, second]] - position[[first, second]]).max() <= 1.5e-4
                    and all(k in before and k in written for k in names)
                    and max(abs(written[k] - before[k]) for k in names) > 1e-12):  # fmt: skip
                # printed ends equal to rs274's 4 decimals, written ends not: the sweep from the written ends (an arc shorter
                # than the printing, or a turn short of a full one by less than it)
                w0 = math.atan2(before[names[1]] - cy, before[names[0]] - cx)
                w1 = math.atan2(written[names[1]] - cy, written[names[0]] - cx)
                sweep = (w1 - w0) % (2 * math.pi) if rotation > 0 else -((w0 - w1) % (2 * math.pi))
            elif rotation > 0:
                sweep = (sweep if sweep > 0 else sweep + 2 * math.pi) + 2 * math.pi * (rotation - 1)
            else:
                sweep = (sweep if sweep < 0 else sweep - 2 * math.pi) - 2 * math.pi * (-rotation - 1)
            r0 = math.hypot(position[first] - cx, position[second] - cy)
            r1 = math.hypot(end[first] - cx, end[second] - cy)
            n = max(2, math.ceil(abs(sweep) * max(r0, r1) / step), math.ceil(abs(end[normal] - position[normal]) / step))
            t = np.linspace(0, 1, n + 1)
            r = r0 + (r1 - r0) * t
            pts = np.zeros((n + 1, 3))
            pts[:, first] = cx + r * np.cos(a0 + sweep * t)
            pts[:, second] = cy + r * np.sin(a0 + sweep * t)
            pts[:, normal] = position[normal] + (end[normal] - position[normal]) * t
            result.samples.append(pts)
            result.feeds.add(feed)
            result.feed_moves += 1
            position = end
        elif name == "NURBS_FEED" and re.search(r"[Gg]\s*0*5\s*\.\s*3", lines[int(number) - 1]):  # G5.2 … G5.3
            pts = nurbs_samples(lines, int(number) - 1, position, plane, step)
            result.samples.append(pts)
            result.feeds.add(feed)
            result.feed_moves += 1
            position = pts[-1].copy()
        elif name == "NURBS_FEED":  # a G5 cubic: from the program's words
            words = {k.upper(): float(x.replace(" ", "")) for k, x in WORD.findall(re.sub(r"\([^)]*\)|;.*", "", lines[int(number) - 1]))}
            end = position.copy()
            end[0], end[1] = words.get("X", position[0]), words.get("Y", position[1])
            p1 = position + np.array([words["I"], words["J"], 0.0])
            p2 = end + np.array([words["P"], words["Q"], 0.0])
            size = np.linalg.norm(p1 - position) + np.linalg.norm(p2 - p1) + np.linalg.norm(end - p2)
            t = np.linspace(0, 1, max(2, math.ceil(size / step)) + 1)[:, None]
            pts = (1 - t) ** 3 * position + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t**2 * p2 + t**3 * end
            result.samples.append(pts)
            result.feeds.add(feed)
            result.feed_moves += 1
            position = end
        elif name == "SET_FEED_RATE":
            feed = float(args)
        elif name == "SELECT_PLANE":
            plane = PLANE_AXES[args.strip()]
        elif name in MACHINE:
            result.calls.append(f"{name}({args})")
    return result


def nurbs_samples(lines: list[str], end_line: int, position: np.ndarray, plane: tuple[int, int, int], step: float) -> np.ndarray:
    """Points of a LinuxCNC G5.2 … G5.3 NURBS ending on line ``end_line`` (0-based), from the program's words.

    LinuxCNC's definition (``interp_convert.cc``, ``nurbs_additional_functions.cc``): the first control point is
    where the tool stands (weight P of the G5.2 line when it names no point, else 1); every line naming both plane
    axes adds a point with weight P; order L when above 3, else 3; knots 0 (k times), 1 … n − k + 1, n − k + 2 (k times).
    """
    first, second, normal = plane
    names = "XYZ"
    start = end_line
    while not re.search(r"[Gg]\s*0*5\s*\.\s*2", re.sub(r"\([^)]*\)|;.*", "", lines[start])):
        start -= 1
    cps, weights, order = [[position[first], position[second]]], [1.0], 3
    for k in range(start, end_line):
        words = {a.upper(): float(x.replace(" ", "")) for a, x in WORD.findall(re.sub(r"\([^)]*\)|;.*", "", lines[k]))}
        if k == start:
            if words.get("L", 0) > 3:
                order = int(words["L"])
            if not (names[first] in words and names[second] in words) and words.get("P", 0) > 0:
                weights[0] = words["P"]
        if names[first] in words and names[second] in words:
            cps.append([words[names[first]], words[names[second]]])
            weights.append(words.get("P", 1.0))
    p, w, kk = np.array(cps), np.array(weights), order
    n = len(p) - 1
    knots = np.array([0.0] * kk + list(range(1, n - kk + 2)) + [n - kk + 2.0] * kk)
    size = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    u = np.linspace(0.0, knots[-1], max(2, math.ceil(size / step) * 4) + 1)
    basis = np.zeros((len(u), len(knots) - 1))
    for i in range(len(knots) - 1):  # order 1: half-open spans, the last one closed
        last = knots[i + 1] == knots[-1] and knots[i] < knots[i + 1]
        basis[:, i] = (u >= knots[i]) & ((u < knots[i + 1]) | (last & (u == knots[i + 1])))
    for order_now in range(2, kk + 1):  # Cox–de Boor
        nxt = np.zeros((len(u), len(knots) - order_now))
        for i in range(len(knots) - order_now):
            d0, d1 = knots[i + order_now - 1] - knots[i], knots[i + order_now] - knots[i + 1]
            a = (u - knots[i]) / d0 * basis[:, i] if d0 > 0 else 0.0
            b = (knots[i + order_now] - u) / d1 * basis[:, i + 1] if d1 > 0 else 0.0
            nxt[:, i] = a + b
        basis = nxt
    weighted = basis * w
    xy = (weighted @ p) / weighted.sum(axis=1, keepdims=True)
    out = np.repeat(position[None], len(u), axis=0).astype(float)
    out[:, first], out[:, second] = xy[:, 0], xy[:, 1]
    return out


@dataclass
class Verdict:
    passed: bool
    reasons: list[str]
    distance: float  # the larger of the two ways (program unit)
    feed_moves: tuple[int, int]


def judge(input_text: str, output_text: str, bound: float, folder: str | None = None) -> Verdict:
    """Whether ``output_text`` does what ``input_text`` does, its cutting path within ``bound`` of the input's."""
    step = bound / 20.0
    a, b = run(input_text, step, folder), run(output_text, step, folder)
    reasons = []
    if a.rapids != b.rapids:
        k = next((i for i, (x, y) in enumerate(zip(a.rapids, b.rapids)) if x != y), min(len(a.rapids), len(b.rapids)))
        reasons.append(f"rapids differ ({len(a.rapids)} in, {len(b.rapids)} out; first at rapid {k})")
    if a.calls != b.calls:
        reasons.append("machine calls differ")
    extra = b.feeds - a.feeds
    if extra:
        reasons.append(f"feeds the input does not use: {sorted(extra)}")
    distance = 0.0
    if a.samples and b.samples:
        pa, pb = np.concatenate(a.samples), np.concatenate(b.samples)
        far = 4.0 * bound  # nearer than this is measured; farther is reported as infinite (a fast query)
        distance = max(float(cKDTree(pb).query(pa, distance_upper_bound=far)[0].max()),
                       float(cKDTree(pa).query(pb, distance_upper_bound=far)[0].max()))  # fmt: skip
        if distance > bound + step + PRINTED:
            reasons.append(f"cutting paths {distance:.4g} apart, beyond {bound:g}")
    elif bool(a.samples) != bool(b.samples):
        reasons.append("one program cuts, the other does not")
    return Verdict(not reasons, reasons, distance, (a.feed_moves, b.feed_moves))
