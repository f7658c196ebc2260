"""Many files with faults injected: workers that die (once, twice, for good), a scheduler killed mid-run,
Ctrl-C and SIGTERM during ``build``, an unwritable summary, file names of any bytes, the same file named
twice, a symbolic link loop, two inputs building into one folder, a make_g2 advice that never ends.
Each run has a timeout: a hang fails the test instead of holding it."""

import csv
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from spiral_cad import Chain
from spiral_cad.app import many as many_module
from spiral_cad.app.cli import core_examples, main
from spiral_cad.app.many import run_many
from spiral_cad.app.many_inputs import expand_inputs
from spiral_cad.io.step import write_step

sys.path.insert(0, str(Path(__file__).parent))
from test_many import assert_session_ended  # noqa: E402

pytest.importorskip("distributed")
LAUNCHER = "import sys; from spiral_cad_launcher import main; sys.exit(main())"
PROGRESS = ("checked ", "built ")


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # a background shell may have left it ignored


def only_error_lines(err: str) -> list[str]:
    """The ``error:`` lines of ``err``, after checking that nothing else but progress is there."""
    strays = [line for line in err.splitlines() if line and not line.startswith(("error: ", *PROGRESS))]
    assert not strays, strays
    return [line for line in err.splitlines() if line.startswith("error: ")]


def in_a_worker() -> bool:
    try:
        from distributed import get_worker

        get_worker()
    except ValueError:
        return False
    return True


def fault(args) -> int:
    """A one-file command that kills its process: on ``die…`` files on a dask worker, on ``always…`` files anywhere."""
    name = Path(args.file).name
    if name.startswith("always") or (name.startswith("die") and in_a_worker()):
        os._exit(3)
    summary = getattr(args, "summary_path", None)
    if name.startswith("die") and summary:  # run alone, after the others: their rows are written already
        print(f"rows before me: {len(Path(summary).read_text(encoding='utf-8').splitlines()) - 1}")
    time.sleep(getattr(args, "pause", 0.0))
    print(f"read {name}")
    return 0


def _run(files, args, seconds=240, **options):
    """``run_many`` of ``fault`` on ``files``; a run that has not ended after ``seconds`` fails (TimeoutError)."""

    def expired(signum, frame):
        raise TimeoutError(f"the run did not end within {seconds} s")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return run_many(fault, files, [{"file": f} for f in files], args, verb="checked", **options)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.slow
def test_files_whose_worker_dies_run_again_alone_however_often_workers_die(tmp_path, capsys):
    import argparse

    files = ["first", "die1", "b", "die2", "always", "last"]
    summary = tmp_path / "rows.csv"
    args = argparse.Namespace(file=None, summary_path=str(summary))
    status = _run(files, args, workers=1, summary=str(summary))  # four deaths of the one worker
    out, err = capsys.readouterr()
    assert status == 2
    errors = only_error_lines(err)
    assert len(errors) == 1 and errors[0].startswith("error: always: its process stopped (exit status 3), also when run alone"), errors
    for name in ("first", "b", "last"):
        assert f"== {name}\nread {name}\n" in out
    seen = []
    for name in ("die1", "die2"):  # the two that killed their worker ran whole, alone, after the others
        found = re.search(rf"== {name}\nrows before me: (\d+)\nread {name}\n", out)
        assert found is not None, out
        seen.append(int(found.group(1)))
    assert max(seen) >= 1  # the rows of files that had finished were written as they arrived, not at the end
    rows = {row["file"]: row["verdict"] for row in csv.DictReader(summary.open(encoding="utf-8"))}
    assert rows == {"first": "ok", "die1": "ok", "b": "ok", "die2": "ok", "always": "error", "last": "ok"}


@pytest.mark.slow
def test_no_worker_left_the_rest_run_here_and_the_run_ends(tmp_path, capsys, monkeypatch):
    import argparse

    clusters = []
    start = many_module._client

    def recording(*args):
        client = start(*args)
        clusters.append(client.cluster)
        return client

    monkeypatch.setattr(many_module, "_client", recording)
    monkeypatch.setattr(many_module, "NO_WORKERS", 2.0)
    done = threading.Event()

    def kill_every_worker():  # again and again, also while its nanny restarts it: no worker lives
        while not done.wait(0.1):
            for cluster in clusters:
                for nanny in list(cluster.workers.values()):
                    pid = getattr(getattr(getattr(nanny, "process", None), "process", None), "pid", None)
                    if pid:
                        try:
                            os.kill(pid, signal.SIGKILL)
                        except OSError:
                            pass

    killer = threading.Thread(target=kill_every_worker, daemon=True)
    killer.start()
    files = [f"f{k}" for k in range(4)]
    try:
        status = _run(files, argparse.Namespace(file=None, pause=0.2), workers=1)
    finally:
        done.set()
        killer.join()
    out, err = capsys.readouterr()
    assert status == 0, err
    assert not only_error_lines(err)
    assert all(f"== {f}\nread {f}\n" in out for f in files)


