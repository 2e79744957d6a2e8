"""Atomic writes: a process killed at any instant leaves the old files whole or the new ones whole.

- **A file** (:func:`write_atomic`) is written to a temporary file beside it, flushed and synced,
  renamed over its path, and the folder synced: a reader sees the old file or the new one.
- **A bundle** (:class:`Bundle`) is the files one command writes together (a CSV and the JSON
  beside it; a run's data, plot and sound). The caller makes it, ``with Bundle() as bundle:``,
  and hands it to each writer (their ``bundle`` argument): the files are written and synced
  under temporary names, and none is renamed into place before the block ends. Then a record
  listing them is written in each folder the bundle writes to, the files are renamed into
  place and the records removed. The last record written is the commit point: killed before
  it, the bundle leaves the old files; after it, the records say the new files are being put
  in place, and the next write to one of those folders finishes that. Until then the files a
  record lists are not read (:func:`unfinished_bundle`): some may be new, some old.
- **A write never replaces what is not a regular file** (a FIFO, a device, a socket: the path is
  refused, not turned into a file), nor, inside :func:`guarding_inputs` (a command's run), a
  file the run read: ``compose s.mid --midi s.mid`` is refused before anything is written over.
- **Temporaries name their writer**, ``.NAME.drumstroke-PID-NONCE.tmp`` (a record ``….bundle``).
  Before a file is written, what killed writers left for it is cleared: their bundles in its
  folder are finished and their temporaries of that file removed. A writer is taken for killed
  when no process of its id runs here; a running writer's temporaries are never touched.
"""

import contextlib
import errno
import json
import os
import re
import secrets
import shutil
import stat
from pathlib import Path

from .errors import ParameterError

_TEMPORARY = re.compile(r"\.(?P<name>.*)\.drumstroke-(?P<pid>\d+)-[0-9a-f]{8}\.(?P<kind>tmp|bundle)", re.DOTALL)


def write_atomic(path, data, *, mode=None, bundle=None):
    """Write ``data`` (str or bytes, or an iterable of their chunks, streamed) to ``path`` through a temporary file
    and a rename.

    The file gets ``mode`` (permission bits, e.g. 0o600 for a secret; it has them from its
    creation, never the umask's first), else the old file's, else what the umask gives. With
    ``bundle`` (a :class:`Bundle`), the file is put in place when the bundle ends, with its
    other files.

    The folder must exist: nothing is created but the file. An error is an ``OSError`` naming
    ``path`` (not the temporary file) with the system's reason: a missing folder, a folder that
    cannot be written, ``path`` a directory, a full disk.
    """
    if bundle is not None:
        bundle.write(path, data, mode=mode)
        return
    path = Path(path)
    with naming(path):
        temporary = _stage(path, data, mode)
        try:
            os.replace(temporary, path)
        except BaseException:
            remove(temporary)
            raise
        sync_folder(path.parent)


def _stage(path, data, mode):
    """Clear what killed writers left for ``path``, then write ``data`` to a new temporary file beside it."""
    check_target(path)
    remove_stale(path.parent, path.name)
    temporary = temporary_path(path)
    write_new(temporary, data.encode() if isinstance(data, str) else data,
              mode=_mode_for(path) if mode is None else mode)
    return temporary


def _mode_for(path):
    """The old file's permissions, or those a new file gets under the umask."""
    try:
        return path.stat().st_mode & 0o777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))

_inputs = None
"""The files read in the run :func:`guarding_inputs` marks, {(device, inode): path}; None outside one."""


