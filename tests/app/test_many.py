"""``spiral-cad check`` and ``build`` on many files: on a two-worker LocalCluster (processes on
loopback), the same results as running the files one by one, a CSV row per file, ``error:`` lines
and exit 2 for the files that do not pass; a single file starts no cluster."""

import csv
import re
import subprocess
import sys
from pathlib import Path

import pytest

from spiral_cad import Chain, Line
from spiral_cad.app import many as many_module
from spiral_cad.app.cli import core_examples, main
from spiral_cad.app.many import expand_inputs, wants_many
from spiral_cad.io.step import write_step

pytest.importorskip("distributed")
HEADING = re.compile(r"^== (.+)$", re.MULTILINE)


def step_files(folder: Path) -> dict[str, str]:
    """Twenty small STEP files and the verdict each should get with ``--require G2``: ten one-wire
    transitions (ok), five of two pieces (fail), three polylines with corners and a box (OCCT's own
    writer: fail, fail, fail, ok), one that is not STEP at all (error)."""
    import build123d as bd

    expected = {}
    for k, (_, transition) in enumerate(core_examples()):
        write_step([Chain(transition.spirals)], folder / f"transition_{k:02d}.step", f"t{k}", "mm", "test")
        expected[f"transition_{k:02d}.step"] = "ok"
    for k, (_, transition) in enumerate(core_examples()[:5]):
        far = Chain([Line((100.0 + k, 0.0), (200.0, 5.0 * k))])
        write_step([Chain(transition.spirals), far], folder / f"two_pieces_{k}.step", f"p{k}", "mm", "test")
        expected[f"two_pieces_{k}.step"] = "fail"
    for k in range(3):
        bd.export_step(bd.Polyline((0, 0), (1 + k, 0), (2 + k, 1 + k)), str(folder / f"corner_{k}.step"))
        expected[f"corner_{k}.step"] = "fail"
    bd.export_step(bd.Box(1, 2, 3), str(folder / "box.step"))
    expected["box.step"] = "ok"
    (folder / "broken.step").write_text("ISO-10303-21;\nthis is not a STEP file\n", encoding="utf-8")
    expected["broken.step"] = "error"
    return expected


def blocks(stdout: str) -> dict[str, str]:
    """The output of a many-file run, file by file (the text under each ``== FILE`` line)."""
    parts = HEADING.split(stdout)
    assert parts[0] == ""
    return {parts[i]: parts[i + 1].lstrip("\n") for i in range(1, len(parts), 2)}


@pytest.mark.slow
def test_twenty_files_on_two_workers_match_the_files_checked_one_by_one(tmp_path, capsys, monkeypatch):
    folder = tmp_path / "parts"
    folder.mkdir()
    expected = step_files(folder)
    assert len(expected) == 20
    monkeypatch.chdir(tmp_path)
    addresses = []

    def recording(*args):
        client = start(*args)
        addresses.extend([client.scheduler.address, *client.scheduler_info()["workers"]])
        return client

    start = many_module._client
    monkeypatch.setattr(many_module, "_client", recording)
    summary = tmp_path / "summary.csv"
    status = main(["check", "parts", "--require", "G2", "--workers", "2", "--summary", str(summary)])
    many = capsys.readouterr()
    assert status == 2 and "Traceback" not in many.err
    assert len(addresses) == 3 and all(a.startswith("tcp://127.0.0.1:") for a in addresses)  # a scheduler, two workers, on loopback
    outputs = blocks(many.out)
    files = [f"parts/{name}" for name in sorted(expected)]
    assert list(outputs) == files  # every file once, in order, whatever order the workers finished in
    rows = sorted(csv.DictReader(summary.open(encoding="utf-8")), key=lambda row: row["file"])  # written as they arrived
    assert [row["file"] for row in rows] == files
    assert [row["verdict"] for row in rows] == [expected[name] for name in sorted(expected)]
    assert all(float(row["seconds"]) > 0 for row in rows)
    errors = [line for line in many.err.splitlines() if line.startswith("error: ")]
    assert [line.split(": ")[1] for line in errors] == [f for f in files if expected[Path(f).name] != "ok"]
    assert re.search(r"checked 20/20 files, 9 not passed, [\d.]+ files/s in [\d.]+ s", many.err)
    for row, file in zip(rows, files):
        alone = main(["check", file, "--require", "G2"])
        one = capsys.readouterr()
        assert outputs[file] == one.out, file  # the same table and verdict line, byte for byte
        assert {0: "ok", 1: "fail", 2: "error"}[alone] == row["verdict"]
        if alone == 2:
            assert f"error: {file}: {one.err.removeprefix('error: ').strip()}" in errors
        else:
            worst = re.search(r"worst (?:joint|tangent edge) (\S+)", one.out)
            assert worst is not None and row["worst_joint"] == worst.group(1).rstrip(";")
        if alone == 1:
            reason = next(line for line in one.out.splitlines() if line.startswith("FAIL: ")).removeprefix("FAIL: ")
            assert f"error: {file}: {reason}" in errors


