"""Atomic writes and published runs: a process killed at any instant leaves old files whole or new ones whole.

- **A file** (:func:`write_atomic`) is written under a temporary name beside it, synced, then
  renamed over its path: a reader sees the old file or the new one.
- **A run's files** (:func:`publish`): inside ``with publish():`` each :func:`write_atomic` is
  staged (written and synced under a temporary name) and no file is replaced until the block
  ends. Then a record listing every staged file and its path is written in each folder the
  run writes to, the files are renamed into place, and the records are removed. The last
  record written is the commit point: a kill before it leaves the previous files (the staged
  ones are debris); a kill after it leaves records that say the set is being replaced, and the
  next run writing to one of those folders completes it (:func:`sweep`).
- **Debris is swept**: every temporary drumstroke makes is named
  ``.NAME.drumstroke-HOST-PID-START-NONCE.tmp`` (a record ``.publish.drumstroke-….run``),
  naming its writer: HOST (8 hex digits of the host name's SHA-256), process id and start time
  (clock ticks after boot, from ``/proc``; 0 where there is none). :func:`sweep` removes those
  of dead writers — a process id that no longer runs, or now runs a process that started at
  another time — owned by this user and made on this host; never a live process's. Each
  folder is swept the first time a process writes to it.
"""

import contextlib
import contextvars
import errno
import glob
import hashlib
import json
import os
import re
import secrets
import shutil
import socket
import threading
import time
from pathlib import Path

from .errors import ParameterError

_HOST = hashlib.sha256(socket.gethostname().encode()).hexdigest()[:8]
_PROC = os.path.exists("/proc/self/stat")
_TEMPORARY = re.compile(r"\.(?P<name>.*)\.drumstroke-(?P<host>[0-9a-f]{8})-(?P<pid>\d+)-(?P<start>\d+)-[0-9a-f]{8}"
                        r"\.(?P<kind>tmp|run)", re.DOTALL)
_LEGACY = re.compile(r"[a-z0-9_]{8}")
"""The random part of the temporary names of older drumstroke (``tempfile``'s), which named no writer."""
_STARTED = time.time()
"""When this process loaded drumstroke: older temporaries of older drumstroke are another process's debris."""
_RUN = contextvars.ContextVar("drumstroke_run", default=None)
_SWEPT = set()
_SWEPT_LOCK = threading.Lock()
_STARTS = {}


