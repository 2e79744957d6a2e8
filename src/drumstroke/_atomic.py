"""Atomic writes: a crash mid-write leaves the old file whole, and a folder appears only complete."""

import os
import shutil
import tempfile
from pathlib import Path

from .errors import ParameterError


def write_atomic(path, data):
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.

    The folder must exist: nothing is created but the file. An error is an ``OSError`` naming
    ``path`` (not the temporary file) with the system's reason: a missing folder, a folder
    that cannot be written, ``path`` a directory, a full disk.
    """
    path = Path(path)
    temporary = None
    try:
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.chmod(temporary, _mode_for(path))
        with os.fdopen(fd, "wb") as handle:
            handle.write(data.encode() if isinstance(data, str) else data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(path)) from None  # the subclass follows errno
    finally:
        if temporary is not None and os.path.lexists(temporary):
            os.unlink(temporary)


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
    work = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
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
        shutil.rmtree(work, ignore_errors=True)