def test_inputs_are_files_patterns_and_folders_each_file_once(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("a/one.step", "a/two.STP", "a/deep/three.iges", "a/notes.txt", "b/four.xodr"):
        Path(name).parent.mkdir(parents=True, exist_ok=True)
        Path(name).write_text("x", encoding="utf-8")
    suffixes = (".step", ".stp", ".igs", ".iges", ".xodr")
    assert expand_inputs(["a"], suffixes) == ["a/deep/three.iges", "a/one.step", "a/two.STP"]
    assert expand_inputs(["a/one.step", "**/*.xodr", "a"], suffixes) == ["a/one.step", "b/four.xodr", "a/deep/three.iges", "a/two.STP"]
    assert expand_inputs(["missing.step"], suffixes) == ["missing.step"]  # that file's own error, among the others
    with pytest.raises(ValueError, match=r"no file matches '\*\.igs'"):
        expand_inputs(["*.igs"], suffixes)
    Path("empty").mkdir()
    with pytest.raises(ValueError, match="folder 'empty' holds no"):
        expand_inputs(["empty"], suffixes)
    assert not wants_many(["a/one.step"], suffixes) and wants_many(["a"], suffixes) and wants_many(["*.step"], suffixes)
    assert wants_many(["x", "y"], suffixes) and not wants_many(["empty"], suffixes)  # refused as the one file it is not


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["check", "a.step", "b.step", "--workers", "0"], "--workers must be at least 1; got 0"),
        (["check", "a.step", "b.step", "--summary", "s.txt"], "--summary 's.txt': the summary is CSV"),
        (["check", "a.step", "b.step", "--comb", "c.step"], "--comb: each writes one file; give one file to check"),
        (["check", "nothing*.step"], "no file matches 'nothing*.step'"),
        (["build", "--from-gcode", "nothing*.nc", "--max-deviation", "0.1"], "no file matches 'nothing*.nc'"),
        (["build", "d.json", "--from-gcode", "p/", "--max-deviation", "0.1"], "give design files or --from-gcode, not both"),
    ],
)
def test_a_bad_many_file_option_is_one_error_line_and_2(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    for name in ("a.step", "b.step", "d.json", "p/x.nc"):
        Path(name).parent.mkdir(exist_ok=True)
        Path(name).write_text("x", encoding="utf-8")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and "Traceback" not in err


@pytest.mark.subprocess
def test_one_file_starts_no_cluster_and_imports_no_dask(tmp_path):
    chain = Chain(core_examples()[0][1].spirals)
    write_step([chain], tmp_path / "one.step", "one", "mm", "test")
    code = ("import sys; from spiral_cad.app.cli import main; status = main(['check', 'one.step', '--require', 'G2']); "
            "print(status, sorted({m.split('.')[0] for m in sys.modules} & {'dask', 'distributed', 'tornado'}))")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "0 []" and "OK: 1 wire" in done.stdout
    assert not done.stdout.startswith("==")  # today's output, no heading


@pytest.mark.slow
def test_many_programs_build_each_into_its_own_folder_as_one_by_one(tmp_path, capsys, monkeypatch):
    program = Path(__file__).resolve().parents[1] / "gcode" / "pocket.nc"
    for shop in ("shop_a", "shop_b"):
        (tmp_path / "programs" / shop).mkdir(parents=True)
        (tmp_path / "programs" / shop / "pocket.nc").write_text(program.read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "programs" / "shop_b" / "cycle.nc").write_text("G21\nG0 X0 Y0 Z5\nG81 X10 Y0 Z-1 R1 F100\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    options = ["--max-deviation", "0.05", "--no-plots"]
    status = main(["build", "--from-gcode", "programs/**/*.nc", *options, "-o", "many", "--workers", "2", "--summary", "built.csv"])
    err = capsys.readouterr().err
    assert status == 2 and "Traceback" not in err
    rows = {row["file"]: row for row in csv.DictReader(open("built.csv", encoding="utf-8"))}
    assert {f: (r["verdict"], r["worst_joint"]) for f, r in rows.items()} == {
        "programs/shop_a/pocket.nc": ("ok", "G2"), "programs/shop_b/cycle.nc": ("error", ""), "programs/shop_b/pocket.nc": ("ok", "G2")}  # fmt: skip
    assert "error: programs/shop_b/cycle.nc: " in err and "G81 is refused" in err
    assert main(["build", "--from-gcode", "programs/shop_a/pocket.nc", *options, "-o", "alone"]) == 0
    for shop in ("shop_a", "shop_b"):
        for name in ("pocket.ngc", "pocket_samples.csv", "pocket_continuity.txt"):
            assert (tmp_path / "many" / shop / "pocket" / name).read_bytes() == (tmp_path / "alone" / name).read_bytes(), name


@pytest.mark.slow
def test_scheduler_runs_on_an_existing_cluster_and_leaves_it_running(tmp_path, capsys, monkeypatch):
    from distributed import Client, LocalCluster

    monkeypatch.chdir(tmp_path)
    Path("parts").mkdir()
    for k, (_, transition) in enumerate(core_examples()[:4]):
        write_step([Chain(transition.spirals)], Path("parts") / f"t{k}.step", f"t{k}", "mm", "test")
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address="127.0.0.1:0") as cluster:
        status = main(["check", "parts/*.step", "--require", "G2", "--scheduler", cluster.scheduler_address])
        out = capsys.readouterr().out
        assert status == 0 and list(blocks(out)) == [f"parts/t{k}.step" for k in range(4)]
        assert all(text.splitlines()[-1].startswith("OK: 1 wire") for text in blocks(out).values())
        with Client(cluster) as client:  # ours closed only its client
            assert client.submit(sum, [1, 2]).result() == 3
    assert main(["check", "parts", "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert "error: --scheduler 'tcp://127.0.0.1:9': no dask scheduler answered" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.subprocess
def test_ctrl_c_in_the_terminal_stops_the_run_and_its_workers_in_one_line(tmp_path):
    import os
    import signal

    for k in range(30):
        write_step([Chain(core_examples()[k % 10][1].spirals)], tmp_path / f"t{k:02d}.step", f"t{k}", "mm", "test")
    code = "import sys; from spiral_cad_launcher import main; sys.exit(main())"
    process = subprocess.Popen([sys.executable, "-c", code, "check", str(tmp_path), "--workers", "2"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True)  # fmt: skip
    assert process.stdout is not None
    for line in process.stdout:
        if line.startswith("== "):  # the cluster runs and a result came back
            break
    os.killpg(process.pid, signal.SIGINT)  # as a terminal does: the command and every process it started
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130 and "Traceback" not in err, err
    assert err.splitlines()[-1] == "error: interrupted"
    assert_session_ended(process.pid)


def assert_session_ended(leader: int) -> None:
    """No process of the session ``leader`` started is still running (a worker may take a moment to finish stopping)."""
    import os

    import psutil

    def session(pid):
        try:
            return os.getsid(pid)
        except OSError:
            return None

    left = [p for p in psutil.process_iter(["status"]) if session(p.pid) == leader and p.info["status"] != psutil.STATUS_ZOMBIE]
    _, alive = psutil.wait_procs(left, timeout=10)
    assert not alive, alive


def stop_the_process_on_a_bad_file(args) -> int:
    """A one-file command that kills its worker on a file named ``bad…`` (an OCCT crash the reader's sandbox missed)."""
    import os

    if Path(args.file).name.startswith("bad"):
        os._exit(3)
    print(f"read {Path(args.file).name}")
    return 0


@pytest.mark.slow
def test_a_file_that_kills_its_worker_is_that_file_s_error_and_the_others_pass(capsys):
    import argparse

    from spiral_cad.app.many import run_many

    files = ["a.step", "bad.step", "b.step", "c.step", "d.step"]
    status = run_many(stop_the_process_on_a_bad_file, files, [{"file": f} for f in files], argparse.Namespace(file=None),
                      verb="checked", workers=2)  # fmt: skip
    out, err = capsys.readouterr()
    assert status == 2 and "Traceback" not in err
    assert blocks(out) == {f: "" if f == "bad.step" else f"read {f}\n" for f in files} and list(blocks(out)) == files
    errors = [line for line in err.splitlines() if line.startswith("error: ")]
    # run again alone in a fresh process, where it stopped that process too
    assert errors == ["error: bad.step: its process stopped (exit status 3), also when run alone in a fresh process"], errors