def write_atomic(path, data, *, now=False, mode=None):
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.

    The file gets ``mode`` (permission bits, e.g. 0o600 for a secret; it has them from its
    creation, never the umask's first), else the old file's, else what the umask gives.

    The folder must exist: nothing is created but the file. Inside :func:`publish`, the file
    is staged and replaced when the run ends, unless ``now`` (a write that is its own atomic
    step, such as a library's manifest). An error is an ``OSError`` naming ``path`` (not the
    temporary file) with the system's reason: a missing folder, a folder that cannot be
    written, ``path`` a directory, a full disk.
    """
    path = Path(path)
    run = None if now else _RUN.get()
    temporary = None
    try:
        _sweep_once(path)
        if path.is_dir():
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR))
        temporary = temporary_path(path)
        write_new(temporary, data.encode() if isinstance(data, str) else data,
                  mode=_mode_for(path) if mode is None else mode)
        if run is not None:
            run.stage(temporary, path)
        else:
            os.replace(temporary, path)
            sync_folder(path.parent)
        temporary = None
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(path)) from None  # the subclass follows errno
    finally:
        if temporary is not None:
            remove(temporary)


@contextlib.contextmanager
def naming(path):
    """Inside, an ``OSError`` that names a temporary (or nothing) names ``path``, the user's file or folder."""
    try:
        yield
    except OSError as error:
        if error.filename is not None and not any(_TEMPORARY.fullmatch(part) for part in Path(error.filename).parts):
            raise
        raise OSError(error.errno, error.strerror or str(error), str(path)) from None


def _mode_for(path):
    """The old file's permissions, or those a new file gets under the umask."""
    try:
        return path.stat().st_mode & 0o777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def write_folder_atomic(path, fill, *, overwrite=False, what="folder"):
    """Make the folder ``path`` by ``fill(folder)`` in a temporary sibling, then a rename.

    ``fill`` is called with a path that does not exist yet, beside ``path``, and must
    create it. An existing ``path`` is refused unless ``overwrite``; then it is moved
    aside only once the new folder is complete, and removed. The parent folder must exist.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise ParameterError(f"{what} {str(path)!r}: the folder {str(path.parent)!r} does not exist")
    if os.path.lexists(path) and not overwrite:
        raise ParameterError(f"{what} {str(path)!r} exists; choose a new path, or overwrite it")
    _sweep_once(path)
    work = temporary_folder(path)
    token = _RUN.set(None)  # the folder is its own atomic step, even inside a run
    try:
        fill(work / path.name)
        old = work / f"{path.name}.old" if os.path.lexists(path) else None
        if old is not None:
            os.replace(path, old)
        try:
            os.replace(work / path.name, path)
        except BaseException:
            if old is not None:
                os.replace(old, path)
            raise
    finally:
        _RUN.reset(token)
        remove(work)


# --- a run's files, published together -----------------------------------------------------------------------------


@contextlib.contextmanager
def publish():
    """Publish every file :func:`write_atomic` writes in the block together, when it ends.

    Until then each is staged beside its path; an exception in the block removes them and
    leaves every file as it was. A ``publish`` inside another joins it. See the module's
    notes for what a kill leaves.
    """
    if _RUN.get() is not None:
        yield
        return
    run = _Run()
    token = _RUN.set(run)
    try:
        yield
    except BaseException:
        _RUN.reset(token)
        run.discard()
        raise
    _RUN.reset(token)
    run.commit()


class _Run:
    """The files of one run, staged: their temporary files by path, in the order written."""

    def __init__(self):
        self.staged = {}

    def stage(self, temporary, path):
        path = Path(os.path.abspath(path))
        earlier = self.staged.pop(path, None)  # written twice: the last one counts
        if earlier is not None:
            remove(earlier)
        self.staged[path] = Path(os.path.abspath(temporary))

    def discard(self):
        for temporary in self.staged.values():
            remove(temporary)
        self.staged.clear()

    def commit(self):
        folders = list(dict.fromkeys(path.parent for path in self.staged))
        records = [temporary_path(folder / "publish", kind="run") for folder in folders] if len(self.staged) > 1 else []
        text = json.dumps({"format": "drumstroke-run", "records": [str(r) for r in records],
                           "files": [{"path": str(p), "staged": str(t)} for p, t in self.staged.items()]}, indent=1)
        try:
            for record in records:
                _write_record(record, text)
            for folder in folders:
                sync_folder(folder)
        except BaseException:
            self._undo(records)
            raise
        try:  # committed: from here on, what a kill or an interrupt leaves is completed by the next run here
            for path, temporary in self.staged.items():
                _replace(temporary, path)
        except OSError:
            self._undo(records)  # the command fails, naming the file that could not be replaced
            raise
        for folder in folders:
            sync_folder(folder)
        for record in records:
            remove(record)

    def _undo(self, records):
        self.discard()
        for record in records:
            remove(record)


def _write_record(record, text):
    try:
        write_new(record, text.encode(), mode=0o600)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(record.parent)) from None


def _replace(temporary, path):
    try:
        os.replace(temporary, path)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(path)) from None


def _complete(record):
    """Finish the run of a dead writer's ``record``: into place if every record of it was written, else undone."""
    try:
        data = json.loads(Path(record).read_text())
        records = [Path(r) for r in data["records"]]
        files = [(Path(f["path"]), Path(f["staged"])) for f in data["files"]]
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, RecursionError):
        remove(record)  # cut short by the kill: its run never committed, and its staged files are debris
        return
    writer = _writer_of(_TEMPORARY.fullmatch(Path(record).name))
    ours = all(_is_temporary_of(r, writer, "run") for r in records) and all(
        _is_temporary_of(staged, writer, "tmp") and staged.parent == path.parent for path, staged in files)
    if ours and all(r.exists() for r in records):
        for path, staged in files:
            if staged.exists() and _owned(staged):
                with contextlib.suppress(OSError):
                    os.replace(staged, path)
    elif ours:
        for _, staged in files:
            remove(staged)
    for r in records if ours else [record]:
        remove(r)


def _is_temporary_of(path, writer, kind):
    match = _TEMPORARY.fullmatch(Path(path).name)
    return match is not None and match["kind"] == kind and _writer_of(match) == writer


# --- temporary names and their writers ------------------------------------------------------------------------------


def temporary_path(path, *, kind="tmp"):
    """A new temporary name beside ``path`` naming this process: ``.NAME.drumstroke-HOST-PID-START-NONCE.tmp``."""
    path = Path(path)
    pid = os.getpid()
    if pid not in _STARTS:  # a forked child finds its own
        _STARTS[pid] = _start_of(pid) or 0
    return path.parent / f".{path.name[:100]}.drumstroke-{_HOST}-{pid}-{_STARTS[pid]}-{secrets.token_hex(4)}.{kind}"


def temporary_folder(path):
    """Make and return a new, empty temporary folder beside ``path`` (named by :func:`temporary_path`)."""
    folder = temporary_path(path)
    os.mkdir(folder)
    return folder


def write_new(path, data, *, mode=0o666):
    """Create the file ``path`` (it must not exist) holding ``data`` (bytes), synced to the disk."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o600)
    try:
        with os.fdopen(fd, "wb") as handle:
            os.chmod(path, mode)
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
    except BaseException:
        remove(path)
        raise


def sync_folder(folder):
    """Sync a folder's entries (new names, renames) to the disk, where the system allows it."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some systems and file systems cannot sync a folder
    finally:
        os.close(fd)


