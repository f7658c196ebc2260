"""All-or-nothing output: destinations checked before anything is replaced, backups restored on
any failure or interrupt, and only our own marked staging folders ever removed."""

import os
import signal
import stat

import pytest

from spiral_cad.io import staging
from spiral_cad.io.staging import MARKER, OutputError, Staging, remove_stale

OLD = {"a.step": "old a", "b.svg": "old b", "c.csv": "old c"}


@pytest.fixture
def out(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    for name, text in OLD.items():
        (folder / name).write_text(text)
    (folder / "mine.txt").write_text("not ours")
    return folder


def contents(folder) -> dict[str, str]:
    return {p.name: p.read_text() if p.is_file() else "<not a file>" for p in sorted(folder.iterdir())}


def stage_new_files(stage: Staging, names=("a.step", "b.svg", "c.csv", "d.dxf")) -> None:
    for name in names:
        (stage.folder / name).write_text(f"new {name[0]}")


def test_commit_replaces_every_file_and_leaves_the_rest(out):
    with Staging(out) as stage:
        stage_new_files(stage)
        written = stage.commit()
    assert [p.name for p in written] == ["a.step", "b.svg", "c.csv", "d.dxf"]
    assert contents(out) == {"a.step": "new a", "b.svg": "new b", "c.csv": "new c", "d.dxf": "new d", "mine.txt": "not ours"}


@pytest.mark.parametrize("blocker", ["folder", "fifo", "read-only"])
def test_a_blocked_destination_is_found_before_anything_is_replaced(out, blocker):
    target = out / "b.svg"
    if blocker == "read-only":
        if os.geteuid() == 0:
            pytest.skip("root may write to read-only files")
        target.chmod(stat.S_IRUSR)
    else:
        target.unlink()
        target.mkdir() if blocker == "folder" else os.mkfifo(target)
    before = contents(out)
    expected = {"folder": "b.svg is a folder", "fifo": "b.svg is not a regular file", "read-only": "b.svg is read-only"}
    with pytest.raises(OutputError, match=f"{expected[blocker]}; nothing there was changed"):
        with Staging(out) as stage:
            stage_new_files(stage)
            stage.commit()
    assert contents(out) == before
    assert not any(p.name.startswith(staging.PREFIX) for p in out.iterdir())


def commit_while(out, monkeypatch, event) -> None:
    """Stage new files and commit them, calling ``event(n)`` before the n-th move (os.replace)."""
    real_replace, calls = os.replace, []

    def replace(source, target):
        calls.append(target)
        event(len(calls))
        real_replace(source, target)

    monkeypatch.setattr(staging.os, "replace", replace)
    try:
        with Staging(out) as stage:
            stage_new_files(stage)
            stage.commit()
    finally:
        monkeypatch.undo()


@pytest.mark.parametrize("failing", [1, 2, 5, 6, 7])
def test_a_failed_move_restores_every_destination(out, monkeypatch, failing):
    """Moves: 1 a.step to the backups, 2 the new a.step in place, 3–4 b.svg, 5–6 c.csv, 7 the new d.dxf."""
    before = contents(out)

    def fail(n):
        if n == failing:
            raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space left"):
        commit_while(out, monkeypatch, fail)
    assert contents(out) == before


def test_an_interrupt_during_the_moves_restores_every_destination(out, monkeypatch):
    before = contents(out)
    handler = signal.getsignal(signal.SIGINT)  # (ignored in a run started in the background by a shell)

    def interrupt(n):
        if n == 3:
            os.kill(os.getpid(), signal.SIGINT)  # recorded, acted on before the next move

    with pytest.raises(KeyboardInterrupt):
        commit_while(out, monkeypatch, interrupt)
    assert contents(out) == before
    assert signal.getsignal(signal.SIGINT) is handler


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_interrupt_the_interpreter_swallowed_stops_the_commit_until_its_block_ends(out):
    """A KeyboardInterrupt raised in a ``__del__`` is only printed; the command's record still stops it."""
    import gc

    from spiral_cad.io.signals import raise_if_interrupted, signals_handled, stop_requested

    class InterruptedWhileCollected:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)

    before = contents(out)
    with signals_handled(("SIGINT",), interrupt=True) as received:
        InterruptedWhileCollected()
        gc.collect()
        assert received == [signal.SIGINT] and stop_requested()
        with pytest.raises(KeyboardInterrupt):
            raise_if_interrupted()
        with pytest.raises(KeyboardInterrupt), Staging(out) as stage:
            stage_new_files(stage)
            stage.commit()
    assert contents(out) == before
    assert not stop_requested()
    raise_if_interrupted()  # the block ended: nothing pending


