"""``python -m drumstroke``: the ``drumstroke`` command."""

import sys

from .cli import console

if __name__ == "__main__":  # not when a doctest run imports it
    sys.exit(console())