def check_target(path):
    """Refuse to write ``path`` if it is a directory, not a regular file, or a file this run read.

    An ``OSError`` naming ``path``, as a failed write's: replaced by a new file, a FIFO or a
    device would no longer be what it was, and an input written over would be lost.

    >>> check_target("/dev/null")
    Traceback (most recent call last):
    ...
    FileExistsError: [Errno 17] it exists and is a character device, not a regular file: it is not written over: '/dev/null'
    """
    try:
        status = os.stat(path)
    except (OSError, ValueError):  # missing (the usual case), or unreadable: the write says why
        return
    if stat.S_ISDIR(status.st_mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    kind = next((kind for test, kind in _KINDS if test(status.st_mode)), None)
    if kind is not None or not stat.S_ISREG(status.st_mode):
        raise FileExistsError(errno.EEXIST, f"it exists and is {kind or 'not a regular file'}, not a regular file: it is "
                                            "not written over", str(path))
    read = _inputs.get((status.st_dev, status.st_ino)) if _inputs is not None else None
    if read is not None:
        same = "" if os.path.abspath(read) == os.path.abspath(path) else f" (as {str(read)!r})"
        raise FileExistsError(errno.EEXIST, f"it is an input of this run{same}: an output is never written over an "
                                            "input", str(path))


@contextlib.contextmanager
def guarding_inputs():
    """Inside, a file read (:func:`note_input`) is never written over by :func:`write_atomic` or a :class:`Bundle`.

    The command line runs each command inside it; outside, a program may write over what it read.
    """
    global _inputs
    saved, _inputs = _inputs, {}
    try:
        yield
    finally:
        _inputs = saved


@contextlib.contextmanager
def not_an_input():
    """Inside, what is read is not noted as an input of the run: a file read to see whether it may be written over."""
    global _inputs
    saved, _inputs = _inputs, None
    try:
        yield
    finally:
        _inputs = saved


def note_input(path, status=None):
    """Record that the run read the file ``path`` (its ``os.stat`` result, if at hand), for :func:`check_target`."""
    if _inputs is None:
        return
    try:
        status = os.stat(path) if status is None else status
    except (OSError, ValueError):
        return
    _inputs[(status.st_dev, status.st_ino)] = path


@contextlib.contextmanager
def naming(path):
    """Inside, an ``OSError`` that names a temporary (or nothing) names ``path``, the user's file or folder."""
    try:
        yield
    except OSError as error:
        if error.filename is not None and not any(_TEMPORARY.fullmatch(part) for part in Path(error.filename).parts):
            raise
        raise OSError(error.errno, error.strerror or str(error), str(path)) from None  # the subclass follows errno


# --- bundles: files put in place together --------------------------------------------------------------------------


class Bundle:
    """Files written together: all are put in place when the ``with`` block ends, none if it raises.

    Give it to the writers as their ``bundle`` (``write_json(path, data, bundle=bundle)``). A file
    written twice counts once, the last time. See the module's notes for what a kill leaves.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with Bundle() as bundle:
    ...     write_atomic(folder / "a.csv", "t\\n0\\n", bundle=bundle)
    ...     bundle.write(folder / "a.json", "{}")
    ...     print(sorted(p.name for p in folder.iterdir() if not p.name.startswith(".")))
    []
    >>> sorted(p.name for p in folder.iterdir())
    ['a.csv', 'a.json']
    """

    def __init__(self):
        self._staged = {}

    def __enter__(self):
        return self

    def __exit__(self, kind, error, trace):
        staged, self._staged = self._staged, {}
        if kind is None:
            _put_in_place(staged)
        else:
            for temporary in staged.values():
                remove(temporary)

    def write(self, path, data, *, mode=None):
        """Write ``data`` (str or bytes) for ``path`` as :func:`write_atomic` does, put in place when the bundle ends."""
        path = Path(os.path.abspath(path))
        with naming(path):
            temporary = _stage(path, data, mode)
        earlier = self._staged.pop(path, None)
        if earlier is not None:
            remove(earlier)
        self._staged[path] = temporary


def bundled(bundle):
    """``with bundled(bundle) as files:``: ``bundle`` if given (its maker ends it), else a new :class:`Bundle`."""
    return contextlib.nullcontext(bundle) if bundle is not None else Bundle()


def _put_in_place(staged):
    """Rename the staged files ({path: temporary}) into place, past a record in each folder if there are several."""
    folders = list(dict.fromkeys(path.parent for path in staged))
    records = [temporary_path(folder / "files", kind="bundle") for folder in folders] if len(staged) > 1 else []
    text = json.dumps({"records": [str(r) for r in records], "files": [[str(p), str(t)] for p, t in staged.items()]})
    try:
        for record in records:
            with naming(record.parent):
                write_new(record, text.encode(), mode=0o600)
        for folder in folders:
            sync_folder(folder)
    except BaseException:
        for temporary in [*staged.values(), *records]:
            remove(temporary)
        raise
    try:  # committed: a kill or an interrupt from here on is finished by the next write in one of the folders
        for path, temporary in staged.items():
            with naming(path):
                os.replace(temporary, path)
    except OSError:
        for temporary in [*staged.values(), *records]:
            remove(temporary)  # the command fails, naming the file that could not be put in place
        raise
    for folder in folders:
        sync_folder(folder)
    for record in records:
        remove(record)


def _finish(record):
    """Finish a killed writer's bundle from its ``record``: in place if all its records were written, else undone."""
    data = _read_record(record)
    pid = _TEMPORARY.fullmatch(record.name)["pid"]
    if data is None or not all(_is_temporary_of(r, pid, "bundle") for r in data["records"]) or not all(
            _is_temporary_of(t, pid, "tmp") and Path(t).parent == Path(p).parent for p, t in data["files"]):
        remove(record)  # cut short by the kill (not committed), or not drumstroke's: touch nothing it names
        return
    committed = all(_read_record(Path(r)) == data for r in data["records"])
    for path, temporary in data["files"]:
        if committed:
            with contextlib.suppress(OSError):  # already in place
                os.replace(temporary, path)
        else:
            remove(temporary)
    for r in [*data["records"], record]:  # itself too, should its folder have moved since
        sync_folder(Path(r).parent)
        remove(r)


def _read_record(record):
    """A bundle's record ({"records": [path], "files": [[path, temporary]]}), or None if it is not whole."""
    try:
        data = json.loads(Path(record).read_text())
        if all(isinstance(r, str) for r in data["records"]) and all(
                len(f) == 2 and all(isinstance(p, str) for p in f) for f in data["files"]):
            return data
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, RecursionError):
        pass
    return None


