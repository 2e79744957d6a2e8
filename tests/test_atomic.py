"""Atomic writes and bundles: what a failure or a kill (real processes, real SIGKILL) leaves.

A write creates nothing but its file, and an error names the file asked for, not the temporary one;
temporaries name their writer, and a killed writer's are removed where that file is next written,
never a running writer's; a bundle's files appear together. A writer killed at any call leaves the
old files whole or the new ones whole, and the next write leaves no debris.
"""

import errno
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import drumstroke
from drumstroke._atomic import Bundle, bundled, describe_temporary, remove_stale, temporary_path, write_atomic

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


# --- temporaries name their writer; a killed writer's are removed where that file is next written ----------------

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


def listing(folder):
    return sorted(p.name for p in Path(folder).iterdir())


def test_only_the_temporaries_of_writers_no_longer_running_are_removed(tmp_path):
    dead, dead_name = make_temporaries(tmp_path, "exit")
    live, live_name = make_temporaries(tmp_path, "wait")
    try:
        assert re.fullmatch(rf"\.s\.csv\.drumstroke-{dead.pid}-[0-9a-f]{{8}}\.tmp", dead_name)
        mine = temporary_path(tmp_path / "mine.csv").name
        for name in (mine, ".notes.txt.tmp", "data.drumstroke-1-2.tmp", f".s.csv.drumstroke-{dead.pid}-xyz.tmp"):
            (tmp_path / name).write_text("z")
        before = listing(tmp_path)
        dead_folder = [n for n in before if n.startswith(".stage.") and f"-{dead.pid}-" in n]
        assert remove_stale(tmp_path) == sorted([dead_name, *dead_folder])
        left = listing(tmp_path)
        assert left == sorted(set(before) - {dead_name, *dead_folder})
        assert live_name in left and mine in left  # a running process's, this process's
        assert describe_temporary(tmp_path / live_name).endswith(f"drumstroke process {live.pid}, running")
    finally:
        live.communicate("")
    assert describe_temporary(tmp_path / live_name).startswith("a temporary file of drumstroke process")
    assert "stopped before it finished" in describe_temporary(tmp_path / live_name)
    assert describe_temporary(tmp_path / ".notes.txt.tmp") is None
    assert remove_stale(tmp_path) == [n for n in left if f"-{live.pid}-" in n and n.endswith(".tmp")]


def test_a_write_removes_the_killed_writers_temporaries_of_its_own_file_only(tmp_path):
    _, dead_name = make_temporaries(tmp_path, "exit")  # a temporary of s.csv, a temporary folder of "stage"
    (stage,) = [n for n in listing(tmp_path) if n.startswith(".stage.")]
    write_atomic(tmp_path / "a.txt", "a")
    assert listing(tmp_path) == sorted([dead_name, stage, "a.txt"])
    write_atomic(tmp_path / "s.csv", "s")
    assert listing(tmp_path) == sorted([stage, "a.txt", "s.csv"])


# --- a bundle's files are put in place together --------------------------------------------------------------------


def test_a_bundle_puts_its_files_in_place_together_when_it_ends(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    (tmp_path / "b.wav").write_text("old b")
    with Bundle() as bundle:
        write_atomic(tmp_path / "a.csv", "new a", bundle=bundle)
        bundle.write(tmp_path / "b.wav", b"new b")
        with bundled(bundle) as joined:  # the caller's bundle: nothing put in place at this block's end
            assert joined is bundle
            write_atomic(tmp_path / "c.json", "new c", bundle=joined)
        assert not (tmp_path / "c.json").exists()
        write_atomic(tmp_path / "a.csv", "newer a", bundle=bundle)  # written twice: the last counts
        assert (tmp_path / "a.csv").read_text() == "old a" and not (tmp_path / "c.json").exists()
        assert len(listing(tmp_path)) == 5  # two files and three staged
        assert write_atomic(tmp_path / "now.txt", "now") is None and (tmp_path / "now.txt").exists()  # no bundle
    assert [(tmp_path / n).read_text() for n in ("a.csv", "b.wav", "c.json")] == ["newer a", "new b", "new c"]
    assert listing(tmp_path) == ["a.csv", "b.wav", "c.json", "now.txt"]
    with bundled(None) as own:  # none given: a bundle of its own, put in place at the block's end
        write_atomic(tmp_path / "d.txt", "d", bundle=own)
        assert not (tmp_path / "d.txt").exists()
    assert (tmp_path / "d.txt").read_text() == "d"


def test_an_error_in_a_bundle_leaves_every_file_as_it_was(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    with pytest.raises(KeyboardInterrupt), Bundle() as bundle:
        write_atomic(tmp_path / "a.csv", "new a", bundle=bundle)
        write_atomic(tmp_path / "b.wav", "new b", bundle=bundle)
        raise KeyboardInterrupt
    assert listing(tmp_path) == ["a.csv"] and (tmp_path / "a.csv").read_text() == "old a"


def test_a_bundle_writing_onto_a_directory_names_it_and_replaces_nothing(tmp_path):
    (tmp_path / "a.csv").write_text("old a")
    (tmp_path / "d").mkdir()
    with pytest.raises(IsADirectoryError) as caught, Bundle() as bundle:
        write_atomic(tmp_path / "a.csv", "new a", bundle=bundle)
        write_atomic(tmp_path / "d", "new d", bundle=bundle)
    assert caught.value.filename == str(tmp_path / "d")
    assert listing(tmp_path) == ["a.csv", "d"] and (tmp_path / "a.csv").read_text() == "old a"


def test_a_rename_refused_at_the_end_of_a_bundle_names_the_file_and_leaves_no_debris(tmp_path, monkeypatch):
    replace = os.replace

    def refuse_b(source, target):
        if Path(target).name == "b.wav":
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))
        replace(source, target)

    monkeypatch.setattr(os, "replace", refuse_b)
    with pytest.raises(PermissionError, match="Permission denied") as caught, Bundle() as bundle:
        write_atomic(tmp_path / "a.csv", "new a", bundle=bundle)
        write_atomic(tmp_path / "b.wav", "new b", bundle=bundle)
    assert caught.value.filename == str(tmp_path / "b.wav")
    assert listing(tmp_path) == ["a.csv"]  # the command failed, naming the file it could not write


