"""A user's file, read within bounds: every reader of :mod:`drumstroke.formats` opens files through here.

A file is read only if it is a regular file (a FIFO, a device such as ``/dev/zero``, a directory
or a socket is refused by name, at once: it is opened without blocking and checked before a byte
is read) and no larger than its format's limit; text must be UTF-8, and a byte-order mark before it (a
Windows editor's) is dropped, whatever the format. A document read from TOML or
JSON is then walked once (:func:`check_document`): tables and arrays nested deeper than
:data:`MAX_DEPTH`, and integers beyond any float (more than 308 digits), are refused naming the
key. Every refusal is a :class:`~drumstroke.errors.ParameterError` naming what the file is, its
path and the reason (the system's, for an ``OSError``); a caller never sees an ``OSError``,
``UnicodeDecodeError``, ``MemoryError`` or ``RecursionError`` from a user's file.

Examples
--------
>>> import os, pathlib, tempfile
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> (folder / "r.toml").write_text("cor = 0.86\\n")
11
>>> read_text(folder / "r.toml", "recipe", limit=1000)
'cor = 0.86\\n'
>>> os.mkfifo(folder / "pipe.toml")
>>> read_text(folder / "pipe.toml", "recipe", limit=1000)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: recipe '.../pipe.toml' cannot be read: it is a FIFO (named pipe), not a regular file
>>> read_text("/dev/zero", "samples.file", limit=1000)
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: samples.file '/dev/zero' cannot be read: it is a character device, not a regular file
>>> check_document({"force": {"parts": [{"value": 10**400}]}}, "recipe 'r.toml'")
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: recipe 'r.toml': force.parts[0].value is an integer of 401 digits, beyond any number drumstroke takes (|x| < 1.8e308)
"""

import csv
import io
import os
import re
import stat
import sys

from .._atomic import note_input, unfinished_bundle
from .._checks import digits
from ..errors import ParameterError

MIB = 1 << 20
"""A mebibyte (bytes), the unit the formats' size limits are given in."""

MAX_DEPTH = 64
"""How deeply tables and arrays of a TOML or JSON document may nest (a recipe needs 5 levels, a sum of sums 7)."""

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def read_bytes(path, what, *, limit):
    """The bytes of the regular file at ``path``, at most ``limit`` of them; anything else is refused naming ``what``.

    Parameters
    ----------
    path : str or path-like
    what : str
        What the file is, for messages (``"recipe"``, ``"samples.file"``).
    limit : int
        The most bytes the file may hold.

    Raises
    ------
    ParameterError
        ``WHAT 'PATH' cannot be read: REASON``: the system's reason (no such file, permission
        denied, …), not a regular file (named: a FIFO, a directory, a device, a socket), larger
        than ``limit``, or one of the files of a bundle whose publication did not finish
        (:func:`drumstroke._atomic.unfinished_bundle`).
    """
    _refuse_special(path, what)
    try:
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    except (OSError, ValueError) as error:  # ValueError: a NUL in the name
        raise _unreadable(path, what, _reason(error)) from None
    with os.fdopen(descriptor, "rb") as handle:
        try:
            status = os.fstat(descriptor)
            _refuse(status.st_mode, path, what)  # what was opened: the path may have changed since
            note_input(path, status)
            record = unfinished_bundle(path)
            if record is not None:
                raise _unreadable(path, what, f"its publication did not finish ({record.name} beside it lists it: the "
                                              "run writing it was stopped; run it again, or any write in the folder "
                                              "finishes it)")
            if status.st_size <= limit:
                data = handle.read(limit + 1)  # a file whose size the system does not know (/proc) stops here too
        except OSError as error:
            raise _unreadable(path, what, _reason(error)) from None
    if status.st_size > limit or len(data) > limit:
        article = "an" if what[:1] in "aeiou" else "a"
        raise _unreadable(path, what, f"it is larger than {_size(limit)}, the most {article} {what} may be")
    return data