@pytest.mark.slow
@pytest.mark.subprocess
def test_a_lost_scheduler_reports_every_finished_file_and_names_the_rest_not_run(tmp_path):
    """An external scheduler killed mid-run (by the third file's task): exit 2, every file in the summary."""

    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    port = 20000 + os.getpid() % 20000
    address = f"tcp://127.0.0.1:{port}"
    scheduler = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                                  "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=environment)  # fmt: skip
    worker = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=environment)  # fmt: skip
    try:
        summary = tmp_path / "rows.csv"
        files = ["a", "b", "stop_scheduler", "c", "d", "e"]
        code = (
            "import argparse, os, signal, sys, time\n"
            "from spiral_cad.app.many import run_many\n"
            "from spiral_cad.app.many_inputs import escaping_streams\n"
            "from test_many_faults import kill_scheduler\n"
            "escaping_streams()\n"
            f"files = {files!r}\n"
            f"args = argparse.Namespace(file=None, scheduler_pid={scheduler.pid})\n"
            f"sys.exit(run_many(kill_scheduler, files, [{{'file': f}} for f in files], args, verb='checked', "
            f"scheduler={address!r}, summary={str(summary)!r}))\n"
        )
        for _ in range(100):  # the scheduler takes a moment to listen
            done = subprocess.run([sys.executable, "-c", f"from distributed import Client; Client({address!r}, timeout='5s').close()"],
                                  capture_output=True, env=environment, timeout=60)  # fmt: skip
            if done.returncode == 0:
                break
        ran = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environment, timeout=180,
                             preexec_fn=_default_sigint)  # fmt: skip
    finally:
        for process in (worker, scheduler):
            process.kill()
            process.wait()
    assert ran.returncode == 2, ran.stderr
    errors = only_error_lines(ran.stderr)
    rows = {row["file"]: row["verdict"] for row in csv.DictReader(summary.open(encoding="utf-8"))}
    assert set(rows) == set(files)  # every file has its row
    assert set(rows.values()) <= {"ok", "not run"} and rows["a"] == "ok" and rows["stop_scheduler"] == "not run", rows
    not_run = [f for f in files if rows[f] == "not run"]
    assert errors == [f"error: {f}: not run: the dask scheduler was lost" for f in not_run]
    assert all(f"== {f}\nread {f}\n" in ran.stdout for f in files if rows[f] == "ok")


def kill_scheduler(args) -> int:
    """Kills the scheduler on the file ``stop_scheduler`` (then waits to be cancelled); reads the others."""
    name = Path(args.file).name
    if name == "stop_scheduler":
        os.kill(args.scheduler_pid, signal.SIGKILL)
        time.sleep(30)
    time.sleep(0.3)
    print(f"read {name}")
    return 0


def test_an_unwritable_summary_is_refused_before_anything_runs(tmp_path, capsys, monkeypatch):
    def no_cluster(*args):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(many_module, "_client", no_cluster)
    monkeypatch.chdir(tmp_path)
    for name in ("a.step", "b.step"):
        Path(name).write_text("x", encoding="utf-8")
    Path("folder.csv").mkdir()
    for summary, why in (("no/such/folder/s.csv", "No such file or directory"), ("folder.csv", "Is a directory")):
        assert main(["check", "a.step", "b.step", "--summary", summary]) == 2
        err = capsys.readouterr().err
        assert err == f"error: --summary {summary!r}: cannot write it ({why}); nothing was run\n"


