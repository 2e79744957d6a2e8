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

import tomllib
from pathlib import Path

from .._atomic import write_atomic
from ..errors import ParameterError

SUFFIXES = (".toml",)
"""The extension of the TOML files written."""


def read_toml(path, what):
    """The TOML file at ``path`` as a dict; an unreadable or invalid file is a ParameterError naming the ``what``."""
    try:
        return tomllib.loads(Path(path).read_text())
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"{what} {str(path)!r} cannot be read: {reason}") from None
    except tomllib.TOMLDecodeError as error:
        raise ParameterError(f"{what} {str(path)!r} is not valid TOML: {error}") from None


def write_toml(path, data):
    """Write ``data`` (a dict of scalars, lists and tables) as TOML to ``path``, atomically."""
    write_atomic(path, toml_text(data))


def toml_text(data):
    """TOML text for ``data`` (a dict): its scalars first, then a table per mapping, nested as deep as it goes."""
    import tomli_w  # only writers need it

    return tomli_w.dumps(_plain(data))


def _plain(value):
    """``value`` with numpy numbers and arrays as Python numbers and lists, and tuples as lists (tomli-w's types)."""
    if isinstance(value, dict):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _plain(value.tolist())
    return value
