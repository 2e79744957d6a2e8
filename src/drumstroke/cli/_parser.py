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

_LONG = re.compile(rf"\S{{{MOST + 1},}}")


def shortened(message, *, most=MOST):
    """``message`` on one line, each long value cut to ``most`` characters followed by its length, and the whole
    to ten times that: no input makes a long error line.

    >>> shortened("velocity must be an integer, got " + "x" * 10_000_000)
    'velocity must be an integer, got xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx... (10000000 characters)'
    >>> shortened("a " * 10_000)[-40:]
    ' a a a a a ... (19999 characters in all)'
    
    """
    line = re.sub(r"\s*\n\s*", " ", message.strip())
    line = _LONG.sub(lambda long: f"{long.group()[:most - 3]}... ({len(long.group())} characters)", line)
    whole = 10 * most
    return line if len(line) <= whole else f"{line[:whole].rstrip()} ... ({len(line)} characters in all)"


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 2, without the usage text.

    Abbreviated options are refused (``--rat`` is not ``--rate``): a later option must not change
    what an old command line means.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **{"allow_abbrev": False, **kwargs})

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {shortened(message)}\n")
