"""Atomic file writes: a crash mid-write leaves the old file whole."""

import os
import tempfile
from pathlib import Path


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