def test_the_same_file_is_taken_once_and_a_link_loop_is_walked_once(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("parts/deep").mkdir(parents=True)
    for name in ("parts/a.step", "parts/deep/b.step"):
        Path(name).write_text("x", encoding="utf-8")
    os.symlink("..", "parts/deep/loop")  # parts/deep/loop/deep/loop/… is parts again
    os.symlink("a.step", "parts/also_a.step")
    suffixes = (".step",)
    assert expand_inputs(["parts"], suffixes) == ["parts/a.step", "parts/deep/b.step"]
    assert expand_inputs(["parts/a.step", "./parts/a.step", "parts/../parts/a.step", "parts/also_a.step"], suffixes) == ["parts/a.step"]
    assert expand_inputs(["parts/**/*.step"], suffixes) == ["parts/a.step", "parts/deep/b.step"]


def test_two_inputs_building_into_one_folder_are_refused_before_anything_runs(tmp_path, capsys, monkeypatch):
    def no_cluster(*args):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(many_module, "_client", no_cluster)
    monkeypatch.chdir(tmp_path)
    Path("programs").mkdir()
    for name in ("pocket.nc", "pocket.ngc", "other.nc"):
        Path("programs", name).write_text("G21\nG1 X10 Y0 F100\nG1 X10 Y10\n", encoding="utf-8")
    assert main(["build", "--from-gcode", "programs", "--max-deviation", "0.1", "-o", "out"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: programs/pocket.nc and programs/pocket.ngc both build into out/pocket/")
    assert not Path("out").exists()  # nothing ran, nothing was made


def _corner_step(path: Path) -> None:
    import build123d as bd

    bd.export_step(bd.Polyline((0, 0), (1, 0), (1, 1)), str(path))  # OCCT's own writer


def test_a_file_name_of_any_bytes_is_checked_and_printed_escaped(tmp_path, capsys):
    folder = os.fsencode(tmp_path)
    name = os.path.join(folder, b"caf\xe9.step")  # Latin-1, not UTF-8
    write_step([Chain(core_examples()[0][1].spirals)], tmp_path / "plain.step", "t", "mm", "test")
    os.rename(tmp_path / "plain.step", name)
    assert main(["check", os.fsdecode(name), "--require", "G2"]) == 0  # one file, as ever
    out, err = capsys.readouterr()
    assert out.startswith("caf\\xe9.step: 1 wire") and "OK: 1 wire" in out and not err
    summary = tmp_path / "one.csv"
    assert main(["check", os.fsdecode(name), "--require", "G2", "--summary", str(summary)]) == 0
    out, err = capsys.readouterr()
    assert f"== {os.fsdecode(folder)}/caf\\xe9.step\n" in out and "OK: 1 wire" in out and not only_error_lines(err)
    rows = list(csv.DictReader(summary.open(encoding="utf-8")))
    assert rows[0]["file"].endswith("caf\\xe9.step") and rows[0]["verdict"] == "ok"


def test_make_g2_advice_has_the_time_limit(tmp_path, capsys, monkeypatch):
    from spiral_cad.cad import g2wire, sandbox

    _corner_step(tmp_path / "corner.step")

    def never_ends(*args, **kwargs):
        time.sleep(3600)

    monkeypatch.setattr(sandbox, "TIME_LIMIT", 2.0)
    monkeypatch.setattr(g2wire, "g2_advice", never_ends)  # a polyline whose advice would take hours
    started = time.monotonic()
    assert main(["check", str(tmp_path / "corner.step"), "--require", "G2"]) == 1
    out = capsys.readouterr().out
    assert time.monotonic() - started < 30
    assert "make_g2: no advice: make_g2's advice failed on" in out and "(no result within 2 s; stopped)" in out
    assert out.splitlines()[-1].startswith("FAIL: worst joint is G0")  # a corner; the verdict stays the last line


@pytest.mark.slow
@pytest.mark.subprocess
@pytest.mark.parametrize(("name", "status", "line"), [("SIGINT", 130, "error: interrupted"), ("SIGTERM", 143, "error: terminated")])
def test_a_signal_during_build_commits_nothing_more_stops_every_process_and_removes_staging(tmp_path, name, status, line):

    for k in range(12):
        (tmp_path / "programs").mkdir(exist_ok=True)
        (tmp_path / "programs" / f"p{k:02d}.nc").write_text(f"G21\nG0 X0 Y0\nG1 X{10 + k} Y0 F100\nG1 X{10 + k} Y10\nG1 X0 Y{12 + k}\n",
                                                              encoding="utf-8")  # fmt: skip
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-c", LAUNCHER, "build", "--from-gcode", "programs", "--max-deviation", "0.05",
                                "--no-plots", "-o", str(out), "--workers", "2", "--summary", str(tmp_path / "built.csv")],
                               cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                               preexec_fn=_default_sigint)  # fmt: skip
    assert process.stdout is not None
    for text in process.stdout:
        if text.startswith("== "):  # a build was committed; others are under way
            break
    committed = {p for p in out.rglob("*") if p.is_file()}
    signal_number = getattr(signal, name)
    if signal_number == signal.SIGINT:
        os.killpg(process.pid, signal_number)  # as a terminal does: the command and every process it started
    else:
        process.send_signal(signal_number)  # as `kill` does: the command alone
    try:
        _, err = process.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        raise
    assert process.returncode == status, err
    assert only_error_lines(err) == [line]
    after = {p for p in out.rglob("*") if p.is_file()}
    assert after <= committed, sorted(map(str, after - committed))  # nothing committed after the signal
    assert not [p for p in out.rglob(".spiral-cad-build-*")]  # no staging folder left
    rows = list(csv.DictReader(open(tmp_path / "built.csv", encoding="utf-8")))
    assert len(rows) == 12 and any(r["verdict"] == "ok" for r in rows) and any(r["verdict"] == "not run" for r in rows)
    assert_session_ended(process.pid)


@pytest.mark.subprocess
def test_a_reader_child_ends_with_the_worker_that_started_it():
    """A worker killed (Ctrl-C, a crash) takes its reader child with it: no reader left running for minutes."""
    import psutil

    code = ("import time\nfrom spiral_cad.cad.sandbox import Isolated\n"
            "child = Isolated(time.sleep, 600, what='the STEP reader', subject='slow.step')\n"
            "print(child._pid, flush=True)\ntime.sleep(600)\n")  # fmt: skip
    worker = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert worker.stdout is not None
    reader = int(worker.stdout.readline())
    assert psutil.pid_exists(reader)
    worker.kill()
    worker.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        try:
            if psutil.Process(reader).status() == psutil.STATUS_ZOMBIE:
                break
        except psutil.NoSuchProcess:
            break
        time.sleep(0.05)
    else:
        pytest.fail(f"the reader child {reader} still runs after its worker was killed")
