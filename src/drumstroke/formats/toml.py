"""TOML files, both ways: recipes, palettes, sweeps, note mappings, robot and listening-test configs.

Reading is the standard library's ``tomllib``; writing covers what drumstroke writes — top-level
scalars, then one table per mapping, with arrays and inline tables inside — so a written file reads
back to the same data.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "r.toml"
>>> write_toml(path, {"cor": 0.86, "force": {"kind": "constant", "value": 100.0}})
>>> read_toml(path, "recipe")
{'cor': 0.86, 'force': {'kind': 'constant', 'value': 100.0}}
"""

import tomllib
from pathlib import Path

from .._atomic import write_atomic
from ..errors import ParameterError


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
    """Write ``data`` (a dict of scalars, lists and one level of tables) as TOML to ``path``, atomically."""
    write_atomic(path, toml_text(data))


def toml_text(data):
    """TOML text for ``data``: top-level scalars, then one table per mapping."""
    lines = [f"{key} = {_value(value)}" for key, value in data.items() if not isinstance(value, dict)]
    for key, value in data.items():
        if isinstance(value, dict):
            lines.append(f"\n[{key}]")
            lines.extend(f"{k} = {_value(v)}" for k, v in value.items())
    return "\n".join(lines) + "\n"


def _value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value))
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"cannot write {value!r} as TOML")