def test_a_failed_restore_keeps_the_backups_and_names_them(out, monkeypatch):
    def break_down(n):
        if n >= 4:  # from the new b.svg on every move fails, the restores too
            raise OSError(5, "Input/output error")

    with pytest.raises(OSError, match="could not restore .*a.step.*the previous files are in"):
        commit_while(out, monkeypatch, break_down)
    (kept,) = [p for p in out.iterdir() if p.name.startswith(staging.PREFIX)]
    assert (kept / staging.BACKUP / "a.step").read_text() == "old a"
    remove_stale(out)  # it holds backups: never removed, even once its process has ended
    assert kept.exists()


def stale_folder(out, name: str, marker: str | None) -> object:
    folder = out / name
    folder.mkdir()
    (folder / "half.step").write_text("ISO-10303-21;")
    if marker is not None:
        (folder / MARKER).write_text(marker)
    return folder


def test_only_our_marked_folders_of_ended_processes_are_removed(out):
    dead, alive = 999_999_999, os.getpid()
    ours = stale_folder(out, f"{staging.PREFIX}{dead}-abc", staging._marker_text(dead))
    unmarked = stale_folder(out, f"{staging.PREFIX}{dead}-def", None)
    wrong_marker = stale_folder(out, f"{staging.PREFIX}{dead}-ghi", "anything")
    other_pid = stale_folder(out, f"{staging.PREFIX}{dead}-jkl", staging._marker_text(dead - 1))
    running = stale_folder(out, f"{staging.PREFIX}{alive}-mno", staging._marker_text(alive))
    huge_pid = stale_folder(out, f"{staging.PREFIX}{'9' * 40}-pqr", staging._marker_text(int("9" * 40)))
    target = stale_folder(out, "elsewhere", staging._marker_text(dead))
    link = out / f"{staging.PREFIX}{dead}-stu"
    link.symlink_to(target)
    assert sorted(remove_stale(out)) == sorted([ours, huge_pid])
    for kept in (unmarked, wrong_marker, other_pid, running, target):
        assert (kept / "half.step").exists()
    assert link.is_symlink()


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="zombies are seen through /proc")
def test_the_folder_of_a_killed_process_not_yet_reaped_is_removed(out):
    """A worker the command has just killed is a zombie until its cluster is closed: it holds no folder."""
    import subprocess
    import sys
    import time

    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        folder = stale_folder(out, f"{staging.PREFIX}{child.pid}-abc", staging._marker_text(child.pid))
        assert remove_stale(out) == []  # running: kept
        os.kill(child.pid, signal.SIGKILL)
        deadline = time.monotonic() + 10
        while not staging._zombie(child.pid) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert staging._zombie(child.pid)
        assert remove_stale(out) == [folder]
    finally:
        child.kill()
        child.wait()
    assert not staging._zombie(child.pid)


def test_a_failed_build_removes_the_output_folders_it_created(tmp_path):
    out = tmp_path / "new" / "out"
    with pytest.raises(RuntimeError):
        with Staging(out) as stage:
            stage_new_files(stage)
            raise RuntimeError("the build failed")
    assert not (tmp_path / "new").exists()


def test_out_must_be_a_folder(tmp_path):
    (tmp_path / "taken").write_text("keep me")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        with Staging(tmp_path / "taken"):
            pass
    assert (tmp_path / "taken").read_text() == "keep me"
