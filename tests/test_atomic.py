"""Atomic writes, published runs and sweeping: what a failure or a kill (real processes, real SIGKILL) leaves.

A write creates nothing but its file, and an error names the file asked for, not the temporary one;
temporaries name their writer, and a sweep removes a dead writer's only; a run's files appear together.
"""

import errno
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import drumstroke
from drumstroke._atomic import describe_temporary, publish, sweep, temporary_path, write_atomic

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from robustness_kill import HOOK, run

SOURCE = str(Path(drumstroke.__file__).resolve().parents[1])


def test_a_write_replaces_the_file_whole_and_keeps_its_permissions(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    path.chmod(0o640)
    write_atomic(path, "new")
    assert path.read_text() == "new" and path.stat().st_mode & 0o777 == 0o640
    assert list(tmp_path.iterdir()) == [path]


def test_a_secret_is_its_owners_only_from_its_creation(tmp_path, monkeypatch):
    """A file written with mode 0o600 (a token) is never readable by others, not even for a moment: every file
    that appears in the folder while it is written, the temporary included, has the mode (the temporary's mode
    read when it is opened and at each write)."""
    import drumstroke._atomic as atomic

    seen = []
    real = atomic.os.fdopen

    def watching(fd, *args, **kwargs):
        seen.append(os.fstat(fd).st_mode & 0o777)
        handle = real(fd, *args, **kwargs)
        original = handle.write

        def write(data):
            seen.append(os.fstat(fd).st_mode & 0o777)
            return original(data)

        handle.write = write
        return handle

    monkeypatch.setattr(atomic.os, "fdopen", watching)
    old_umask = os.umask(0o022)
    try:
        path = tmp_path / "token.toml"
        path.write_text("older, readable by all")
        path.chmod(0o644)
        write_atomic(path, "secret", mode=0o600)
    finally:
        os.umask(old_umask)
    assert path.read_text() == "secret" and path.stat().st_mode & 0o777 == 0o600
    assert seen and set(seen) == {0o600}


def test_a_missing_folder_is_an_error_naming_the_file_and_is_not_created(tmp_path):
    path = tmp_path / "no" / "such" / "a.txt"
    with pytest.raises(FileNotFoundError) as caught:
        write_atomic(path, "x")
    assert caught.value.filename == str(path) and caught.value.errno == errno.ENOENT
    assert list(tmp_path.iterdir()) == []


def test_writing_onto_a_directory_names_it_and_leaves_no_temporary(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(IsADirectoryError) as caught:
        write_atomic(tmp_path / "d", b"x")
    assert caught.value.filename == str(tmp_path / "d")
    assert list(tmp_path.iterdir()) == [tmp_path / "d"] and list((tmp_path / "d").iterdir()) == []


def test_a_full_disk_names_the_file_with_the_reason_and_keeps_the_old_one(tmp_path, monkeypatch):
    path = tmp_path / "a.txt"
    path.write_text("old")

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError, match="No space left on device") as caught:
        write_atomic(path, "new")
    assert caught.value.filename == str(path) and caught.value.errno == errno.ENOSPC
    assert path.read_text() == "old" and list(tmp_path.iterdir()) == [path]


# --- temporaries name their writer; a sweep removes only the dead's -----------------------------------------------

MAKE = """
import sys
from drumstroke._atomic import temporary_folder, temporary_path, write_new
folder = temporary_folder(sys.argv[5] + "/stage")
write_new(folder / "a.csv", b"x" * 5000)
path = temporary_path(sys.argv[5] + "/s.csv")
write_new(path, b"y" * 1000)
print(path, flush=True)
if sys.argv[6] == "wait":
    sys.stdin.read()
"""


def make_temporaries(folder, mode):
    """A real process writes a temporary folder and file in ``folder`` and exits ("exit") or waits ("wait")."""
    process = subprocess.Popen([sys.executable, "-c", HOOK + MAKE, "any", "", "0", "", str(folder), mode],
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": SOURCE})
    name = Path(process.stdout.readline().strip()).name
    if mode == "exit":
        process.wait()
    return process, name


def renamed(name, **fields):
    """A temporary's name with its host, pid or start replaced."""
    match = re.fullmatch(r"(.*\.drumstroke-)([0-9a-f]{8})-(\d+)-(\d+)(-.*)", name)
    host, pid, start = fields.get("host", match[2]), fields.get("pid", match[3]), fields.get("start", match[4])
    return f"{match[1]}{host}-{pid}-{start}{match[5]}"


def test_a_sweep_removes_the_temporaries_of_dead_writers_only(tmp_path, monkeypatch):
    dead, dead_name = make_temporaries(tmp_path, "exit")
    live, live_name = make_temporaries(tmp_path, "wait")
    try:
        assert re.fullmatch(rf"\.s\.csv\.drumstroke-[0-9a-f]{{8}}-{dead.pid}-\d+-[0-9a-f]{{8}}\.tmp", dead_name)
        reused = renamed(live_name, start=int(re.search(r"-(\d+)-[0-9a-f]{8}\.tmp$", live_name)[1]) + 1)
        host = re.search(r"drumstroke-([0-9a-f]{8})-", dead_name)[1]
        elsewhere = renamed(dead_name, host="0" * 8 if host != "0" * 8 else "1" * 8)
        mine = temporary_path(tmp_path / "mine.csv").name
        for name in (reused, elsewhere, mine, ".notes.txt.tmp", "data.drumstroke-1-2-3.tmp"):
            (tmp_path / name).write_text("z")
        before = sorted(p.name for p in tmp_path.iterdir())
        someone_else = os.getuid() + 1
        monkeypatch.setattr(os, "getuid", lambda: someone_else)  # none of these is theirs
        assert sweep(tmp_path) == [] and sorted(p.name for p in tmp_path.iterdir()) == before
        monkeypatch.undo()
        removed = sweep(tmp_path)
        dead_folder = [n for n in before if n.startswith(".stage.") and f"-{dead.pid}-" in n]
        assert removed == sorted([dead_name, reused, *dead_folder])  # a pid now running a younger process: dead
        left = sorted(p.name for p in tmp_path.iterdir())
        assert left == sorted(set(before) - set(removed))
        assert live_name in left and elsewhere in left and mine in left  # running, another host's, this process's
        assert describe_temporary(tmp_path / live_name).endswith(f"drumstroke process {live.pid}, running")
    finally:
        live.communicate("")
    assert describe_temporary(tmp_path / live_name).startswith("a temporary file of drumstroke process")
    assert "stopped before it finished" in describe_temporary(tmp_path / live_name)
    assert sorted(sweep(tmp_path)) == sorted(n for n in left if f"-{live.pid}-" in n and n.endswith(".tmp"))


def test_a_write_sweeps_its_folder_and_older_drumstrokes_temporaries_of_its_file(tmp_path):
    make_temporaries(tmp_path, "exit")
    old, new, other = ".a.txt.k3x_9q2a.tmp", ".a.txt.zz81mmq0.tmp", ".b.txt.k3x_9q2a.tmp"
    for name in (old, new, other):
        (tmp_path / name).write_text("left by drumstroke 0.1")
    an_hour_ago = time.time() - 3600
    for name in (old, other):
        os.utime(tmp_path / name, (an_hour_ago, an_hour_ago))
    write_atomic(tmp_path / "a.txt", "a")
    # The dead writer's temporaries went; of the old unnamed ones, only a.txt's older than this process.
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([new, other, "a.txt"])


# --- a run's files are published together --------------------------------------------------------------------------


def listing(folder):
    return sorted(p.name for p in Path(folder).iterdir())


def test_a_run_publishes_its_files_together_when_it_ends(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    (tmp_path / "b.wav").write_text("old b")
    with publish():
        write_atomic(tmp_path / "a.csv", "new a")
        write_atomic(tmp_path / "b.wav", b"new b")
        with publish():  # joins the run
            write_atomic(tmp_path / "c.json", "new c")
        write_atomic(tmp_path / "a.csv", "newer a")  # written twice: the last counts
        assert (tmp_path / "a.csv").read_text() == "old a" and not (tmp_path / "c.json").exists()
        assert len(listing(tmp_path)) == 5  # two files and three staged
        assert write_atomic(tmp_path / "now.txt", "now", now=True) is None and (tmp_path / "now.txt").exists()
    assert [(tmp_path / n).read_text() for n in ("a.csv", "b.wav", "c.json")] == ["newer a", "new b", "new c"]
    assert listing(tmp_path) == ["a.csv", "b.wav", "c.json", "now.txt"]


def test_an_error_in_a_run_leaves_every_file_as_it_was(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    with pytest.raises(KeyboardInterrupt), publish():
        write_atomic(tmp_path / "a.csv", "new a")
        write_atomic(tmp_path / "b.wav", "new b")
        raise KeyboardInterrupt
    assert listing(tmp_path) == ["a.csv"] and (tmp_path / "a.csv").read_text() == "old a"


def test_a_run_writing_onto_a_directory_names_it_and_replaces_nothing(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    (tmp_path / "d").mkdir()
    with pytest.raises(IsADirectoryError) as caught, publish():
        write_atomic(tmp_path / "a.csv", "new a")
        write_atomic(tmp_path / "d", "new d")
    assert caught.value.filename == str(tmp_path / "d")
    assert listing(tmp_path) == ["a.csv", "d"] and (tmp_path / "a.csv").read_text() == "old a"


def test_a_rename_refused_at_the_end_of_a_run_names_the_file_and_leaves_no_debris(tmp_path, monkeypatch):
    replace = os.replace

    def refuse_b(source, target):
        if Path(target).name == "b.wav":
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))
        replace(source, target)

    monkeypatch.setattr(os, "replace", refuse_b)
    with pytest.raises(PermissionError, match="Permission denied") as caught, publish():
        write_atomic(tmp_path / "a.csv", "new a")
        write_atomic(tmp_path / "b.wav", "new b")
    assert caught.value.filename == str(tmp_path / "b.wav")
    assert listing(tmp_path) == ["a.csv"]  # the command failed, naming the file it could not write


RUN = """
from drumstroke._atomic import publish, write_atomic
with publish():
    for path in arguments:
        write_atomic(path, "new " + path.rsplit("/", 1)[-1])
"""


def run_killed(paths, kill):
    """Write ``paths`` in one run in a real process, killed by SIGKILL where ``kill`` (name, part, k) says."""
    status, _ = run([str(p) for p in paths], kill=kill, program=HOOK + RUN)
    assert status == -signal.SIGKILL


def contents(paths):
    return [Path(p).read_text() if Path(p).exists() else None for p in paths]


def test_a_run_killed_while_renaming_is_completed_by_the_next_run_writing_in_either_folder(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv", two / "b.wav", one / "c.json"]
    for path in paths:
        path.write_text(f"old {path.name}")
    run_killed(paths, ("replace", str(tmp_path), 2))  # after a.csv went into place, before b.wav
    assert contents(paths) == ["new a.csv", "old b.wav", "old c.json"]  # a mix, and a record says so
    for folder in (one, two):
        assert [n for n in listing(folder) if n.startswith(".publish.drumstroke-")]
    write_atomic(two / "other.txt", "x")  # the next run writing to one of the folders completes it
    assert contents(paths) == ["new a.csv", "new b.wav", "new c.json"]
    assert listing(one) == ["a.csv", "c.json"] and listing(two) == ["b.wav", "other.txt"]


def test_a_run_killed_before_its_last_record_is_undone(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv", two / "b.wav"]
    for path in paths:
        path.write_text(f"old {path.name}")
    run_killed(paths, ("open", ".publish.drumstroke-", 2))  # one record written, not the other: not committed
    assert contents(paths) == ["old a.csv", "old b.wav"]
    assert len(listing(one)) == 3 and len(listing(two)) == 2  # a record and staged files
    write_atomic(two / "other.txt", "x")
    write_atomic(one / "other.txt", "x")
    assert contents(paths) == ["old a.csv", "old b.wav"]
    assert listing(one) == ["a.csv", "other.txt"] and listing(two) == ["b.wav", "other.txt"]


def test_a_run_killed_while_staging_leaves_the_old_files_and_debris_the_next_run_sweeps(tmp_path):
    paths = [tmp_path / "a.csv", tmp_path / "b.wav"]
    for path in paths:
        path.write_text(f"old {path.name}")
    run_killed(paths, ("fsync", "", 2))  # b.wav's data written, not yet synced
    assert contents(paths) == ["old a.csv", "old b.wav"] and len(listing(tmp_path)) == 4
    write_atomic(tmp_path / "a.csv", "mine")
    assert listing(tmp_path) == ["a.csv", "b.wav"] and contents(paths) == ["mine", "old b.wav"]