def unfinished_bundle(path):
    """The record of a committed bundle that lists ``path`` and whose files are not all in place yet, or None.

    A reader refuses such a file: the bundle's other files may still be the old ones.
    """
    target = os.path.abspath(path)
    folder = os.path.dirname(target)
    try:
        names = os.listdir(folder)
    except OSError:
        return None
    for name in names:
        match = _TEMPORARY.fullmatch(name)
        if match is None or match["kind"] != "bundle":
            continue
        data = _read_record(Path(folder) / name)
        if data is not None and any(os.path.abspath(p) == target for p, _ in data["files"]) and all(
                _read_record(Path(r)) == data for r in data["records"]):  # committed: every record written
            return Path(folder) / name
    return None


def _is_temporary_of(path, pid, kind):
    match = _TEMPORARY.fullmatch(Path(path).name)
    return match is not None and match["pid"] == pid and match["kind"] == kind


# --- temporaries and what killed writers left ---------------------------------------------------------------------


def temporary_path(path, *, kind="tmp"):
    """A new temporary name beside ``path`` naming this process: ``.NAME.drumstroke-PID-NONCE.tmp``."""
    path = Path(path)
    return path.parent / f".{path.name[:100]}.drumstroke-{os.getpid()}-{secrets.token_hex(4)}.{kind}"


def remove_stale(folder, name=None):
    """Clear what killed writers left in ``folder``; return the names of the temporaries removed.

    Their bundles' records are seen to first (the files put in place if the bundle had
    committed), then their temporaries are removed: of the file ``name`` only, if given.
    """
    folder = Path(folder)
    stale = _stale(folder)
    if any(match["kind"] == "bundle" for match in stale):
        for match in stale:
            if match["kind"] == "bundle":
                _finish(folder / match.string)
        stale = _stale(folder)
    removed = sorted(m.string for m in stale if m["kind"] == "tmp" and (name is None or m["name"] == name[:100]))
    for temporary in removed:
        remove(folder / temporary)
    return removed


def _stale(folder):
    """The temporaries in ``folder`` whose writers no longer run, as matches of their names."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return [match for name in names if (match := _TEMPORARY.fullmatch(name)) and not _running(int(match["pid"]))]


def _running(pid):
    """Whether the process ``pid`` may be running here: yes unless the system says there is none."""
    if pid == os.getpid() or os.name != "posix":  # elsewhere os.kill would stop it
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):
        return True  # another user's, or no such id to ask about: left alone
    return True


def describe_temporary(path):
    """What the temporary at ``path`` is, in words, or None if it is not one of drumstroke's."""
    match = _TEMPORARY.fullmatch(Path(path).name)
    if match is None:
        return None
    pid = int(match["pid"])
    what = "record of a bundle" if match["kind"] == "bundle" else "folder" if os.path.isdir(path) else "file"
    if _running(pid):
        return f"a temporary {what} of drumstroke process {pid}, running"
    return f"a temporary {what} of drumstroke process {pid}, which was stopped before it finished; the next run " \
           "writing here removes it"


# --- files and folders ------------------------------------------------------------------------------------------------


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
    remove_stale(path.parent, path.name)
    work = temporary_folder(path)
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
        remove(work)


def temporary_folder(path):
    """Make and return a new, empty temporary folder beside ``path`` (named by :func:`temporary_path`)."""
    folder = temporary_path(path)
    os.mkdir(folder)
    return folder


def write_new(path, data, *, mode=0o666):
    """Create the file ``path`` (it must not exist) holding ``data``, synced to the disk.

    ``data`` is bytes, or an iterable of str or bytes chunks written as they come (a long output streamed).
    """
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o600)
    try:
        with os.fdopen(fd, "wb") as handle:
            os.chmod(path, mode)
            for chunk in (data,) if isinstance(data, bytes) else data:
                handle.write(chunk.encode() if isinstance(chunk, str) else chunk)
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
