"""Large G-code programs: reading, and rounding as a Chain (``round_toolpath``) or as arrays.

Run: ``.venv/bin/python benchmarks/bench_gcode.py [--quick] [--sizes N ...] [--chain-max N] [--write-max N] [--build-max N] [--out FILE]``
(the harness and its conventions: ``timing.py``). Each size is a generated pocketing
program (a zigzag of G1 moves with jittered ends, layer after layer, 4 decimals in mm),
written to a file; after a warm-up on 50 moves (the kernels compile), every job runs in a child process of its own, so its peak memory
(the child's maximum resident set, imports included) is its own. Jobs: ``read_gcode``
alone; ``read_gcode`` + ``round_toolpath`` (spirals as objects in a ``Chain``, what
``build --from-gcode`` writes STEP from), up to ``--chain-max`` moves; ``read_gcode`` +
``round_toolpath_arrays`` (the same spirals as arrays); and, up to ``--write-max`` moves, the
moves' plan (x, y after the plunge) rounded as a Chain and written as G-code (``gcode_program``:
LinuxCNC with exact G5, and generic with biarcs within 0.001 mm), and the LinuxCNC program
read back as the same chain (``parse_gcode_chain``); and, up to ``--build-max`` moves, the whole
command ``spiral-cad build --from-gcode FILE --max-deviation 0.01 --no-plots`` (read, round, write
STEP, G-code, samples and DXF; peak = the larger of the command's process and its children); and, up to ``--g2-max``
moves, the in-place rewrite ``spiral-cad g2 FILE --max-deviation 0.01 -o OUT`` of a pocketing and contouring
program of as many moves (``contour_program``: pockets of G1 rows, rounded-rectangle contours of G1 lines and G3
corners, bosses cut as G1 chords with R-word arcs, each entered by a rapid and a plunge, at their own feeds; the
command as a user runs it, its progress lines on stderr kept; from 20 000 moves its runs are made G2 in one forked
process per core: its peak is given as the command's plus each process's). One run per job (a minute-long
job on a shared machine: the spread is not measured); the peer of the arrays is the
Chain at the same size. Goals: 100 000 moves read and rounded in ≤ 60 s and ≤ 1.5 GB;
1 M moves rounded in ≤ 20 s and ≤ 3 GB; ``build --from-gcode`` and ``g2`` of 100 000 moves each in ≤ 30 s and ≤ 1 GB.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable

import numpy as np
from timing import Report, Timing, arguments

from spiral_cad.io.gcode_processes import processes as forked

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.io.gcode",
    "spiral_cad.io.gcode_paths",
    "spiral_cad.io.gcode_pieces",
    "spiral_cad.io.toolpath_rounding",
    "spiral_cad.io.toolpath",
    "spiral_cad.io.gcode_write",
    "spiral_cad.design.rounding",
    "spiral_cad.design.rounded_paths",
    "spiral_cad.core.space",
    "spiral_cad.core.chain",
    "spiral_cad.app.designfile",
    "spiral_cad.io.samples",
    "spiral_cad.io.step",
    "spiral_cad.core.bezier",
    "spiral_cad.io.gcode_inplace",
    "spiral_cad.io.gcode_processes",
    "spiral_cad.app.g2_document",
    "spiral_cad.design.g2",
    "spiral_cad.design._g2_pieces",
    "spiral_cad.design._g2_solve",
    "spiral_cad.design._g2_measure",
    "spiral_cad.design._g2_kept",
    "spiral_cad.design.fillets",
    "spiral_cad.core.segments",
)

MAX_DEVIATION = 0.01  # mm at every corner


def program(moves: int) -> str:
    """A pocketing program of ``moves`` G1 moves: rows 20 mm long, 0.5 mm apart, 200 rows a layer, 0.1 mm deeper each."""
    rng = np.random.default_rng(7)
    rows = (moves + 1) // 2
    row = np.repeat(np.arange(rows), 2)[:moves]
    x = np.tile([0.0, 20.0, 20.0, 0.0], rows // 2 + 1)[:moves] + rng.uniform(-0.2, 0.2, moves)
    y = (row % 200) * 0.5
    z = -1.0 - (row // 200) * 0.1
    body = "\n".join(f"X{a:.4f} Y{b:.4f} Z{c:.4f}" for a, b, c in zip(x.tolist(), y.tolist(), z.tolist()))
    return f"%\n(pocket, {moves} moves)\nG21 G90 G17 G40 G49 G80\nT1 M6\nS12000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F800\n{body}\nG0 Z5\nM30\n%\n"


def contour_program(moves: int) -> str:
    """A program of about ``moves`` moves, part after part: a pocket of G1 rows (jittered ends, F1000), a rounded
    rectangle of G1 sides and G3 corners (F800), and a boss cut as G1 chords of a circle (F600) with two R-word
    arcs (a reversal) after it; each entered by a rapid and a plunge (F200) and left by a rapid retract."""
    rng = np.random.default_rng(7)
    out = ["%", f"(pocket and contour, {moves} moves)", "G21 G90 G17 G40 G49 G80 G94", "T1 M6", "S12000 M3", "M8"]
    count = part = 0
    while count < moves:
        ox, oy, depth = (part % 10) * 60.0, (part // 10 % 10) * 50.0, -1.0 - (part // 100) * 0.5
        rows = int(rng.integers(20, 60))
        out += ["G0 Z5", f"G0 X{ox + 2:.4f} Y{oy + 2:.4f}", f"G1 Z{depth:.4f} F200"]
        for r in range(rows):
            y = oy + 2 + r * 0.8
            x0, x1 = ox + 2 + rng.uniform(-0.05, 0.05), ox + 38 + rng.uniform(-0.05, 0.05)
            b = x0 if r % 2 else x1
            out += [f"G1 X{b:.4f} Y{y:.4f}" + (" F1000" if r == 0 else ""), f"X{b:.4f} Y{y + 0.8:.4f}"]
        w, h, c = 40.0, rows * 0.8 + 4, 3.0
        out += ["G0 Z5", f"G0 X{ox + c:.4f} Y{oy:.4f}", f"G1 Z{depth:.4f} F200",
                f"G1 X{ox + w - c:.4f} Y{oy:.4f} F800", f"G3 X{ox + w:.4f} Y{oy + c:.4f} I0 J{c:.4f}",
                f"G1 Y{oy + h - c:.4f}", f"G3 X{ox + w - c:.4f} Y{oy + h:.4f} I{-c:.4f} J0",
                f"G1 X{ox + c:.4f}", f"G3 X{ox:.4f} Y{oy + h - c:.4f} I0 J{-c:.4f}",
                f"G1 Y{oy + c:.4f}", f"G3 X{ox + c:.4f} Y{oy:.4f} I{c:.4f} J0"]  # fmt: skip
        cx, cy, radius = ox + 20, oy + h / 2, 5 + rng.uniform(0, 1)
        n = int(rng.integers(40, 120))
        t = np.linspace(0, 2 * np.pi, n + 1)
        out += ["G0 Z5", f"G0 X{cx + radius:.4f} Y{cy:.4f}", f"G1 Z{depth:.4f} F200",
                f"G1 X{cx + radius * np.cos(t[1]):.4f} Y{cy + radius * np.sin(t[1]):.4f} F600"]  # fmt: skip
        out += [f"X{cx + radius * np.cos(a):.4f} Y{cy + radius * np.sin(a):.4f}" for a in t[2:]]
        out += [f"G2 X{cx + radius - 4:.4f} Y{cy:.4f} R2", f"G3 X{cx + radius - 8:.4f} Y{cy:.4f} R2",
                f"G1 X{cx + radius - 9:.4f} Y{cy + 1:.4f}", "G0 Z5"]  # fmt: skip
        count += 2 * rows + n + 22
        part += 1
    return "\n".join(out + ["M9", "M5", "G0 Z25", "M30", "%", ""])


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def child(job: str, moves: int) -> None:
    """One job in this process; prints its seconds and peak memory as JSON."""
    if job == "build":
        build(moves)
        return
    if job == "g2":
        g2(moves)
        return
    from spiral_cad.io.gcode import parse_gcode, read_gcode
    from spiral_cad.io.toolpath_rounding import round_toolpath, round_toolpath_arrays

    warm = parse_gcode(program(50))  # compile the kernels first (one warm-up, as compare does)
    if job in ("chain", "write"):
        round_toolpath(warm, max_deviation=MAX_DEVIATION, for_occt=False)
    else:
        round_toolpath_arrays(warm, max_deviation=MAX_DEVIATION)
    with tempfile.TemporaryDirectory() as folder:
        file = os.path.join(folder, f"pocket{moves}.nc")
        with open(file, "w", encoding="ascii") as handle:
            handle.write(program(moves))
        before = peak_mb()
        started = time.perf_counter()
        path = read_gcode(file)
        read = time.perf_counter() - started
        rounded = 0.0
        if job == "write":
            from spiral_cad.design import round_corners
            from spiral_cad.io.gcode import parse_gcode_chain
            from spiral_cad.io.gcode_write import gcode_program

            # the program's moves in the plane (every corner a G5 pair; LinuxCNC takes G5 in XY only)
            chain = round_corners(path.points[~path.rapid][1:, :2], max_deviation=MAX_DEVIATION, units=path.units).chain
            times = {}
            started = time.perf_counter()
            text = gcode_program(chain).text
            times["linuxcnc"] = time.perf_counter() - started
            started = time.perf_counter()
            gcode_program(chain, dialect="generic")
            times["generic"] = time.perf_counter() - started
            started = time.perf_counter()
            back = parse_gcode_chain(text)
            times["back"] = time.perf_counter() - started
            assert len(back) == len(chain), (len(back), len(chain))
            print(json.dumps({**times, "segments": len(chain), "peak_mb": peak_mb()}))
            return
        if job != "read":
            started = time.perf_counter()
            if job == "chain":
                result = round_toolpath(path, max_deviation=MAX_DEVIATION, for_occt=False)
                corners = len(result.corners)
            else:
                corners = len(round_toolpath_arrays(path, max_deviation=MAX_DEVIATION))
            rounded = time.perf_counter() - started
            assert corners > 0.9 * moves, corners
    print(json.dumps({"read": read, "round": rounded, "peak_mb": peak_mb(), "before_mb": before, "moves": len(path)}))


def _command(name: str, text: str, argv: Callable[[str, str], list[str]]) -> float:
    """Seconds that ``spiral-cad`` with ``argv(file, folder)`` takes on ``text`` written to ``name`` in a
    fresh folder, as the command runs it (its stdout dropped, its stderr kept); a failure stops the job."""
    from spiral_cad.app.cli import main

    with tempfile.TemporaryDirectory() as folder:
        file = os.path.join(folder, name)
        with open(file, "w", encoding="ascii") as handle:
            handle.write(text)
        started = time.perf_counter()
        with open(os.devnull, "w") as quiet:
            stdout, sys.stdout = sys.stdout, quiet
            try:
                code = main(argv(file, folder))
            finally:
                sys.stdout = stdout
        seconds = time.perf_counter() - started
    assert code == 0, code
    return seconds


def build(moves: int) -> None:
    """``spiral-cad build --from-gcode`` of a program of ``moves`` moves."""
    seconds = _command(f"pocket{moves}.nc", program(moves), lambda file, folder: [
        "build", "--from-gcode", file, "--max-deviation", str(MAX_DEVIATION), "--out", os.path.join(folder, "out"), "--no-plots"])  # fmt: skip
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    print(json.dumps({"build": seconds, "peak_mb": max(peak_mb(), children)}))


def g2(moves: int) -> None:
    """``spiral-cad g2`` of a ``contour_program`` of ``moves`` moves (its reversals split: allowed)."""
    seconds = _command(f"contour{moves}.ngc", contour_program(moves), lambda file, folder: [
        "g2", file, "--max-deviation", str(MAX_DEVIATION), "-o", os.path.join(folder, "out.ngc"), "--allow-splits"])  # fmt: skip
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0  # the processes sharing the runs, if any
    print(json.dumps({"g2": seconds, "peak_mb": peak_mb(), "child_mb": children}))


def run(job: str, moves: int) -> dict:
    done = subprocess.run([sys.executable, __file__, "--child", job, str(moves)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{job} {moves}: {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        child(sys.argv[2], int(sys.argv[3]))
        return
    args = arguments(__doc__, sizes=([10_000, 100_000, 1_000_000], [300]), chain_max=(100_000, 2_000), write_max=(10_000, 300),
                     build_max=(10_000, 300), g2_max=(100_000, 300))  # fmt: skip
    report = Report("G-code benchmark", f"Generated pocketing programs, max_deviation {MAX_DEVIATION} mm; one run per job, "
                                        "each in its own process (peak = that process's maximum resident set).")  # fmt: skip
    rows = []
    for moves in args.sizes:
        read = run("read", moves)
        report.add(f"read_gcode, {moves:,} moves", read["read"], "s", Timing((read["read"],)), goal=f"peak {read['peak_mb']:,.0f} MB")
        arrays = run("arrays", moves)
        chain = run("chain", moves) if moves <= args.chain_max else None
        total = chain["read"] + chain["round"] if chain else float("nan")
        if chain:
            goal = ""
            if moves == 100_000:
                ok = total <= 60 and chain["peak_mb"] <= 1536
                goal = f"read + round ≤ 60 s, ≤ 1.5 GB: {'met' if ok else 'missed'}"
            report.add(f"read + round_toolpath (Chain), {moves:,} moves", total, "s", Timing((total,)), goal=goal)
        goal = ""
        if moves == 1_000_000:
            ok = arrays["round"] <= 20 and arrays["peak_mb"] <= 3072
            goal = f"rounded ≤ 20 s, ≤ 3 GB: {'met' if ok else 'missed'}"
        report.add(f"round_toolpath_arrays, {moves:,} moves", arrays["round"], "s", Timing((arrays["round"],)),
                   f"Chain {chain['round']:.2f} s" if chain else "", chain["round"] / arrays["round"] if chain else None, goal)  # fmt: skip
        if moves <= args.write_max:
            written = run("write", moves)
            segments = f"{written['segments']:,} segments"
            report.add(f"gcode_program (LinuxCNC, G5), {moves:,} moves", written["linuxcnc"], "s", Timing((written["linuxcnc"],)), segments)
            report.add(f"gcode_program (generic, biarcs), {moves:,} moves", written["generic"], "s", Timing((written["generic"],)),
                       f"LinuxCNC {written['linuxcnc']:.2f} s", written["linuxcnc"] / written["generic"])  # fmt: skip
            report.add(f"parse_gcode_chain of it (the same chain), {moves:,} moves", written["back"], "s", Timing((written["back"],)))
        for job, limit, label in (
            ("build", args.build_max, "spiral-cad build --from-gcode"),
            ("g2", args.g2_max, "spiral-cad g2 (in place)"),
        ):
            if moves <= limit:
                done = run(job, moves)
                goal = ""
                processes = forked() if done.get("child_mb") else 0
                memory = done["peak_mb"] + processes * done.get("child_mb", 0.0)  # a bound: forked pages are shared
                if moves == 100_000:
                    goal = f"≤ 30 s, ≤ 1 GB: {'met' if done[job] <= 30 and memory <= 1024 else 'missed'}"
                peak = f"peak {done['peak_mb']:,.0f} MB" + (f" + {processes} × {done['child_mb']:,.0f} MB" if processes else "")
                report.add(f"{label}, {moves:,} moves", done[job], "s", Timing((done[job],)), peak, goal=goal)
        rows.append(f"| {moves:,} | {read['read']:.2f} s, {read['peak_mb']:,.0f} MB | "
                    + (f"{chain['round']:.2f} s, {chain['peak_mb']:,.0f} MB" if chain else "not run (above --chain-max)")
                    + f" | {arrays['round']:.2f} s, {arrays['peak_mb']:,.0f} MB |")  # fmt: skip
    report.section(
        "Peak memory per job (process maximum, imports and the program's text included)",
        "| moves | read_gcode | round_toolpath (Chain) | round_toolpath_arrays |\n|---|---|---|---|\n" + "\n".join(rows),
    )
    report.finish(args)


if __name__ == "__main__":
    main()
