"""``python -m drumstroke.cli``: the ``drumstroke`` command."""

import sys

from . import main

if __name__ == "__main__":  # not when a doctest run imports it
    sys.exit(main())
