"""The command line's parser and its one wording of a library parameter as an option: light, for the front door.

``drumstroke --version`` and ``--help`` import this and nothing of the library's numerics.
"""

import argparse
import re

OPTIONS = {"mapping": "--mapping", "channels": "--channel", "tracks": "--track", "rudiment": "NAME"}
"""The option of each library parameter the command line passes on under another name: what errors and reports
about that parameter call it (:func:`named_option`)."""

ALLOWED = {"rudiment": "a name, title or number in [1, 40] of the rudiments 'drumstroke rudiment --list' lists"}
"""What a library parameter allows, in the command line's words where the library's point at Python (the
rudiments: ``rudiments()``): errors about it say this instead (:func:`named_option`)."""


def named_option(error):
    """``error`` (a ParameterError) about its parameter's option, when the command line has one: ``--channel ...``."""
    option = OPTIONS.get(error.parameter)
    return error.renamed(option, allowed=ALLOWED.get(error.parameter)) if option else error


MOST = 80
"""The most characters of one value an error line shows; a longer one is cut, with its length said."""

PATH_MAX = 4096
"""The longest path a system takes (characters): a path in an error line is shown whole, up to this."""

_LONG = re.compile(rf"\S{{{MOST + 1},}}")


def shortened(message, *, most=MOST):
    """``message`` on one line, each long value cut to ``most`` characters followed by its length (a path, which
    names the file at fault, up to :data:`PATH_MAX`), and the whole to :data:`PATH_MAX`: no input makes a long
    error line.

    >>> shortened("velocity must be an integer, got " + "x" * 10_000_000)
    'velocity must be an integer, got xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx... (10000000 characters)'
    >>> shortened("recipe '/tmp/" + "a" * 100 + "/r.toml' is missing")[-30:]
    "aaaaaaaaaaa/r.toml' is missing"
    >>> shortened("a " * 10_000)[-40:]
    ' a a a a a ... (19999 characters in all)'
    """
    line = re.sub(r"\s*\n\s*", " ", message.strip())
    line = _LONG.sub(lambda long: _cut(long.group(), most), line)
    return line if len(line) <= PATH_MAX else f"{line[:PATH_MAX].rstrip()} ... ({len(line)} characters in all)"


def _cut(value, most):
    if "/" in value and len(value) <= PATH_MAX:
        return value
    return f"{value[:most - 3]}... ({len(value)} characters)"


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 2, without the usage text.

    Abbreviated options are refused (``--rat`` is not ``--rate``): a later option must not change
    what an old command line means.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **{"allow_abbrev": False, **kwargs})

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {shortened(message)}\n")