# --- killed by SIGKILL at any point (real processes) ---------------------------------------------------------------

RUN = """
from drumstroke._atomic import Bundle, write_atomic
content, paths = arguments[0], arguments[1:]
if len(paths) == 1:
    write_atomic(paths[0], content + " " + paths[0].rsplit("/", 1)[-1])
else:
    with Bundle() as bundle:
        for path in paths:
            write_atomic(path, content + " " + path.rsplit("/", 1)[-1], bundle=bundle)
if count_file:
    with open(count_file, "w") as handle:
        handle.write(str(calls))
"""


def write_in_process(content, paths, kill=("any", "", 0), count_file=""):
    """Write ``paths`` (one file, or several as one bundle) holding ``content`` in a real process, killed by
    SIGKILL where ``kill`` (name, part, k) says; its exit status."""
    status, _ = run([content, *map(str, paths)], kill=kill, count_file=count_file, program=HOOK + RUN)
    return status


def contents(paths):
    return [Path(p).read_text() if Path(p).exists() else None for p in paths]


def records(*folders):
    return [n for folder in folders for n in listing(folder) if n.endswith(".bundle")]


def test_a_bundle_killed_while_renaming_is_finished_by_the_next_write_in_either_folder(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv", two / "b.wav", one / "c.json"]
    for path in paths:
        path.write_text(f"old {path.name}")
    assert write_in_process("new", paths, kill=("replace", str(tmp_path), 2)) == -signal.SIGKILL  # after a.csv
    assert contents(paths) == ["new a.csv", "old b.wav", "old c.json"]  # a mix, and a record in each folder says so
    assert len(records(one)) == 1 and len(records(two)) == 1
    write_atomic(two / "other.txt", "x")  # the next write in one of the folders finishes it
    assert contents(paths) == ["new a.csv", "new b.wav", "new c.json"]
    assert listing(one) == ["a.csv", "c.json"] and listing(two) == ["b.wav", "other.txt"]


def test_a_bundle_killed_before_its_last_record_is_undone(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv", two / "b.wav"]
    for path in paths:
        path.write_text(f"old {path.name}")
    # One record written, not the other: not committed.
    assert write_in_process("new", paths, kill=("open", ".files.drumstroke-", 2)) == -signal.SIGKILL
    assert contents(paths) == ["old a.csv", "old b.wav"]
    assert len(listing(one)) == 3 and len(listing(two)) == 2  # a record and staged files
    write_atomic(one / "other.txt", "x")  # the record in one: its staged files in both folders go
    assert contents(paths) == ["old a.csv", "old b.wav"]
    assert listing(one) == ["a.csv", "other.txt"] and listing(two) == ["b.wav"]


@pytest.mark.parametrize("layout", ["one file", "a bundle in two folders"])
def test_a_writer_killed_at_any_call_leaves_old_or_new_whole_and_the_next_write_no_debris(tmp_path, layout):
    """SIGKILL before each file-system call the writer makes, in turn: after it, every file holds the old text or
    every file the new one, or (killed while renaming a committed bundle) a record is there and clearing what the
    killed writer left (what the next write does first) gives the new files; the next write then leaves the files
    and nothing else."""
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv"] if layout == "one file" else [one / "a.csv", two / "b.wav", one / "c.json"]
    count = tmp_path / "calls.txt"
    assert write_in_process("old", paths, count_file=str(count)) == 0
    calls = int(count.read_text())
    assert calls >= (4 if layout == "one file" else 12)
    outcomes = set()
    for k in range(1, calls + 1):
        assert write_in_process("new", paths, kill=("any", "", k)) == -signal.SIGKILL
        found = contents(paths)
        old, new = [f"old {p.name}" for p in paths], [f"new {p.name}" for p in paths]
        if found not in (old, new):
            assert records(one, two), (k, found)
            for folder in (one, two):
                remove_stale(folder)
            assert contents(paths) == new, k
            found = "finished"
        outcomes.add("old" if found == old else "new" if found == new else found)
        write_in_process("old", paths)  # the next run, to the end
        assert contents(paths) == old, k
        assert listing(one) + listing(two) == sorted(p.name for p in paths if p.parent == one) + sorted(
            p.name for p in paths if p.parent == two), k
    assert outcomes == ({"old", "new"} if layout == "one file" else {"old", "new", "finished"})


# --- what a write never replaces, and what a reader refuses ----------------------------------------------------------


def test_a_fifo_a_device_or_a_socket_is_never_replaced_by_a_file(tmp_path):
    import socket

    from drumstroke.formats.json import write_json

    os.mkfifo(tmp_path / "pipe.json")
    os.symlink("/dev/null", tmp_path / "null.json")
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(tmp_path / "sock.json"))
    for name, kind in (("pipe.json", "a FIFO"), ("null.json", "a character device"), ("sock.json", "a socket")):
        with pytest.raises(FileExistsError, match=f"is {kind}.*not a regular file") as error:
            write_json(tmp_path / name, {"a": 1})
        assert error.value.filename == str(tmp_path / name)
        with pytest.raises(FileExistsError, match=kind), Bundle() as bundle:
            write_atomic(tmp_path / "ok.txt", "x", bundle=bundle)
            write_atomic(tmp_path / name, "x", bundle=bundle)
    assert os.path.islink(tmp_path / "null.json") and Path("/dev/null").is_char_device()
    assert stat_kinds(tmp_path) == {"null.json": "link", "pipe.json": "fifo", "sock.json": "socket"}  # nothing new


def stat_kinds(folder):
    import stat

    kinds = {}
    for name in os.listdir(folder):
        mode = os.lstat(folder / name).st_mode
        kinds[name] = ("link" if stat.S_ISLNK(mode) else "fifo" if stat.S_ISFIFO(mode) else
                       "socket" if stat.S_ISSOCK(mode) else "file")
    return kinds


def test_inside_a_guarded_run_no_file_read_is_written_over(tmp_path):
    from drumstroke._atomic import guarding_inputs
    from drumstroke.formats.pattern import read_pattern_file

    score = tmp_path / "s.pattern"
    score.write_text("tempo 120\n0 single 100\n")
    read_pattern_file(score)
    write_atomic(score, "tempo 90\n0 single 100\n")  # outside a run, a program may write over what it read
    os.link(score, tmp_path / "hard.pattern")
    with guarding_inputs():
        read_pattern_file(score)
        for path in (score, tmp_path / "hard.pattern", tmp_path / "." / "s.pattern"):
            with pytest.raises(FileExistsError, match="an input of this run") as error:
                write_atomic(path, "tempo 60\n")
            assert error.value.filename == str(path)
        write_atomic(tmp_path / "other.pattern", "x")
    assert score.read_text() == "tempo 90\n0 single 100\n"
    write_atomic(score, "tempo 60\n")  # the run over, the guard is gone
    assert score.read_text() == "tempo 60\n"


def test_the_files_of_a_bundle_killed_while_renaming_are_refused_until_it_is_finished(tmp_path):
    from drumstroke.errors import ParameterError
    from drumstroke.formats.reading import read_text

    paths = [tmp_path / "a.csv", tmp_path / "c.json"]
    for path in paths:
        path.write_text(f"old {path.name}")
    assert write_in_process("new", paths, kill=("replace", str(tmp_path), 2)) == -signal.SIGKILL  # after a.csv
    for path in paths:  # the new a.csv and the old c.json: neither is read
        with pytest.raises(ParameterError, match=rf"^x '{re.escape(str(path))}' cannot be read: its publication did "
                                                 r"not finish \(\.files\.drumstroke-\d+-[0-9a-f]{8}\.bundle beside it"):
            read_text(path, "x", limit=100)
    write_atomic(tmp_path / "other.txt", "x")  # the next write in the folder finishes it
    assert [read_text(p, "x", limit=100) for p in paths] == ["new a.csv", "new c.json"]


def test_the_files_of_a_bundle_killed_before_it_committed_are_read_as_they_were(tmp_path):
    from drumstroke.formats.reading import read_text

    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    paths = [one / "a.csv", two / "b.wav"]
    for path in paths:
        path.write_text(f"old {path.name}")
    assert write_in_process("new", paths, kill=("open", ".files.drumstroke-", 2)) == -signal.SIGKILL
    assert records(one)  # a record, but not all of them: not committed, the old files stand
    assert [read_text(p, "x", limit=100) for p in paths] == ["old a.csv", "old b.wav"]