def read_text(path, what, *, limit):
    """The text of the regular file at ``path`` (UTF-8, at most ``limit`` bytes), as :func:`read_bytes` reads it.

    A byte-order mark before the text is dropped. Text that is not UTF-8 is refused naming the
    line and column of the first bad byte.
    """
    data = read_bytes(path, what, limit=limit)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        column = error.start - (data.rfind(b"\n", 0, error.start) + 1) + 1
        raise _unreadable(path, what, f"not a UTF-8 text file (byte 0x{data[error.start]:02x} at line {line}, "
                                      f"column {column})") from None


def read_csv_rows(path, what, *, limit, rows_of=""):
    """The rows (lists of text cells) of the CSV file at ``path``, read by :func:`read_text`.

    ``rows_of`` says what the rows should be (e.g. ``" of 't,value' rows"``), for the message when
    the text is not CSV.
    """
    return csv_rows(read_text(path, what, limit=limit), path, what, rows_of=rows_of)


def csv_rows(text, path, what, *, rows_of=""):
    """The rows (lists of text cells) of the CSV ``text``, read from the file ``path`` (for the message, as
    :func:`read_csv_rows`)."""
    try:
        return list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as error:
        raise ParameterError(f"{what} {os.fspath(path)!r} is not a CSV file{rows_of}: {error}", parameter=what,
                             value=os.fspath(path), allowed="a CSV file") from None


def check_regular(path, what):
    """Refuse ``path`` (naming ``what``) unless it is a regular file that exists; nothing is opened."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError) as error:
        raise _unreadable(path, what, _reason(error)) from None
    _refuse(mode, path, what)


def check_document(data, where, *, depth=MAX_DEPTH):
    """Refuse a TOML or JSON document (dicts, lists, scalars) that nests too deeply or holds an integer beyond a float.

    The walk is iterative, so it never runs out of stack. ``where`` starts each message
    (``"recipe 'r.toml'"``), then the key path of the offending value (``force.parts[0].value``).
    """
    stack = [(data, "", 0)]
    while stack:
        value, key, level = stack.pop()
        if isinstance(value, dict | list):
            if level >= depth:
                top = re.match(r"[^.\[]*", key).group() or "the document"
                raise ParameterError(f"{where}: {top} nests tables or arrays more than {depth} levels deep, the most "
                                     "a file may")
            items = value.items() if isinstance(value, dict) else enumerate(value)
            for name, item in items:
                path = f"{key}[{name}]" if isinstance(value, list) else f"{key}.{name}" if key else str(name)
                stack.append((item, path, level + 1))
        elif isinstance(value, Huge) or isinstance(value, int) and value.bit_length() > 1024:
            count = value.digits if isinstance(value, Huge) else digits(value)
            raise ParameterError(f"{where}: {key} is an integer of {count} digits, beyond any number drumstroke takes "
                                 "(|x| < 1.8e308)")


class Huge:
    """An integer literal too long to convert (the interpreter's limit is 4300 digits), kept as its digit count."""

    def __init__(self, text):
        self.digits = len(text.lstrip("+-"))


def parse_int(text):
    """An integer literal as an int, or :class:`Huge` when it is too long to convert (a JSON reader's ``parse_int``)."""
    most = sys.get_int_max_str_digits()
    return Huge(text) if most and len(text.lstrip("+-")) > most else int(text)


def _refuse_special(path, what):
    """Refuse a path that exists and is not a regular file, before it is opened (opening a FIFO could block)."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):  # missing, unreadable, or a name with a NUL: opening says why
        return
    _refuse(mode, path, what)


def _refuse(mode, path, what):
    for test, kind in _KINDS:
        if test(mode):
            raise _unreadable(path, what, f"it is {kind}, not a regular file")
    if not stat.S_ISREG(mode):
        raise _unreadable(path, what, "it is not a regular file")


def _unreadable(path, what, reason):
    """The error that the file ``path`` (the parameter ``what``) cannot be read, for ``reason``."""
    return ParameterError(f"{what} {os.fspath(path)!r} cannot be read: {reason}", parameter=what, value=os.fspath(path),
                          allowed="a readable regular file")


def _reason(error):
    return getattr(error, "strerror", None) or str(error)


def _size(limit):
    return f"{limit / MIB:g} MiB" if limit >= MIB else f"{limit} bytes"