def move_aside(path):
    """Rename ``path`` to a temporary name beside it (one atomic step) and return that name."""
    aside = temporary_path(path)
    os.replace(path, aside)
    return aside


def remove(path):
    """Remove a file or a folder and its contents, if it is there; never follow a link."""
    try:
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            os.unlink(path)
    except OSError:
        pass


def _start_of(pid):
    """A process's start (clock ticks after boot) from /proc; None if it does not run (or is a zombie)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            text = handle.read().decode(errors="replace")
    except OSError:
        return None
    state, *fields = text[text.rindex(")") + 2:].split()
    return None if state in ("Z", "X") else int(fields[18])


def _writer_of(match):
    return match["host"], int(match["pid"]), int(match["start"])


def _alive(host, pid, start):
    """Whether a temporary's writer may still run: yes unless it is known to be dead."""
    if host != _HOST:
        return True
    if _PROC:
        return _start_of(pid) == start
    if os.name != "posix":
        return True  # no safe way to ask
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _owned(path):
    """Whether ``path`` (not followed) belongs to this user; on systems without owners, yes."""
    if not hasattr(os, "getuid"):
        return True
    try:
        return os.lstat(path).st_uid == os.getuid()
    except OSError:
        return False


# --- sweeping ------------------------------------------------------------------------------------------------------


def sweep(folder):
    """Remove from ``folder`` the temporaries of dead drumstroke processes; return the names removed.

    Only names of drumstroke's pattern (see the module's notes) owned by this user, made on
    this host by a process that no longer runs. A dead run's records are seen to first: its
    files are put in place if it had committed, else its staged files removed.
    """
    folder = Path(folder)
    writers = {_writer_of(match) for match in _temporaries(folder)}
    dead = {writer for writer in writers if not _alive(*writer)}
    if not dead:
        return []
    # The dead write no more: list again, so that a record written just before the end is seen.
    for match in _temporaries(folder):
        if match["kind"] == "run" and _writer_of(match) in dead:
            _complete(folder / match.string)
    removed = []
    for match in _temporaries(folder):
        if match["kind"] == "tmp" and _writer_of(match) in dead:
            remove(folder / match.string)
            removed.append(match.string)
    return sorted(removed)


def _temporaries(folder):
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return [match for name in names if (match := _TEMPORARY.fullmatch(name)) and _owned(os.path.join(folder, name))]


def sweep_legacy(folder, prefix, suffix=""):
    """Remove the temporaries ``PREFIX????????SUFFIX`` older drumstroke left in ``folder`` before this process started.

    Those names (``tempfile``'s) do not say who wrote them: only one older than this process and
    owned by this user is taken for a killed run's.
    """
    pattern = glob.escape(os.path.join(folder, prefix)) + "?" * 8 + glob.escape(suffix)
    removed = []
    for name in glob.glob(pattern):
        middle = os.path.basename(name)[len(prefix):len(os.path.basename(name)) - len(suffix)]
        try:
            old = os.lstat(name).st_mtime < _STARTED
        except OSError:
            continue
        if _LEGACY.fullmatch(middle) and old and _owned(name):
            remove(name)
            removed.append(os.path.basename(name))
    return sorted(removed)


def _sweep_once(path):
    """Sweep ``path``'s folder the first time this process writes there, and older drumstroke's temporaries of it."""
    folder = os.path.abspath(path.parent)
    with _SWEPT_LOCK:
        first = (os.getpid(), folder) not in _SWEPT
        _SWEPT.add((os.getpid(), folder))
    if first:
        sweep(folder)
    sweep_legacy(folder, f".{path.name}.", ".tmp")


def describe_temporary(path):
    """What the temporary at ``path`` is, in words, or None if it is not one of drumstroke's."""
    match = _TEMPORARY.fullmatch(Path(path).name)
    if match is None:
        return None
    host, pid, start = _writer_of(match)
    what = "record of a run" if match["kind"] == "run" else "folder" if os.path.isdir(path) else "file"
    if host != _HOST:
        return f"a temporary {what} of drumstroke on another host"
    if _alive(host, pid, start):
        return f"a temporary {what} of drumstroke process {pid}, running"
    return f"a temporary {what} of drumstroke process {pid}, which was stopped before it finished; the next run " \
           "writing here removes it"


@contextlib.contextmanager
def locked(folder, *, shared=False):
    """Hold an advisory lock on ``folder`` (shared for readers), where the system offers ``flock``."""
    try:
        import fcntl

        fd = os.open(folder, os.O_RDONLY)
    except (ImportError, OSError):
        yield
        return
    try:
        with contextlib.suppress(OSError):  # a file system without locks: go on without
            fcntl.flock(fd, fcntl.LOCK_SH if shared else fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)
