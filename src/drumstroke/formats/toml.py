"""TOML files, both ways: recipes, palettes, sweeps, note mappings, robot and listening-test configs.

Reading is the standard library's ``tomllib``; writing is ``tomli-w``'s, so any TOML reader
reads a written file back to the same data: floats at full precision, nested tables, arrays
of arrays or of tables, strings with any character. Numpy numbers and arrays are written as
the numbers and lists they hold.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "r.toml"
>>> write_toml(path, {"cor": 0.86, "force": {"kind": "constant", "value": 100.0}})
>>> print(path.read_text(), end="")
cor = 0.86
<BLANKLINE>
[force]
kind = "constant"
value = 100.0
>>> read_toml(path, "recipe")
{'cor': 0.86, 'force': {'kind': 'constant', 'value': 100.0}}
"""

import contextlib
import re
import sys
import tomllib

from .._atomic import write_atomic
from ..errors import ParameterError, located
from .reading import MAX_DEPTH, MIB, check_document, read_text

SUFFIXES = (".toml",)
"""The extension of the TOML files written."""

MAX_BYTES = 8 * MIB
"""The largest TOML file read (bytes): a recipe, a palette or a config is a few kB."""

_LONG_INTEGER = re.compile(r"[+-]?[0-9][0-9_]{4000,}")


def read_toml(path, what):
    """The TOML file at ``path`` as a dict, read within bounds (:mod:`.reading`).

    A byte-order mark before the text (a Windows editor's) is dropped. A file that cannot be read,
    is not valid TOML, nests deeper than :data:`~drumstroke.formats.reading.MAX_DEPTH` or holds an
    integer beyond a float is a ParameterError naming the ``what`` and the path (and the line or key).
    """
    where = f"{what} {str(path)!r}"
    text = read_text(path, what, limit=MAX_BYTES)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ParameterError(f"{where} is not valid TOML: {error}") from None
    except RecursionError:
        raise ParameterError(f"{where} cannot be read: its tables or arrays nest more than {MAX_DEPTH} levels deep, "
                             "the most a file may") from None
    except ValueError as error:  # tomllib converts integers with int(), which refuses over 4300 digits
        raise ParameterError(f"{where} cannot be read: {_long_integer(text) or error}") from None
    check_document(data, where)
    return data


@contextlib.contextmanager
def reading_toml(path, what):
    """``with reading_toml(path, what) as data:``, the TOML file at ``path`` as :func:`read_toml` reads it; an error
    raised inside, by whatever builds something of ``data``, names the file (``recipe 'r.toml': cor must be …``).

    >>> import pathlib, tempfile
    >>> from drumstroke._checks import check_real
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "r.toml"
    >>> write_toml(path, {"cor": 1.5})
    >>> with reading_toml(path, "recipe") as data:
    ...     check_real("cor", data["cor"], low=0.0, high=1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: recipe '.../r.toml': cor must be in [0, 1], got 1.5
    """
    data = read_toml(path, what)
    with located(f"{what} {str(path)!r}"):
        yield data


def write_toml(path, data, *, mode=None, bundle=None):
    """Write ``data`` (a dict of scalars, lists and tables) as TOML to ``path``, atomically (``mode`` and
    ``bundle``: as :func:`drumstroke._atomic.write_atomic`'s)."""
    write_atomic(path, toml_text(data), mode=mode, bundle=bundle)


def toml_text(data):
    """TOML text for ``data`` (a dict): its scalars first, then a table per mapping, nested as deep as it goes."""
    import tomli_w  # only writers need it

    return tomli_w.dumps(_plain(data))


def _long_integer(text):
    """Where the first integer too long to convert is: ``line N: KEY is an integer of D digits``, or None."""
    for match in _LONG_INTEGER.finditer(text):
        digits = sum(c.isdigit() for c in match.group())
        if digits > sys.get_int_max_str_digits():
            start = text.rfind("\n", 0, match.start()) + 1
            before = text[start:match.start()]
            key = before.split("=", 1)[0].strip() if "=" in before else "a value"
            return (f"line {text.count(chr(10), 0, start) + 1}: {key} is an integer of {digits} digits, beyond any "
                    "number drumstroke takes (|x| < 1.8e308)")
    return None


def _plain(value):
    """``value`` with numpy numbers and arrays as Python numbers and lists, and tuples as lists (tomli-w's types)."""
    if isinstance(value, dict):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _plain(value.tolist())
    return value
